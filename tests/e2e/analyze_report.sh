#!/usr/bin/env bash
# analyze_report.sh ATONLAB CSV OUTDIR
# `atonlab analyze --csv CSV` writes the documented outputs: report.html
# (self-contained: no external reference, no script), summary.json, fits.csv,
# trials.csv, and every figure summary.json lists exists and is not empty.
# Exit 77 (a skip) when gnuplot is not installed (analyze then exits 5).
set -uo pipefail
atonlab=$1 csv=$2 outdir=$3
rm -rf "$outdir" && mkdir -p "$outdir"
"$atonlab" analyze --csv "$csv" --out "$outdir/report" --bootstrap 200 >"$outdir/out" 2>"$outdir/err"
status=$?
if [ "$status" -eq 5 ] && ! command -v gnuplot >/dev/null; then echo "missing tool: gnuplot is not installed (Debian package gnuplot-nox)"; exit 77; fi
if [ "$status" -ne 0 ]; then echo "atonlab analyze failed ($status):"; cat "$outdir/err"; exit 1; fi
fail=0
for f in report.html summary.json fits.csv trials.csv; do
  if [ ! -s "$outdir/report/$f" ]; then echo "$f missing or empty"; fail=1; fi
done
html=$outdir/report/report.html
for bad in 'src="http' "href=\"http" 'src="//' 'href="//' '<script' '<link' '@import'; do
  if grep -qiF -- "$bad" "$html"; then echo "report.html contains $bad"; fail=1; fi
done
if ! grep -q '^<!DOCTYPE html>' "$html" || ! grep -q '</html>' "$html"; then echo "report.html is not a whole HTML page"; fail=1; fi
n=0
for rel in $(grep -o '"\(png\|svg\)": *"[^"]*"' "$outdir/report/summary.json" | sed 's/.*: *"\(.*\)"/\1/'); do
  n=$((n + 1))
  if [ ! -s "$outdir/report/$rel" ]; then echo "figure $rel is listed but missing or empty"; fail=1; fi
done
if [ "$n" -lt 4 ]; then echo "only $n figure files listed"; fail=1; fi
if [ "$(grep -c 'data:image/png;base64,' "$html")" -lt 2 ]; then echo "report.html embeds no figures"; fail=1; fi
# Two observers: each has a row per condition, plus the pooled one, and the paired comparison is there.
for who in P01 P02 '(pooled)'; do
  if ! grep -q "^night,$who,headline," "$outdir/report/fits.csv"; then echo "no headline row for $who"; fail=1; fi
done
if ! grep -q '"factor": *"adaptation luminance"' "$outdir/report/summary.json"; then
  echo "no paired comparison of night and dusk"; fail=1
fi
echo "$n figure files; $(wc -l <"$outdir/report/fits.csv") lines in fits.csv"
exit $fail
