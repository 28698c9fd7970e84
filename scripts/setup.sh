#!/usr/bin/env bash
# setup.sh - installs the Debian packages vwalls needs, and only those missing.
# Idempotent: a second run installs nothing and does not touch the network.
# usage: scripts/setup.sh [build|bench|fuzz|mpich|docs|fresh]...   (default: build)
set -euo pipefail

want=()
for what in "${@:-build}"; do
  case "$what" in
    # python3: tests read the stats JSON with it (radiosity_mpi_np*, dynamic_cli).
    build) want+=(gcc libc6-dev make cmake pkg-config libembree-dev libpng-dev zlib1g-dev
                  libopenmpi-dev openmpi-bin openssh-client iproute2 python3) ;;
    bench) want+=(povray gnuplot-nox time python3 valgrind) ;;
    fuzz)  want+=(clang libclang-rt-14-dev) ;;
    mpich) want+=(libmpich-dev mpich) ;;
    docs)  want+=(doxygen) ;;
    fresh) want+=(debootstrap git) ;;   # scripts/fresh-debian.sh
    *) echo "setup.sh: unknown package set '$what' (build, bench, fuzz, mpich, docs, fresh)" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${want[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "setup: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
# dpkg's hundreds of lines go to a log, shown (its end) only if something fails.
log=$(mktemp "${TMPDIR:-/tmp}/vwalls-setup.XXXXXX")
if ! { $SUDO apt-get update -qq &&
       $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"; } > "$log" 2>&1; then
  tail -n 40 "$log" >&2
  echo "setup: apt-get failed; its whole output is in $log" >&2
  exit 1
fi
rm -f "$log"
echo "setup: installed ${#missing[@]} packages and what they need" >&2
