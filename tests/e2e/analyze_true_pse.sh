#!/usr/bin/env bash
# analyze_true_pse.sh ATONLAB PROTOCOL OUTDIR
# Model observer -> study file -> analysis, end to end: `atonlab run` answers
# PROTOCOL with the model observer (headless; it prints the model's true PSE
# per condition), `atonlab analyze` fits the study file, and every condition
# with a true PSE must have a headline interval (fits.csv) that holds it.
# The stimulus snapshots are in the report. Then the report's trials.csv is analysed again as a CSV input and must give
# the same fits.csv rows. Exit 77 (a skip) where no GL 4.5 context exists.
set -uo pipefail
atonlab=$1 protocol=$2 outdir=$3
rm -rf "$outdir" && mkdir -p "$outdir"
"$atonlab" run "$protocol" --db "$outdir/study.db" --model-observer --headless >"$outdir/run.out" 2>"$outdir/run.err"
status=$?
if [ "$status" -eq 3 ]; then echo "no GPU: no OpenGL 4.5 context ($(cat "$outdir/run.err"))"; exit 77; fi
if [ "$status" -ne 0 ]; then echo "atonlab run failed ($status):"; cat "$outdir/run.err"; exit 1; fi
# "  CONDITION   ...; model's true PSE 2.046 (estimate − true = ...)"
sed -n "s/^  \([^ ]*\) .*model's true PSE \([-0-9.]*\).*/\1 \2/p" "$outdir/run.out" >"$outdir/true.txt"
if [ ! -s "$outdir/true.txt" ]; then echo "atonlab run printed no true PSE:"; cat "$outdir/run.out"; exit 1; fi

"$atonlab" analyze "$outdir/study.db" --out "$outdir/report" --bootstrap 400 >"$outdir/analyze.out" 2>"$outdir/analyze.err"
status=$?
if [ "$status" -ne 0 ]; then echo "atonlab analyze failed ($status):"; cat "$outdir/analyze.err"; exit 1; fi
fail=0
# fits.csv columns: condition,observer,analysis,track,task,procedure,level_unit,n_trials,n_levels,estimate,ci_lower,ci_upper,...
while read -r condition truth; do
  row=$(awk -F, -v c="$condition" '$1 == c && $3 == "headline" { print $10, $11, $12; exit }' "$outdir/report/fits.csv")
  read -r estimate lower upper <<<"$row"
  if [ -z "$lower" ] || [ -z "$upper" ]; then
    echo "$condition: no interval in fits.csv (row: $row)"; fail=1; continue
  fi
  if awk -v t="$truth" -v lo="$lower" -v hi="$upper" 'BEGIN { exit !(lo <= t && t <= hi) }'; then
    echo "$condition: true PSE $truth inside [$lower, $upper] (estimate $estimate)"
  else
    echo "$condition: true PSE $truth OUTSIDE [$lower, $upper] (estimate $estimate)"; fail=1
  fi
done <"$outdir/true.txt"

# Each condition's stored stimulus snapshot became a PNG in the report.
while read -r condition truth; do
  png="$outdir/report/figures/snapshot-$condition.png"
  if [ ! -s "$png" ] || [ "$(head -c 4 "$png" | tail -c 3)" != "PNG" ]; then echo "no snapshot PNG for $condition"; fail=1; fi
done <"$outdir/true.txt"
for bad in 'src="http' 'href="http' '<script'; do
  if grep -qiF -- "$bad" "$outdir/report/report.html"; then echo "report.html contains $bad"; fail=1; fi
done

# fits.csv carries the design's factors as typed columns (a CSV reader, no pandas): the adaptation
# luminance and the tone mapper of every condition, and the block's environment luminance (a factor
# column named by its scene key), with no TOML quotes.
if ! bash "$(dirname "$0")/check_fits_factors.sh" "$outdir/report/fits.csv" adaptation_cd_m2=number \
     tone_operator=name glare_test=name environment.luminance_cd_m2=number; then fail=1; fi
# trials.csv: a chose_reference column; session ids that do not depend on the path given to analyze.
if ! head -1 "$outdir/report/trials.csv" | grep -q ',chose_reference,'; then echo "trials.csv has no chose_reference"; fail=1; fi
if grep -qF -- "$outdir/study.db#" "$outdir/report/trials.csv" || ! grep -q '^study\.db#1,' "$outdir/report/trials.csv"; then
  echo "trials.csv session ids are not study.db#ID"; fail=1
fi

# The tidy trials.csv read back as input gives the same fits (rows sorted: a CSV does not carry the protocol's order).
"$atonlab" analyze --csv "$outdir/report/trials.csv" --out "$outdir/again" --bootstrap 400 >/dev/null 2>"$outdir/again.err"
status=$?
if [ "$status" -ne 0 ]; then echo "analyze of trials.csv failed ($status):"; cat "$outdir/again.err"; fail=1; fi
if ! diff <(sort "$outdir/report/fits.csv") <(sort "$outdir/again/fits.csv") >"$outdir/fits.diff"; then
  echo "fits.csv differs after the trials.csv round trip:"; head -20 "$outdir/fits.diff"; fail=1
fi
exit $fail
