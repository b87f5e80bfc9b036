#!/usr/bin/env bash
# analyze_expect_error.sh ATONLAB OUTDIR PATTERN KIND [ARGS...]
# Runs `atonlab analyze ARGS... --out OUTDIR/report` on bad input and passes
# if it exits with status 4 for a study file it refuses (not SQLite, a newer
# schema: docs/store.md "Opening") or 2 for other bad input (KIND none: a CSV),
# prints exactly one line on stderr that matches
# PATTERN (an extended regex: the file, and the line and column where there
# is one), and writes nothing: no report folder, and the input unchanged.
# KIND prepares an input in OUTDIR first:
#   not-sqlite    OUTDIR/notes.db, a text file
#   newer-schema  OUTDIR/newer.db, a valid SQLite file whose header says it is
#                 an atonlab study (application_id "ATON") of schema version 999
#   none          nothing (ARGS name the input)
set -uo pipefail
atonlab=$1 outdir=$2 pattern=$3 kind=$4
shift 4
rm -rf "$outdir" && mkdir -p "$outdir"
case "$kind" in
  not-sqlite)
    printf 'observer,condition,level,response\nP,c,1,1\n' >"$outdir/notes.db" ;;
  newer-schema)
    # One 4096-byte page: the 100-byte database header (sqlite.org/fileformat.html
    # §1.3) and an empty table b-tree leaf for sqlite_schema (§1.6). Big-endian:
    # page size 4096, 1 page, schema format 4, UTF-8, user_version 999 (0x3e7),
    # application_id 0x41544f4e, SQLite version 3040001.
    {
      printf 'SQLite format 3\000'
      printf '\x10\x00\x01\x01\x00\x40\x20\x20'           # page size, versions, reserved, payload fractions
      printf '\x00\x00\x00\x01\x00\x00\x00\x01'           # change counter, size in pages
      printf '\x00\x00\x00\x00\x00\x00\x00\x00'           # freelist trunk, freelist count
      printf '\x00\x00\x00\x01\x00\x00\x00\x04'           # schema cookie, schema format
      printf '\x00\x00\x00\x00\x00\x00\x00\x00'           # cache size, largest root page
      printf '\x00\x00\x00\x01\x00\x00\x03\xe7'           # text encoding, user_version = 999
      printf '\x00\x00\x00\x00\x41\x54\x4f\x4e'           # incremental vacuum, application_id "ATON"
      head -c 20 /dev/zero                                # reserved for expansion
      printf '\x00\x00\x00\x01\x00\x2e\x6c\x01'           # version-valid-for, SQLite version number
      printf '\x0d\x00\x00\x00\x00\x10\x00\x00'           # leaf table page, no cells, content at 4096
      head -c $((4096 - 108)) /dev/zero
    } >"$outdir/newer.db" ;;
  none) ;;
  *) echo "unknown kind $kind"; exit 1 ;;
esac
before=$(cd "$outdir" && find . -type f -exec cksum {} + | sort)
"$atonlab" analyze "$@" --out "$outdir/report" 2>"$outdir/stderr" >/dev/null
status=$?
fail=0
expected=2
if [ "$kind" != none ]; then expected=4; fi
if [ "$status" -ne "$expected" ]; then echo "expected exit status $expected, got $status"; fail=1; fi
if [ "$(wc -l <"$outdir/stderr")" -ne 1 ]; then echo "expected one line on stderr"; fail=1; fi
if ! grep -Eq -- "$pattern" "$outdir/stderr"; then echo "stderr does not match /$pattern/"; fail=1; fi
if [ -e "$outdir/report" ]; then echo "the output folder was created"; fail=1; fi
after=$(cd "$outdir" && find . -type f ! -name stderr -exec cksum {} + | sort)
if [ "$before" != "$after" ]; then echo "the input changed (or a file appeared):"; diff <(echo "$before") <(echo "$after"); fail=1; fi
echo "stderr: $(cat "$outdir/stderr")"
exit $fail
