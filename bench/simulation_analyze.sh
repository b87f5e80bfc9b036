#!/usr/bin/env bash
# bench/simulation_analyze.sh BUILD_DIR OUT_CSV [N ...]
# The simulation report's reading and merging at scale (docs/bench.md, "The
# simulation report"): for each N (default 1000 10000) a simulation folder of N
# study files, one simulated session each (the constant-stimuli glare protocol,
# 2 conditions × 7 levels × 10 repetitions = 140 trials; 200 distinct sessions,
# the others byte copies: every file is opened, checked and read whole all the
# same), made on /dev/shm by make_simulation_folder, then `atonlab analyze DIR`
# with the default profile intervals on all cores. Writes one CSV row per N:
# wall time, CPU time (user + system) and peak resident memory of the whole
# command (GNU time's %e, %U + %S and %M), analyze's own read time, files per second. Then one bootstrap row:
# 100 files with --intervals bootstrap --bootstrap 200, the refits per second.
set -euo pipefail
build=$1 out=$2
shift 2
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(1000 10000)
base=$(mktemp -d /dev/shm/atonlab-bench-sim-XXXXXX)
trap 'rm -rf "$base"' EXIT
echo "n_files,intervals,wall_s,cpu_s,peak_rss_mib,read_s,files_per_s,bootstrap_fits_per_s,threads,load_average" >"$out"
row() {  # N INTERVALS EXTRA...
  local n=$1 intervals=$2
  shift 2
  local dir=$base/sim-$n
  [ -d "$dir" ] || "$build/tests/e2e/make_simulation_folder" "$dir" "$n" 10 "$(( n < 200 ? n : 200 ))"
  rm -rf "$base/report"
  /usr/bin/time -f "%e %U %S %M" -o "$base/time" "$build/runner/atonlab" analyze "$dir" --out "$base/report" --quiet \
    --intervals "$intervals" "$@"
  read -r wall user sys kib <"$base/time"
  local load
  load=$(cut -d" " -f1 /proc/loadavg)
  python3 - "$base/report/summary.json" "$n" "$intervals" "$wall" "$user" "$sys" "$kib" "$load" >>"$out" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
t = s["timing"]
fits = t["bootstrap_fits_per_s"]
cpu = float(sys.argv[5]) + float(sys.argv[6])
print(f'{sys.argv[2]},{sys.argv[3]},{sys.argv[4]},{cpu:.1f},{int(sys.argv[7]) / 1024:.0f},{t["read_s"]:.2f},'
      f'{t["files_per_s"]:.0f},{"" if fits is None else f"{fits:.0f}"},{t["threads"]},{sys.argv[8]}')
PY
  tail -1 "$out"
}
for n in "${sizes[@]}"; do row "$n" profile; done
row 100 bootstrap --bootstrap 200
