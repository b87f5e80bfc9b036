#!/usr/bin/env bash
# One script for a machine with a GPU (issue 27 item 5; docs/bench.md "On a
# GPU"): builds atonlab into build-device/, runs the GL tests on the hardware
# EGL device, the simulator-frame sequence and the whole `atonlab bench`, and
# writes everything under bench/results/<device>/ for a commit:
#   gl-tests.log, gl-tests-junit.xml   ctest -R '^GL\.' (ATONLAB_EGL_DEVICE=hardware)
#   simulator/                         atonlab bench --only simulator_frames
#   bench/                             atonlab bench (every knob)
#   device.txt                         nvidia-smi, the GL renderer, the commit, each step's time and status
#
#   bash bench/device/run.sh                              # on the device machine
#   ATONLAB_DEVICE_DRY_RUN=1 ATONLAB_DEVICE_BUILD_DIR=build bash bench/device/run.sh
#       # anywhere: llvmpipe, the quick bench, the GL tests' simulator, bench and
#       # moving-pupil and GPU-PSF suites only, in the existing build/
#
# Needs the build dependencies of scripts/setup.sh already installed (a device
# machine may have no package archive; the script says what is missing
# instead of installing). Every step runs even if one before it failed; the
# exit status is the first failure's. $ATONLAB_DEVICE_LABEL names the folder
# (default: the GPU's name from nvidia-smi, else the GL renderer).
set -uo pipefail
cd "$(dirname "$0")/../.."
dry_run="${ATONLAB_DEVICE_DRY_RUN:-0}"
build_dir="${ATONLAB_DEVICE_BUILD_DIR:-build-device}"
jobs="$(nproc)"

missing=()
for tool in cmake ninja pkg-config g++; do command -v "$tool" >/dev/null || missing+=("$tool"); done
for pc in epoxy egl glfw3 tomlplusplus fftw3 sqlite3 nlopt OpenEXR libpng fmt; do
  pkg-config --exists "$pc" 2>/dev/null || missing+=("pkg-config:$pc")
done
if ((${#missing[@]})); then
  echo "device: missing build dependencies: ${missing[*]} (scripts/setup.sh installs them on Debian 12)" >&2
  exit 3
fi

slug() { tr '[:upper:]' '[:lower:]' | sed -e 's/[^a-z0-9]\+/-/g' -e 's/^-//' -e 's/-$//' | cut -c1-60; }
label="${ATONLAB_DEVICE_LABEL:-}"
if [ -z "$label" ] && command -v nvidia-smi >/dev/null; then
  label="$(nvidia-smi --query-gpu=name --format=csv,noheader 2>/dev/null | head -n1)"
fi
[ "$dry_run" = 1 ] && label="${label:-dry-run-llvmpipe}"
label="${label:-unknown-gpu}"
out="bench/results/$(printf '%s' "$label" | slug)"
mkdir -p "$out"
summary="$out/device.txt"
{
  echo "device: $label"
  echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  echo "commit: $(git rev-parse HEAD 2>/dev/null || echo unknown)$(git diff --quiet 2>/dev/null || echo ' (with uncommitted changes)')"
  echo "host: $(uname -srm), $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2 / 1048576}' /proc/meminfo)"
  echo "dry run: $([ "$dry_run" = 1 ] && echo 'yes (llvmpipe, quick bench, a subset of the GL tests)' || echo no)"
  if command -v nvidia-smi >/dev/null; then
    echo "nvidia-smi:"
    nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv 2>&1 | sed 's/^/  /'
  fi
} >"$summary"

status=0
# step NAME COMMAND...: runs it, appends its wall time and exit status to the summary.
step() {
  local name="$1"; shift
  local t0 rc
  t0="$(date +%s.%N)"
  echo "device: $name: $*"
  "$@"
  rc=$?
  awk -v n="$name" -v rc="$rc" -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%s: exit %d, %.1f s\n", n, rc, b - a }' >>"$summary"
  if [ "$rc" -ne 0 ] && [ "$status" -eq 0 ]; then status=$rc; fi
  return 0
}

egl_device=hardware
bench_args=()
gl_filter='^GL\.'
if [ "$dry_run" = 1 ]; then
  egl_device=software
  bench_args=(--quick)
  gl_filter='^GL\.(SimulatorFrames|MovingPupil|PsfAnchoredGpu|bench)\.'
fi

# A build folder configured already keeps its settings (ATONLAB_DEVICE_BUILD_DIR=build reuses
# scripts/setup.sh's build for a dry run without rebuilding it under other flags).
if [ ! -f "$build_dir/build.ninja" ]; then
  step configure cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DATONLAB_PYTHON=OFF
fi
# Everything: the GL tests include the window, Xvfb and end-to-end ones, which run atonlab itself.
step build cmake --build "$build_dir" --parallel "$jobs"
atonlab="$build_dir/runner/atonlab"
# The GL tests on the chosen EGL device; their own log and JUnit file.
step gl-tests env ATONLAB_EGL_DEVICE="$egl_device" CI=true \
  ctest --test-dir "$build_dir" -R "$gl_filter" --parallel "$jobs" --timeout 900 \
  --output-on-failure --output-junit "$(pwd)/$out/gl-tests-junit.xml" >"$out/gl-tests.log" 2>&1
tail -n 3 "$out/gl-tests.log" | sed 's/^/  /' >>"$summary"
step simulator-frames env ATONLAB_EGL_DEVICE="$egl_device" \
  "$atonlab" bench "${bench_args[@]}" --only simulator_frames --out "$out/simulator" --device-label "$label"
step bench env ATONLAB_EGL_DEVICE="$egl_device" \
  "$atonlab" bench "${bench_args[@]}" --out "$out/bench" --device-label "$label"
grep -m1 -i "renderer" "$out/bench/machine.txt" >>"$summary" 2>/dev/null
echo "device: results in $out (device.txt: each step's time and status); exit $status"
exit "$status"
