#!/usr/bin/env bash
# check_fits_factors.sh FITS_CSV COLUMN=TYPE...
# Reads fits.csv as any CSV reader would (RFC 4180: quoted fields with commas
# and doubled quotes; no pandas, no R: awk) and checks that each named column
# exists and that every headline row holds a value of its TYPE there:
#   number  a finite decimal number        name  a bare word (letters, digits, - _ .), no quotes
# Prints the headline rows' values. Exit 1 on the first column that is missing
# or badly typed.
set -uo pipefail
fits=$1
shift
awk -v specs="$*" '
function split_csv(line, out,    n, i, c, field, quoted) {
  n = 0; field = ""; quoted = 0
  for (i = 1; i <= length(line); i++) {
    c = substr(line, i, 1)
    if (quoted) {
      if (c == "\"" && substr(line, i + 1, 1) == "\"") { field = field "\""; i++ }
      else if (c == "\"") quoted = 0
      else field = field c
    } else if (c == "\"") quoted = 1
    else if (c == ",") { out[++n] = field; field = "" }
    else field = field c
  }
  out[++n] = field
  return n
}
NR == 1 {
  sub(/\r$/, "")
  ncols = split_csv($0, header)
  for (i = 1; i <= ncols; i++) col[header[i]] = i
  nspec = split(specs, spec, " ")
  for (s = 1; s <= nspec; s++) {
    split(spec[s], kv, "=")
    if (!(kv[1] in col)) { printf "fits.csv has no column %s (header: %s)\n", kv[1], $0; bad = 1; exit 1 }
  }
  next
}
{
  sub(/\r$/, "")
  n = split_csv($0, f)
  if (n != ncols) { printf "line %d has %d fields, the header %d\n", NR, n, ncols; bad = 1; exit 1 }
  if (f[col["analysis"]] != "headline") next
  rows++
  line = f[col["condition"]] " " f[col["observer"]] ":"
  for (s = 1; s <= nspec; s++) {
    split(spec[s], kv, "=")
    v = f[col[kv[1]]]
    if (kv[2] == "number" && v !~ /^-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?$/) {
      printf "%s: column %s is \"%s\", not a number\n", line, kv[1], v; bad = 1; exit 1
    }
    if (kv[2] == "name" && v !~ /^[A-Za-z0-9_.-]+$/) {
      printf "%s: column %s is \"%s\", not a bare name\n", line, kv[1], v; bad = 1; exit 1
    }
    line = line " " kv[1] "=" v
  }
  print line
}
END {
  if (bad) exit 1
  if (rows == 0) { print "no headline rows"; exit 1 }
}' "$fits"
