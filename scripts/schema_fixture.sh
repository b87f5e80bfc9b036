#!/usr/bin/env bash
# schema_fixture.sh FILE.db
# Prints the schema an atonlab study (or display-profile) file holds as the
# fixture text of tests/data/store_schema/: every CREATE statement of its
# sqlite_schema, in the order SQLite lists them, each ended by ";" (SQLite
# makes sqlite_sequence and the sqlite_autoindex_* indexes itself when the
# text is run). A new schema version ships with its fixture:
#   scripts/schema_fixture.sh new-study.db > tests/data/store_schema/study_vN.sql
# where new-study.db is a study file the new build has just created.
set -euo pipefail
file=$1
version=$(sqlite3 -readonly "$file" "PRAGMA user_version")
printf -- '-- The schema of an atonlab file at user_version %s, as SQLite stores it\n' "$version"
printf -- '-- (scripts/schema_fixture.sh; tests/data/store_schema/README.md). A released\n'
printf -- '-- version never changes: do not edit.\n'
sqlite3 -readonly "$file" \
  "SELECT sql || ';' FROM sqlite_schema WHERE sql IS NOT NULL AND name NOT LIKE 'sqlite\\_%' ESCAPE '\\' ORDER BY rowid"
