#!/usr/bin/env bash
# Installs every dependency of dressguard from Debian 12's packages. Idempotent; run as root.
# Each package is here for one named reason; add a line only with its reason.
set -euo pipefail
if [ "$(id -u)" -ne 0 ]; then
  echo "install-deps.sh: must run as root (it calls apt-get)" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
packages=(
  # build
  build-essential cmake ninja-build pkg-config git
  # the chosen libraries
  libeigen3-dev libspdlog-dev libfmt-dev libgtest-dev libgmock-dev libmodbus-dev
  # MPI for calibration and synthesis runs that outgrow one machine
  libopenmpi-dev openmpi-bin
  # reference HMM library the paper used (GHMM), for the comparison test; ATLAS for its LAPACK calls
  libghmm-dev libatlas3-base
  # libFuzzer for the model-file loader fuzz test
  clang libclang-rt-14-dev
  # real SocketCAN tests: Debian's kernel under qemu, busybox initramfs, can-utils
  qemu-system-x86 busybox-static cpio can-utils kmod iproute2 file
  # independent Modbus peers for the bridge tests
  python3-pymodbus mbpoll
  # plots
  python3-matplotlib python3-numpy
  # pagmo2's CMA-ES, the side-by-side comparison for our own (tools/bench/bench_calib_cmaes.cpp)
  libpagmo-dev
)
if [ -z "${DRESSGUARD_SKIP_APT_UPDATE:-}" ]; then
  apt-get update -qq
fi
apt-get install -y -qq --no-install-recommends "${packages[@]}"
echo "install-deps.sh: all dependencies installed"
