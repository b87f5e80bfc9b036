#!/usr/bin/env bash
# schema_altered.sh ATONLAB SOURCE_DIR OUTDIR
# A study file whose schema was altered by hand (docs/store.md, "Opening",
# step 3) is refused before GL: for each alteration of
# tests/data/store_schema/alterations.txt, made with the sqlite3 shell on a
# file holding the current schema (tests/data/store_schema/study_vN.sql),
# `atonlab run` (headless, model observer), `atonlab calibrate import` and
# `atonlab analyze` exit 4 with one line on stderr naming the file and the
# difference, and the file's SHA-256 is unchanged. The unaltered file passes
# the same checks (analyze: exit 2, it holds no sessions; calibrate list: 0).
set -uo pipefail
atonlab=$1 src=$2 out=$3
fixtures=$src/tests/data/store_schema
rm -rf "$out" && mkdir -p "$out"
command -v sqlite3 >/dev/null || { echo "missing tool: sqlite3"; exit 1; }
version=$(ls "$fixtures"/study_v*.sql | sed 's/.*study_v\([0-9]*\)\.sql/\1/' | sort -n | tail -1)
make_study() {
  sqlite3 "$1" <"$fixtures/study_v$version.sql" &&
    sqlite3 "$1" "PRAGMA user_version = $version; PRAGMA application_id = 1096044366; PRAGMA journal_mode = WAL;" >/dev/null
}
fail=0
check() {  # NAME STATUS EXPECTED_STATUS STDERR_FILE PATTERN
  if [ "$2" -ne "$3" ]; then echo "$1: expected exit status $3, got $2: $(cat "$4")"; fail=1; fi
  if [ -n "$5" ]; then
    if [ "$(wc -l <"$4")" -ne 1 ]; then echo "$1: expected one line on stderr: $(cat "$4")"; fail=1; fi
    if ! grep -qF -- "$5" "$4"; then echo "$1: stderr does not say \"$5\": $(cat "$4")"; fail=1; fi
  fi
}
commands() {  # DB: runs the three commands, stderr into $out/*.err, statuses in $st_*
  "$atonlab" run "$src/tests/data/run/tiny_2afc.toml" --db "$1" --headless --model-observer --quiet \
    >/dev/null 2>"$out/run.err"
  st_run=$?
  "$atonlab" calibrate import "$src/tests/data/calibration/display.ti3" --display lcd --db "$1" --width-px 320 \
    --height-px 180 --width-m 0.1 --viewing-distance-m 0.9 --date 2024-03-12 >/dev/null 2>"$out/cal.err"
  st_cal=$?
  "$atonlab" analyze "$1" --out "$out/report" --quiet >/dev/null 2>"$out/an.err"
  st_an=$?
}

# The unaltered file: every check passes.
good=$out/good.db
make_study "$good" || { echo "cannot make a study from the fixture"; exit 1; }
"$atonlab" calibrate list --db "$good" >/dev/null 2>"$out/list.err"
check "unaltered: calibrate list" $? 0 "$out/list.err" ""
"$atonlab" analyze "$good" --out "$out/report" --quiet >/dev/null 2>"$out/an.err"
check "unaltered: analyze" $? 2 "$out/an.err" "holds no sessions"

n=0
while IFS='|' read -r name says sql; do
  case "$name" in ''|'#'*) continue ;; esac
  n=$((n + 1))
  db=$out/$name.db
  make_study "$db" && sqlite3 "$db" "$sql" || { echo "$name: cannot alter the study"; fail=1; continue; }
  before=$(sha256sum <"$db")
  sentence="$db's schema was altered ($says"
  commands "$db"
  check "$name: run" "$st_run" 4 "$out/run.err" "$sentence"
  check "$name: calibrate import" "$st_cal" 4 "$out/cal.err" "$sentence"
  check "$name: analyze" "$st_an" 4 "$out/an.err" "$sentence"
  [ -e "$out/report/report.html" ] && { echo "$name: analyze wrote a report"; fail=1; }
  [ "$(sha256sum <"$db")" = "$before" ] || { echo "$name: the file's SHA-256 changed"; fail=1; }
  echo "$name: $(cat "$out/run.err")"
done <"$fixtures/alterations.txt"
[ "$n" -eq 6 ] || { echo "expected 6 alterations, read $n"; fail=1; }
exit $fail
