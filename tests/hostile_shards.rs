//! Shard files as an attacker on a shared cluster filesystem would write them (issue 41): a
//! digest proves only that a file is as its writer left it, and anyone can recompute kiln's
//! (FNV-1a), so `kiln merge` must treat every field of a shard as hostile. Each example below
//! edited a real shard and recomputed its digests; each aborted, panicked or wrote a table
//! whose error claim was false before, and must end with exit 2, a message naming the field and
//! its bound, and nothing written. Then structure-aware mutants of a valid set of shards
//! (counts, indices, options, ranges, values, checks, digests recomputed or not) go through the
//! library's merge under a counting allocator: an error or tables that pass every reader's
//! check, never a panic, never an allocation beyond what the shards' own bounds allow.

#![cfg(feature = "cli")]

use std::path::{Path, PathBuf};

use kiln::shard::{ShardFile, ShardIndex, ShardedBake};

#[path = "common/command.rs"]
mod command;
use command::kiln;

#[path = "common/watching.rs"]
mod watching;

fn stderr(output: &std::process::Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Exit 2 with a message on stderr naming every one of `needles`, no panic.
fn refused(output: &std::process::Output, needles: &[&str]) {
    let message = stderr(output);
    assert_eq!(output.status.code(), Some(2), "{message}");
    assert!(!message.contains("panicked"), "{message}");
    for needle in needles {
        assert!(message.contains(needle), "wanted '{needle}' in: {message}");
    }
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The three shards of a small bake (`E` and `E_avg`, 8 x 8, QMC at 1e-3 and its check against
/// the reference), as files in `dir`.
fn three_shards(dir: &Path) -> Vec<PathBuf> {
    (0..3)
        .map(|i| {
            let shard = format!("{i}/3");
            let out = kiln(&[
                "bake",
                "-q",
                "--quantity",
                "e,e-avg",
                "--size",
                "8",
                "--max-error",
                "1e-3",
                "--format",
                "json",
                "--out",
                path(dir),
                "--shard",
                &shard,
            ]);
            assert!(out.status.success(), "{}", stderr(&out));
            dir.join(format!("kiln-shard-{i}-of-3.json"))
        })
        .collect()
}

fn read(file: &Path) -> ShardFile {
    serde_json::from_slice(&std::fs::read(file).unwrap()).unwrap()
}

/// Writes `shard` with both digests recomputed, as an attacker who read kiln's source would.
fn forge(file: &Path, mut shard: ShardFile) {
    shard.bake_digest = shard.bake.digest();
    for table in &mut shard.tables {
        table.digest = table.compute_digest();
    }
    std::fs::write(file, serde_json::to_vec(&shard).unwrap()).unwrap();
}

/// `kiln merge` of `files` into a fresh `out`, which must not exist afterwards when refused.
fn merge(files: &[PathBuf], out: &Path) -> std::process::Output {
    let mut args = vec!["merge", "--out", path(out)];
    args.extend(files.iter().map(|f| path(f)));
    kiln(&args)
}

/// A shard count or index beyond `--shard`'s bounds sized an allocation (capacity overflow,
/// exit 101): now refused by name before anything is sized by it.
#[test]
fn a_shard_count_beyond_the_bound_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let files = three_shards(dir.path());
    let out = dir.path().join("out");
    for count in [1_099_511_627_776_usize, 9_223_372_036_854_775_808] {
        let mut shard = read(&files[0]);
        shard.count = count;
        forge(&files[0], shard);
        refused(
            &merge(&files, &out),
            &[
                "kiln-shard-0-of-3.json: index and count",
                "the shard count must be 1 to 100000",
                &count.to_string(),
            ],
        );
        assert!(!out.exists());
    }
    // The raw JSON too (above usize: serde's own error, not a panic).
    let text = std::fs::read_to_string(&files[1]).unwrap();
    let at = text.find("\"count\":3").unwrap();
    let edited = format!(
        "{}\"count\":184467440737095516160{}",
        &text[..at],
        &text[at + 9..]
    );
    std::fs::write(&files[1], edited).unwrap();
    refused(&merge(&files, &out), &["not a readable kiln shard file"]);
    assert!(!out.exists());
}

/// Options under a recomputed bake digest were trusted: `size = 100000` aborted on an 80 GB
/// allocation, `2147483648` panicked. Now every bound `kiln bake` applies, each axis and their
/// product, is applied first.
#[test]
fn forged_bake_options_get_every_bound_kiln_bake_applies() {
    let dir = tempfile::tempdir().unwrap();
    let files = three_shards(dir.path());
    let out = dir.path().join("out");
    type Edit = fn(&mut ShardedBake);
    let cases: [(Edit, &[&str]); 6] = [
        (
            |b| b.options.size = 100_000,
            &["size must be between 2 and 4096 (got 100000)"],
        ),
        (
            |b| b.options.size = 2_147_483_648,
            &["size must be between 2 and 4096 (got 2147483648)"],
        ),
        (|b| b.options.samples = 1 << 60, &["--samples", "2^32"]),
        (
            |b| {
                b.options.size = 4096;
                b.options.ior_size = 5;
                b.options.quantities = vec![kiln::Quantity::EDielectric];
            },
            &["5 x 4096 x 4096 = 83886080 texels", "67108864 (2^26)"],
        ),
        (
            |b| b.options.max_error = Some(0.0),
            &["max-error must be between 1e-10 and 0.5"],
        ),
        (
            |b| b.options.ior_max = 1e300,
            &["ior-max must be above 1 and at most 100"],
        ),
    ];
    for (edit, needles) in cases {
        let shards: Vec<ShardFile> = files.iter().map(|f| read(f)).collect();
        for (file, mut shard) in files.iter().zip(shards.clone()) {
            edit(&mut shard.bake);
            forge(file, shard);
        }
        let mut wanted = vec!["its bake options are not a bake kiln runs"];
        wanted.extend_from_slice(needles);
        refused(&merge(&files, &out), &wanted);
        assert!(!out.exists());
        for (file, shard) in files.iter().zip(shards) {
            forge(file, shard);
        }
    }
}

/// Values set to 0.5 with their check terms set to 0 and the digests recomputed merged with
/// exit 0 into a table claiming `node_max_error 0.0`; values of 5.0 were written too. Now the
/// merge computes texels and check terms again at a keyed sample, and every value must be in
/// the range every reader accepts.
#[test]
fn forged_values_and_error_claims_are_not_written() {
    let dir = tempfile::tempdir().unwrap();
    let files = three_shards(dir.path());
    let out = dir.path().join("out");
    let originals: Vec<ShardFile> = files.iter().map(|f| read(f)).collect();
    // Every value of E set to `v`, the check's terms to 0, as one careful forger would.
    for (v, needles) in [
        (
            0.5,
            &["the value of ggx-height-correlated-E at texel", "5e-1"][..],
        ),
        (5.0, &["ggx-height-correlated-E", "texel"][..]),
    ] {
        for (file, original) in files.iter().zip(&originals) {
            let mut shard = original.clone();
            let e = &mut shard.tables[0];
            assert_eq!(e.spec.quantity, kiln::Quantity::E);
            e.value.iter_mut().for_each(|x| *x = v);
            e.one_minus_value.iter_mut().for_each(|x| *x = 1.0 - v);
            e.check.iter_mut().for_each(|c| c.0 = 0.0);
            forge(file, shard);
        }
        let got = merge(&files, &out);
        refused(&got, needles);
        assert!(
            stderr(&got).contains("was edited") || stderr(&got).contains("outside [0, 1]"),
            "{}",
            stderr(&got)
        );
        assert!(!out.exists());
    }
    // Only the error claims lowered: the values are right, the check terms say 0.
    for (file, original) in files.iter().zip(&originals) {
        let mut shard = original.clone();
        shard.tables[0].check.iter_mut().for_each(|c| c.0 = 0.0);
        forge(file, shard);
    }
    refused(
        &merge(&files, &out),
        &["the stated node error against the reference of ggx-height-correlated-E"],
    );
    assert!(!out.exists());
    // The originals merge.
    for (file, original) in files.iter().zip(originals) {
        forge(file, original);
    }
    let got = merge(&files, &out);
    assert!(got.status.success(), "{}", stderr(&got));
}

/// `--size 4096 --ior-size 4096` aborted on a 2 TiB allocation and `--ior-size 5` (84 M texels)
/// started baking: the product of the axes is bounded, in a plain bake and a sharded one.
#[test]
fn a_bake_whose_axes_multiply_past_the_bound_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    for (ior, texels) in [("4096", "68719476736"), ("5", "83886080")] {
        for shard in [None, Some("0/4")] {
            let mut args = vec![
                "bake",
                "--quantity",
                "e-dielectric",
                "--size",
                "4096",
                "--ior-size",
                ior,
                "--out",
                path(&out),
            ];
            args.extend(shard.iter().flat_map(|s| ["--shard", s]));
            refused(
                &kiln(&args),
                &[
                    &format!("{ior} x 4096 x 4096 = {texels} texels"),
                    "more than the 67108864 (2^26) a table may hold",
                    "ior-size",
                ],
            );
            assert!(!out.exists(), "{args:?} wrote {}", out.display());
        }
    }
    // Time: each axis within its bound, 2^32 samples per texel of a 4096 x 4096 Beckmann E.
    refused(
        &kiln(&[
            "bake",
            "--ndf",
            "beckmann",
            "--size",
            "4096",
            "--quantity",
            "e",
            "--method",
            "qmc",
            "--samples",
            "4294967296",
            "--scrambles",
            "2",
            "--out",
            path(&out),
        ]),
        &["core-seconds", "more than the 1e7 kiln starts"],
    );
    assert!(!out.exists());
}

#[path = "common/rng.rs"]
mod rng;
use rng::Rng;

/// A large, a negative-looking or an out-of-range number for a size field.
fn hostile_size(rng: &mut Rng) -> usize {
    [
        0,
        1,
        2,
        4097,
        100_000,
        2_147_483_648,
        1 << 40,
        usize::MAX,
        usize::MAX / 2 + 1,
    ][rng.below(9)]
}

/// One structure-aware edit of a set of shards.
fn mutate(shards: &mut [ShardFile], rng: &mut Rng) {
    let s = rng.below(shards.len());
    let shard = &mut shards[s];
    match rng.below(12) {
        0 => shard.count = hostile_size(rng),
        1 => shard.index = hostile_size(rng),
        2 => shard.bake.options.size = hostile_size(rng),
        3 => shard.bake.options.ior_size = hostile_size(rng),
        4 => {
            shard.bake.options.samples = 1 << rng.below(64);
            shard.bake.options.scrambles = [0, 1, 2, u32::MAX][rng.below(4)];
        }
        5 => {
            shard.bake.options.max_error =
                [None, Some(0.0), Some(-1.0), Some(1e-10), Some(1.0)][rng.below(5)];
        }
        6 => {
            let t = rng.below(shard.tables.len());
            let table = &mut shard.tables[t];
            table.range = (hostile_size(rng), hostile_size(rng));
        }
        7 => {
            let t = rng.below(shard.tables.len());
            let table = &mut shard.tables[t];
            let v = [0.5, 5.0, -1.0, 1e308, -1e308, 1.0, 0.0][rng.below(7)];
            let n = table.value.len();
            if n > 0 {
                let k = rng.below(n);
                match rng.below(3) {
                    0 => table.value[k] = v,
                    1 => table.one_minus_value[k] = v,
                    _ => table.std_error[k] = v,
                }
            }
        }
        8 => {
            let t = rng.below(shard.tables.len());
            let table = &mut shard.tables[t];
            match rng.below(4) {
                0 => {
                    table.value.pop();
                }
                1 => table.value.push(0.5),
                2 => table.check.push((0.0, true)),
                _ => table.check.iter_mut().for_each(|c| c.0 = 0.0),
            }
        }
        9 => {
            let t = rng.below(shard.tables.len());
            shard.tables.remove(t);
            if shard.tables.is_empty() {
                return;
            }
        }
        10 => {
            shard.bake.options.quantities = vec![
                [
                    kiln::Quantity::EDielectric,
                    kiln::Quantity::EAvgDielectricInside,
                    kiln::Quantity::FMsNorm,
                    kiln::Quantity::EScale,
                ][rng.below(4)],
            ];
        }
        _ => shard.bake.options.ior_max = [f64::MAX, 0.5, 1.0, 100.0][rng.below(4)],
    }
    // Most mutants recompute the digests, as an attacker would.
    if rng.below(4) != 0 {
        for shard in shards.iter_mut() {
            shard.bake_digest = shard.bake.digest();
            for table in &mut shard.tables {
                table.digest = table.compute_digest();
            }
        }
    }
}

/// 120 structure-aware mutants of a valid set of shards through the library's merge: each is
/// refused or merges into tables every reader accepts, without a panic or an allocation over
/// 1 GiB.
#[test]
fn structure_aware_mutants_of_shards_never_panic_nor_allocate_past_their_bounds() {
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
    let valid: Vec<ShardFile> = (0..3)
        .map(|i| kiln::shard::bake_shard(&bake, ShardIndex::new(i, 3).unwrap(), &|_| {}).unwrap())
        .collect();
    let named = |shards: Vec<ShardFile>| -> Vec<(PathBuf, ShardFile)> {
        shards
            .into_iter()
            .enumerate()
            .map(|(i, s)| (PathBuf::from(format!("kiln-shard-{i}-of-3.json")), s))
            .collect()
    };
    assert!(kiln::shard::merge(&named(valid.clone())).is_ok());
    let mut rng = Rng(0x005e_ed41);
    let (mut refused, mut merged) = (0, 0);
    for round in 0..120 {
        let mut shards = valid.clone();
        for _ in 0..=rng.below(3) {
            mutate(&mut shards, &mut rng);
        }
        watching::reset();
        let outcome = std::panic::catch_unwind(|| kiln::shard::merge(&named(shards.clone())));
        let largest = watching::largest();
        assert!(
            largest <= 1 << 30,
            "round {round}: an allocation of {largest} bytes"
        );
        match outcome {
            Err(_) => panic!("round {round}: merge panicked"),
            Ok(Err(_)) => refused += 1,
            Ok(Ok((_, tables))) => {
                merged += 1;
                for table in &tables {
                    table
                        .check()
                        .unwrap_or_else(|m| panic!("round {round}: {m}"));
                }
            }
        }
    }
    eprintln!("{refused} refused, {merged} merged");
    assert!(refused > 90, "{refused} refused, {merged} merged");
}
