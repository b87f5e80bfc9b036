#!/usr/bin/env bash
# run_expect_error.sh ATONLAB PROTOCOL OUTDIR PATTERN
# Runs `atonlab run PROTOCOL --db OUTDIR/study.db --model-observer --headless`
# and passes if it exits with status 2, prints exactly one line on stderr that
# matches PATTERN (an extended regex: the file, line and key), and creates no
# study file: a bad protocol is refused before anything is stored.
set -uo pipefail
atonlab=$1 protocol=$2 outdir=$3 pattern=$4
rm -rf "$outdir" && mkdir -p "$outdir"
"$atonlab" run "$protocol" --db "$outdir/study.db" --model-observer --headless 2>"$outdir/stderr" >/dev/null
status=$?
fail=0
if [ "$status" -ne 2 ]; then echo "expected exit status 2, got $status"; fail=1; fi
if [ "$(wc -l <"$outdir/stderr")" -ne 1 ]; then echo "expected one line on stderr"; fail=1; fi
if ! grep -Eq -- "$pattern" "$outdir/stderr"; then echo "stderr does not match /$pattern/"; fail=1; fi
left=$(find "$outdir" -type f ! -name stderr)
if [ -n "$left" ]; then echo "output left behind: $left"; fail=1; fi
echo "stderr: $(cat "$outdir/stderr")"
exit $fail
