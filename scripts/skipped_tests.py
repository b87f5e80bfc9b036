#!/usr/bin/env python3
"""Lists every skipped test with its reason, from CTest's JUnit file
(ctest --output-junit), and under CI=true fails when a test skipped for a
missing tool or library.

A skip says why on a line of its own that starts with its kind
(tests/support/skip.h):

  no GPU:          a machine may lack it and CI may too: a skip, listed
  missing tool:    scripts/setup.sh installs it: under CI=true, a failure
  not applicable:  the test cannot apply here: a skip, listed

A skip whose output has no such line is "unclassified", and under CI=true a
failure too: a skip that does not say why could hide anything. Both CTest's
skips (SKIP_RETURN_CODE, SKIP_REGULAR_EXPRESSION) and GoogleTest's skips
inside a test CTest counts as passed (a whole test binary run under Xvfb) are
listed.

Usage: skipped_tests.py CTEST_JUNIT.xml     (exit 0, or 1 under CI=true as above)
"""
import os
import re
import sys
import xml.etree.ElementTree as ET

KINDS = ("no GPU", "missing tool", "not applicable")
FAILS_UNDER_CI = ("missing tool", "unclassified")
REASON = re.compile(r"^(?:skipped: )?(" + "|".join(re.escape(k) for k in KINDS) + r"): (.*)$")
RUN = re.compile(r"^\[ RUN      \] (\S+)")
GTEST_SKIPPED = re.compile(r"^\[  SKIPPED \] (\S+) \(")


def reason_of(lines):
    """(kind, text) from the first line that names a kind, else ("unclassified", the last line said)."""
    for line in lines:
        m = REASON.match(line.strip())
        if m:
            return m.group(1), m.group(2)
    said = [l.strip() for l in lines if l.strip() and not l.startswith("[")]
    return "unclassified", said[-1] if said else "(the test said nothing)"


def gtest_skips(output):
    """[(test name, lines of its run)] for each GoogleTest test the output shows skipped."""
    out, current, lines = [], None, []
    for line in output.splitlines():
        m = RUN.match(line)
        if m:
            current, lines = m.group(1), []
            continue
        m = GTEST_SKIPPED.match(line)
        if m and m.group(1) == current:
            out.append((current, lines))
            current = None
            continue
        if current is not None:
            lines.append(line)
    return out


def skips(junit_file):
    """[(name, kind, reason)] for every skip in the JUnit file."""
    found = []
    for case in ET.parse(junit_file).getroot().iter("testcase"):
        name = case.get("name", "?")
        output = case.findtext("system-out") or ""
        inner = gtest_skips(output)
        if case.find("skipped") is not None or case.get("status") == "notrun":
            if case.find("skipped") is not None and case.find("skipped").get("message") == "Disabled":
                continue
            kind, why = reason_of(inner[0][1] if len(inner) == 1 else output.splitlines())
            found.append((name, kind, why))
        else:
            # A test CTest ran and passed, inside which GoogleTest skipped some.
            for sub, lines in inner:
                kind, why = reason_of(lines)
                found.append((f"{name} ({sub})", kind, why))
    return found


def main(argv):
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        return 2
    if not os.path.exists(argv[1]):
        print(f"skipped tests: {argv[1]} does not exist (did ctest run with --output-junit?)", file=sys.stderr)
        return 2
    ci = os.environ.get("CI", "") == "true"
    try:
        found = skips(argv[1])
    except ET.ParseError as e:
        # Without the list no skip can be judged: a failure under CI only.
        print(f"skipped tests: {argv[1]} cannot be read ({e}); the skips are not listed")
        return 1 if ci else 0
    print(f"Skipped tests: {len(found)}")
    for name, kind, why in sorted(found):
        print(f"  {name}  [{kind}] {why}")
    bad = [f for f in found if f[1] in FAILS_UNDER_CI]
    if ci and bad:
        print(f"FAIL: under CI=true, {len(bad)} test(s) skipped for a missing tool or library, or without saying "
              "why; scripts/setup.sh installs what they need:")
        for name, kind, why in sorted(bad):
            print(f"  {name}  [{kind}] {why}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
