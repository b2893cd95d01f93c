//! Hostile input, deterministically: for every reader (kiln's JSON, binary, EXR, KTX2, DDS, C
//! and Rust files; every preset's engine file; external text and raw tables; scenes; cache
//! entries; formula files, whose error messages may quote no raw control character; a games202
//! PNG as its verdict reads it), a few hundred seeded mutants of a valid file: bit flips, truncations at every
//! header word and at random, huge or zero length fields, NaN and infinity written over
//! values, numbers in text replaced by `NaN`, `1e999` or `-1`, lines dropped or doubled. Each
//! must read as an error or as a table whose every number is finite, never panic, never ask
//! for more than 1 GiB at once (a counting allocator watches every allocation) and never take
//! more than 5 s.
//!
//! `KILN_FUZZ_SECONDS=N cargo test --release --test hostile_input -- --nocapture` runs each
//! reader for N seconds of fresh mutants instead (the longer fuzzing run), printing the counts.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use kiln::format::{Format, Precision, replace::Replace};
use kiln::preset::Preset;
use kiln::verify::input::{AxisName, Encoding, Layout, read_external, read_kiln};
use kiln::{BakeOptions, Grid, MuMapping, Quantity, RoughnessConvention, Table};

#[path = "common/watching.rs"]
mod watching;

const ALLOCATION_LIMIT: usize = 1 << 30;
const TIME_LIMIT: Duration = Duration::from_secs(5);
const MUTANTS: usize = 150;

#[path = "common/rng.rs"]
mod rng;
use rng::Rng;

/// What a reader made of a file: the numbers it read (to be finite), or an error.
type Outcome = Result<Vec<f64>, String>;

/// How a target reads the bytes of one mutant.
type Reader = Box<dyn Fn(&[u8]) -> Outcome>;

/// A reader under test: its name, a valid file and how to read bytes of that kind.
struct Target {
    name: String,
    seed: Vec<u8>,
    text: bool,
    read: Reader,
}

fn numbers(tables: &[Table]) -> Vec<f64> {
    tables
        .iter()
        .flat_map(|t| t.value.iter().chain(&t.one_minus_value).chain(&t.std_error))
        .copied()
        .collect()
}

/// One mutant of `seed`, mutation chosen by `rng` (text-aware for text formats).
fn mutate(seed: &[u8], text: bool, rng: &mut Rng, round: usize) -> Vec<u8> {
    let mut bytes = seed.to_vec();
    let len = bytes.len();
    // Truncation at each of the first 64 header words, once each.
    if round < 64 && !text {
        bytes.truncate((4 * round).min(len));
        return bytes;
    }
    let near_start = |rng: &mut Rng| {
        if rng.below(2) == 0 {
            rng.below(len.min(512))
        } else {
            rng.below(len)
        }
    };
    match rng.below(if text { 9 } else { 6 }) {
        0 => {
            for _ in 0..=rng.below(4) {
                let at = near_start(rng);
                bytes[at] ^= 1 << rng.below(8);
            }
        }
        1 => bytes.truncate(rng.below(len)),
        2 => {
            // A huge, negative-looking or zero length or size field.
            let at = near_start(rng) & !3;
            let word: u32 = [
                0xffff_ffff,
                0x7fff_ffff,
                0x8000_0000,
                0x0010_0000,
                0,
                1 << 20,
            ][rng.below(6)];
            for (k, b) in word.to_le_bytes().iter().enumerate() {
                if at + k < len {
                    bytes[at + k] = *b;
                }
            }
        }
        3 => {
            // NaN or infinity in f32 or f16 over a value.
            let half = rng.below(2) == 0;
            let at = rng.below(len) & if half { !1 } else { !3 };
            let word: &[u8] = match (half, rng.below(2)) {
                (true, 0) => &[0x00, 0x7e],
                (true, _) => &[0x00, 0x7c],
                (false, 0) => &[0x00, 0x00, 0xc0, 0x7f],
                (false, _) => &[0x00, 0x00, 0x80, 0x7f],
            };
            for (k, b) in word.iter().enumerate() {
                if at + k < len {
                    bytes[at + k] = *b;
                }
            }
        }
        4 => {
            // A chunk doubled.
            let at = rng.below(len);
            let n = rng.below(64.min(len - at) + 1);
            let chunk = bytes[at..at + n].to_vec();
            bytes.splice(at..at, chunk);
        }
        5 => {
            // A chunk removed.
            let at = rng.below(len);
            let n = rng.below(64.min(len - at) + 1);
            bytes.drain(at..at + n);
        }
        6 | 7 => {
            // A number replaced by something that is not a table value.
            let text = String::from_utf8_lossy(&bytes).into_owned();
            let starts: Vec<usize> = text
                .char_indices()
                .filter(|&(i, c)| {
                    c.is_ascii_digit()
                        && (i == 0 || !text.as_bytes()[i - 1].is_ascii_alphanumeric())
                })
                .map(|(i, _)| i)
                .collect();
            if starts.is_empty() {
                return bytes;
            }
            let start = starts[rng.below(starts.len())];
            let end = text[start..]
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '.' || c == '-' || c == '+'))
                .map_or(text.len(), |n| start + n);
            let with = [
                "NaN",
                "nan",
                "1e999",
                "-1",
                "inf",
                "1e308",
                "0x7e00",
                "",
                "99999999999",
            ][rng.below(9)];
            bytes = format!("{}{with}{}", &text[..start], &text[end..]).into_bytes();
        }
        _ => {
            // A line dropped.
            let text = String::from_utf8_lossy(&bytes).into_owned();
            let lines: Vec<&str> = text.lines().collect();
            let drop = rng.below(lines.len());
            bytes = lines
                .iter()
                .enumerate()
                .filter(|&(k, _)| k != drop)
                .map(|(_, l)| *l)
                .collect::<Vec<_>>()
                .join("\n")
                .into_bytes();
        }
    }
    bytes
}

/// Runs one mutant through `target`, checking the promises; returns whether it read.
fn run_one(target: &Target, bytes: &[u8], what: &str) -> bool {
    watching::reset();
    let start = Instant::now();
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| (target.read)(bytes)));
    let elapsed = start.elapsed();
    let largest = watching::largest();
    let Ok(outcome) = outcome else {
        panic!("{}: {what}: the reader panicked", target.name);
    };
    assert!(
        largest <= ALLOCATION_LIMIT,
        "{}: {what}: an allocation of {largest} bytes",
        target.name
    );
    assert!(
        elapsed <= TIME_LIMIT,
        "{}: {what}: {elapsed:?}",
        target.name
    );
    match outcome {
        Ok(values) => {
            assert!(
                values.iter().all(|v| v.is_finite()),
                "{}: {what}: read with a non-finite number",
                target.name
            );
            true
        }
        Err(_) => false,
    }
}

/// A scratch file per target, rewritten for every mutant.
fn scratch(dir: &Path, name: &str) -> PathBuf {
    dir.join(name)
}

fn kiln_file_target(dir: &Path, source: &Path) -> Target {
    let name = source.file_name().unwrap().to_string_lossy().into_owned();
    let seed = std::fs::read(source).unwrap();
    // The mutant takes the file's place (beside its pristine sidecar, for bin and dds).
    let work = dir.join("work");
    std::fs::create_dir_all(&work).unwrap();
    let sidecar = source.with_extension("json");
    if sidecar != source && sidecar.is_file() {
        std::fs::copy(&sidecar, work.join(sidecar.file_name().unwrap())).unwrap();
    }
    let path = scratch(&work, &name);
    let text = matches!(
        source.extension().and_then(|e| e.to_str()),
        Some("json" | "h" | "rs")
    );
    Target {
        name,
        seed,
        text,
        read: Box::new(move |bytes| {
            std::fs::write(&path, bytes).unwrap();
            match read_kiln(&path) {
                Ok(Some(table)) => Ok(numbers(&[table])),
                Ok(None) => Err("not kiln's".into()),
                Err(e) => Err(e.to_string()),
            }
        }),
    }
}

fn preset_target(preset: Preset, seed: Vec<u8>, text: bool) -> Target {
    Target {
        name: format!("preset {}", preset.name()),
        seed,
        text,
        read: Box::new(move |bytes| {
            let tables = preset
                .read_tables(bytes, "mutant")
                .map_err(|e| e.to_string())?;
            let mut values = numbers(&tables);
            if let Some(extra) = preset.decode_extra(bytes).map_err(|e| e.to_string())? {
                // The extra channel is audited (and refused if not finite) by audit_extra;
                // decoding it must not panic.
                values.extend(extra.iter().filter(|v| v.is_finite()));
            }
            Ok(values)
        }),
    }
}

/// A preset's engine file, encoded from tables of its layout holding smooth made-up values.
fn engine_file(preset: Preset) -> Vec<u8> {
    let tables: Vec<Table> = preset
        .options()
        .resolved()
        .specs()
        .into_iter()
        .map(|spec| {
            let value: Vec<f64> = (0..spec.len())
                .map(|k| 0.25 + 0.5 * ((k % 97) as f64 / 97.0))
                .collect();
            Table {
                one_minus_value: value.iter().map(|v| 1.0 - v).collect(),
                std_error: vec![0.0; value.len()],
                value,
                spec,
                command: "hostile_input".into(),
                node_errors: None,
                requested_max_error: None,
                lookup_fit: None,
            }
        })
        .collect();
    preset.encode(&tables).unwrap()
}

fn targets(dir: &Path) -> Vec<Target> {
    let mut targets = Vec::new();
    // kiln's own files, from a small bake.
    let tables = BakeOptions {
        quantities: vec![Quantity::E, Quantity::EAvg],
        size: 6,
        max_error: Some(1e-3),
        ..BakeOptions::default()
    }
    .bake(&|_| {})
    .unwrap();
    let out = dir.join("kiln");
    let formats = [
        Format::Json,
        Format::Exr,
        Format::Bin,
        Format::Ktx2,
        Format::Dds,
        Format::H,
        Format::Rs,
    ];
    kiln::format::write_tables(&out, &tables, &formats, Precision::F32, Replace::Force).unwrap();
    for format in formats {
        let file = out.join(format!("ggx-height-correlated-E.{}", format.name()));
        targets.push(kiln_file_target(&dir.join(format.name()), &file));
    }
    // A half-float EXR of the average (other header, other sizes).
    let half = dir.join("half");
    kiln::format::write_tables(
        &half,
        &tables[1..],
        &[Format::Exr],
        Precision::F16,
        Replace::Force,
    )
    .unwrap();
    targets.push(kiln_file_target(
        &dir.join("half-exr"),
        &half.join("ggx-height-correlated-E_avg.exr"),
    ));

    // Engine files: the real ones kiln vendors, and the others as kiln writes them.
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/engines");
    for (preset, file, text) in [
        (Preset::Cycles, "cycles/shader.tables", true),
        (Preset::Bevy, "bevy/dfg.ktx2", false),
        (Preset::Three, "three/DFGLUTData-16.js", true),
    ] {
        targets.push(preset_target(
            preset,
            std::fs::read(data.join(file)).unwrap(),
            text,
        ));
    }
    for (preset, text) in [
        (Preset::EnterprisePbr, false),
        (Preset::Filament, true),
        (Preset::Godot, false),
        (Preset::UnityHdrp, false),
        (Preset::Unreal, false),
    ] {
        targets.push(preset_target(preset, engine_file(preset), text));
    }

    // External tables: text and raw f32.
    let e = &tables[0];
    let layout = Layout {
        model: e.spec.model,
        quantity: Quantity::E,
        fresnel: None,
        shape: vec![6, 6],
        order: vec![AxisName::R, AxisName::Mu],
        grid: Grid::Nodes,
        roughness: RoughnessConvention::Perceptual,
        // kiln's layout of the table baked above: the balanced axis and rows, fitted.
        mu_mapping: MuMapping::Balanced,
        roughness_spacing: kiln::RoughnessSpacing::Balanced,
        texels: kiln::table::Texels::LookupFit,
    };
    let text: String = e.value.iter().map(|v| format!("{v}\n")).collect();
    let raw: Vec<u8> = e
        .value
        .iter()
        .flat_map(|&v| (v as f32).to_le_bytes())
        .collect();
    for (name, seed, encoding, is_text) in [
        ("external text", text.into_bytes(), Encoding::Text, true),
        (
            "external raw f32",
            raw,
            Encoding::Raw(Precision::F32),
            false,
        ),
    ] {
        let path = dir.join(name.replace(' ', "-"));
        let layout = layout.clone();
        targets.push(Target {
            name: name.into(),
            seed,
            text: is_text,
            read: Box::new(move |bytes| {
                std::fs::write(&path, bytes).unwrap();
                read_external(&path, &encoding, &layout)
                    .map(|t| numbers(&[t]))
                    .map_err(|e| e.to_string())
            }),
        });
    }

    // A scene, as text.
    let scene =
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scene.toml")).unwrap();
    targets.push(Target {
        name: "scene".into(),
        seed: scene,
        text: true,
        read: Box::new(|bytes| {
            let text = String::from_utf8(bytes.to_vec()).map_err(|e| e.to_string())?;
            kiln::scene::Scene::parse(&text, "mutant.toml")
                .map(|scene| {
                    // A scene holds no table; what it plans must be finite.
                    scene
                        .plan()
                        .tables
                        .iter()
                        .map(|t| t.estimated_core_seconds)
                        .collect()
                })
                .map_err(|e| e.to_string())
        }),
    });

    // A formula file (`kiln verify-fit FILE`): the formula language. A message about a bad
    // file quotes its text escaped and bounded (issue 64, defect 7): no control character may
    // reach the terminal, however the text was mutated.
    let formula = std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/fits/karis-mobile.toml"),
    )
    .unwrap();
    targets.push(Target {
        name: "formula file".into(),
        seed: formula,
        text: true,
        read: Box::new(|bytes| {
            let text = String::from_utf8(bytes.to_vec()).map_err(|e| e.to_string())?;
            match kiln::fit::FormulaFit::parse(&text) {
                Ok(fit) => {
                    let fit = kiln::fit::Fit::Formula(fit);
                    for shown in [fit.name(), fit.source()] {
                        let printed = kiln::error::escaped(shown);
                        assert!(!printed.chars().any(char::is_control), "{printed:?}");
                    }
                    // A formula may divide by zero: a NaN there is the fit's, which the audit
                    // reports; evaluating it must not panic.
                    let mut values = Vec::new();
                    for quantity in fit.quantities() {
                        for (mu, r) in [(0.0, 0.0), (0.5, 0.5), (1.0, 1.0), (1e-9, 1e-9)] {
                            values.push(fit.value(quantity, mu, r));
                        }
                    }
                    Ok(values.into_iter().filter(|v| v.is_finite()).collect())
                }
                Err(error) => {
                    let message = error.to_string();
                    assert!(
                        !message.chars().any(|c| c.is_control() && c != '\n'),
                        "raw control characters in {message:?}"
                    );
                    Err(message)
                }
            }
        }),
    });

    // A games202 PNG LUT as `kiln verify --preset games202` reads it for its verdict: the
    // tables, and the precision its data holds (sBIT, levels widened from 8 bits, palettes).
    targets.push(Target {
        name: "games202 png verdict".into(),
        seed: engine_file(Preset::Games202),
        text: false,
        read: Box::new(|bytes| {
            let tables = Preset::Games202
                .read_tables(bytes, "mutant")
                .map_err(|e| e.to_string())?;
            let _ = Preset::Games202.storage_of(bytes);
            let _ = kiln::format::png::effective_bits(bytes);
            Ok(numbers(&tables))
        }),
    });

    // A cache entry.
    let cache_dir = dir.join("cache");
    let cache = kiln::cache::Cache::new(&cache_dir);
    let key = kiln::cache::CacheKey::new(&e.spec, Some(1e-3), &e.command);
    cache.store(&key, e).unwrap();
    let entry = cache_dir.join(key.file_name());
    targets.push(Target {
        name: "cache entry".into(),
        seed: std::fs::read(&entry).unwrap(),
        text: true,
        read: Box::new(move |bytes| {
            std::fs::write(&entry, bytes).unwrap();
            match cache.lookup(&key) {
                kiln::cache::Lookup::Hit(table) => Ok(numbers(&[*table])),
                kiln::cache::Lookup::Miss => Err("miss".into()),
                kiln::cache::Lookup::Damaged(why) => Err(why),
            }
        }),
    });
    targets
}

#[test]
fn every_reader_survives_its_mutants() {
    let dir = tempfile::tempdir().unwrap();
    let targets = targets(dir.path());
    let seconds: Option<u64> = std::env::var("KILN_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok());
    for (index, target) in targets.iter().enumerate() {
        assert!(
            run_one(target, &target.seed, "the valid seed"),
            "{}: the valid seed does not read",
            target.name
        );
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ (index as u64 + 1));
        let start = Instant::now();
        let (mut read, mut refused, mut round) = (0, 0, 0);
        loop {
            match seconds {
                Some(s) if start.elapsed() >= Duration::from_secs(s) => break,
                None if round >= MUTANTS => break,
                _ => {}
            }
            let mutant = mutate(&target.seed, target.text, &mut rng, round);
            if run_one(target, &mutant, &format!("mutant {round}")) {
                read += 1;
            } else {
                refused += 1;
            }
            round += 1;
        }
        if seconds.is_some() {
            println!(
                "{}: {round} mutants in {:.0} s: {read} read (all finite), {refused} refused, \
                 no panic, largest allocation within 1 GiB, none over 5 s",
                target.name,
                start.elapsed().as_secs_f64()
            );
        }
    }
}
