#!/usr/bin/env python3
"""Walks the README's quick start and checks that it is true.

Usage: readme_quickstart.py ATONLAB REPO_ROOT WORK_DIR

In the README's "## Quick start" section:
- a ```toml block right after a paragraph that ends with a `path.toml`: must be
  that file of the repository, byte for byte (the reader copies what they see);
- a ```console block holds commands (lines starting with "$ ") each followed by
  what it prints. Every command is run in WORK_DIR (where the repository's
  protocols/, scenes/ and docs/ are visible), with `atonlab` the built binary
  first on PATH; it must exit 0, and every printed line the README shows must
  appear in its output, in the README's order ("…" stands for any text: times,
  paths). A command whose line ends in "# on screen" needs a person at a
  display and is not run; `export` and `cd` lines are the reader's set-up.
"""
import os
import re
import shutil
import subprocess
import sys


def quick_start(readme):
    start = readme.index("\n## Quick start")
    end = readme.find("\n## ", start + 1)
    return readme[start:end if end >= 0 else len(readme)]


def blocks(section):
    """(language, body, text before the block) for each fenced block."""
    out = []
    pos = 0
    pattern = re.compile(r"^```(\w*)\n(.*?)^```$", re.S | re.M)
    for m in pattern.finditer(section):
        out.append((m.group(1), m.group(2), section[pos:m.start()]))
        pos = m.end()
    return out


def line_pattern(expected):
    parts = [re.escape(p) for p in expected.strip().split("…")]
    return re.compile(".*".join(parts))


def check_output(command, expected_lines, output):
    lines = output.splitlines()
    at = 0
    for want in expected_lines:
        if not want.strip():
            continue
        pat = line_pattern(want)
        while at < len(lines) and not pat.search(lines[at]):
            at += 1
        if at == len(lines):
            sys.exit(f"FAIL: `{command}` did not print (in the README's order):\n  {want}\n"
                     f"it printed:\n{output}")
        at += 1


def main():
    atonlab, root, work = sys.argv[1:4]
    readme = open(os.path.join(root, "README.md"), encoding="utf-8").read()
    section = quick_start(readme)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    for d in ("protocols", "scenes", "docs"):
        os.symlink(os.path.join(root, d), os.path.join(work, d))
    bindir = os.path.join(work, ".bin")
    os.makedirs(bindir)
    os.symlink(os.path.abspath(atonlab), os.path.join(bindir, "atonlab"))
    env = dict(os.environ, PATH=bindir + os.pathsep + os.environ.get("PATH", ""))

    files_checked = commands_run = 0
    for lang, body, before in blocks(section):
        if lang == "toml":
            named = re.findall(r"`([\w./-]+\.toml)`", before.strip().split("\n\n")[-1])
            if not named:
                sys.exit("FAIL: a toml block in the quick start without a file name before it")
            path = os.path.join(root, named[-1])
            if open(path, encoding="utf-8").read() != body:
                sys.exit(f"FAIL: the README's copy of {named[-1]} differs from the file")
            files_checked += 1
        elif lang == "console":
            steps = []
            for line in body.splitlines():
                if line.startswith("$ "):
                    steps.append([line[2:], []])
                elif steps:
                    steps[-1][1].append(line)
            for command, expected in steps:
                if command.rstrip().endswith("# on screen") or re.match(r"(export|cd)\b", command):
                    continue
                r = subprocess.run(command, shell=True, cwd=work, env=env, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True, timeout=1200)
                if r.returncode != 0:
                    sys.exit(f"FAIL: `{command}` exited {r.returncode}:\n{r.stdout}")
                check_output(command, expected, r.stdout)
                commands_run += 1
                print(f"ok: {command}")
    if files_checked == 0 or commands_run == 0:
        sys.exit(f"FAIL: the quick start has {files_checked} files and {commands_run} commands to check")
    print(f"the README's quick start holds: {files_checked} file(s), {commands_run} command(s)")


if __name__ == "__main__":
    main()
