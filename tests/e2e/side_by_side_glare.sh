#!/usr/bin/env bash
# side_by_side_glare.sh ATONLAB PROTOCOL OUTDIR
# Issue 14, end to end: a side-by-side 2AFC whose test light has its own
# wave-optics glare and whose reference has none (test_set / reference_set on
# light.NAME.glare) runs with the model observer; every stored trial names
# each view's glare model (stimulus_json views[].glare), and `atonlab analyze`
# reports "wave-optics" on the test and "none" on the reference (trials.csv
# and report.html). Issue 24: the report calls the glare-only difference an
# enhancement by glare, its snapshot shows both lights, and trials.csv has the
# block's name and numeric positions. Exit 77 (a skip) where no GL 4.5 context exists.
set -uo pipefail
atonlab=$1 protocol=$2 outdir=$3
rm -rf "$outdir" && mkdir -p "$outdir"
"$atonlab" run "$protocol" --db "$outdir/study.db" --model-observer --headless --no-true-pse >"$outdir/run.out" 2>"$outdir/run.err"
status=$?
if [ "$status" -eq 3 ]; then echo "no GPU: no OpenGL 4.5 context ($(cat "$outdir/run.err"))"; exit 77; fi
if [ "$status" -ne 0 ]; then echo "atonlab run failed ($status):"; cat "$outdir/run.err"; exit 1; fi
fail=0
# The stored views (read with the sqlite3 shell where it is installed).
if command -v sqlite3 >/dev/null; then
  n=$(sqlite3 "$outdir/study.db" "SELECT count(*) FROM trials")
  both=$(sqlite3 "$outdir/study.db" "SELECT count(*) FROM trials WHERE stimulus_json LIKE '%\"role\":\"test\",\"glare\":\"wave-optics\"%' AND stimulus_json LIKE '%\"role\":\"reference\",\"glare\":\"none\"%'")
  if [ "$n" -lt 2 ] || [ "$both" -ne "$n" ]; then echo "$both of $n stored trials name both views' glare"; fail=1; fi
else
  echo "(sqlite3 shell not installed: the stored views are checked through the analysis only)"
fi
"$atonlab" analyze "$outdir/study.db" --out "$outdir/report" --bootstrap 50 >"$outdir/analyze.out" 2>"$outdir/analyze.err"
status=$?
if [ "$status" -eq 5 ] && ! command -v gnuplot >/dev/null; then echo "missing tool: gnuplot is not installed (Debian package gnuplot-nox)"; exit 77; fi
if [ "$status" -ne 0 ]; then echo "atonlab analyze failed ($status):"; cat "$outdir/analyze.err"; exit 1; fi
# trials.csv: glare_test and glare_reference columns.
header=$(head -1 "$outdir/report/trials.csv")
col() { echo "$header" | tr ',' '\n' | grep -nxF -- "$1" | cut -d: -f1; }
gt=$(col glare_test) gr=$(col glare_reference)
pairs=$(tail -n +2 "$outdir/report/trials.csv" | cut -d, -f"$gt,$gr" | sort -u)
if [ "$pairs" != "wave-optics,none" ]; then echo "trials.csv glare_test,glare_reference: $pairs"; fail=1; fi
if ! grep -q "glare wave-optics on the test and none on the reference" "$outdir/report/report.html"; then
  echo "report.html does not name each side's glare model"; fail=1
fi
# Issue 24: glare is the only difference between the two white lights, so the
# report calls it an enhancement by glare; the snapshot crops around both
# lights; trials.csv names the block and writes positions as numbers.
if ! grep -q "enhancement by glare" "$outdir/report/report.html"; then
  echo "report.html does not call a glare-only difference an enhancement by glare"; fail=1
fi
if ! grep -q "frame 0 test (white, F, spd d65, glare wave-optics)" "$outdir/report/report.html" ||
   ! grep -q "frame 0 reference (white, F, spd d65, glare none)" "$outdir/report/report.html"; then
  echo "the snapshot's caption does not name both lights"; fail=1
fi
blocks=$(tail -n +2 "$outdir/report/trials.csv" | cut -d, -f"$(col block)" | sort -u)
if [ "$blocks" != "starlight" ]; then echo "trials.csv block: $blocks"; fail=1; fi
x=$(col 'light.test.position_m[0]')
if [ -z "$x" ]; then echo "trials.csv has no numeric position column"; fail=1
else
  xs=$(tail -n +2 "$outdir/report/trials.csv" | cut -d, -f"$x" | sort -u | tr '\n' ' ')
  if [ "$xs" != "-26.2 26.2 " ]; then echo "trials.csv light.test.position_m[0]: $xs"; fail=1; fi
fi
echo "glare test/reference: $pairs"
exit $fail
