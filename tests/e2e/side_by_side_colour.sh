#!/usr/bin/env bash
# side_by_side_colour.sh ATONLAB PROTOCOL OUTDIR
# Issue 24, end to end: a red Fl(1) 4s test light with glare beside a steady
# white reference without it (colour and rhythm set by the protocol's
# test_set over the scene's white lights). The study file stores the scene
# text with its SHA-256; `atonlab analyze` names each side's colour and rhythm
# in report.html, summary.json and fits.csv, never calls the difference an
# "enhancement by glare" (colour and rhythm differ too), and its snapshot
# names both lights. Exit 77 (a skip) where no GL 4.5 context exists.
set -uo pipefail
atonlab=$1 protocol=$2 outdir=$3
rm -rf "$outdir" && mkdir -p "$outdir"
"$atonlab" run "$protocol" --db "$outdir/study.db" --model-observer --headless --no-true-pse \
  --allow-undisplayable >"$outdir/run.out" 2>"$outdir/run.err"
status=$?
if [ "$status" -eq 3 ]; then echo "skipped: no OpenGL 4.5 context ($(cat "$outdir/run.err"))"; exit 77; fi
if [ "$status" -ne 0 ]; then echo "atonlab run failed ($status):"; cat "$outdir/run.err"; exit 1; fi
fail=0
scene=$(dirname "$protocol")/small.scene.toml
if command -v sqlite3 >/dev/null && command -v sha256sum >/dev/null; then
  stored=$(sqlite3 "$outdir/study.db" "SELECT sc.sha256 FROM sessions s JOIN scenes sc ON sc.id = s.scene_id")
  want=$(sha256sum "$scene" | cut -d' ' -f1)
  if [ "$stored" != "$want" ]; then echo "stored scene SHA-256 $stored, the file's $want"; fail=1; fi
fi
"$atonlab" analyze "$outdir/study.db" --out "$outdir/report" --bootstrap 50 >"$outdir/analyze.out" 2>"$outdir/analyze.err"
status=$?
if [ "$status" -eq 5 ] && ! command -v gnuplot >/dev/null; then echo "skipped: gnuplot is not installed"; exit 77; fi
if [ "$status" -ne 0 ]; then echo "atonlab analyze failed ($status):"; cat "$outdir/analyze.err"; exit 1; fi
r=$outdir/report
for f in report.html summary.json fits.csv; do
  if grep -q "enhancement by glare" "$r/$f"; then echo "$f calls a red-vs-white difference an enhancement by glare"; fail=1; fi
done
grep -q "red, rhythm Fl(1) 4s" "$r/report.html" || { echo "report.html does not name the red test"; fail=1; }
grep -q "white, rhythm F" "$r/report.html" || { echo "report.html does not name the white reference"; fail=1; }
grep -q "test − reference" "$r/report.html" || { echo "report.html does not say test − reference"; fail=1; }
grep -q "frame 0 test (red, Fl(1) 4s, spd iala-red, glare wave-optics)" "$r/report.html" &&
  grep -q "frame 0 reference (white, F, spd d65, glare none)" "$r/report.html" ||
  { echo "the snapshot's caption does not name both lights"; fail=1; }
grep -q '"colour": "red"' "$r/summary.json" || { echo "summary.json does not name the red test"; fail=1; }
# fits.csv quotes fields that hold commas (reasons, methods): read it with a CSV reader.
fits_col() { python3 -c 'import csv, sys; print("\n".join(sorted({r[sys.argv[2]] for r in csv.DictReader(open(sys.argv[1]))})))' "$r/fits.csv" "$1"; }
tc=$(fits_col test_colour)
rc=$(fits_col reference_colour)
if [ "$tc" != "red" ] || [ "$rc" != "white" ]; then echo "fits.csv test_colour $tc, reference_colour $rc"; fail=1; fi
echo "test $tc / reference $rc"
exit $fail
