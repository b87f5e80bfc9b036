#!/usr/bin/env bash
# install.consumer: `cmake --install` the development component of a built tree
# into a fresh prefix, then build examples/simulator_loop.cpp against it twice —
# with find_package(atonlab) (tests/install/CMakeLists.txt) and with pkg-config
# (atonlab.pc) — and run both headless (EGL). Exit 77 (skip) without GL.
#   consumer.sh BUILD_DIR WORK_DIR SOURCE_DIR [CXX_COMPILER] [COMPILER_LAUNCHER]
set -euo pipefail
build=$1 work=$2 src=$3 cxx=${4:-c++} launcher=${5:-}
rm -rf "$work"
mkdir -p "$work"
prefix=$work/prefix

cmake --install "$build" --prefix "$prefix" --component development > "$work/install.log"
for f in include/atonlab/stimuli/pipeline.h include/atonlab/present/presenter.h lib/cmake/atonlab/atonlabConfig.cmake \
         lib/pkgconfig/atonlab.pc lib/libatonlab_stimuli.a lib/libatonlab_present.a; do
  [ -f "$prefix/$f" ] || { echo "consumer: $f was not installed"; exit 1; }
done
# Nothing points back into the source or build tree.
if grep -rlF -e "$src" -e "$build" "$prefix/lib/cmake" "$prefix/lib/pkgconfig"; then
  echo "consumer: the package files above name the source or build tree"; exit 1
fi

args=(-S "$src/tests/install" -B "$work/cmake-build" -G Ninja -DCMAKE_BUILD_TYPE=Release
      -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_COMPILER="$cxx" -DSIMULATOR_SOURCE="$src/examples/simulator_loop.cpp")
[ -n "$launcher" ] && args+=(-DCMAKE_CXX_COMPILER_LAUNCHER="$launcher")
cmake "${args[@]}" > "$work/configure.log"
cmake --build "$work/cmake-build"

# pkg-config: the same source, one compiler line.
export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
# shellcheck disable=SC2046
$launcher "$cxx" -std=c++20 -O1 "$src/examples/simulator_loop.cpp" -o "$work/simulator_loop_pc" \
  $(pkg-config --cflags --libs atonlab)

status=0
"$work/cmake-build/simulator_loop" --frames 5 || status=$?
[ $status -eq 77 ] && { echo "no GPU: the installed example found no GL context"; exit 77; }
[ $status -eq 0 ] || { echo "consumer: the find_package build failed with status $status"; exit 1; }
"$work/simulator_loop_pc" --frames 5 --ldr
echo "consumer: find_package and pkg-config builds ran"
rm -rf "$work"
