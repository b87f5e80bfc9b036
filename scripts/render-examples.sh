#!/usr/bin/env bash
# Renders every scene in scenes/ to out/NAME.exr (cd/m²) and out/NAME.png.
# The flashing buoy is sampled at several times through its period; the others
# are also rendered without glare (NAME-noglare), holding the same energy.
set -euo pipefail
cd "$(dirname "$0")/.."
atonlab="${ATONLAB_BUILD_DIR:-build}/runner/atonlab"
mkdir -p out
for scene in scenes/*.toml; do
  name="$(basename "$scene" .toml)"
  case "$name" in
    flashing-buoy)
      for t in 0.0 0.25 1.0 1.75 2.0 5.0; do
        "$atonlab" render "$scene" --time "$t" -o "out/${name}-t${t}s.exr" --png "out/${name}-t${t}s.png"
      done ;;
    sectored-lighthouse)
      # Seen from 3 km along several true bearings from seaward (observer -> light).
      for b in 080 088 090 092 100; do
        pos=$(awk -v b="$b" 'BEGIN { r = b * atan2(0, -1) / 180; printf "[%.3f, 3.0, %.3f]", -3000 * sin(r), 3000 * cos(r) }')
        "$atonlab" render "$scene" --set "camera.position_m=$pos" --set "camera.yaw_deg=$((10#$b))" \
          -o "out/${name}-bearing${b}.exr" --png "out/${name}-bearing${b}.png"
      done ;;
    tonemap-four-lights)
      # K2012 fig 6.20-6.24: adaptation levels (cd/m²) x tone mappers.
      for level in 0.001 0.0051 0.016 0.03 0.15 24 1570; do
        for op in empirical perceptual; do
          "$atonlab" render "$scene" --set "environment.luminance_cd_m2=$level" --set "eye.adaptation_cd_m2=$level" \
            --set "tonemap.operator=\"$op\"" -o "out/${name}-${level}-${op}.exr" --png "out/${name}-${level}-${op}.png"
        done
      done ;;
    *)
      "$atonlab" render "$scene" -o "out/${name}.exr" --png "out/${name}.png"
      # The energy-matched no-glare variant of the same frame.
      "$atonlab" render "$scene" --set 'eye.glare="none"' -o "out/${name}-noglare.exr" --png "out/${name}-noglare.png" ;;
  esac
done
echo "Rendered $(ls out/*.exr | wc -l) frames: EXR (linear Rec.709, cd/m²) and PNG previews are in $(pwd)/out/"
