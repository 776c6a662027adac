#!/usr/bin/env bash
# Runs every fuzz target for MINUTES minutes each (fractions allowed: 0.5 is 30 s), one
# after another, each as one libFuzzer process (one job). Builds the targets once
# (`cargo +nightly fuzz build`: release, debug assertions on), copies the committed seeds
# (fuzz/seeds/TARGET/) into the scratch corpus fuzz/corpus/TARGET/, and prints the
# executions and crashes of each target. Exits 1 when any target crashed (or hung past
# 10 s on one input, or went over its memory bound); the inputs are in
# fuzz/artifacts/TARGET/.
#
# Memory: each target may use 1 GiB, and no single allocation may exceed 1 GiB. The
# replay target may use 2 GiB in all, because a replayed compressed frame may be as large
# as `image_io::DEFAULT_MAX_PIXELS` (64 Mpx, decoded through 16-bit RGBA); its single
# allocations are still held to 1 GiB, which is what caught the MCAP reader reserving a
# string's declared length (src/replay/preflight.rs).
#
#   fuzz/run.sh MINUTES [TARGET ...]     # targets: config image resume replay (default: all)
set -uo pipefail
cd "$(dirname "$0")"
if [[ $# -lt 1 ]] || ! [[ "$1" =~ ^[0-9]+(\.[0-9]+)?$ ]]; then
    echo "usage: fuzz/run.sh MINUTES [TARGET ...]" >&2
    exit 2
fi
seconds=$(awk -v m="$1" 'BEGIN { s = int(m * 60 + 0.5); print (s < 1 ? 1 : s) }')
shift
targets=("$@")
[[ ${#targets[@]} -eq 0 ]] && targets=(config image resume replay)

cargo +nightly fuzz build || exit 2
bin=target/x86_64-unknown-linux-gnu/release
log=$(mktemp -d)
trap 'rm -rf "$log"' EXIT
crashed=0
results=()
for t in "${targets[@]}"; do
    if [[ ! -x "$bin/$t" ]]; then
        echo "fuzz: no target $t" >&2
        exit 2
    fi
    mkdir -p "corpus/$t" "artifacts/$t"
    cp -n "seeds/$t"/* "corpus/$t/"
    echo "fuzz: $t for ${seconds} s"
    start=$(date +%s)
    rss=1024
    [[ $t == replay ]] && rss=2048
    "$bin/$t" "corpus/$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=$rss -malloc_limit_mb=1024 \
        -print_final_stats=1 -artifact_prefix="artifacts/$t/" >"$log/$t" 2>&1
    rc=$?
    took=$(($(date +%s) - start))
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log/$t" | tail -1)
    artifact=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$log/$t" | tail -1)
    if [[ $rc -ne 0 ]]; then
        crashed=1
        grep -E "panicked at|ERROR: libFuzzer|SUMMARY" "$log/$t" | head -5
        results+=("$t: ${execs:-?} executions in ${took} s, 1 crash: ${artifact:-see log} (exit $rc)")
    else
        results+=("$t: ${execs:-?} executions in ${took} s, 0 crashes")
    fi
    tail -3 "$log/$t"
done
echo "fuzz summary:"
printf '  %s\n' "${results[@]}"
exit $crashed
