#!/usr/bin/env bash
# Fuzzes every reader kiln has with cargo-fuzz (libFuzzer): kiln's own files, engine files,
# external tables, scenes, cache entries, sets of shards for `kiln merge`, formula files and
# games202 PNG LUTs as their verdict reads them (fuzz/fuzz_targets/). Needs a nightly toolchain and `cargo install cargo-fuzz`. Seeds each
# target's corpus with valid files (a small bake, the vendored engine files, every preset as
# kiln writes it, the example scene, a shard and edit lists), then runs each
# target for SECONDS (default 600) under a 1 GiB allocation limit, a 2 GiB RSS limit and a 5 s
# per-input timeout. Findings land in fuzz/artifacts/TARGET/. Leak detection is off: rayon's
# worker threads live as long as the process and keep their thread-local buffers (and exr's),
# which LeakSanitizer reports as leaks (a false alarm that stops the run).
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]
#
# The stable test suite runs a deterministic version of the same idea in under 30 s
# (tests/hostile_input.rs).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(kiln_file preset_file external_table scene cache_entry shard_merge formula_file
        png_verdict)
fi
corpus=fuzz/corpus
seeds=$(mktemp -d)
trap 'rm -rf "$seeds"' EXIT
cargo build --release --quiet
kiln=target/release/kiln
"$kiln" bake --quantity e,e-avg --size 6 --max-error 1e-3 \
    --format json,exr,bin,ktx2,dds,h,rs -q --out "$seeds/kiln"
mkdir -p "$corpus"/{kiln_file,preset_file,external_table,scene,cache_entry,shard_merge}
mkdir -p "$corpus"/{formula_file,png_verdict}
# The formula language: the example file, and the corpus kept in the repository
# (fuzz/seeds/formula_file: every function, operator and define form the language has).
cp examples/fits/karis-mobile.toml "$corpus/formula_file/"
cp fuzz/seeds/formula_file/* "$corpus/formula_file/"
# PNG verdicts: games202's LUT as kiln writes it, and the kept seeds (fuzz/seeds/png_verdict:
# 16-bit widened, sBIT 8, 4-bit grey, palette).
"$kiln" bake --preset games202 -q --out "$seeds/games202"
cp "$seeds"/games202/*.png "$corpus/png_verdict/"
cp fuzz/seeds/png_verdict/* "$corpus/png_verdict/"
# kiln_file: a selector byte (json 0, exr 1, bin 2, ktx2 3, dds 4, h 5, rs 6), then the file.
i=0
for ext in json exr bin ktx2 dds h rs; do
    for f in "$seeds"/kiln/*."$ext"; do
        { printf "\\x$(printf %02x $i)"; cat "$f"; } > "$corpus/kiln_file/$(basename "$f")"
    done
    i=$((i + 1))
done
# preset_file: a selector byte in the order of Preset::ALL, then the file.
seed_preset() { { printf "\\x$(printf %02x "$1")"; cat "$2"; } > "$corpus/preset_file/$3"; }
seed_preset 0 tests/data/engines/cycles/shader.tables blender-shader.tables
seed_preset 1 tests/data/engines/bevy/dfg.ktx2 bevy-dfg.ktx2
seed_preset 2 tests/data/engines/three/DFGLUTData-16.js three-DFGLUTData.js
i=0
for preset in cycles bevy three enterprise-pbr filament godot unity-hdrp unreal; do
    "$kiln" bake --preset "$preset" -q --out "$seeds/$preset"
    for f in "$seeds/$preset"/*; do
        case "$f" in *.json) ;; *) seed_preset $i "$f" "kiln-$preset-$(basename "$f")" ;; esac
    done
    i=$((i + 1))
done
# external_table: selector 0 (text, 4 x 4, r slowest).
{ printf '\x00'; printf '0.9 0.95 0.99 1\n%.0s' 1 2 3 4; } > "$corpus/external_table/text"
cp examples/scene.toml "$corpus/scene/"
# shard_merge: a few edit lists (mode byte 0: digests recomputed after the edits) and one shard
# as JSON (mode 0xff).
printf '\x00\x02\x03' > "$corpus/shard_merge/size"
printf '\x00\x0a\xff\x00\x00\x00\x00\x00\x00\xe0\x3f\x0c\x00' > "$corpus/shard_merge/values"
"$kiln" bake --quantity e,e-avg --size 6 --max-error 1e-3 --shard 0/3 -q --out "$seeds/shards"
{ printf '\xff'; cat "$seeds/shards/kiln-shard-0-of-3.json"; } > "$corpus/shard_merge/json"
cd fuzz
for target in "${targets[@]}"; do
    echo "== $target: $seconds s"
    cargo +nightly fuzz run "$target" "corpus/$target" -- \
        -max_total_time="$seconds" -malloc_limit_mb=1024 -rss_limit_mb=2048 -timeout=5 \
        -detect_leaks=0 -print_final_stats=1
done
