#!/usr/bin/env bash
# Set up, build with warnings as errors, and run every test (unit, GL on the
# headless EGL context, end-to-end), then a short fuzz run of the loaders. ATONLAB_SANITIZE=1 builds with ASan/UBSan
# into build-asan/.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${ATONLAB_SANITIZE:-0}" = 1 ]; then
  export ATONLAB_BUILD_DIR="${ATONLAB_BUILD_DIR:-build-asan}"
  export ATONLAB_CMAKE_ARGS="${ATONLAB_CMAKE_ARGS:-} -DATONLAB_WERROR=ON -DATONLAB_SANITIZE=ON"
  # LeakSanitizer reports Mesa's own one-time allocations; leaks in atonlab code are still found by ASan's other checks.
  export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0}"
else
  export ATONLAB_CMAKE_ARGS="${ATONLAB_CMAKE_ARGS:-} -DATONLAB_WERROR=ON"
fi
bash scripts/setup.sh
ctest --test-dir "${ATONLAB_BUILD_DIR:-build}" --output-on-failure --parallel "$(nproc)" --timeout 600
# The loaders' fuzz targets, built with clang into build-fuzz/, 20 s each (docs/fuzzing.md).
if [ "${ATONLAB_SANITIZE:-0}" != 1 ]; then
  bash scripts/fuzz.sh
fi
