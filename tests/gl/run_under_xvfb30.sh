#!/usr/bin/env bash
# run_under_xvfb30.sh PROGRAM: runs PROGRAM under its own Xvfb with a 10-bit
# (depth 30) 1024x64 screen whose framebuffer Xvfb keeps in a file (-fbdir),
# named in ATONLAB_XVFB_SCREEN_FILE (tests/gl/window10_xvfb.cpp). The display
# number is claimed atomically as in run_under_xvfb.sh.
set -uo pipefail
program=$1
shift
fbdir=$(mktemp -d /tmp/atonlab-xvfb30-fb.XXXXXX)
for n in $(shuf -i 191-230); do
  lock="/tmp/.atonlab-xvfb-$n.lock"
  if [ ! -e "/tmp/.X$n-lock" ] && [ ! -e "/tmp/.X11-unix/X$n" ] && mkdir "$lock" 2>/dev/null; then
    trap 'rm -rf "$lock" "$fbdir"' EXIT
    export ATONLAB_XVFB_SCREEN_FILE="$fbdir/Xvfb_screen0"
    xvfb-run -n "$n" -s "-screen 0 1024x64x30 -noreset -fbdir $fbdir" "$program" "$@"
    exit $?
  fi
done
echo "no free X display number in 191..230"
exit 1
