#!/usr/bin/env bash
# Builds the SocketCAN test VM's initramfs (cpio newc, gzip): busybox-static, the CAN modules of
# Debian's kernel (can, can-raw, can-dev, vcan and their dependencies from modules.dep, loaded in
# order by /init; vcan with echo=1), the traffic-control modules and iproute2's tc that drop a
# CAN identifier on its way out (sch_prio, cls_basic, em_canid, act_gact), can-utils (candump,
# canplayer, cansend), the project's binaries with their shared libraries (found with ldd), the
# test logs and model, and the in-VM test script.
#   build_initramfs.sh --cache build/vm --out build/vm/initramfs.gz --bin BIN... --data DIR --script FILE
set -euo pipefail
CACHE=build/vm; OUT=""; DATA=""; SCRIPT=""; BINS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --cache) CACHE=$2; shift 2;;
    --out) OUT=$2; shift 2;;
    --data) DATA=$2; shift 2;;
    --script) SCRIPT=$2; shift 2;;
    --bin) BINS+=("$2"); shift 2;;
    *) echo "build_initramfs.sh: unknown argument $1" >&2; exit 2;;
  esac
done
[ -n "$OUT" ] && [ -n "$SCRIPT" ] || { echo "build_initramfs.sh: --out and --script are required" >&2; exit 2; }
HERE=$(cd "$(dirname "$0")" && pwd)
release=$("$HERE/fetch_kernel.sh" "$CACHE")
KDIR=$(cd "$CACHE/kernel" && pwd)
BUSYBOX=$(command -v busybox) || { echo "build_initramfs.sh: busybox-static not installed" >&2; exit 77; }
[[ "$(file -L "$BUSYBOX")" == *"statically linked"* ]] || { echo "build_initramfs.sh: $BUSYBOX is not static (install busybox-static)" >&2; exit 77; }
root=$(mktemp -d)
trap 'rm -rf "$root"' EXIT
mkdir -p "$root"/{bin,sbin,usr/bin,lib,lib64,proc,sys,dev,tmp,data,modules,etc}
cp "$BUSYBOX" "$root/bin/busybox"
for app in $("$BUSYBOX" --list); do [ "$app" = busybox ] || ln -sf busybox "$root/bin/$app"; done

# Binaries and their shared libraries (ldd), at the same paths as on the host.
copy_with_libs() {
  local b=$1
  cp -L "$b" "$root/usr/bin/"
  ldd "$b" 2>/dev/null | awk '/=> \//{print $3} /^\t\/lib/{print $1}' | while read -r lib; do
    mkdir -p "$root$(dirname "$lib")"
    cp -Ln "$lib" "$root$lib" 2>/dev/null || true
  done
}
for b in /usr/bin/candump /usr/bin/canplayer /usr/bin/cansend "${BINS[@]}"; do copy_with_libs "$b"; done
# iproute2's ip, if busybox's cannot create a vcan link.
if [ -x /usr/sbin/ip ] || [ -x /sbin/ip ]; then
  ipbin=$( [ -x /usr/sbin/ip ] && echo /usr/sbin/ip || echo /sbin/ip )
  copy_with_libs "$ipbin"
  mv "$root/usr/bin/ip" "$root/usr/bin/ip2"
fi
# tc: the "stop frames never reach the bus" scenario. Installed as tc2 (as ip is as ip2): the
# busybox shell runs its own applets first, and busybox's tc has no filters.
tcbin=$(command -v tc || true)
[ -z "$tcbin" ] && [ -x /usr/sbin/tc ] && tcbin=/usr/sbin/tc
[ -n "$tcbin" ] || { echo "build_initramfs.sh: iproute2's tc not installed" >&2; exit 77; }
copy_with_libs "$tcbin"
mv "$root/usr/bin/tc" "$root/usr/bin/tc2"
# Its table of ematch kinds (canid among them): /etc/iproute2 or, since iproute2 6.5, /usr/share.
for d in /etc/iproute2 /usr/share/iproute2; do
  if [ -f "$d/ematch_map" ]; then mkdir -p "$root/etc/iproute2" && cp "$d/ematch_map" "$root/etc/iproute2/"; break; fi
done

# Modules in dependency order (modules.dep lists a module's dependencies after it).
: > "$root/modules/order"
declare -A seen=()
add_module() {
  local rel=$1
  [ -n "${seen[$rel]:-}" ] && return
  seen[$rel]=1
  local deps
  deps=$(awk -v m="$rel:" '$1 == m {for (i = 2; i <= NF; i++) print $i}' "$KDIR/lib/modules/$release/modules.dep")
  for d in $deps; do add_module "$d"; done
  local name
  name=$(basename "$rel")
  case "$name" in
    *.ko.xz) xz -dc "$KDIR/lib/modules/$release/$rel" > "$root/modules/${name%.xz}"; name=${name%.xz};;
    *.ko.zst) zstd -dcq "$KDIR/lib/modules/$release/$rel" > "$root/modules/${name%.zst}"; name=${name%.zst};;
    *) cp "$KDIR/lib/modules/$release/$rel" "$root/modules/$name";;
  esac
  echo "$name" >> "$root/modules/order"
}
for m in can can-raw can-dev vcan sch_prio cls_basic em_canid act_gact; do
  rel=$(awk -F: -v m="/$m.ko" 'index($1, m) && substr($1, length($1) - length(m) + 1) == m {print $1; exit}' "$KDIR/lib/modules/$release/modules.dep")
  rel=${rel:-$(cd "$KDIR/lib/modules/$release" && find kernel -name "$m.ko*" | sed -n 1p)}  # not head: pipefail
  [ -n "$rel" ] || { echo "build_initramfs.sh: module $m not in the kernel package" >&2; exit 1; }
  add_module "$rel"
done

[ -n "$DATA" ] && cp -r "$DATA"/. "$root/data/"
cp "$SCRIPT" "$root/vm_tests.sh"
chmod +x "$root/vm_tests.sh"
cat > "$root/init" <<'INIT'
#!/bin/sh
export PATH=/usr/bin:/bin:/sbin
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev 2>/dev/null
mount -t tmpfs tmp /tmp
# vcan with echo=1: the driver, not the CAN core, loops a sent frame back once it is "on the
# bus" (as a real controller does on its transmit-complete interrupt), so a frame dropped on
# its way out is never echoed: the stop socket's echo means what it means on real hardware.
for m in $(cat /modules/order); do
  args=""; [ "$m" = vcan.ko ] && args="echo=1"
  insmod /modules/$m $args || echo "DG-VM: insmod $m failed"
done
echo "DG-VM: kernel $(uname -r) $(uname -v)"
sh /vm_tests.sh
echo "DG-VM: done"
poweroff -f
INIT
chmod +x "$root/init"
mkdir -p "$(dirname "$OUT")"
(cd "$root" && find . | cpio -o -H newc --quiet | gzip -1) > "$OUT.tmp"
mv "$OUT.tmp" "$OUT"
echo "$KDIR/boot/vmlinuz-$release"
