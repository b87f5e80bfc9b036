#!/usr/bin/env bash
# simulate_slurm.sh ATONLAB SOURCE_DIR OUTDIR
# `atonlab simulate --slurm` against a real Slurm (docs/simulate-cluster.md):
# a one-node slurmctld + slurmd + munged started here as root from a temp-dir
# configuration (tests/e2e/slurm_cluster.sh). A 20-task array is submitted
# (held, so that a second submission into the folder is refused while it
# lives), one task is cancelled with scancel while it runs and another killed
# (SIGKILL, as when its node dies), --status shows them failed, analyze lists
# the .partial files left and merges none, --resubmit runs the two again, and the merged sessions equal a local
# `--jobs 2` run's with the same seeds: the same files, none missing, none
# extra, none half-written, identical trials in every one.
# Before the daemons: no sbatch on PATH and a malformed --time are refused,
# exit 2, nothing written.
# Exit 77 (a skip, with its kind on a line: tests/support/skip.h) without root
# (under CI=true that is a failure), without the Slurm or munge programs, or
# without an OpenGL 4.5 context for the decision table.
set -uo pipefail
atonlab=$(readlink -f "$1") src=$2 out=$3
protocol=$src/tests/data/simulate/sim_2afc.toml
if [ "$(id -u)" -ne 0 ]; then
  if [ "${CI:-}" = true ]; then echo "the Slurm test must run under CI=true, and it needs root to start slurmd"; exit 1; fi
  echo "not applicable: starting slurmctld and slurmd needs root (CI runs as root)"
  exit 77
fi
for tool in munged slurmctld slurmd sbatch squeue scancel scontrol sinfo python3; do
  command -v "$tool" >/dev/null || { echo "missing tool: $tool is not installed (scripts/setup.sh installs slurm-wlm and munge)"; exit 77; }
done
rm -rf "$out" && mkdir -p "$out"
fail=0
# Sessions of 2 × 250 trials (a staircase that stops at max_trials), so a task
# of 8 sessions (about 1 s on this 2-core VM) runs long enough to be cancelled while it runs.
heavy=(--set max_trials=250 --set n_reversals=1000)
sessions=160 per_task=8  # 20 tasks

refused() { # refused NAME NEEDLE PATH_THAT_MUST_NOT_EXIST -- ENV/ARGS...
  local name=$1 needle=$2 absent=$3; shift 4
  "$@" >"$out/$name.out" 2>"$out/$name.err"
  local status=$?
  [ "$status" -eq 2 ] || { echo "$name: exit $status, expected 2"; cat "$out/$name.err"; fail=1; }
  grep -qF -- "$needle" "$out/$name.err" || { echo "$name: stderr does not say '$needle':"; cat "$out/$name.err"; fail=1; }
  if [ -n "$absent" ] && [ -e "$absent" ]; then echo "$name: $absent was written"; fail=1; fi
}
refused no_sbatch "sbatch is not on PATH" "$out/nosbatch" -- \
  env PATH=/nonexistent "$atonlab" simulate "$protocol" --sessions 10 --out "$out/nosbatch" --slurm
refused bad_time "--time" "$out/badtime" -- \
  "$atonlab" simulate "$protocol" --sessions 10 --out "$out/badtime" --slurm --time 1h30
refused time_needs_slurm "--time" "$out/badtime" -- \
  "$atonlab" simulate "$protocol" --sessions 10 --out "$out/badtime" --time 30

# The decision table once, for both the array and the local run (a share never builds one).
"$atonlab" simulate "$protocol" "${heavy[@]}" --sessions $sessions --out "$out/local" --jobs 2 \
  >"$out/local.out" 2>&1
status=$?
if [ "$status" -eq 3 ]; then echo "no GPU: no OpenGL 4.5 context for the decision table ($(tail -1 "$out/local.out"))"; exit 77; fi
[ "$status" -eq 0 ] || { echo "the local run failed:"; cat "$out/local.out"; exit 1; }
refused share_builds "never builds a table" "" -- \
  "$atonlab" simulate "$protocol" "${heavy[@]}" --sessions 5 --out "$out/local" --first 0 --count 5 --table-cache "$out/empty-cache"

. "$src/tests/e2e/slurm_cluster.sh"
cluster=$(mktemp -d /tmp/atonlab-slurm.XXXXXX)
trap 'stop_slurm; rm -rf "$cluster"' EXIT
start_slurm "$cluster" || exit 1

squeue_tasks() { squeue -h -r -o '%F %K %T' 2>/dev/null; }
wait_for_job_end() { # wait_for_job_end JOBID: up to 10 min
  local i
  for i in $(seq 1 1200); do
    squeue_tasks | grep -q "^$1 " || return 0
    sleep 0.5
  done
  echo "job $1 still queued after 10 min:"; squeue_tasks; return 1
}

dir=$out/sweep
"$atonlab" simulate "$protocol" "${heavy[@]}" --sessions $sessions --sessions-per-task $per_task --out "$dir" \
  --table-cache "$out/local/tables" --slurm --time 10:00 --sbatch-arg=--hold >"$out/submit.out" 2>&1 ||
  { echo "--slurm failed:"; cat "$out/submit.out"; exit 1; }
job=$(sed -n 's/^simulate: submitted job \([0-9]*\):.*/\1/p' "$out/submit.out")
[ -n "$job" ] || { echo "--slurm printed no job id:"; cat "$out/submit.out"; exit 1; }
grep -q "^#SBATCH --array=0-19$" "$dir/simulate.sbatch" || { echo "the script's array is not 0-19:"; cat "$dir/simulate.sbatch"; fail=1; }
refused second_submission "still queued or running" "" -- \
  "$atonlab" simulate "$protocol" "${heavy[@]}" --sessions $sessions --out "$dir" --slurm
"$atonlab" simulate --status "$dir" >"$out/status0.out" 2>&1
grep -q "^  pending  20: 0-19$" "$out/status0.out" || { echo "--status of the held job:"; cat "$out/status0.out"; fail=1; }
scontrol release "$job"

# Stop a task mid-way: the first seen running, once it has written a session
# of its 8 (a task's sessions are renamed from .partial in batches, a second's
# worth: docs/simulate.md); should it have finished all 8 before the signal
# reached it (a race lost), the next one. Twice: `scancel` (SIGTERM: atonlab
# keeps the sessions it finished), then SIGKILL to the task's atonlab, as when
# its node dies (the sessions not yet renamed stay .partial).
files_of() { # files_of TASK NAME_PATTERN: the task's session files named so
  find "$dir/sessions" -name "$2" 2>/dev/null | awk -F'session-' -v t="$1" -v k=$per_task \
    '{i = substr($2, 1, 6) + 0; if (int(i / k) == t) c++} END {print c + 0}'
}
kill_task() { # kill_task JOB_TASK: SIGKILL to the atonlab of array task JOB_TASK (started by this test)
  local first=$(( ${1#*_} * per_task )) pid
  for pid in $(pgrep -f -- "--out $dir .*--first $first --count"); do kill -9 "$pid"; done
}
stop_one() { # stop_one COMMAND...: runs COMMAND JOB_TASK; prints the task stopped mid-way
  local task n
  for _ in $(seq 1 1200); do
    task=$(squeue_tasks | awk -v j="$job" '$1 == j && $3 == "RUNNING" {print $2; exit}')
    if [ -n "$task" ]; then
      for _ in $(seq 1 400); do  # until a session is written and the next begun, or it no longer runs
        [ "$(files_of "$task" 'session-*')" -ge 2 ] && break
        squeue_tasks | grep -q "^$job $task RUNNING" || break
        sleep 0.02
      done
      "$@" "${job}_${task}"
      for _ in $(seq 1 100); do squeue_tasks | grep -q "^$job $task " || break; sleep 0.1; done
      n=$(files_of "$task" 'session-*.db')
      if [ "$n" -lt "$per_task" ]; then
        echo "$task"
        echo "task $task stopped ($*) with $n of its $per_task sessions finished," \
          "$(files_of "$task" 'session-*.partial') .partial" >&2
        return 0
      fi
    fi
    squeue_tasks | grep -q "^$job " || return 1
    sleep 0.05
  done
  return 1
}
cancelled=$(stop_one scancel) || { echo "no task could be cancelled while it ran"; exit 1; }
# SIGTERM reaches atonlab itself (the script execs it): the session in hand is
# finished and renamed, no .partial file is left.
[ "$(files_of "$cancelled" 'session-*.partial')" -eq 0 ] ||
  { echo "scancel left .partial files of task $cancelled: atonlab did not stop on its own SIGTERM"; fail=1; }
killed=$(stop_one kill_task) || { echo "no task could be killed while it ran"; exit 1; }
wait_for_job_end "$job" || exit 1
"$atonlab" simulate --status "$dir" >"$out/status1.out" 2>&1
cat "$out/status1.out"
stopped=$(printf '%s\n' "$cancelled" "$killed" | sort -n | paste -sd,)
if [ $(( ${stopped#*,} - ${stopped%,*} )) -eq 1 ]; then stopped=${stopped%,*}-${stopped#*,}; fi  # --array's form: 0-1
grep -q "^  failed   2: $stopped$" "$out/status1.out" || { echo "--status does not show tasks $stopped failed"; fail=1; }
grep -q "^  done     18:" "$out/status1.out" || { echo "--status does not show 18 tasks done"; fail=1; }
# A half-written session is never merged: analyze lists each .partial file and counts only whole sessions.
partials=$(find "$dir/sessions" -name "*.db.partial" | wc -l)
echo "$partials .partial file(s) left by the stopped tasks"
"$atonlab" analyze "$dir" --out "$out/report-before" >"$out/analyze-before.out" 2>&1 ||
  { echo "analyze of the stopped run failed:"; cat "$out/analyze-before.out"; fail=1; }
for f in $(find "$dir/sessions" -name "*.db.partial"); do
  grep -qF "$(basename "$f")" "$out/analyze-before.out" "$out/report-before/summary.json" ||
    { echo "analyze does not list $(basename "$f")"; fail=1; }
done

"$atonlab" simulate --resubmit "$dir" >"$out/resubmit.out" 2>&1 || { echo "--resubmit failed:"; cat "$out/resubmit.out"; exit 1; }
cat "$out/resubmit.out"
job2=$(sed -n 's/.* as job \([0-9]*\)$/\1/p' "$out/resubmit.out")
grep -qF "resubmitted 2 task(s) ($stopped)" "$out/resubmit.out" ||
  { echo "--resubmit did not submit tasks $stopped alone"; fail=1; }
refused resubmit_live "still queued or running" "" -- "$atonlab" simulate --resubmit "$dir"
scontrol release "$job2"
wait_for_job_end "$job2" || exit 1
"$atonlab" simulate --status "$dir" >"$out/status2.out" 2>&1
grep -q "^  done     20: 0-19$" "$out/status2.out" || { echo "after --resubmit, not every task is done:"; cat "$out/status2.out"; fail=1; }

python3 - "$out/local" "$dir" $sessions <<'PY' || fail=1
import glob, os, sqlite3, sys
local, cluster, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
def trials(root):
    out = {}
    # A session's file or its .partial; not the -wal/-shm files a reader may leave.
    for f in sorted(glob.glob(os.path.join(root, "sessions", "*", "*.db*"))):
        if f.endswith(("-wal", "-shm")):
            continue
        name = os.path.relpath(f, root)
        if not f.endswith(".db"):
            out[name] = "not a finished session"
            continue
        con = sqlite3.connect(f"file:{f}?mode=ro", uri=True)
        out[name] = con.execute("select count(*) || '|' || group_concat(level || ':' || response || ':' || test_on_left, ' ') "
                                "from (select * from trials order by trial_index)").fetchone()[0]
        con.close()
    return out
ta, tb = trials(local), trials(cluster)
expected = {f"sessions/00/session-{i:06}.db" for i in range(n)}
if set(ta) != expected: print(f"the local run has {len(ta)} files, not the {n} sessions"); sys.exit(1)
if set(tb) != expected:
    print(f"the Slurm run's files differ from the {n} sessions: missing {sorted(expected - set(tb))[:3]}, "
          f"extra {sorted(set(tb) - expected)[:3]}"); sys.exit(1)
diff = [k for k in sorted(expected) if ta[k] != tb[k]]
if diff: print(f"{len(diff)} sessions differ from the local run's, e.g. {diff[:3]}"); sys.exit(1)
print(f"the Slurm run's {n} sessions equal the local --jobs 2 run's, none lost, duplicated or half-written")
PY
"$atonlab" analyze "$dir" --out "$out/report" >"$out/analyze.out" 2>&1 || { echo "analyze failed:"; cat "$out/analyze.out"; fail=1; }
[ -f "$out/report/report.html" ] || { echo "analyze wrote no report.html"; fail=1; }
exit $fail
