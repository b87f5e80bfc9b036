#!/usr/bin/env bash
# Set up, build with warnings as errors (into build/, the build scripts/main.sh
# uses too), and run every test (unit, GL on the headless EGL context,
# end-to-end); then scripts/fuzz.sh: one clang build with ASan + UBSan runs the
# unit tests (tests/unit but the runner's, tests/display) and a short fuzz run
# of the loaders. ATONLAB_SANITIZE=1 instead builds everything with ASan/UBSan
# into build-asan/ and runs every test there.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${ATONLAB_SANITIZE:-0}" = 1 ]; then
  export ATONLAB_BUILD_DIR="${ATONLAB_BUILD_DIR:-build-asan}"
  export ATONLAB_CMAKE_ARGS="${ATONLAB_CMAKE_ARGS:-} -DATONLAB_SANITIZE=ON"
  # LeakSanitizer reports Mesa's own one-time allocations; leaks in atonlab code are still found by ASan's other checks.
  export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0}"
fi
bash scripts/setup.sh
ctest --test-dir "${ATONLAB_BUILD_DIR:-build}" --output-on-failure --parallel "$(nproc)" --timeout 600
# The sanitizer step: the unit tests under ASan + UBSan, then the loaders' fuzz
# targets 20 s each, from one clang build in build-fuzz/ (docs/fuzzing.md).
if [ "${ATONLAB_SANITIZE:-0}" != 1 ]; then
  bash scripts/fuzz.sh
fi
