#!/usr/bin/python3
"""Shell scripts under `set -o pipefail` must not pipe into a reader that stops early.

`grep -q` (also -l, -L, -m and their long forms) exits at its first match and `head` after its
lines; a writer with more still to write then dies of SIGPIPE (exit 141), pipefail makes the
whole pipeline fail, and an `if` takes the wrong branch or `set -e` ends the script. Whether it
happens depends on how much the writer buffers, so it passes most runs and fails some
(session 85's tools review, finding 1: main-job.sh skipped its replays 17 runs in 20). Capture
the output first (`x=$(cmd)`, then `grep -q ... <<<"$x"`) or use a reader that reads to the end
(`sed -n 1,8p`).

usage: pipefail_readers.py SOURCE_DIR   (checks SOURCE_DIR/tools and SOURCE_DIR/models)
Prints each offending line as FILE:LINE and exits 1, or exits 0.
"""
import os
import re
import sys

PIPEFAIL = re.compile(r"^\s*set\s+(-[A-Za-z]*o\s+pipefail|-o\s+pipefail)\b", re.M)
# A pipe (not ||), then a reader that may close its input before the writer is done.
EARLY = re.compile(r"(?<!\|)\|(?!\|)&?\s*(head\b|grep\s+(?:-\S+\s+)*(?:-[A-Za-z]*[qlLm](?=[\d\s]|$)|--quiet|--silent"
                   r"|--max-count|--files-with(?:out)?-match))")


def shell_script(path):
    if path.endswith(".sh"):
        return True
    try:
        with open(path, "rb") as f:
            first = f.readline()
    except OSError:
        return False
    return first.startswith(b"#!") and re.search(rb"\b(ba|da|k|z)?sh\b", first) is not None


def logical_lines(text):
    """(first line number, text) per command line: backslash continuations and lines ending in
    a pipe joined to the next; comment lines left out."""
    pending, start = "", 0
    for n, line in enumerate(text.splitlines(), 1):
        if not pending and line.lstrip().startswith("#"):
            continue
        if not pending:
            start = n
        if line.endswith("\\"):
            pending += line[:-1] + " "
            continue
        if line.rstrip().endswith("|") and not line.rstrip().endswith("||"):
            pending += line + " "
            continue
        yield start, pending + line
        pending = ""
    if pending:
        yield start, pending


def main(argv):
    if len(argv) != 2:
        sys.exit(__doc__)
    found = []
    for top in ("tools", "models"):
        for folder, dirs, files in os.walk(os.path.join(argv[1], top)):
            dirs[:] = sorted(d for d in dirs if d != "build")
            for name in sorted(files):
                path = os.path.join(folder, name)
                if not shell_script(path):
                    continue
                with open(path, encoding="utf-8", errors="replace") as f:
                    text = f.read()
                if not PIPEFAIL.search(text):
                    continue
                for n, line in logical_lines(text):
                    if EARLY.search(line):
                        found.append(f"{os.path.relpath(path, argv[1])}:{n}: {line.strip()}")
    for f in found:
        print(f)
    if found:
        print(f"{len(found)} pipeline(s) under set -o pipefail end in a reader that may stop early "
              "(grep -q/-l/-m, head): capture the output first or read to the end (sed -n 1,Np)")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
