#!/usr/bin/env bash
# bench/simulate.sh BUILD_DIR OUT_CSV [PROTOCOL]
# `atonlab simulate`'s speeds (docs/bench.md, "Planning a study"), on the
# quick start by default (one side-by-side condition at 1920×1080, two
# staircases of 16 trials):
#   table     the decision table built from full renders (frames, seconds);
#   jobs1     2,000 sessions on one worker once the table exists: trials per
#             second per core;
#   jobs2     10,000 sessions on two workers: the whole run's wall time.
# Each row has the wall and CPU time (GNU time), the peak resident memory and
# the load average when it ended (the VM is shared: a loaded machine is slower).
set -euo pipefail
build=$1 out=$2
protocol=${3:-$(dirname "$0")/../protocols/examples/quickstart.toml}
base=$(mktemp -d /dev/shm/atonlab-bench-simulate-XXXXXX)
trap 'rm -rf "$base"' EXIT
echo "row,sessions,jobs,trials,wall_s,cpu_s,peak_rss_mib,trials_per_s,trials_per_s_per_core,table_frames,load_average" >"$out"
run() {  # ROW SESSIONS JOBS DIR
  local row=$1 n=$2 jobs=$3 dir=$4
  /usr/bin/time -f "%e %U %S %M" -o "$base/time" "$build/runner/atonlab" simulate "$protocol" --sessions "$n" \
    --jobs "$jobs" --out "$dir" >"$base/$row.out" 2>&1
  read -r wall user sys kib <"$base/time"
  local trials frames
  trials=$(sed -n 's/.*done: \([0-9]*\) trials.*/\1/p' "$base/$row.out")
  frames=$(sed -n 's/.*decision table built from \([0-9]*\) frames.*/\1/p' "$base/$row.out")
  python3 - "$row" "$n" "$jobs" "${trials:-0}" "$wall" "$user" "$sys" "$kib" "${frames:-}" \
    "$(cut -d' ' -f1 /proc/loadavg)" >>"$out" <<'PY'
import sys
row, n, jobs, trials, wall, user, sys_s, kib, frames, load = sys.argv[1:]
wall, cpu, trials, jobs = float(wall), float(user) + float(sys_s), int(trials), int(jobs)
rate = trials / wall if wall > 0 and row != "table" else 0
print(f"{row},{n},{jobs},{trials},{wall:.1f},{cpu:.1f},{int(kib) / 1024:.0f},{rate:.0f},"
      f"{rate / jobs:.0f},{frames},{load}")
PY
  cat "$base/$row.out" | tail -2
}
# The table alone: one session, so the row is the build (and its displayability check).
run table 1 1 "$base/sim"
rm -rf "$base/sim/sessions"
run jobs1 2000 1 "$base/sim"
rm -rf "$base/sim/sessions"
run jobs2 10000 2 "$base/sim"
cat "$out"
