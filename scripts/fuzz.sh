#!/usr/bin/env bash
# Builds the fuzz targets (fuzz/, docs/fuzzing.md) with clang into build-fuzz/
# (or $ATONLAB_FUZZ_BUILD_DIR), every library instrumented with ASan + UBSan,
# and runs each target for $ATONLAB_FUZZ_SECONDS (default 20) under CTest.
# The same build first runs the unit tests that need no GL and no runner
# (unit_tests: tests/unit; display_tests: tests/display) under ASan + UBSan:
# the sanitizer step of CI (docs/measured.md). ATONLAB_FUZZ_UNIT_TESTS=0 skips
# them. Only what these need is built (common, display, stimuli, protocols,
# store, analysis and the tests). Needs clang and libclang-rt-14-dev (libFuzzer),
# which scripts/setup.sh installs.
#   bash scripts/fuzz.sh                            # CI: the unit tests, then 20 s per target
#   ATONLAB_FUZZ_SECONDS=600 ATONLAB_FUZZ_UNIT_TESTS=0 bash scripts/fuzz.sh   # a longer fuzz run alone
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${ATONLAB_FUZZ_BUILD_DIR:-build-fuzz}"
seconds="${ATONLAB_FUZZ_SECONDS:-20}"
unit_tests="${ATONLAB_FUZZ_UNIT_TESTS:-1}"
targets=(fuzz_scene_file fuzz_protocol_file fuzz_set_override)
if [ "$unit_tests" = 1 ]; then targets+=(unit_tests display_tests); fi
# -O1 and line tables only, as the sanitizers' documentation advises: the
# stack traces keep file and line, and the build takes less CPU than at -O2 -g.
# shellcheck disable=SC2086
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" \
  -DCMAKE_CXX_COMPILER=clang++ -DATONLAB_FUZZ=ON -DATONLAB_BUILD_TESTS="$([ "$unit_tests" = 1 ] && echo ON || echo OFF)" \
  -DATONLAB_FUZZ_SECONDS="$seconds" ${ATONLAB_FUZZ_CMAKE_ARGS:-}
cmake --build "$build_dir" --parallel "$(nproc)" --target "${targets[@]}"
echo "fuzz: configure and build of $build_dir: $SECONDS s"
if [ "$unit_tests" = 1 ]; then
  # Every unit.* test of the two executables (not the shape and GL-free checks,
  # which test.sh runs). A sanitizer report fails the test: UBSan stops at the
  # first (-fno-sanitize-recover), ASan always does. detect_leaks=0 as in
  # fuzz/run_fuzz.sh (LeakSanitizer needs ptrace, which containers often
  # forbid); ASAN_OPTIONS=detect_leaks=1 turns it on.
  # Three long numerical sweeps are left to the suite (uninstrumented) and to
  # the whole-suite sanitizer run (ATONLAB_SANITIZE=1 scripts/test.sh): 89 s of
  # the step's 170 s of test time (docs/measured.md), for code the shorter
  # tests of the same suites run here under the sanitizers too.
  long_sweeps='AnalysisRecovery\.UnbiasedAndIntervalsCover95Percent|PupilKernelCache\.InterpolatedKernelIsWithinATenthOfAPercentOfTheExactPupilsOverDuskToNight|AddingLight\.NeverLowersTheDisplayedLuminanceOnEveryOperatorAndDisplay'
  ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=0}" UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}" \
    ctest --test-dir "$build_dir" -R '^unit\.' -E "^unit\.(source_shape|display_is_gl_free|${long_sweeps})\$" \
    --output-on-failure --parallel "$(nproc)" --timeout 600
fi
# One target at a time: each is a single process, and the machine's cores are
# better spent on one fuzzer's speed than on three fighting for them. -V: the
# log keeps each run's statistics (executions, coverage, corpus size).
ctest --test-dir "$build_dir" -R '^fuzz\.' --output-on-failure -V
