#!/usr/bin/env bash
# scripts/test-under-load.sh [--busy N] [-R REGEX] [-j JOBS] [--build-dir DIR]
# Runs the GL and runner tests (CTest names matching REGEX, default
# '^GL\.|^e2e\.run\.': every GL test, the full-screen runner's GL.runner.*
# among them, and the runner's command-line refusals) while N busy processes
# (default 2; 0 for a baseline without load) of Debian's stress-ng share the
# cores, then reports each test's result and time (from CTest's JUnit file)
# and the run's wall-clock time. The stressors are stopped on exit, however
# the script ends (trap). Exit status: CTest's (0 when every test passed).
# Nothing here passes or fails by speed: the tests bound a hang only
# (docs/measured.md "Tests on a loaded machine" has the times measured).
#
# Example, the fast subset used while developing:
#   scripts/test-under-load.sh --busy 4 -R 'GL\.(runner|RunnerVirtual|MissedBound)'
set -euo pipefail
cd "$(dirname "$0")/.."

busy=2
regex='^GL\.|^e2e\.run\.'
jobs=$(nproc)
build_dir="${ATONLAB_BUILD_DIR:-build}"
usage() { sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; }
while [ $# -gt 0 ]; do
  case $1 in
    --busy) busy=$2; shift 2 ;;
    -R) regex=$2; shift 2 ;;
    -j) jobs=$2; shift 2 ;;
    --build-dir) build_dir=$2; shift 2 ;;
    -h | --help) usage; exit 0 ;;
    *) echo "test-under-load: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
case $busy in
  '' | *[!0-9]*) echo "test-under-load: --busy takes a whole number of processes, not '$busy'" >&2; exit 2 ;;
esac
if [ ! -f "$build_dir/CTestTestfile.cmake" ]; then
  echo "test-under-load: no build in $build_dir (run scripts/setup.sh first)" >&2
  exit 2
fi
if [ "$busy" -gt 0 ] && ! command -v stress-ng >/dev/null; then
  echo "test-under-load: stress-ng is not installed (scripts/setup.sh installs it: apt-get install stress-ng)" >&2
  exit 2
fi

out_dir="$build_dir/Testing/under-load"
mkdir -p "$out_dir"
case "$out_dir" in
  /*) ;;
  *) out_dir="$(pwd)/$out_dir" ;;
esac
junit="$out_dir/junit-busy$busy.xml"
log="$out_dir/ctest-busy$busy.log"
rm -f "$junit"

stress_pid=""
stop_stressors() {
  if [ -n "$stress_pid" ]; then
    # stress-ng ends its workers when it gets SIGTERM, then exits.
    kill -TERM "$stress_pid" 2>/dev/null || true
    wait "$stress_pid" 2>/dev/null || true
    stress_pid=""
  fi
}
trap stop_stressors EXIT
trap 'stop_stressors; exit 130' INT
trap 'stop_stressors; exit 143' TERM

if [ "$busy" -gt 0 ]; then
  # N CPU workers that never sleep (their default mix of methods), until killed.
  stress-ng --cpu "$busy" --timeout 0 --quiet &
  stress_pid=$!
  sleep 1  # the workers are running before the first test starts
fi

echo "test-under-load: $busy busy process(es) (stress-ng --cpu $busy) on $(nproc) core(s); ctest -R '$regex' -j $jobs"
# The machine may be shared: its load before the tests (1, 5, 15 min averages), stressors included.
echo "test-under-load: load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
start=$SECONDS
status=0
ctest --test-dir "$build_dir" -R "$regex" --parallel "$jobs" --output-on-failure --output-junit "$junit" \
  >"$log" 2>&1 || status=$?
wall=$((SECONDS - start))
echo "test-under-load: load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
stop_stressors

# Each test's result and time, from the JUnit file CTest wrote.
python3 - "$junit" "$busy" "$wall" <<'EOF'
import sys
import xml.etree.ElementTree as ET

junit, busy, wall = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
try:
    cases = ET.parse(junit).getroot().iter("testcase")
except (OSError, ET.ParseError) as e:
    print(f"test-under-load: no JUnit results ({e})")
    sys.exit(0)
rows = []
for c in cases:
    # CTest's JUnit: status "run" (passed), "fail", "notrun" / "disabled"; a skip has <skipped/>.
    raw = c.get("status") or ""
    status = {"run": "passed", "fail": "FAILED", "notrun": "not-run", "disabled": "not-run"}.get(raw, raw)
    if c.find("failure") is not None:
        status = "FAILED"
    if c.find("skipped") is not None:
        status = "skipped"
    rows.append((c.get("name"), status, float(c.get("time") or 0.0)))
width = max((len(r[0]) for r in rows), default=4)
print(f"{'test':<{width}}  {'result':<8} {'time (s)':>9}")
for name, status, t in sorted(rows, key=lambda r: -r[2]):
    print(f"{name:<{width}}  {status:<8} {t:9.2f}")
counts = {}
for _, status, _ in rows:
    counts[status] = counts.get(status, 0) + 1
total = sum(r[2] for r in rows)
print(f"test-under-load: {len(rows)} tests with {busy} busy process(es): "
      + ", ".join(f"{n} {s}" for s, n in sorted(counts.items()))
      + f"; {total:.1f} s of test time, {wall} s wall-clock")
EOF
echo "test-under-load: CTest's output is in $log"
exit "$status"
