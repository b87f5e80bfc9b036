#!/usr/bin/env bash
# unit.display_is_gl_free: the executables that link atonlab::display alone
# need no GL, EGL, epoxy, GLFW or X library at run time (docs/architecture.md:
# no GL below stimuli). Usage: gl_free.sh EXE...
set -u
status=0
for exe in "$@"; do
  needed=$(readelf -d "$exe" | grep NEEDED) || { echo "$exe: readelf failed" >&2; exit 1; }
  if bad=$(grep -Ei 'lib(GL|GLX|EGL|OpenGL|epoxy|glfw|X11)[^a-z]' <<<"$needed"); then
    echo "$exe links a GL library: $bad" >&2
    status=1
  fi
done
[ "$status" = 0 ] && echo "no GL library in $# executable(s) linking atonlab::display"
exit "$status"
