#!/usr/bin/env bash
# Mutation testing of the modules that hold kiln's numbers (issue 18): every mutant cargo-mutants
# makes in them must make some test fail. Usage:
#   scripts/mutants.sh                 # the whole scope below (hours on 2 cores)
#   scripts/mutants.sh src/format/f16.rs src/integrate/estimate.rs   # some files
#   SHARD=0/4 scripts/mutants.sh       # one of four shards of the scope
#   TARGETS="--lib --test suite" TESTS="-- containers::" scripts/mutants.sh src/format/f16.rs  # fewer tests
#   TARGETS=--lib TESTS="-- model::" scripts/mutants.sh src/model/special.rs  # and fewer tests
#   RE="cody_rational|beckmann_lambda_of_a" scripts/mutants.sh src/model/special.rs   # some functions
#   EXCLUDE_RE="cody_rational" scripts/mutants.sh src/model/special.rs   # all but some functions
#   ITERATE=1 scripts/mutants.sh src/table   # again, skipping the mutants the last runs caught
#   TIMEOUT=60 scripts/mutants.sh ...  # seconds a mutant's tests may take (default 300; a mutant
#                                      # can make a test run far longer than it does)
# Needs cargo-mutants (`cargo install cargo-mutants --locked`). Results in target/mutants.out/:
# caught.txt, missed.txt, timeout.txt, unviable.txt (under target/, which git ignores). Runs every
# test binary with release's optimisation, as CI does.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v cargo-mutants > /dev/null; then
    echo "cargo-mutants is not installed: cargo install cargo-mutants --locked" >&2
    exit 2
fi
files=("$@")
if [ ${#files[@]} -eq 0 ]; then
    files=(src/model src/integrate/estimate.rs src/table src/verify src/format/f16.rs)
fi
args=()
for f in "${files[@]}"; do
    if [ -d "$f" ]; then
        args+=(--file "$f/**/*.rs")
    else
        args+=(--file "$f")
    fi
done
if [ -n "${SHARD:-}" ]; then
    args+=(--shard "$SHARD")
fi
if [ -n "${ITERATE:-}" ]; then
    args+=(--iterate)
fi
if [ -n "${RE:-}" ]; then
    args+=(--re "$RE")
fi
if [ -n "${EXCLUDE_RE:-}" ]; then
    args+=(--exclude-re "$EXCLUDE_RE")
fi
# Cargo.toml's `mutants` profile for the build and the test alike: the release build's code
# (the tests' tolerances and run times are release's) without debug info and incremental, so a
# mutant rebuilds in about a third of a release build's time. (A test-only flag builds each
# mutant twice.)
test_args=(--profile mutants)
# TARGETS: the test targets built and run (cargo's --lib, --test NAME), for the build of each
# mutant as well as its test; TESTS: arguments of the test run alone (a name filter after --).
for t in ${TARGETS:-}; do
    test_args+=("--cargo-arg=$t")
done
for t in ${TESTS:-}; do
    test_args+=("--cargo-test-arg=$t")
done
exec cargo mutants "${args[@]}" --output target --jobs 1 --timeout "${TIMEOUT:-300}" --build-timeout 900 "${test_args[@]}"
