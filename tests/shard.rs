//! Sharded bakes (`kiln bake --shard I/N`, `kiln merge`): the merged files are byte-identical to
//! the unsharded bake's for any shard count, any order and any thread count; every broken set of
//! shards is refused by name with nothing written; `--shard auto` reads Slurm's and Kubernetes'
//! variables as their schedulers set them.

#![cfg(feature = "cli")]

use std::path::Path;
use std::process::{Command, Output};

fn kiln_env(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_kiln"));
    command.args(args);
    for var in [
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_COUNT",
        "SLURM_ARRAY_TASK_MIN",
        "SLURM_ARRAY_TASK_MAX",
        "JOB_COMPLETION_INDEX",
        "KILN_SHARD_COUNT",
    ] {
        command.env_remove(var);
    }
    command.envs(env.iter().copied());
    command.output().expect("kiln runs")
}

fn ok(output: &Output) {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

fn refused(output: &Output, needle: &str) {
    let message = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{message}");
    assert!(message.contains(needle), "wanted '{needle}' in: {message}");
}

/// Every file under `dir`, by name, with its bytes.
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut all: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| {
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    all.sort();
    all
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// For a bake given by `bake` (its arguments), N in {1, 2, 3, 7}: the shards (alternately on 1
/// and 2 threads, run last to first) merge into exactly the unsharded bake's files.
fn merged_equals_unsharded(bake: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole");
    let mut args = vec!["bake", "-q", "--out", path(&whole)];
    args.extend_from_slice(bake);
    ok(&kiln_env(&args, &[]));
    let expected = files(&whole);
    assert!(expected.len() >= 3);
    for n in [1, 2, 3, 7] {
        let shards = dir.path().join(format!("shards-{n}"));
        for i in (0..n).rev() {
            let shard = format!("{i}/{n}");
            let mut args = vec!["bake", "-q", "--out", path(&shards), "--shard", &shard];
            args.extend_from_slice(bake);
            let threads = if i % 2 == 0 { "1" } else { "2" };
            ok(&kiln_env(&args, &[("RAYON_NUM_THREADS", threads)]));
        }
        let merged = dir.path().join(format!("merged-{n}"));
        ok(&kiln_env(
            &["merge", path(&shards), "--out", path(&merged), "-q"],
            &[],
        ));
        let got = files(&merged);
        assert_eq!(
            got.iter().map(|f| &f.0).collect::<Vec<_>>(),
            expected.iter().map(|f| &f.0).collect::<Vec<_>>(),
            "{bake:?} in {n} shards"
        );
        for (g, e) in got.iter().zip(&expected) {
            assert!(g.1 == e.1, "{bake:?} in {n} shards: {} differs", g.0);
        }
    }
}

#[test]
#[ignore = "long (about 20 s): .ci/run runs it with --ignored (.ci/run's Slurm check merges the default bake too)"]
fn the_default_bake_merges_byte_for_byte() {
    merged_equals_unsharded(&[]);
}

#[test]
#[ignore = "long (about 20 s): .ci/run runs it with --ignored"]
fn a_beckmann_bake_merges_byte_for_byte() {
    merged_equals_unsharded(&[
        "--ndf",
        "beckmann",
        "--masking",
        "height-correlated,separable",
        "--size",
        "12",
        "--max-error",
        "1e-6",
        "--format",
        "json,exr,bin",
    ]);
}

#[test]
fn a_dielectric_bake_merges_byte_for_byte() {
    merged_equals_unsharded(&[
        "--quantity",
        "e-dielectric,e-dielectric-inside",
        "--size",
        "6",
        "--ior-size",
        "5",
        "--max-error",
        "1e-6",
        "--format",
        "json,exr,bin",
    ]);
}

/// Missing, duplicate, foreign, miscounted and damaged shards are errors naming the shard and
/// the texels, and nothing is written.
#[test]
fn broken_sets_of_shards_are_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bake = ["--size", "8", "--max-error", "1e-5", "--format", "json"];
    let shard = |out: &str, s: &str, extra: &[&str]| {
        let out = d.join(out);
        let mut args = vec!["bake", "-q", "--out", path(&out), "--shard", s];
        args.extend_from_slice(&bake);
        args.extend_from_slice(extra);
        ok(&kiln_env(&args, &[]));
        out
    };
    let a = shard("a", "0/3", &[]);
    shard("a", "1/3", &[]);
    shard("a", "2/3", &[]);
    let file = |dir: &Path, i: usize, n: usize| dir.join(format!("kiln-shard-{i}-of-{n}.json"));
    let out = d.join("out");
    let merge = |inputs: &[&Path]| {
        let mut args = vec!["merge", "--out", path(&out)];
        args.extend(inputs.iter().map(|p| path(p)));
        kiln_env(&args, &[])
    };
    // Missing: shard 1 of 3, with its texel ranges.
    refused(
        &merge(&[&file(&a, 0, 3), &file(&a, 2, 3)]),
        "shard 1 of 3 is missing (ggx-height-correlated-E texels",
    );
    // Duplicate.
    let copy = d.join("copy.json");
    std::fs::copy(file(&a, 0, 3), &copy).unwrap();
    refused(
        &merge(&[&file(&a, 0, 3), &copy, &file(&a, 1, 3), &file(&a, 2, 3)]),
        "are both shard 0 of 3",
    );
    // Foreign: a shard of another bake (another size).
    let other = d.join("other");
    let mut args = vec!["bake", "-q", "--out", path(&other), "--shard", "1/3"];
    args.extend_from_slice(&["--size", "6", "--max-error", "1e-5", "--format", "json"]);
    ok(&kiln_env(&args, &[]));
    refused(
        &merge(&[&file(&a, 0, 3), &file(&other, 1, 3), &file(&a, 2, 3)]),
        "is a shard of another bake",
    );
    // Another count.
    let b = shard("b", "1/2", &[]);
    refused(
        &merge(&[&file(&a, 0, 3), &file(&b, 1, 2), &file(&a, 2, 3)]),
        "is shard 1 of 2",
    );
    // Damaged: one digit of one value changed.
    let damaged = d.join("damaged");
    std::fs::create_dir_all(&damaged).unwrap();
    let text = std::fs::read_to_string(file(&a, 1, 3)).unwrap();
    let at = text.find("\"value\":[0.9").unwrap() + 12;
    let digit = text.as_bytes()[at];
    let changed = format!(
        "{}{}{}",
        &text[..at],
        if digit == b'5' { '6' } else { '5' },
        &text[at + 1..]
    );
    std::fs::write(file(&damaged, 1, 3), changed).unwrap();
    refused(
        &merge(&[&file(&a, 0, 3), &file(&damaged, 1, 3), &file(&a, 2, 3)]),
        "does not hold",
    );
    // Cut short.
    std::fs::write(file(&damaged, 1, 3), &text[..text.len() / 2]).unwrap();
    refused(
        &merge(&[&file(&a, 0, 3), &file(&damaged, 1, 3), &file(&a, 2, 3)]),
        "not a readable kiln shard file",
    );
    assert!(!out.exists(), "nothing written after a refused merge");
    // And the whole set merges.
    ok(&merge(&[&a]));
    assert!(out.join("ggx-height-correlated-E.json").is_file());
    // Bad --shard values.
    let bad = |s: &str, needle: &str| {
        let mut args = vec!["bake", "-q", "--out", path(&out), "--shard", s];
        args.extend_from_slice(&bake);
        refused(&kiln_env(&args, &[]), needle);
    };
    bad("3/3", "is not below the count 3");
    bad("x/3", "is not a whole number");
    bad("2", "takes I/N");
}

/// `--shard auto` as the schedulers set it: a Slurm array (`--array=0-2`, or `--array=5-7`
/// with its MIN and MAX), a Kubernetes indexed job (JOB_COMPLETION_INDEX with KILN_SHARD_COUNT); missing or conflicting variables are errors.
#[test]
fn shard_auto_reads_slurm_and_kubernetes_variables() {
    let dir = tempfile::tempdir().unwrap();
    let bake = ["--size", "6", "--max-error", "1e-5", "--format", "json"];
    let run = |out: &str, env: &[(&str, &str)], extra: &[&str]| {
        let out = dir.path().join(out);
        let mut args = vec!["bake", "-q", "--out", path(&out), "--shard", "auto"];
        args.extend_from_slice(&bake);
        args.extend_from_slice(extra);
        (kiln_env(&args, env), out)
    };
    for id in ["0", "1", "2"] {
        let (o, out) = run(
            "slurm",
            &[("SLURM_ARRAY_TASK_ID", id), ("SLURM_ARRAY_TASK_COUNT", "3")],
            &[],
        );
        ok(&o);
        assert!(out.join(format!("kiln-shard-{id}-of-3.json")).is_file());
    }
    let (o, out) = run(
        "slurm-offset",
        &[
            ("SLURM_ARRAY_TASK_ID", "6"),
            ("SLURM_ARRAY_TASK_MIN", "5"),
            ("SLURM_ARRAY_TASK_MAX", "7"),
        ],
        &[],
    );
    ok(&o);
    assert!(out.join("kiln-shard-1-of-3.json").is_file());
    let (o, out) = run(
        "k8s-env",
        &[("JOB_COMPLETION_INDEX", "3"), ("KILN_SHARD_COUNT", "4")],
        &[],
    );
    ok(&o);
    assert!(out.join("kiln-shard-3-of-4.json").is_file());
    // The whole Slurm array merges like the unsharded bake.
    let whole = dir.path().join("whole");
    let mut args = vec!["bake", "-q", "--out", path(&whole)];
    args.extend_from_slice(&bake);
    ok(&kiln_env(&args, &[]));
    let merged = dir.path().join("merged");
    ok(&kiln_env(
        &[
            "merge",
            path(&dir.path().join("slurm")),
            "--out",
            path(&merged),
            "-q",
        ],
        &[],
    ));
    assert_eq!(files(&merged), files(&whole));

    refused(&run("x", &[], &[]).0, "neither SLURM_ARRAY_TASK_ID");
    refused(
        &run("x", &[("JOB_COMPLETION_INDEX", "0")], &[]).0,
        "needs the completion count",
    );
    refused(
        &run(
            "x",
            &[("JOB_COMPLETION_INDEX", "0"), ("SLURM_ARRAY_TASK_ID", "0")],
            &[],
        )
        .0,
        "both SLURM_ARRAY_TASK_ID and JOB_COMPLETION_INDEX",
    );
    refused(
        &run("x", &[("SLURM_ARRAY_TASK_ID", "0")], &[]).0,
        "needs SLURM_ARRAY_TASK_COUNT",
    );
    refused(
        &run(
            "x",
            &[
                ("SLURM_ARRAY_TASK_ID", "3"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
            &[],
        )
        .0,
        "is not below the count 3",
    );
}
