//! `kiln merge` over structure-aware mutations of a valid set of shards: the input's bytes are
//! a list of edits (counts, indices, bake options, ranges, values, checks, tables dropped),
//! after which the digests are recomputed (as an attacker who read kiln's source would) unless
//! the first byte says not to; or, with a first byte of 0xff, the rest replaces one shard's
//! JSON. Whatever the edits, the merge is an error or tables every reader accepts, never a
//! panic or an allocation past the fuzzer's limit.
#![no_main]

use kiln::shard::{ShardFile, ShardIndex, ShardedBake};
use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::OnceLock;

fn valid() -> &'static Vec<ShardFile> {
    static SHARDS: OnceLock<Vec<ShardFile>> = OnceLock::new();
    SHARDS.get_or_init(|| {
        let bake = ShardedBake {
            options: kiln::BakeOptions {
                quantities: vec![kiln::Quantity::E, kiln::Quantity::EAvg],
                size: 6,
                max_error: Some(1e-3),
                ..kiln::BakeOptions::default()
            },
            formats: vec![kiln::format::Format::Json],
            precision: kiln::format::Precision::F32,
        };
        (0..3)
            .map(|i| kiln::shard::bake_shard(&bake, ShardIndex::new(i, 3).unwrap(), &|_| {}).unwrap())
            .collect()
    })
}

/// A number from the next eight bytes, or a hostile size chosen by one.
fn number(bytes: &mut &[u8]) -> u64 {
    let Some((&b, rest)) = bytes.split_first() else {
        return 0;
    };
    *bytes = rest;
    const SIZES: [u64; 8] = [0, 1, 4097, 100_000, 1 << 31, 1 << 40, u64::MAX, u64::MAX / 2 + 1];
    if b < 0x80 {
        SIZES[usize::from(b) % SIZES.len()]
    } else {
        let n = bytes.len().min(8);
        let mut word = [0; 8];
        word[..n].copy_from_slice(&bytes[..n]);
        *bytes = &bytes[n..];
        u64::from_le_bytes(word)
    }
}

fn edit(shards: &mut [ShardFile], bytes: &mut &[u8]) {
    let Some((&op, rest)) = bytes.split_first() else {
        return;
    };
    *bytes = rest;
    let s = usize::from(op >> 4) % shards.len();
    let n = number(bytes);
    let shard = &mut shards[s];
    let t = (n as usize) % shard.tables.len().max(1);
    match op & 0x0f {
        0 => shard.count = n as usize,
        1 => shard.index = n as usize,
        2 => shard.bake.options.size = n as usize,
        3 => shard.bake.options.ior_size = n as usize,
        4 => shard.bake.options.samples = n,
        5 => shard.bake.options.scrambles = n as u32,
        6 => shard.bake.options.max_error = Some(f64::from_bits(n)),
        7 => shard.bake.options.ior_max = f64::from_bits(n),
        8 if !shard.tables.is_empty() => shard.tables[t].range.0 = n as usize,
        9 if !shard.tables.is_empty() => shard.tables[t].range.1 = n as usize,
        10 if !shard.tables.is_empty() => {
            let table = &mut shard.tables[t];
            if !table.value.is_empty() {
                let k = (n >> 32) as usize % table.value.len();
                table.value[k] = f64::from_bits(n.rotate_left(17)).clamp(-1e300, 1e300);
            }
        }
        11 if !shard.tables.is_empty() => {
            let table = &mut shard.tables[t];
            if !table.one_minus_value.is_empty() {
                let k = (n >> 32) as usize % table.one_minus_value.len();
                table.one_minus_value[k] = (n as f64) / u64::MAX as f64;
            }
        }
        12 if !shard.tables.is_empty() => shard.tables[t].check.iter_mut().for_each(|c| c.0 = 0.0),
        13 if !shard.tables.is_empty() => {
            shard.tables.remove(t);
        }
        14 if !shard.tables.is_empty() => shard.tables[t].value.truncate(n as usize % 64),
        _ => shard.bake.options.seed = n,
    }
}

fuzz_target!(|data: &[u8]| {
    let mut shards = valid().clone();
    let Some((&mode, mut bytes)) = data.split_first() else {
        return;
    };
    if mode == 0xff {
        match serde_json::from_slice::<ShardFile>(bytes) {
            Ok(shard) => shards[0] = shard,
            Err(_) => return,
        }
    } else {
        while !bytes.is_empty() {
            edit(&mut shards, &mut bytes);
        }
        if mode & 1 == 0 {
            for shard in &mut shards {
                shard.bake_digest = shard.bake.digest();
                for table in &mut shard.tables {
                    table.digest = table.compute_digest();
                }
            }
        }
    }
    let named: Vec<(PathBuf, ShardFile)> = shards
        .into_iter()
        .enumerate()
        .map(|(i, s)| (PathBuf::from(format!("kiln-shard-{i}-of-3.json")), s))
        .collect();
    if let Ok((_, tables)) = kiln::shard::merge(&named) {
        for table in &tables {
            assert!(table.check().is_ok());
        }
    }
});
