#!/usr/bin/env bash
# Runs the fuzz targets one after another, each for SECONDS, and prints
# executions, executions per second and findings per target.
#
#   fuzz/run.sh SECONDS [TARGET...]      # all targets when none is named
#
# Each target grows its corpus in fuzz/work/TARGET (not committed) from the
# seeds in fuzz/corpus/TARGET (never written to), with fuzz/dict/TARGET.dict.
# libFuzzer runs in fork mode and keeps going after a crash, a timeout or
# running out of memory; the inputs are saved in fuzz/artifacts/TARGET/
# (minimise one with `cargo fuzz tmin`, see fuzz/README.md). Logs are in
# fuzz/logs/.
#
# Environment: FUZZ_MAX_LEN (4096), FUZZ_TIMEOUT (10 seconds an input),
# FUZZ_RSS_MB (2048), FUZZ_SANITIZER (none; `address` for ASan, slower),
# FUZZ_JOBS (1 process at a time).
#
# Needs `cargo install cargo-fuzz`. Without a sanitizer the stable toolchain
# builds the targets as it is; AddressSanitizer needs the nightly-only
# -Zsanitizer, which RUSTC_BOOTSTRAP=1 (set here) lets stable rustc accept.
set -euo pipefail

if [[ $# -lt 1 || ! $1 =~ ^[0-9]+$ ]]; then
    sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
fi
secs=$1
shift
cd "$(dirname "$0")/.."
export RUSTC_BOOTSTRAP=1
san=${FUZZ_SANITIZER:-none}
flags=(-O -a -s "$san")   # release, debug assertions and overflow checks on
if [[ $# -gt 0 ]]; then
    targets=("$@")
else
    mapfile -t targets < <(cargo fuzz list)
fi

cargo fuzz build "${flags[@]}"
mkdir -p fuzz/logs
summary=fuzz/logs/summary.txt
printf '%-20s %12s %8s %7s %s\n' target executions exec/s seconds 'oom/timeout/crash' | tee "$summary"
for t in "${targets[@]}"; do
    mkdir -p "fuzz/work/$t" "fuzz/artifacts/$t"
    log="fuzz/logs/$t.log"
    cargo fuzz run "${flags[@]}" "$t" "fuzz/work/$t" "fuzz/corpus/$t" -- \
        -fork="${FUZZ_JOBS:-1}" -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
        -max_total_time="$secs" -max_len="${FUZZ_MAX_LEN:-4096}" \
        -timeout="${FUZZ_TIMEOUT:-10}" -rss_limit_mb="${FUZZ_RSS_MB:-2048}" \
        -dict="fuzz/dict/$t.dict" >"$log" 2>&1 || echo "$t: libFuzzer exited with $? (see $log)"
    # The last status line of fork mode: "#EXECS: cov: ... oom/timeout/crash: O/T/C time: Ns ..."
    last=$(grep -E '^#[0-9]+: cov:' "$log" | tail -n 1 || true)
    execs=$(sed -E 's/^#([0-9]+):.*/\1/' <<<"$last")
    time=$(sed -E 's/.* time: ([0-9]+)s.*/\1/' <<<"$last")
    found=$(sed -E 's#.*oom/timeout/crash: ([0-9]+/[0-9]+/[0-9]+).*#\1#' <<<"$last")
    rate=$(( ${time:-0} > 0 ? ${execs:-0} / time : 0 ))
    printf '%-20s %12s %8s %7s %s\n' "$t" "${execs:-?}" "$rate" "${time:-?}" "${found:-?}" | tee -a "$summary"
done
echo "artifacts (findings), if any:"
find fuzz/artifacts -type f | sort
