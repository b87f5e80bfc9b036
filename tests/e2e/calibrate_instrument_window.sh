#!/usr/bin/env bash
# calibrate_instrument_window.sh ATONLAB OUTDIR XVFB_SCRIPT
# `atonlab calibrate measure` and `check` with the virtual instrument in the
# real full-screen window under Xvfb (the instrument reads the window's
# framebuffer back): measure a GOG display (peak 150, black 0.3 cd/m², γ 2.4),
# then check it (passes) and check it with the peak 10 % lower (fails naming
# peak_percent); the stored grey-128 reading is the law at code 128.
# Exit 77 (skip) without GL 4.5 or a display.
set -uo pipefail
atonlab=$1 outdir=$2 xvfb=$3
rm -rf "$outdir" && mkdir -p "$outdir"
law="--virtual-peak-cd-m2 150 --virtual-black-cd-m2 0.3 --virtual-gamma 2.4"
cat >"$outdir/run.sh" <<SCRIPT
#!/usr/bin/env bash
"$atonlab" calibrate measure --display win --db "$outdir/study.db" --instrument virtual --settle-s 0 $law \
  --width-m 0.5 --viewing-distance-m 0.7 >"$outdir/measure.log" 2>&1 || exit \$?
"$atonlab" calibrate check --display win --db "$outdir/study.db" --instrument virtual --settle-s 0 $law \
  --no-plot >"$outdir/check.log" 2>&1 || exit 10
"$atonlab" calibrate check --display win --db "$outdir/study.db" --instrument virtual --settle-s 0 \
  --virtual-peak-cd-m2 135 --virtual-black-cd-m2 0.3 --virtual-gamma 2.4 --no-plot >"$outdir/dim.log" 2>&1
[ \$? -eq 1 ] || exit 11
SCRIPT
chmod +x "$outdir/run.sh"
bash "$xvfb" "$outdir/run.sh"
status=$?
cat "$outdir"/*.log
if [ "$status" -eq 3 ]; then echo "no GPU: no OpenGL 4.5 context or display server (atonlab exited with status 3)"; exit 77; fi
[ "$status" -eq 0 ] || { echo "measure/check in the window failed with status $status"; exit 1; }
grep -q "full-screen 1280 x 720 on monitor 0" "$outdir/measure.log" || { echo "not shown full screen"; exit 1; }
grep -q "PASSED" "$outdir/check.log" || { echo "the check on the same display did not pass"; exit 1; }
grep -q "peak_percent" "$outdir/dim.log" || { echo "the dimmer display's check did not name peak_percent"; exit 1; }
# grey-128: Y = 0.3 + 149.7 (128/255)^2.4, stored from the window's read-back codes.
stored=$(sqlite3 "$outdir/study.db" "SELECT luminance_cd_m2 FROM calibration_readings WHERE patch = 'grey-128'")
python3 - "$stored" <<'PY' || exit 1
import sys
want = 0.3 + 149.7 * (128 / 255) ** 2.4
got = float(sys.argv[1])
print(f"grey-128: stored {got} cd/m2, law {want} cd/m2")
sys.exit(0 if abs(got - want) <= 1e-6 * want else 1)
PY
