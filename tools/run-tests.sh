#!/usr/bin/env bash
# Builds the release preset and runs the whole test suite with ctest.
# Tests that need ../shared/data skip with a message when it is absent; the VM tests need
# qemu-system-x86 and the packages of tools/install-deps.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release -j "$(nproc)" "$@"
