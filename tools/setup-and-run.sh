#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to the main job's results:
# installs the dependencies (as root), builds the release preset, runs tools/main-job.sh.
set -euo pipefail
# OUT as the caller wrote it (relative to where they stand); the default out/ is the repository's.
if [ $# -ge 1 ]; then out=$(realpath -m -- "$1"); else out=out; fi
cd "$(dirname "$0")/.."
if [ "$(id -u)" -eq 0 ]; then
  ./tools/install-deps.sh
elif command -v sudo >/dev/null 2>&1; then
  sudo ./tools/install-deps.sh
else
  echo "setup-and-run.sh: installing packages needs root: run it as root, or install sudo" >&2
  exit 1
fi
cmake --preset release >/dev/null
cmake --build --preset release
./tools/main-job.sh "$out"
