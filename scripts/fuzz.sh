#!/usr/bin/env bash
# Builds the fuzz targets (fuzz/, docs/fuzzing.md) with clang into build-fuzz/
# (or $ATONLAB_FUZZ_BUILD_DIR) and runs each for $ATONLAB_FUZZ_SECONDS
# (default 20) under CTest. Only the libraries the targets need are built
# (common, stimuli, protocols). Needs clang and libclang-rt-14-dev (libFuzzer),
# which scripts/setup.sh installs.
#   bash scripts/fuzz.sh                            # CI: 20 s per target
#   ATONLAB_FUZZ_SECONDS=600 bash scripts/fuzz.sh   # a longer run
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${ATONLAB_FUZZ_BUILD_DIR:-build-fuzz}"
seconds="${ATONLAB_FUZZ_SECONDS:-20}"
# shellcheck disable=SC2086
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
  -DCMAKE_CXX_COMPILER=clang++ -DATONLAB_FUZZ=ON -DATONLAB_BUILD_TESTS=OFF \
  -DATONLAB_FUZZ_SECONDS="$seconds" ${ATONLAB_FUZZ_CMAKE_ARGS:-}
cmake --build "$build_dir" --parallel "$(nproc)" --target fuzz_scene_file fuzz_protocol_file fuzz_set_override
# One target at a time: each is a single process, and the machine's cores are
# better spent on one fuzzer's speed than on three fighting for them. -V: the
# log keeps each run's statistics (executions, coverage, corpus size).
ctest --test-dir "$build_dir" -R '^fuzz\.' --output-on-failure -V
