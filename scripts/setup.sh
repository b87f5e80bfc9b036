#!/usr/bin/env bash
# Installs the Debian packages atonlab needs (only those missing; as root or
# via sudo), then configures and builds into build/ (or $ATONLAB_BUILD_DIR).
# scripts/main.sh and scripts/test.sh share this one build: the same flags
# (warnings are errors), so running one after the other rebuilds nothing.
# Extra CMake arguments can be given in $ATONLAB_CMAKE_ARGS; $ATONLAB_BUILD_TARGETS
# names the targets to build (default: all).
set -euo pipefail
cd "$(dirname "$0")/.."

# Build tools, libraries (docs/architecture.md "Dependencies"), and the Mesa EGL/llvmpipe
# driver that the headless GL tests run on.
packages=(
  build-essential cmake ninja-build pkg-config
  libglfw3-dev libepoxy-dev libegl-dev libegl-mesa0 libgl1-mesa-dri libglm-dev
  libopenexr-dev libimath-dev libpng-dev libsqlite3-dev libfftw3-dev
  libtomlplusplus-dev libcli11-dev libfmt-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libboost-math-dev libnlopt-cxx-dev libstb-dev fonts-dejavu-core
  gnuplot-nox
  pfstools pfstmo  # tests and bench only: `atonlab tonemap --operator reinhard` is compared with pfstmo_reinhard02 (in pfstmo; pfsin/pfsout are in pfstools)
  xvfb xauth
  xdotool  # the full-screen runner's Xvfb tests send real X key events (XTEST) with it
  python3 sqlite3  # tests only: the README quick-start walk, the fake spotread's transcripts, reading study files from shell tests
  clang libclang-rt-14-dev  # scripts/fuzz.sh: the loaders' fuzz targets (libFuzzer is in libclang-rt-14-dev)
  parallel  # tests only: `atonlab simulate --print-commands | parallel` (tests/e2e/simulate_cli.sh)
  slurm-wlm munge  # tests only: `atonlab simulate --slurm` against a one-node Slurm started as root (tests/e2e/simulate_slurm.sh)
  chromium  # the report's layout test renders report.html headless (tests/e2e/report_chromium.sh)
  pybind11-dev python3-dev python3-numpy  # the Python module atonlab (python/, docs/python.md): pybind11, the headers, numpy arrays
  python3-pandas  # the Python module's studies as DataFrames (atonlab.read_study, analyze, check's table)
  python3-pytest python3-matplotlib  # the Python module's tests, and examples/python/glare_matching.py's figures (Agg)
  stress-ng  # scripts/test-under-load.sh: the GL and runner tests beside N busy processes (docs/measured.md)
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
setup_start=$SECONDS
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
  "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q
  # Under CI=true (a throw-away machine) dpkg skips its fsync per file, as
  # Debian's own container images do: the packages install in 7.4 min instead
  # of 12.1 in a fresh debootstrap chroot (docs/measured.md). A person's
  # machine keeps dpkg's safe default.
  unsafe_io=()
  if [ "${CI:-}" = true ]; then unsafe_io=(-o Dpkg::Options::=--force-unsafe-io); fi
  "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
    "${unsafe_io[@]}" "${missing[@]}"
fi

echo "setup: packages: $((SECONDS - setup_start)) s (${#missing[@]} missing of ${#packages[@]})"

build_dir="${ATONLAB_BUILD_DIR:-build}"
build_start=$SECONDS
# shellcheck disable=SC2086
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DATONLAB_WERROR=ON ${ATONLAB_CMAKE_ARGS:-}
# shellcheck disable=SC2086
cmake --build "$build_dir" --parallel "$(nproc)" ${ATONLAB_BUILD_TARGETS:+--target $ATONLAB_BUILD_TARGETS}
echo "setup: configure and build of $build_dir: $((SECONDS - build_start)) s"
