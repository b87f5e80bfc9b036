#!/usr/bin/env bash
# unit.display_is_gl_free (docs/architecture.md: no GL below stimuli).
# Usage: gl_free.sh "LINK_LIBRARIES of atonlab_display" EXE...
# 1. atonlab_display's link libraries name no GL, EGL, epoxy, GLFW or stimuli
#    target; 2. the executables that link atonlab::display alone need no GL,
#    EGL, epoxy, GLFW or X library at run time.
set -u
status=0
links=$1
shift
if bad=$(tr ';' '\n' <<<"$links" | grep -Ei 'epoxy|egl|glfw|opengl|stimuli|(^|::)GL$'); then
  echo "atonlab_display links $bad" >&2
  status=1
fi
for exe in "$@"; do
  needed=$(readelf -d "$exe" | grep NEEDED) || { echo "$exe: readelf failed" >&2; exit 1; }
  if bad=$(grep -Ei 'lib(GL|GLX|EGL|OpenGL|epoxy|glfw|X11)[^a-z]' <<<"$needed"); then
    echo "$exe needs a GL library: $bad" >&2
    status=1
  fi
done
[ "$status" = 0 ] && echo "atonlab_display links [$links]; no GL library in $# executable(s) linking it alone"
exit "$status"
