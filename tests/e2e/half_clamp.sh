#!/usr/bin/env bash
# half_clamp.sh ATONLAB SCENE OUTDIR: a 250 cd light of 1 cm radius (8e5 cd/m²) is far above the half-float
# range; `render --half` must still succeed, clamp (never +inf) and warn once.
set -uo pipefail
atonlab=$1 scene=$2 outdir=$3
mkdir -p "$outdir"
"$atonlab" render "$scene" --half --set "light.white.position_m=[0.0, 3.0, -5.0]" --set light.white.radius_m=0.01 -o "$outdir/half.exr" 2>"$outdir/stderr" >/dev/null
status=$?
if [ "$status" -eq 3 ]; then echo "no GPU: no OpenGL 4.5 context or display server (atonlab exited with status 3)"; exit 77; fi
[ "$status" -eq 0 ] || { echo "render failed with status $status"; cat "$outdir/stderr"; exit 1; }
grep -q "clamped" "$outdir/stderr" || { echo "no clamp warning"; exit 1; }
[ -s "$outdir/half.exr" ] || { echo "no EXR written"; exit 1; }
