#!/usr/bin/env bash
# expect_error.sh ATONLAB SCENE OUTDIR [EXTRA_ARGS] [PATTERN]
# Runs `atonlab render SCENE -o OUTDIR/x.exr --png OUTDIR/x.png EXTRA_ARGS` and
# passes if it exits with status 2, prints exactly one line on stderr that
# matches PATTERN (default: the scene's "# expect:" line, an extended regex),
# and leaves no output file behind.
set -uo pipefail
atonlab=$1 scene=$2 outdir=$3 extra=${4:-} pattern=${5:-}
if [ -z "$pattern" ]; then
  pattern=$(sed -n 's/^# expect: //p' "$scene" | head -1)
fi
rm -rf "$outdir" && mkdir -p "$outdir"
# shellcheck disable=SC2086
eval set -- $extra
"$atonlab" render "$scene" -o "$outdir/x.exr" --png "$outdir/x.png" "$@" 2>"$outdir/stderr" >/dev/null
status=$?
err=$(cat "$outdir/stderr")
fail=0
if [ "$status" -ne 2 ]; then echo "expected exit status 2, got $status"; fail=1; fi
if [ "$(wc -l <"$outdir/stderr")" -ne 1 ]; then echo "expected one line on stderr"; fail=1; fi
if ! grep -Eq -- "$pattern" "$outdir/stderr"; then echo "stderr does not match /$pattern/"; fail=1; fi
left=$(find "$outdir" -type f ! -name stderr)
if [ -n "$left" ]; then echo "output left behind: $left"; fail=1; fi
echo "stderr: $err"
exit $fail
