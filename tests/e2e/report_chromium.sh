#!/usr/bin/env bash
# report_chromium.sh ATONLAB INPUT OUTDIR
# The report as a reader's browser shows it (headless Chromium, 1280 px wide):
# the page does not overflow sideways (document scrollWidth == clientWidth: wide
# tables scroll inside their own box), every <img> decodes (naturalWidth > 0),
# and a screenshot at 1280 px is 1280 px wide. INPUT is a trials CSV (analysed
# with --csv), a protocol (run headless with the model observer first), or the
# make_simulation_folder tool (a simulation folder of 20 sessions, analysed as
# `atonlab analyze DIR --effect 0.05`: the simulation report).
# Exit 77 (a skip) when chromium or gnuplot is not installed (scripts/setup.sh
# installs both) or, for a protocol, where no GL 4.5 context exists.
set -uo pipefail
atonlab=$1 input=$2 outdir=$3
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then echo "missing tool: chromium is not installed (scripts/setup.sh installs it)"; exit 77; fi
rm -rf "$outdir" && mkdir -p "$outdir"
if [[ "$input" == *.toml ]]; then
  "$atonlab" run "$input" --db "$outdir/study.db" --model-observer --headless >"$outdir/run.out" 2>"$outdir/run.err"
  status=$?
  if [ "$status" -eq 3 ]; then echo "no GPU: no OpenGL 4.5 context ($(cat "$outdir/run.err"))"; exit 77; fi
  if [ "$status" -ne 0 ]; then echo "atonlab run failed ($status):"; cat "$outdir/run.err"; exit 1; fi
  "$atonlab" analyze "$outdir/study.db" --out "$outdir/report" --bootstrap 100 >"$outdir/out" 2>"$outdir/err"
elif [[ "$(basename "$input")" == make_simulation_folder ]]; then
  "$input" "$outdir/sim" 20 4 || { echo "make_simulation_folder failed"; exit 1; }
  "$atonlab" analyze "$outdir/sim" --out "$outdir/report" --effect 0.05 >"$outdir/out" 2>"$outdir/err"
else
  "$atonlab" analyze --csv "$input" --out "$outdir/report" --bootstrap 100 >"$outdir/out" 2>"$outdir/err"
fi
status=$?
if [ "$status" -eq 5 ] && ! command -v gnuplot >/dev/null; then echo "missing tool: gnuplot is not installed (Debian package gnuplot-nox)"; exit 77; fi
if [ "$status" -ne 0 ]; then echo "atonlab analyze failed ($status):"; cat "$outdir/err"; exit 1; fi

# A copy of the page with a measuring script at its end (the report itself has
# no script): it writes what it finds into an attribute that --dump-dom shows.
page=$outdir/report/check.html
sed 's|</body>|<script>addEventListener("load", () => { const e = document.documentElement; const imgs = [...document.images]; const broken = imgs.filter(i => !(i.complete \&\& i.naturalWidth > 0)).map(i => i.alt); document.body.setAttribute("data-check", `scroll=${e.scrollWidth} client=${e.clientWidth} images=${imgs.length} broken=${broken.length} [${broken.join("; ")}]`); });</script></body>|' \
  "$outdir/report/report.html" >"$page"
flags=(--headless=new --no-sandbox --disable-gpu --hide-scrollbars --window-size=1280,1000 --virtual-time-budget=10000)
timeout 120 "$browser" "${flags[@]}" --dump-dom "file://$(realpath "$page")" >"$outdir/dom.html" 2>"$outdir/chromium.err"
check=$(grep -o 'data-check="[^"]*"' "$outdir/dom.html" | head -1)
if [ -z "$check" ]; then echo "chromium ran no check:"; tail -5 "$outdir/chromium.err"; exit 1; fi
echo "at 1280 px: $check"
fail=0
read -r scroll client images broken <<<"$(sed 's/.*scroll=\([0-9]*\) client=\([0-9]*\) images=\([0-9]*\) broken=\([0-9]*\).*/\1 \2 \3 \4/' <<<"$check")"
if [ "$client" -ne 1280 ] || [ "$scroll" -ne "$client" ]; then
  echo "the page overflows sideways: scrollWidth $scroll, clientWidth $client (want both 1280)"; fail=1
fi
if [ "$images" -lt 2 ]; then echo "only $images images in the page"; fail=1; fi
if [ "$broken" -ne 0 ]; then echo "$broken image(s) do not decode: $check"; fail=1; fi

# The screenshot a reader would see, 1280 px wide (PNG IHDR: width at bytes 16..19).
timeout 120 "$browser" "${flags[@]}" --window-size=1280,2400 --screenshot="$outdir/report-1280.png" \
  "file://$(realpath "$outdir/report/report.html")" >/dev/null 2>>"$outdir/chromium.err"
if [ ! -s "$outdir/report-1280.png" ]; then echo "no screenshot"; exit 1; fi
width=$(od -An -tu1 -j16 -N4 "$outdir/report-1280.png" | awk '{ print $1 * 16777216 + $2 * 65536 + $3 * 256 + $4 }')
echo "screenshot: $outdir/report-1280.png, $width px wide"
if [ "$width" -ne 1280 ]; then echo "the screenshot is $width px wide, not 1280"; fail=1; fi
exit $fail
