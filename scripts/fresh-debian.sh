#!/usr/bin/env bash
# fresh-debian.sh - the README's two commands, run as a newcomer runs them: on a minimal
# Debian 12 (debootstrap --variant=minbase: bash, apt and coreutils; no compiler, make
# or cmake), with a clone of this repository's HEAD (and ../shared beside it, when there
# is one), under chroot as root. Checks first that the system has none of the build
# tools, then runs each COMMAND (default: demo test) and reports its time.
#
# usage: scripts/fresh-debian.sh [--keep] [DIR] [demo|test]...
#   DIR     where the system goes (default: a new temporary folder, removed afterwards
#           unless --keep; an existing DIR with a system in it is reused as it is)
# Needs root (it installs debootstrap when missing: scripts/setup.sh fresh) and Debian's
# mirror (VW_DEBIAN_MIRROR, default http://deb.debian.org/debian). Exit status 77 when
# the system cannot be made (no mirror, no chroot): nothing was tested.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
keep=0
if [ "${1:-}" = --keep ]; then keep=1; shift; fi
dir=""
if [ $# -gt 0 ] && [ "$1" != demo ] && [ "$1" != test ]; then dir=$1; shift; fi
cmds=(demo test)
[ $# -eq 0 ] || cmds=("$@")
for c in "${cmds[@]}"; do
  case "$c" in demo|test) ;; *) echo "fresh-debian.sh: unknown command '$c' (demo, test)" >&2; exit 2 ;; esac
done
[ "$(id -u)" = 0 ] || { echo "fresh-debian.sh: needs root (debootstrap, chroot, mounts)" >&2; exit 2; }
"$ROOT/scripts/setup.sh" fresh || exit 77

made=0
if [ -z "$dir" ]; then dir=$(mktemp -d "${TMPDIR:-/tmp}/vwalls-debian.XXXXXX"); made=1; fi
mounted=()
cleanup() {
  local i
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do umount -l "${mounted[$i]}" 2>/dev/null || true; done
  if [ "$made" = 1 ] && [ "$keep" = 0 ]; then
    # Never through a mount that is still there: the host's /dev is bound into it.
    if grep -q " $dir/" /proc/mounts; then
      echo "fresh-debian.sh: $dir still has mounts; left in place" >&2
    else
      rm -rf --one-file-system "$dir"
    fi
  fi
}
trap cleanup EXIT

fresh=0
if [ ! -x "$dir/bin/bash" ]; then
  fresh=1
  echo "fresh-debian: debootstrap --variant=minbase bookworm into $dir" >&2
  debootstrap --variant=minbase bookworm "$dir" "${VW_DEBIAN_MIRROR:-http://deb.debian.org/debian}" \
    > "$dir.debootstrap.log" 2>&1 ||
    { tail -n 20 "$dir.debootstrap.log" >&2; echo "fresh-debian.sh: debootstrap failed" >&2; exit 77; }
  rm -f "$dir.debootstrap.log"
  # What an installed system has and debootstrap leaves out: without /etc/hosts every
  # MPI process waits seconds in MPI_Init for the host name to resolve.
  printf '127.0.0.1\tlocalhost\n127.0.1.1\t%s\n' "$(hostname)" > "$dir/etc/hosts"
  cp /etc/resolv.conf "$dir/etc/resolv.conf"
fi
# The point of the exercise: the commands must install every tool themselves.
for tool in gcc cc make cmake git; do
  if [ "$fresh" = 1 ] && chroot "$dir" /bin/bash -c "command -v $tool" > /dev/null 2>&1; then
    echo "fresh-debian.sh: the new system already has $tool: not a minimal one" >&2
    exit 1
  fi
done

cannot_mount() { echo "fresh-debian.sh: cannot mount $1 in $dir (no privilege here?)" >&2; exit 77; }
for m in proc sys dev dev/pts; do
  mount --bind "/$m" "$dir/$m" || cannot_mount "/$m"
  mounted+=("$dir/$m")
done
mount -t tmpfs tmpfs "$dir/run" || cannot_mount /run
mounted+=("$dir/run")

if [ ! -d "$dir/root/vwalls/main" ]; then
  mkdir -p "$dir/root/vwalls"
  git clone -q "$ROOT" "$dir/root/vwalls/main"
  if [ -d "$ROOT/../shared" ]; then cp -r "$ROOT/../shared" "$dir/root/vwalls/shared"; fi
fi

for c in "${cmds[@]}"; do
  echo "fresh-debian: ./run $c" >&2
  s=$(date +%s)
  chroot "$dir" /usr/bin/env -i HOME=/root TERM=dumb \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    /bin/bash -c "cd /root/vwalls/main && ./run $c"
  echo "fresh-debian: ./run $c passed in $(( $(date +%s) - s )) s" >&2
done
