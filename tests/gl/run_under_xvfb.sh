#!/usr/bin/env bash
# run_under_xvfb.sh [--screen WxHxD] [--framebuffer-file] [--displays LO-HI] PROGRAM [ARGS...]
# runs PROGRAM under its own Xvfb with one screen (default 1280x720x24; depth
# 30 for the 10-bit test, tests/gl/window10_xvfb.cpp). --framebuffer-file:
# Xvfb keeps the screen's pixels in a file (-fbdir) whose path is exported in
# ATONLAB_XVFB_SCREEN_FILE, so a test can read what the X server shows
# (tests/gl/runner_xvfb.cpp, window10_xvfb.cpp). --displays: the display
# numbers to try (default 90-140; each CTest user takes its own range).
#
# xvfb-run -a picks a display by looking for a free lock file, which races when
# two test suites start at once; here the display number is claimed atomically
# (mkdir of a lock directory) from the range, and released afterwards.
set -uo pipefail
screen=1280x720x24
framebuffer_file=0
displays=90-140
while [ $# -gt 0 ]; do
  case $1 in
    --screen) screen=$2; shift 2 ;;
    --framebuffer-file) framebuffer_file=1; shift ;;
    --displays) displays=$2; shift 2 ;;
    *) break ;;
  esac
done
program=$1
shift
server_args="-screen 0 $screen -noreset"
fbdir=""
if [ "$framebuffer_file" = 1 ]; then
  fbdir=$(mktemp -d /tmp/atonlab-xvfb-fb.XXXXXX)
  server_args="$server_args -fbdir $fbdir"
  export ATONLAB_XVFB_SCREEN_FILE="$fbdir/Xvfb_screen0"
fi
# Shuffled, so back-to-back runs do not meet a lock Xvfb is still removing.
for n in $(shuf -i "$displays"); do
  lock="/tmp/.atonlab-xvfb-$n.lock"
  if [ ! -e "/tmp/.X$n-lock" ] && [ ! -e "/tmp/.X11-unix/X$n" ] && mkdir "$lock" 2>/dev/null; then
    trap 'rm -rf "$lock" ${fbdir:+"$fbdir"}' EXIT
    # -noreset: Xvfb otherwise resets when its last client disconnects (each
    # atonlab run is a client), and a test that opens a new connection during
    # that reset fails to open the display.
    xvfb-run -n "$n" -s "$server_args" "$program" "$@"
    exit $?
  fi
done
[ -n "$fbdir" ] && rm -rf "$fbdir"
echo "no free X display number in $displays"
exit 1
