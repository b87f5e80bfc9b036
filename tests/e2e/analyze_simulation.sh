#!/usr/bin/env bash
# analyze_simulation.sh ATONLAB MAKE_SIMULATION_FOLDER OUTDIR
# `atonlab analyze DIR` of a simulation folder writes report.html (self-contained),
# summary.json, simulation.csv (a row per condition), sessions.csv (a row per
# session and condition) and three figures, and lists the unfinished file it left
# out; a folder that is no simulation and --effect given with a study file exit 2.
# Exit 77 (a skip) when gnuplot is not installed (analyze then exits 5).
set -uo pipefail
atonlab=$1 make=$2 outdir=$3
rm -rf "$outdir" && mkdir -p "$outdir"
"$make" "$outdir/sim" 30 4 || { echo "make_simulation_folder failed"; exit 1; }
# An unfinished session, as `simulate` leaves one it was stopped in.
cp "$outdir/sim/sessions/00/session-000000.db" "$outdir/sim/sessions/00/session-000030.db.partial"
"$atonlab" analyze "$outdir/sim" --out "$outdir/report" --effect 0.05 >"$outdir/out" 2>"$outdir/err"
status=$?
if [ "$status" -eq 5 ] && ! command -v gnuplot >/dev/null; then echo "missing tool: gnuplot is not installed (Debian package gnuplot-nox)"; exit 77; fi
if [ "$status" -ne 0 ]; then echo "atonlab analyze DIR failed ($status):"; cat "$outdir/err"; exit 1; fi
fail=0
for f in report.html summary.json simulation.csv sessions.csv figures/simulation-estimates.png \
         figures/simulation-widths.png figures/simulation-coverage.png; do
  if [ ! -s "$outdir/report/$f" ]; then echo "$f missing or empty"; fail=1; fi
done
html=$outdir/report/report.html
for bad in 'src="http' "href=\"http" '<script' '<link' '@import'; do
  if grep -qiF -- "$bad" "$html"; then echo "report.html contains $bad"; fail=1; fi
done
if [ "$(grep -c 'data:image/png;base64,' "$html")" -ne 3 ]; then echo "report.html does not embed the 3 figures"; fail=1; fi
if [ "$(wc -l <"$outdir/report/simulation.csv")" -ne 3 ]; then echo "simulation.csv: not a header and 2 conditions"; fail=1; fi
if [ "$(wc -l <"$outdir/report/sessions.csv")" -ne 61 ]; then echo "sessions.csv: not a header and 30 x 2 rows"; fail=1; fi
if ! grep -q 'session-000030.db.partial.*unfinished' "$outdir/err"; then echo "the .partial file is not listed on stderr"; fail=1; fi
if ! grep -q 'session-000030.db.partial' "$html"; then echo "the .partial file is not listed in report.html"; fail=1; fi
if ! grep -q '"read": 30' "$outdir/report/summary.json"; then echo "summary.json: not 30 sessions read"; fail=1; fi
# Bad input: exit 2, nothing written.
mkdir -p "$outdir/plain"
"$atonlab" analyze "$outdir/plain" --out "$outdir/plain-out" 2>"$outdir/err2"
if [ $? -ne 2 ] || ! grep -q 'without simulation.json' "$outdir/err2" || [ -e "$outdir/plain-out" ]; then
  echo "a folder without simulation.json was not refused with exit 2:"; cat "$outdir/err2"; fail=1
fi
"$atonlab" analyze "$outdir/sim/sessions/00/session-000001.db" --effect 0.05 --out "$outdir/effect-out" 2>"$outdir/err3"
if [ $? -ne 2 ] || ! grep -q -- '--effect' "$outdir/err3" || [ -e "$outdir/effect-out" ]; then
  echo "--effect with a study file was not refused with exit 2:"; cat "$outdir/err3"; fail=1
fi
cat "$outdir/out"
exit $fail
