#!/usr/bin/env bash
# Regenerates tables/, the default tables, exactly as the README's bake command does.
# `cargo test --release` checks that the committed files are byte-identical to this output.
set -euo pipefail
cd "$(dirname "$0")/.."
rm -rf tables
cargo run --release -- bake --out tables
