#!/usr/bin/env bash
# run_fuzz.sh TARGET SECONDS CORPUS SEEDS ARTIFACT_PREFIX [LIBFUZZER_OPTIONS...]
# Runs a libFuzzer target for SECONDS from the seed folder, keeping the inputs
# it finds in CORPUS, and fails if it finds a crash, a sanitizer report, a
# timeout (an input taking over 10 s) or an input needing over 2 GB. Prints
# libFuzzer's final statistics (executions, speed, coverage, corpus size).
set -uo pipefail
target=$1 seconds=$2 corpus=$3 seeds=$4 prefix=$5
shift 5
mkdir -p "$corpus"
# detect_leaks=0: the loaders allocate nothing that outlives an input, and
# LeakSanitizer needs ptrace, which containers often forbid.
ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0}" UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}" \
  "$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
  -artifact_prefix="$prefix" "$@" "$corpus" "$seeds" 2>&1 | grep -v '^#[0-9]*.*\(NEW\|REDUCE\|pulse\)'
status=${PIPESTATUS[0]}
if [ "$status" -ne 0 ]; then
  echo "fuzzing $(basename "$target") failed (exit status $status): the input is in ${prefix}*"
fi
exit "$status"
