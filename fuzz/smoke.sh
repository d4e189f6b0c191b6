#!/usr/bin/env bash
# A short fuzzing run of every target (CI runs this after the tests: 15 s each, a minute in
# all). It seeds the corpus, installs cargo-fuzz if it is missing, and fails on any crash,
# panic, timeout or leak, leaving the reproducer in fuzz/artifacts/<target>/.
# Usage: fuzz/smoke.sh [seconds per target]
set -euo pipefail
cd "$(dirname "$0")"
seconds=${1:-15}
if ! cargo fuzz --version >/dev/null 2>&1; then
    cargo install cargo-fuzz --version 0.13.2 --locked
fi
./seed.sh
# cargo-fuzz passes nightly-only sanitizer flags; the bootstrap switch lets stable rustc take them.
export RUSTC_BOOTSTRAP=1
cargo fuzz build -O
log=$(mktemp)
for target in case_toml assignment_scene obj png_decode; do
    dict=()
    if [ -f "$target.dict" ]; then dict=(-dict="$target.dict"); fi
    if ! cargo fuzz run -O "$target" "corpus/$target" -- "${dict[@]}" \
        -max_total_time="$seconds" -timeout=10 -print_final_stats=1 >"$log" 2>&1; then
        tail -n 40 "$log" >&2
        echo "fuzz target $target failed; reproducer in fuzz/artifacts/$target/" >&2
        exit 1
    fi
    executions=$(grep -oE '^stat::number_of_executed_units: [0-9]+' "$log" | grep -oE '[0-9]+$')
    coverage=$(grep -oE 'DONE +cov: [0-9]+' "$log" | grep -oE '[0-9]+$')
    echo "fuzz $target: ${seconds}s, $executions executions, coverage $coverage, no crash"
done
rm -f "$log"
