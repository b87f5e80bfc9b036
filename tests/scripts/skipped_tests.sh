#!/usr/bin/env bash
# scripts/skipped_tests.py, the classifier at the end of scripts/test.sh, on
# JUnit files as CTest 3.25 writes them (ctest --output-junit): under CI=true
# a skip for a missing tool fails (exit 1, one FAIL line naming the test), as
# does a skip that does not say why; a skip for a missing GPU passes and is
# listed; without CI=true every skip is listed and none fails. Also a
# GoogleTest skip inside a test CTest counts as passed (a binary run whole
# under Xvfb) is found.
set -uo pipefail
classifier="$1/scripts/skipped_tests.py"
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
failures=0
expect() {  # expect NAME WANTED_STATUS CI_VALUE FILE PATTERN...
  local name=$1 want=$2 ci=$3 file=$4
  shift 4
  CI=$ci python3 "$classifier" "$file" >"$dir/out" 2>&1
  local got=$?
  if [ "$got" -ne "$want" ]; then
    echo "FAIL $name: exit $got, wanted $want"; cat "$dir/out"; failures=$((failures + 1)); return
  fi
  for pattern in "$@"; do
    if ! grep -qF -- "$pattern" "$dir/out"; then
      echo "FAIL $name: no line with '$pattern'"; cat "$dir/out"; failures=$((failures + 1))
    fi
  done
}
junit() {  # junit FILE, test cases from stdin
  { echo '<?xml version="1.0" encoding="UTF-8"?>'; echo '<testsuite name="t" tests="2">'; cat; echo '</testsuite>'; } >"$1"
}

# A GoogleTest skip for a missing tool, as gtest_discover_tests' SKIP_REGULAR_EXPRESSION reports it.
junit "$dir/tool.xml" <<'XML'
<testcase name="GL.ImageCommands.Peer" classname="GL.ImageCommands.Peer" time="0.1" status="notrun">
<skipped message="SKIP_REGULAR_EXPRESSION_MATCHED"/>
<system-out>Running main() from gtest_main.cc
Note: Google Test filter = ImageCommands.Peer
[ RUN      ] ImageCommands.Peer
/src/tests/gl/test_image_commands.cpp:84: Skipped
missing tool: pfstmo_reinhard02 is not installed (Debian package pfstmo)

[  SKIPPED ] ImageCommands.Peer (2 ms)
[  SKIPPED ] 1 test, listed below:
[  SKIPPED ] ImageCommands.Peer
</system-out></testcase>
<testcase name="unit.A.B" classname="unit.A.B" time="0.1" status="run"><system-out>[ RUN      ] A.B
[       OK ] A.B (0 ms)
</system-out></testcase>
XML
expect "tool skip under CI" 1 true "$dir/tool.xml" \
  "GL.ImageCommands.Peer  [missing tool] pfstmo_reinhard02 is not installed" "FAIL: under CI=true, 1 test(s)"
expect "tool skip outside CI" 0 "" "$dir/tool.xml" "Skipped tests: 1" "[missing tool]"

# A shell test's skip for a missing GPU (exit 77, SKIP_RETURN_CODE).
junit "$dir/gpu.xml" <<'XML'
<testcase name="GL.e2e.psf" classname="GL.e2e.psf" time="0.1" status="notrun">
<skipped message="SKIP_RETURN_CODE=77"/>
<system-out>no GPU: no OpenGL 4.5 context (eglInitialize failed)
</system-out></testcase>
XML
expect "GPU skip under CI" 0 true "$dir/gpu.xml" "GL.e2e.psf  [no GPU] no OpenGL 4.5 context"

# A skip that does not say why.
junit "$dir/silent.xml" <<'XML'
<testcase name="GL.e2e.render_ok" classname="GL.e2e.render_ok" time="0.1" status="notrun">
<skipped message="SKIP_RETURN_CODE=77"/><system-out></system-out></testcase>
XML
expect "unclassified skip under CI" 1 true "$dir/silent.xml" "[unclassified]" "FAIL: under CI=true"

# GoogleTest skips inside a test CTest passed (the window tests under xvfb-run): one per kind.
junit "$dir/inner.xml" <<'XML'
<testcase name="GL.window.xvfb" classname="GL.window.xvfb" time="0.1" status="run"><system-out>[ RUN      ] Window.Opens
/src/tests/gl/window_xvfb.cpp:17: Skipped
no GPU: no display server (DISPLAY unset)

[  SKIPPED ] Window.Opens (0 ms)
[ RUN      ] Window.Font
/src/tests/gl/window_xvfb.cpp:40: Skipped
missing tool: /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf is not installed (fonts-dejavu-core)

[  SKIPPED ] Window.Font (0 ms)
</system-out></testcase>
XML
expect "inner skips under CI" 1 true "$dir/inner.xml" "GL.window.xvfb (Window.Opens)  [no GPU]" \
  "GL.window.xvfb (Window.Font)  [missing tool]" "FAIL: under CI=true, 1 test(s)"

if [ "$failures" -ne 0 ]; then exit 1; fi
echo "skipped_tests.py: every case as expected"
