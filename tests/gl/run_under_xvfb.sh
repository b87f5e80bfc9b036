#!/usr/bin/env bash
# run_under_xvfb.sh PROGRAM: runs PROGRAM under its own Xvfb (1280x720x24).
# xvfb-run -a picks a display by looking for a free lock file, which races when
# two test suites start at once; here the display number is claimed atomically
# (mkdir of a lock directory) from a range, and released afterwards.
set -uo pipefail
program=$1
# Shuffled, so back-to-back runs do not meet a lock Xvfb is still removing.
for n in $(shuf -i 90-140); do
  lock="/tmp/.atonlab-xvfb-$n.lock"
  if [ ! -e "/tmp/.X$n-lock" ] && [ ! -e "/tmp/.X11-unix/X$n" ] && mkdir "$lock" 2>/dev/null; then
    trap 'rm -rf "$lock"' EXIT
    # -noreset: Xvfb otherwise resets when its last client disconnects, and a test
    # that opens a new connection during that reset fails to open the display.
    xvfb-run -n "$n" -s "-screen 0 1280x720x24 -noreset" "$program"
    exit $?
  fi
done
echo "no free X display number in 90..140"
exit 1
