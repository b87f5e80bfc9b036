#!/usr/bin/env bash
# psf.sh ATONLAB OUTDIR
# `atonlab psf` writes the RGB PSF, the mono PSF and the area layers with their
# header attributes; bad input (pupil <= 0, size not a power of two, unknown
# SPD, an unreadable scene) exits with status 2, one line, and writes nothing.
set -uo pipefail
atonlab=$1 outdir=$2
rm -rf "$outdir" && mkdir -p "$outdir"
fail=0
"$atonlab" psf --clear --pupil-mm 3 --size 128 --samples 8 --area-radius-px 4 --area-layers 3 -o "$outdir/psf.exr" >"$outdir/log" 2>&1
status=$?
if [ "$status" -eq 3 ]; then echo "no GPU: no OpenGL 4.5 context"; exit 77; fi
if [ "$status" -ne 0 ]; then echo "psf failed with status $status"; cat "$outdir/log"; fail=1; fi
for f in psf.exr psf-mono.exr psf-area-00.exr psf-area-02.exr; do
  [ -s "$outdir/$f" ] || { echo "missing $f"; fail=1; }
done
for attr in degreesPerPixel wavelength units; do
  grep -aq "$attr" "$outdir/psf-mono.exr" || { echo "psf-mono.exr has no $attr attribute"; fail=1; }
done
bad() {  # bad PATTERN ARGS...
  local pattern=$1; shift
  local dir="$outdir/bad" && rm -rf "$dir" && mkdir -p "$dir"
  "$atonlab" psf "$@" -o "$dir/x.exr" >/dev/null 2>"$dir/stderr"
  local s=$?
  [ "$s" -eq 2 ] || { echo "psf $*: expected status 2, got $s"; fail=1; }
  [ "$(wc -l <"$dir/stderr")" -eq 1 ] || { echo "psf $*: expected one line on stderr"; fail=1; }
  grep -Eq -- "$pattern" "$dir/stderr" || { echo "psf $*: stderr does not match /$pattern/: $(cat "$dir/stderr")"; fail=1; }
  [ -z "$(find "$dir" -name '*.exr')" ] || { echo "psf $*: wrote output"; fail=1; }
}
bad "pupil-mm.*positive" --pupil-mm 0
bad "pupil-mm.*positive" --pupil-mm -2
bad "size.*power of two" --size 300
bad "spd.*unknown spectrum \"sodium\"" --spd sodium
bad "no-such-scene.toml" --scene "$outdir/no-such-scene.toml"
exit $fail
