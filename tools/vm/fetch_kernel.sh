#!/usr/bin/env bash
# Fetches and unpacks Debian's PREEMPT_RT kernel image package (the one linux-image-rt-amd64
# depends on) into CACHE (default build/vm), once: CACHE/kernel/{boot/vmlinuz-*,lib/modules/*}
# with a modules.dep made by depmod. Falls back to the generic linux-image-amd64 flavour when the
# RT one cannot be had. Prints the kernel release on success; exits 77 (ctest's skip code) when no
# kernel package can be downloaded.
set -euo pipefail
CACHE=${1:-build/vm}
mkdir -p "$CACHE/deb"
CACHE=$(cd "$CACHE" && pwd)
if [ -f "$CACHE/kernel/.release" ]; then cat "$CACHE/kernel/.release"; exit 0; fi
pkg=""
for meta in linux-image-rt-amd64 linux-image-amd64; do
  pkg=$(apt-cache depends "$meta" 2>/dev/null | awk '/Depends: linux-image-[0-9]/{print $2; exit}')
  [ -n "$pkg" ] || continue
  if (cd "$CACHE/deb" && apt-get download "$pkg" >/dev/null 2>&1); then break; fi
  pkg=""
done
if [ -z "$pkg" ]; then
  echo "fetch_kernel.sh: cannot download a Debian kernel image package (apt-get download linux-image-*-amd64)" >&2
  exit 77
fi
rm -rf "$CACHE/kernel"
mkdir -p "$CACHE/kernel"
dpkg-deb -x "$CACHE"/deb/"$pkg"_*.deb "$CACHE/kernel"
release=$(ls "$CACHE/kernel/lib/modules" | head -1)
depmod -b "$CACHE/kernel" "$release"
echo "$release" > "$CACHE/kernel/.release"
echo "$release"
