#!/usr/bin/env bash
# calibrate_window.sh ATONLAB OUTDIR XVFB_SCRIPT
# `atonlab calibrate check` in its real full-screen window under Xvfb (the
# window path of the patches: GLFW full screen on monitor 0, every patch read
# back from the window's framebuffer), with file readings, after importing a
# calibration to check against. Exit 77 (skip) without GL 4.5 or a display.
set -uo pipefail
atonlab=$1 outdir=$2 xvfb=$3
src=$(cd "$(dirname "$0")/../.." && pwd)
rm -rf "$outdir" && mkdir -p "$outdir"
"$atonlab" calibrate import "$src/tests/data/calibration/grey_ramp.csv" --display win --db "$outdir/study.db" \
  --width-px 1280 --height-px 720 --width-m 0.5 --viewing-distance-m 0.7 >"$outdir/import.log" 2>&1 \
  || { cat "$outdir/import.log"; echo "import failed"; exit 1; }
# grey_ramp.csv is an sRGB monitor, 0.2 .. 100.1 cd/m2: readings near it pass.
printf 'black 0.2\ngrey-064 5.33\ngrey-128 21.8\ngrey-191 52.2\nwhite 100.1\n' >"$outdir/readings.txt"
cat >"$outdir/check.sh" <<SCRIPT
#!/usr/bin/env bash
exec "$atonlab" calibrate check --display win --db "$outdir/study.db" --readings "$outdir/readings.txt" \
  --patch-seconds 0.05 --plot "$outdir/check.svg"
SCRIPT
chmod +x "$outdir/check.sh"
bash "$xvfb" "$outdir/check.sh" >"$outdir/check.log" 2>&1
status=$?
cat "$outdir/check.log"
if [ "$status" -eq 3 ]; then echo "no GPU: no OpenGL 4.5 context or display server (atonlab exited with status 3)"; exit 77; fi
[ "$status" -eq 0 ] || { echo "check in the window failed with status $status"; exit 1; }
grep -q "full-screen 1280 x 720 on monitor 0" "$outdir/check.log" || { echo "not shown full screen"; exit 1; }
grep -q "PASSED" "$outdir/check.log" || { echo "the check did not pass"; exit 1; }
