#!/usr/bin/env bash
# render_ok.sh ATONLAB SCENE OUTDIR: renders SCENE to EXR + PNG and checks both
# exist and are non-empty. Exit 77 (skip) when no GL 4.5 context can be made.
set -uo pipefail
atonlab=$1 scene=$2 outdir=$3
name=$(basename "$scene" .toml)
mkdir -p "$outdir"
"$atonlab" render "$scene" -o "$outdir/$name.exr" --png "$outdir/$name.png"
status=$?
if [ "$status" -eq 3 ]; then echo "no GPU: no OpenGL 4.5 context or display server (atonlab exited with status 3)"; exit 77; fi
[ "$status" -eq 0 ] || { echo "render failed with status $status"; exit 1; }
[ -s "$outdir/$name.exr" ] && [ -s "$outdir/$name.png" ] || { echo "missing output"; exit 1; }
