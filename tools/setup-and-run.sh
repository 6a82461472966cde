#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to the main job's results:
# installs the dependencies (as root), builds the release preset, runs tools/main-job.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(id -u)" -eq 0 ]; then
  ./tools/install-deps.sh
else
  echo "setup-and-run.sh: not root, so not installing packages (run tools/install-deps.sh as root first)" >&2
fi
cmake --preset release >/dev/null
cmake --build --preset release
./tools/main-job.sh "${1:-out}"
