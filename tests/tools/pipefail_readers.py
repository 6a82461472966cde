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
Prints each offending line as FILE:LINE and exits 1, or exits 0. It first checks its own patterns
on the cases in SELF_TEST (exit 2 naming the case that goes wrong), so that a pattern that stops
matching cannot pass the repository's scripts unseen.
"""
import os
import re
import sys

# `-o pipefail` anywhere on a `set` line, alone or ending a cluster: set -o pipefail, set -euo
# pipefail, set -e -o pipefail, set -eu -o pipefail, set -o errexit -o pipefail. (It once had
# to follow `set` at once, so the last three were missed: a script written so was never checked.)
PIPEFAIL = re.compile(r"^[ \t]*set[ \t]+(?:[^\n#;&|]*[ \t])?-[A-Za-z]*o[ \t]+pipefail\b", re.M)
# A pipe (not ||), then a reader that may close its input before the writer is done: head, or
# grep (egrep, fgrep) with an option that stops it early. Short options cluster (-qE, -qs, -lr):
# a cluster counts when q, l, L or m appears in it before any letter that takes an argument
# (-e, -f, -m, -A, -B, -C, -d, -D: the rest of the cluster is that argument, so -ve q is no -q).
# Options before it may take a number of their own (-A 2 -q). The cluster once had to end in
# the letter, so grep -qE and grep -lr passed.
_ARGUMENT_LETTERS = "efmABCdD"
EARLY = re.compile(r"(?<!\|)\|(?!\|)&?\s*(head\b|[ef]?grep\s+(?:-\S+\s+(?:\d+\s+)?)*"
                   r"(?:-(?:(?![" + _ARGUMENT_LETTERS + r"])[A-Za-z])*[qlLm]|--quiet|--silent"
                   r"|--max-count|--files-with(?:out)?-match))")

# (script text, the lines offending() must name). Each case is one that a pattern got wrong
# once or could: the flag clusters, the forms of `set`, and what must not be flagged.
SELF_TEST = [
    # Every form of `set` that turns pipefail on makes a script checked.
    ("set -o pipefail\nx | grep -q a\n", [2]),
    ("set -euo pipefail\nx | grep -q a\n", [2]),
    ("set -e -o pipefail\nx | grep -q a\n", [2]),
    ("set -eu -o pipefail\nx | grep -q a\n", [2]),
    ("  set -o errexit -o pipefail\nx | grep -q a\n", [2]),
    ("set -eo pipefail  # strict\nx | head -1\n", [2]),
    # ... and nothing else does: no pipefail, turned off, in a comment or an echo.
    ("set -eu\nx | grep -q a\n", []),
    ("set +o pipefail\nx | grep -q a\n", []),
    ("# set -o pipefail\nx | grep -q a\n", []),
    ("echo set -o pipefail\nx | grep -q a\n", []),
    ("set -o nounset\nx | grep -q a\n", []),
    # Early readers, alone and in clusters, after other options, long forms, |& and a continued line.
    ("set -eu -o pipefail\nif x | grep -qE 'a|b'; then :; fi\n", [2]),
    ("set -e -o pipefail\nx | grep -qF a\nx | grep -qs a\nx | grep -qi a\nx | grep -lr a\n", [2, 3, 4, 5]),
    ("set -o pipefail\nx | grep -Eq a\nx | grep -iL a\nx | grep -E -q a\nx | grep -A 2 -q a\n", [2, 3, 4, 5]),
    ("set -o pipefail\nx | grep -m1 a\nx | grep -m 1 a\nx | grep -cm1 a\nx | egrep -q a\n", [2, 3, 4, 5]),
    ("set -o pipefail\nx | grep --quiet a\nx | grep -i --max-count=1 a\nx |& grep -q a\n", [2, 3, 4]),
    ("set -o pipefail\nx |\n  grep -qE a\ny \\\n  | head -n 2\n", [2, 4]),
    # Readers that read to the end, options whose letters are another's argument, no pipe, ||.
    ("set -o pipefail\nx | grep a\nx | grep -c a\nx | grep -vE a\nx | grep -i --line-buffered a\n", []),
    ("set -o pipefail\nx | grep -e q\nx | grep -ve q\nx | grep -A1 a\nx | sed -n 1,8p\n", []),
    ("set -o pipefail\ngrep -q a file\nx || grep -q a file\ny=$(x); grep -qE a <<<\"$y\"\n", []),
    ("set -o pipefail\n# x | grep -q a\n", []),
]


def offending(text):
    """(line number, line) of each pipeline in `text` that ends in an early reader under pipefail."""
    if not PIPEFAIL.search(text):
        return []
    return [(n, line) for n, line in logical_lines(text) if EARLY.search(line)]


def self_test():
    """Names each SELF_TEST case offending() gets wrong; empty when all are right."""
    wrong = []
    for text, want in SELF_TEST:
        got = [n for n, _ in offending(text)]
        if got != want:
            wrong.append(f"self-test: {text!r}: flagged lines {got}, expected {want}")
    return wrong


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
    wrong = self_test()
    if wrong:
        print("\n".join(wrong))
        return 2
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
                for n, line in offending(text):
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
