#!/usr/bin/env bash
# Set up, build with warnings as errors (into build/, the build scripts/main.sh
# uses too), and run every test (unit, GL on the headless EGL context,
# end-to-end); then scripts/fuzz.sh: one clang build with ASan + UBSan runs the
# unit tests (tests/unit but the runner's, tests/display) and a short fuzz run
# of the loaders. ATONLAB_SANITIZE=1 instead builds everything with ASan/UBSan
# into build-asan/ and runs every test there. The ctest step ends by listing
# every skipped test with its reason (scripts/skipped_tests.py); under CI=true
# a skip for a missing tool or library, or one that does not say why, fails
# the run (a missing GPU or display server stays a skip).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${ATONLAB_SANITIZE:-0}" = 1 ]; then
  export ATONLAB_BUILD_DIR="${ATONLAB_BUILD_DIR:-build-asan}"
  export ATONLAB_CMAKE_ARGS="${ATONLAB_CMAKE_ARGS:-} -DATONLAB_SANITIZE=ON"
  # LeakSanitizer reports Mesa's own one-time allocations; leaks in atonlab code are still found by ASan's other checks.
  export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0}"
fi
bash scripts/setup.sh
build_dir="${ATONLAB_BUILD_DIR:-build}"
case "$build_dir" in
  /*) junit="$build_dir/ctest-junit.xml" ;;
  *) junit="$(pwd)/$build_dir/ctest-junit.xml" ;;
esac
rm -f "$junit"
# The longest tests start first (CTest's cost data, seeded from tests/ctest_cost_data.txt
# on a fresh build; CTest keeps it up to date from then on), so that with 2 cores
# no 2-minute test starts last.
cost_data="$build_dir/Testing/Temporary/CTestCostData.txt"
if [ ! -f "$cost_data" ]; then
  mkdir -p "$(dirname "$cost_data")"
  cp tests/ctest_cost_data.txt "$cost_data"
fi
tests_start=$SECONDS
ctest_status=0
ctest --test-dir "$build_dir" --output-on-failure --parallel "$(nproc)" --timeout 600 --output-junit "$junit" ||
  ctest_status=$?
skip_status=0
python3 scripts/skipped_tests.py "$junit" || skip_status=$?
echo "test: the suite in $build_dir: $((SECONDS - tests_start)) s"
if [ "$ctest_status" -ne 0 ]; then exit "$ctest_status"; fi
if [ "$skip_status" -ne 0 ]; then
  echo "test: failed: under CI=true, tests were skipped for a missing tool or library or without a reason (listed above)" >&2
  exit "$skip_status"
fi
# The sanitizer step: the unit tests under ASan + UBSan, then the loaders' fuzz
# targets 20 s each, from one clang build in build-fuzz/ (docs/fuzzing.md).
if [ "${ATONLAB_SANITIZE:-0}" != 1 ]; then
  fuzz_start=$SECONDS
  bash scripts/fuzz.sh
  echo "test: the sanitizer step (scripts/fuzz.sh): $((SECONDS - fuzz_start)) s"
fi
echo "test: done in $SECONDS s"
