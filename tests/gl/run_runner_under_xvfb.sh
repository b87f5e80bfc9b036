#!/usr/bin/env bash
# run_runner_under_xvfb.sh PROGRAM [ARGS...]: runs PROGRAM under its own Xvfb
# for the full-screen runner's tests (tests/gl/runner_xvfb.cpp): one 640x360x24
# screen whose framebuffer Xvfb keeps in a file (-fbdir), so a test can read
# what the X server shows; the file's path is in ATONLAB_XVFB_SCREEN_FILE.
# The display number is claimed atomically as in run_under_xvfb.sh.
set -uo pipefail
program=$1
shift
fbdir=$(mktemp -d /tmp/atonlab-xvfb-fb.XXXXXX)
for n in $(shuf -i 141-190); do
  lock="/tmp/.atonlab-xvfb-$n.lock"
  if [ ! -e "/tmp/.X$n-lock" ] && [ ! -e "/tmp/.X11-unix/X$n" ] && mkdir "$lock" 2>/dev/null; then
    trap 'rm -rf "$lock" "$fbdir"' EXIT
    export ATONLAB_XVFB_SCREEN_FILE="$fbdir/Xvfb_screen0"
    # -noreset: Xvfb would otherwise reset when its last client disconnects
    # (each atonlab run is a client), failing the next run's connection.
    xvfb-run -n "$n" -s "-screen 0 640x360x24 -noreset -fbdir $fbdir" "$program" "$@"
    exit $?
  fi
done
echo "no free X display number in 141..190"
exit 1
