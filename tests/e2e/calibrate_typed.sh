#!/usr/bin/env bash
# calibrate_typed.sh ATONLAB OUTDIR XVFB_SCRIPT
# `atonlab calibrate check` in its full-screen window under Xvfb with the
# readings typed on the terminal (here: piped to stdin): a typo is refused
# and asked again, "r" shows the patch again, a reading below a lower level's
# must be typed twice, "b" goes back one patch, units cd/m2 and fL are taken.
# Passes when the check stores exactly the readings finally accepted, saves
# them beside the study file, and passes. Exit 77 (skip) without GL 4.5 or a display.
set -uo pipefail
atonlab=$1 outdir=$2 xvfb=$3
src=$(cd "$(dirname "$0")/../.." && pwd)
rm -rf "$outdir" && mkdir -p "$outdir"
"$atonlab" calibrate import "$src/tests/data/calibration/grey_ramp.csv" --display typed --db "$outdir/study.db" \
  --width-px 1280 --height-px 720 --width-m 0.5 --viewing-distance-m 0.7 >"$outdir/import.log" 2>&1 \
  || { cat "$outdir/import.log"; echo "import failed"; exit 1; }
# black; grey-064 (a typo, then right); grey-128 (r, a slip of the decimal point
# below grey-064's reading, then right); grey-191 (b: back to grey-128, again);
# grey-191 in cd/m2; white in foot-lamberts: 29.2 fL = 100.046 cd/m2.
printf '0.2\n5.3x\n5.33\nr\n2.18\n21.8\nb\n21.7\n52.2 cd/m2\n29.2 fL\n' >"$outdir/typed.txt"
cat >"$outdir/check.sh" <<SCRIPT
#!/usr/bin/env bash
exec "$atonlab" calibrate check --display typed --db "$outdir/study.db" --no-plot <"$outdir/typed.txt"
SCRIPT
chmod +x "$outdir/check.sh"
bash "$xvfb" "$outdir/check.sh" >"$outdir/check.log" 2>&1
status=$?
cat "$outdir/check.log"
if [ "$status" -eq 3 ]; then echo "no GPU: no OpenGL 4.5 context or display server (atonlab exited with status 3)"; exit 77; fi
[ "$status" -eq 0 ] || { echo "the typed check failed with status $status"; exit 1; }
fail=0
grep -q "not a reading ('5.3x' is not a number)" "$outdir/check.log" || { echo "the typo was not refused"; fail=1; }
grep -q "grey-064 is shown again" "$outdir/check.log" && { echo "r showed the wrong patch"; fail=1; }
grep -q "grey-128 is shown again" "$outdir/check.log" || { echo "r did not show the patch again"; fail=1; }
grep -q "2.18 cd/m² is below the 5.33 cd/m² of grey-064" "$outdir/check.log" || { echo "no typo guard"; fail=1; }
grep -Eq "^  white: 100.05 cd/m²" "$outdir/check.log" || { echo "fL was not converted"; fail=1; }
saved=$(ls "$outdir"/study-typed-*.readings 2>/dev/null | head -1)
[ -n "$saved" ] || { echo "the typed readings were not saved beside the study"; fail=1; }
want=$'black 0.2\ngrey-064 5.33\ngrey-128 21.7\ngrey-191 52.2'
got=$(grep -v '^#' "$saved" | head -4)
[ "$got" == "$want" ] || { echo "saved readings: $got"; fail=1; }
exit $fail
