#!/usr/bin/env bash
# view_screenshot.sh ATONLAB SCENE OUTDIR XVFB_SCRIPT "COMMON" "RENDER_EXTRA" "VIEW_EXTRA"
# Renders SCENE headless (`atonlab render --png`) with the arguments COMMON
# and RENDER_EXTRA, then shows it in `atonlab view` under Xvfb (XVFB_SCRIPT,
# the tests/gl/run_under_xvfb.sh of the window test) for 3 frames with COMMON
# and VIEW_EXTRA (e.g. scripted keys) and writes the displayed frame.
# Passes when the two PNGs hold the same code values (byte-identical files from
# the same PNG writer). Exit 77 (skip) without GL 4.5 or a display server.
set -uo pipefail
atonlab=$1 scene=$2 outdir=$3 xvfb=$4 common=$5 render_extra=$6 view_extra=$7
rm -rf "$outdir" && mkdir -p "$outdir"
eval "render_args=($common $render_extra)"
"$atonlab" render "$scene" -o "$outdir/render.exr" --png "$outdir/render.png" "${render_args[@]}" >"$outdir/render.log" 2>&1
status=$?
if [ "$status" -eq 3 ]; then cat "$outdir/render.log"; echo "no GPU: no OpenGL 4.5 context (atonlab exited with status 3)"; exit 77; fi
[ "$status" -eq 0 ] || { cat "$outdir/render.log"; echo "render failed with status $status"; exit 1; }

# The command goes in a script, so that COMMON and VIEW_EXTRA keep their shell quoting.
cat >"$outdir/view.sh" <<SCRIPT
#!/usr/bin/env bash
exec "$atonlab" view "$scene" $common $view_extra --frames 3 --screenshot "$outdir/view.png"
SCRIPT
chmod +x "$outdir/view.sh"
bash "$xvfb" "$outdir/view.sh" >"$outdir/view.log" 2>&1
status=$?
cat "$outdir/view.log"
if [ "$status" -eq 3 ]; then echo "no GPU: no OpenGL 4.5 context or display server (atonlab exited with status 3)"; exit 77; fi
[ "$status" -eq 0 ] || { echo "view failed with status $status"; exit 1; }
[ -s "$outdir/view.png" ] || { echo "view wrote no screenshot"; exit 1; }
if ! cmp -s "$outdir/render.png" "$outdir/view.png"; then
  echo "the view's displayed frame differs from atonlab render's PNG: $outdir/render.png vs $outdir/view.png"
  exit 1
fi
echo "view.png == render.png ($(stat -c %s "$outdir/view.png") bytes)"
