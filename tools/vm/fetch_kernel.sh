#!/usr/bin/env bash
# Fetches and unpacks Debian's PREEMPT_RT kernel image package (the one linux-image-rt-amd64
# depends on) into CACHE (default build/vm), once: CACHE/kernel/{boot/vmlinuz-*,lib/modules/*}
# with a modules.dep made by depmod. Falls back to the generic linux-image-amd64 flavour when the
# RT one cannot be had; a cached generic kernel is replaced by the RT one as soon as that can be
# had. Prints the kernel release on success; exits 77 (ctest's skip code) when no kernel package
# can be downloaded or apt is missing. Holds a lock on CACHE: two builds may share it.
set -euo pipefail
# depmod lives in /sbin, which a user's PATH on Debian leaves out.
PATH=$PATH:/usr/sbin:/sbin
CACHE=${1:-build/vm}
mkdir -p "$CACHE/deb"
CACHE=$(cd "$CACHE" && pwd)
exec 9>"$CACHE/.lock"
flock 9
cached=""
[ -f "$CACHE/kernel/.release" ] && cached=$(cat "$CACHE/kernel/.release")
case "$cached" in *-rt-*) echo "$cached"; exit 0;; esac
for tool in apt-cache apt-get dpkg-deb depmod; do
  if ! command -v "$tool" >/dev/null; then
    [ -n "$cached" ] && { echo "$cached"; exit 0; }
    echo "fetch_kernel.sh: $tool not found (a Debian machine with apt and kmod is needed)" >&2
    exit 77
  fi
done
metas="linux-image-rt-amd64 linux-image-amd64"
[ -n "$cached" ] && metas="linux-image-rt-amd64"   # a generic one is cached: only RT can improve it
pkg=""
for meta in $metas; do
  # apt-cache fails (100) for a package the archive lacks: that is a fallback, not an error.
  pkg=$(apt-cache depends "$meta" 2>/dev/null | awk '/Depends: linux-image-[0-9]/{print $2; exit}') || pkg=""
  [ -n "$pkg" ] || continue
  if (cd "$CACHE/deb" && apt-get download "$pkg" >/dev/null 2>&1); then break; fi
  pkg=""
done
if [ -z "$pkg" ]; then
  [ -n "$cached" ] && { echo "$cached"; exit 0; }
  echo "fetch_kernel.sh: cannot download a Debian kernel image package (apt-get download linux-image-*-amd64)" >&2
  exit 77
fi
# Unpacked beside the cache and moved in whole: a failed step leaves no half kernel behind.
rm -rf "$CACHE/kernel.new"
mkdir -p "$CACHE/kernel.new"
dpkg-deb -x "$CACHE"/deb/"$pkg"_*.deb "$CACHE/kernel.new"
# sed reads to the end: head would leave ls to SIGPIPE, and pipefail to fail the line.
release=$(ls "$CACHE/kernel.new/lib/modules" | sed -n 1p)
depmod -b "$CACHE/kernel.new" "$release"
echo "$release" > "$CACHE/kernel.new/.release"
rm -rf "$CACHE/kernel"
mv "$CACHE/kernel.new" "$CACHE/kernel"
echo "$release"
