#!/usr/bin/env bash
# simulate_cli.sh ATONLAB SOURCE_DIR OUTDIR
# `atonlab simulate` from the command line (docs/simulate.md): bad input exits 2
# naming its option or key with nothing written; a protocol the display cannot
# show is refused as `atonlab run` refuses it; a run killed mid-way continues
# where it stopped, and its sessions equal an uninterrupted run's; a folder
# holding another simulation is refused and left as it was; more sessions
# extend a simulation; --print-commands' commands, run by GNU parallel, make
# the uninterrupted run's sessions. Exit 77 (a skip) where no GL 4.5 context exists.
set -uo pipefail
atonlab=$1 src=$2 out=$3
protocol=$src/tests/data/simulate/sim_2afc.toml
rm -rf "$out" && mkdir -p "$out"
fail=0
check() { # check NAME EXPECTED_STATUS NEEDLE [PATH_THAT_MUST_NOT_EXIST] -- ARGS...
  local name=$1 want=$2 needle=$3 absent=$4; shift 5
  "$atonlab" simulate "$@" >"$out/$name.out" 2>"$out/$name.err"
  local status=$?
  if [ "$status" -eq 3 ]; then echo "no GPU: no OpenGL 4.5 context ($(cat "$out/$name.err"))"; exit 77; fi
  if [ "$status" -ne "$want" ]; then echo "$name: exit $status, expected $want"; cat "$out/$name.err"; fail=1; fi
  if ! grep -qF -- "$needle" "$out/$name.err"; then echo "$name: stderr does not say '$needle':"; cat "$out/$name.err"; fail=1; fi
  if [ -n "$absent" ] && [ -e "$absent" ]; then echo "$name: $absent was written"; fail=1; fi
}
check sessions0 2 "--sessions" "$out/a" -- "$protocol" --sessions 0 --out "$out/a"
check unwritable 2 "--out" "" -- "$protocol" --sessions 5 --out /proc/atonlab-simulation
check observer 2 "eta" "$out/b" -- "$protocol" --sessions 5 --out "$out/b" --observer eta=1.5
check observer_key 2 "--observer" "$out/b" -- "$protocol" --sessions 5 --out "$out/b" --observer etta=0.2
check vary 2 "--vary" "$out/b" -- "$protocol" --sessions 5 --out "$out/b" --vary max_trials=20

# Refused as `atonlab run` refuses it: the same sentence, exit 2, nothing written.
undisplayable=$src/tests/data/run/undisplayable_2afc.toml
"$atonlab" run "$undisplayable" --db "$out/u.db" --headless --model-observer >/dev/null 2>"$out/run-refusal.err"
check undisplayable 2 "$(grep -m1 "cannot produce a match" "$out/run-refusal.err")" "$out/u" -- "$undisplayable" --sessions 5 --out "$out/u"

# A whole run, then the same with a shared table cache killed mid-way and run again.
"$atonlab" simulate "$protocol" --sessions 400 --out "$out/whole" --table-cache "$out/cache" >"$out/whole.out" 2>&1 ||
  { echo "the uninterrupted run failed"; cat "$out/whole.out"; exit 1; }
"$atonlab" simulate "$protocol" --sessions 400 --out "$out/killed" --table-cache "$out/cache" --jobs 2 \
  >"$out/killed1.out" 2>&1 &
pid=$!
for _ in $(seq 1 200); do  # until some sessions are done
  n=$(find "$out/killed/sessions" -name 'session-*.db' 2>/dev/null | wc -l)
  [ "$n" -ge 20 ] && break
  sleep 0.05
done
kill -9 "$pid" 2>/dev/null; wait "$pid" 2>/dev/null
done_before=$(find "$out/killed/sessions" -name 'session-*.db' | wc -l)
"$atonlab" simulate "$protocol" --sessions 400 --out "$out/killed" --table-cache "$out/cache" >"$out/killed2.out" 2>&1 ||
  { echo "the continued run failed"; cat "$out/killed2.out"; exit 1; }
echo "killed after $done_before sessions; continued: $(grep -o '[0-9]* to run, [0-9]* done before' "$out/killed2.out")"
python3 - "$out/whole" "$out/killed" <<'PY' || fail=1
import glob, os, sqlite3, sys
a, b = sys.argv[1], sys.argv[2]
def trials(root):
    out = {}
    for f in sorted(glob.glob(os.path.join(root, "sessions", "*", "*"))):
        name = os.path.relpath(f, root)
        if not f.endswith(".db"):
            out[name] = "not a finished session"
            continue
        con = sqlite3.connect(f"file:{f}?mode=ro", uri=True)
        out[name] = con.execute("select group_concat(level || ':' || response || ':' || test_on_left, ' ') "
                                "from (select * from trials order by trial_index)").fetchone()[0]
        con.close()
    return out
ta, tb = trials(a), trials(b)
if len(ta) != 400: print(f"the uninterrupted run has {len(ta)} files, not 400"); sys.exit(1)
if ta != tb:
    diff = [k for k in sorted(set(ta) | set(tb)) if ta.get(k) != tb.get(k)]
    print(f"{len(diff)} sessions differ from the uninterrupted run's, e.g. {diff[:3]}"); sys.exit(1)
print("the continued run's 400 sessions equal the uninterrupted run's, none lost or duplicated")
PY

# --print-commands: one command per task, run here by GNU parallel; the
# sessions equal the uninterrupted run's (docs/simulate-cluster.md).
"$atonlab" simulate "$protocol" --sessions 40 --sessions-per-task 15 --out "$out/commands" --table-cache "$out/cache" \
  --print-commands >"$out/commands.txt" 2>"$out/commands.err" || { echo "--print-commands failed"; cat "$out/commands.err"; fail=1; }
[ "$(wc -l <"$out/commands.txt")" -eq 3 ] || { echo "--print-commands printed not 3 commands:"; cat "$out/commands.txt"; fail=1; }
grep -q -- "--first 30 --count 10 --quiet$" "$out/commands.txt" || { echo "the last share is not 30 + 10:"; cat "$out/commands.txt"; fail=1; }
if command -v parallel >/dev/null; then
  parallel --will-cite --jobs 2 <"$out/commands.txt" || { echo "parallel's commands failed"; fail=1; }
elif [ "${CI:-}" = true ]; then
  echo "GNU parallel is not installed (scripts/setup.sh installs it)"; fail=1
else
  bash "$out/commands.txt" || { echo "the printed commands failed"; fail=1; }
fi
python3 - "$out/whole" "$out/commands" <<'PY' || fail=1
import glob, os, sqlite3, sys
def trials(f):
    con = sqlite3.connect(f"file:{f}?mode=ro", uri=True)
    t = con.execute("select group_concat(level || ':' || response || ':' || test_on_left, ' ') "
                    "from (select * from trials order by trial_index)").fetchone()[0]
    con.close()
    return t
names = sorted(os.path.relpath(f, sys.argv[2]) for f in glob.glob(os.path.join(sys.argv[2], "sessions", "*", "*.db")))
expected = [f"sessions/00/session-{i:06}.db" for i in range(40)]
if names != expected: print(f"the printed commands wrote {len(names)} sessions, not 0 to 39"); sys.exit(1)
diff = [n for n in names if trials(os.path.join(sys.argv[1], n)) != trials(os.path.join(sys.argv[2], n))]
if diff: print(f"{len(diff)} sessions of the printed commands differ from the uninterrupted run's, e.g. {diff[:3]}"); sys.exit(1)
print("the printed commands' 40 sessions equal the uninterrupted run's")
PY

# Another protocol into the folder: refused, nothing changed.
before=$(cd "$out/whole" && find . -type f -exec sha256sum {} + | sort | sha256sum)
check another 2 "--out" "" -- "$src/protocols/examples/quickstart.toml" --sessions 5 --out "$out/whole"
check another_seed 2 "seed" "" -- "$protocol" --sessions 5 --out "$out/whole" --seed 99
after=$(cd "$out/whole" && find . -type f -exec sha256sum {} + | sort | sha256sum)
[ "$before" = "$after" ] || { echo "a refused run changed $out/whole"; fail=1; }
# More sessions extend it.
"$atonlab" simulate "$protocol" --sessions 410 --out "$out/whole" --table-cache "$out/cache" >"$out/extend.out" 2>&1 ||
  { echo "extending failed"; cat "$out/extend.out"; fail=1; }
grep -q "10 to run, 400 done before" "$out/extend.out" || { echo "extending ran: $(cat "$out/extend.out")"; fail=1; }
exit $fail
