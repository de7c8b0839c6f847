#!/usr/bin/env bash
# The recorded campaign (docs/fuzzing.md): each target alone, one job, no sanitizer (the
# code under test is safe Rust; overflow checks and debug assertions stay on), at least
# RUNS executions each; stops at the first target that finds something.
# Usage: fuzz/campaign.sh [target…]   (from anywhere; nightly and cargo-fuzz installed)
set -euo pipefail
cd "$(dirname "$0")"
RUNS=${RUNS:-11000000}
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(can_frame telemetry param_store can_server ingest rig_file bench_log)
fi
mkdir -p logs work
for t in "${targets[@]}"; do
    mkdir -p "work/$t" "regressions/$t"
    max_len=4096
    echo "=== $t: $RUNS runs, -max_len=$max_len"
    if ! nice cargo +nightly fuzz run -s none "$t" "work/$t" "seeds/$t" "regressions/$t" -- \
        -runs="$RUNS" -max_total_time=7200 -max_len=$max_len -print_final_stats=1 \
        -timeout=10 -rss_limit_mb=2048 > "logs/campaign-$t.log" 2>&1; then
        echo "$t: finding, see fuzz/logs/campaign-$t.log and fuzz/artifacts/$t/"
        exit 1
    fi
    grep -E "^stat::(number_of_executed_units|average_exec_per_sec|new_units_added|peak_rss_mb)|DONE" \
        "logs/campaign-$t.log" | tail -5
done
