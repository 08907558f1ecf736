#!/usr/bin/env bash
# Builds the fuzz targets with libFuzzer's coverage instrumentation on the stable
# toolchain (the sancov flags cargo-fuzz passes with `-s none`; no nightly, no
# cargo-fuzz needed) and runs each for SECONDS (default 10) from the committed corpus.
# Any panic, timeout (> 5 s per input) or > 1 GiB memory fails the script; the crashing
# input is left in $CARGO_TARGET_DIR/fuzz-artifacts/<target>/.
#
#   bash fuzz/run.sh [SECONDS]        # CI: bash fuzz/run.sh 10
#   bash fuzz/run.sh 0                # build only
set -euo pipefail
cd "$(dirname "$0")"
seconds="${1:-10}"
host="$(rustc -vV | sed -n 's/^host: //p')"
target_dir="${CARGO_TARGET_DIR:-target}"
export RUSTFLAGS="-Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4 \
-Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-pc-table \
-Cllvm-args=-sanitizer-coverage-trace-compares --cfg fuzzing -Cdebug-assertions -Coverflow-checks"
# --target: build scripts and proc macros stay uninstrumented, as with cargo-fuzz.
# Not --locked: fuzz/Cargo.lock is a copy of the workspace lock plus libfuzzer-sys and
# would go stale whenever a workspace dependency changes; cargo resolves it minimally.
cargo build --release --target "$host" --bins
[ "$seconds" -gt 0 ] || exit 0
for t in reference_expr reference_case cli_numbers cli_run_json claims_parse; do
    work="$target_dir/fuzz-corpus/$t"
    artifacts="$target_dir/fuzz-artifacts/$t"
    mkdir -p "$work" "$artifacts"
    echo "fuzz $t for ${seconds} s"
    log="$target_dir/fuzz-$t.log"
    set +e
    "$target_dir/$host/release/$t" "$work" "corpus/$t" -max_total_time="$seconds" -timeout=5 \
        -rss_limit_mb=1024 -artifact_prefix="$artifacts/" -print_final_stats=1 >"$log" 2>&1
    status=$?
    set -e
    grep -E "^(Done|stat::number_of_executed_units|stat::new_units_added)|INFO: seed corpus" "$log" || true
    if [ "$status" -ne 0 ]; then
        tail -40 "$log"
        echo "fuzz $t failed (exit $status); the input is in $artifacts"
        exit 1
    fi
done
