#!/usr/bin/env bash
# echo_bounded.sh ATONLAB OUTDIR
# Values that once made errors grow without bound or break over lines: each
# must be refused by `atonlab render` with exit status 2 and one line on
# stderr, at most 600 bytes, that names the file, line and key (or --set)
# and echoes the value cut to 80 characters with control characters escaped.
#  - a colour name of 4 MiB (once echoed whole: a 4 MB message);
#  - a colour name with a newline (once two lines);
#  - a --set value with a newline, and a --set key of 100 KB;
#  - /dev/zero as the scene file (once "internal error: std::bad_alloc").
set -uo pipefail
atonlab=$1 outdir=$2
rm -rf "$outdir" && mkdir -p "$outdir"
fail=0

scene_with_colour() {  # FILE COLOUR_TOML_STRING_BODY
  {
    printf '[display]\nwidth_px = 64\nheight_px = 48\nwidth_m = 0.3\nviewing_distance_m = 0.6\n\n'
    printf '[[light]]\nname = "buoy"\nposition_m = [0.0, 2.0, -500.0]\nintensity_cd = 10.0\ncolour = "'
    cat
    printf '"\n'
  } >"$1"
}

expect() {  # NAME PATTERN ATONLAB_ARGS...
  local name=$1 pattern=$2
  shift 2
  "$atonlab" render "$@" -o "$outdir/$name.exr" 2>"$outdir/$name.err" >/dev/null
  local status=$?
  local lines bytes
  lines=$(wc -l <"$outdir/$name.err")
  bytes=$(wc -c <"$outdir/$name.err")
  if [ "$status" -ne 2 ]; then echo "$name: expected exit status 2, got $status"; fail=1; fi
  if [ "$lines" -ne 1 ]; then echo "$name: expected one line on stderr, got $lines"; fail=1; fi
  if [ "$bytes" -gt 600 ]; then echo "$name: the message is $bytes bytes, more than 600"; fail=1; fi
  if ! grep -Eq -- "$pattern" "$outdir/$name.err"; then echo "$name: stderr does not match /$pattern/"; fail=1; fi
  if [ -e "$outdir/$name.exr" ]; then echo "$name: an output file was written"; fail=1; fi
  echo "$name ($bytes bytes): $(head -c 600 "$outdir/$name.err")"
}

head -c 4194304 /dev/zero | tr '\0' 'x' | scene_with_colour "$outdir/long.toml"
expect long "long\.toml:11: key 'light\[0\]\.colour': .*unknown colour \"x{80}… \(4194304 bytes in all\)\"" \
  "$outdir/long.toml"

printf 'red\\nblue' | scene_with_colour "$outdir/newline.toml"
expect newline 'newline\.toml:11: key .light\[0\]\.colour.: .*unknown colour "red\\nblue"' "$outdir/newline.toml"

printf 'green' | scene_with_colour "$outdir/ok.toml"
expect set_newline '^atonlab: --set: key .light\.buoy\.colour.: .*"red\\nx"' "$outdir/ok.toml" \
  --set "light.buoy.colour=red
x"
long_key=$(head -c 102400 /dev/zero | tr '\0' 'k')
expect set_long_key "^atonlab: --set: key 'camera\.k{73}… \(102407 bytes in all\)': unknown key 'k{80}…" "$outdir/ok.toml" \
  --set "camera.$long_key=1"

expect dev_zero '^atonlab: /dev/zero: cannot read the scene file: it is larger than 16\.0 MiB' /dev/zero
exit $fail
