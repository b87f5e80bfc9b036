#!/usr/bin/env bash
# render_spectra.sh ATONLAB SCENE OUTDIR: the four-colour Sabik scene (red, green,
# white, yellow by IALA name, no spd) renders with each light's glare spectrum
# named in the output and in the EXR header (docs/glare.md "The light's spectrum").
# Exit 77 (skip) when no GL 4.5 context can be made.
set -uo pipefail
atonlab=$1 scene=$2 outdir=$3
mkdir -p "$outdir"
"$atonlab" render "$scene" -o "$outdir/spectra.exr" >"$outdir/stdout" 2>"$outdir/stderr"
status=$?
if [ "$status" -eq 3 ]; then exit 77; fi
[ "$status" -eq 0 ] || { echo "render failed with status $status"; cat "$outdir/stderr"; exit 1; }
want="red=iala-red green=iala-green white=d65 yellow=iala-yellow"
grep -qF "light spectra: $want" "$outdir/stdout" || { echo "no per-light spectra line:"; cat "$outdir/stdout"; exit 1; }
for spd in iala-red iala-green d65 iala-yellow; do
    grep -q "spd=$spd " "$outdir/stdout" || { echo "no glare kernel for spd=$spd:"; cat "$outdir/stdout"; exit 1; }
done
# The header's string attribute: its name, then its value, as plain bytes.
grep -aqF "spd_lights" "$outdir/spectra.exr" || { echo "no spd_lights attribute in the EXR header"; exit 1; }
grep -aqF "$want" "$outdir/spectra.exr" || { echo "spd_lights does not list $want"; exit 1; }
