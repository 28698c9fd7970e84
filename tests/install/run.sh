#!/bin/sh
# run.sh - the install test: installs the build into a temporary prefix, then builds the
# example modules and the tutorial out of tree against it, with pkg-config (shared and
# static) and with find_package, and runs them; also the installed command and man page.
#   usage: run.sh BUILD_DIR TEST_SRC_DIR CC VERSION DOCDIR LIBDIR [MPIEXEC NP_FLAG]
set -eu
build=$1 here=$2 cc=$3 version=$4 docdir=$5 libdir=$6 mpiexec=${7:-} npflag=${8:--np}
tmp=$(mktemp -d "${TMPDIR:-/tmp}/vwalls-install.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
fail() { echo "install test: $*" >&2; exit 1; }
step() { echo "== $*"; }

step "cmake --install into $prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
for f in bin/vwalls "$libdir/libvwalls.so" "$libdir/libvwalls.a" "$libdir/pkgconfig/vwalls.pc" \
         "$libdir/cmake/vwalls/vwallsConfig.cmake" "$libdir/cmake/vwalls/vwallsConfigVersion.cmake" \
         include/vwalls/vwalls.h include/vwalls/version.h share/man/man1/vwalls.1 \
         "$docdir/examples/components.c" "$docdir/tutorial/hello_cells.c" "$docdir/tutorial.md"; do
  [ -e "$prefix/$f" ] || fail "not installed: $f"
done
# The installed binaries do not search the current directory for their libraries.
sh "$here/runpath.sh" "$prefix/bin/vwalls" "$prefix/$libdir/libvwalls.so" >/dev/null
# Internal headers stay internal.
[ -z "$(find "$prefix/include" -name '*internal*')" ] || fail "internal headers installed"

step "installed command"
out=$("$prefix/bin/vwalls" --version)
[ "$out" = "vwalls $version" ] || fail "vwalls --version says '$out', expected 'vwalls $version'"
"$prefix/bin/vwalls" example-components --spheres 2000 --radius 0.06 --cells 2x2x2 --workers 2 --check --quiet
"$prefix/bin/vwalls" example-pairs --spheres 2000 --radius 0.06 --cells 2x2x2 --workers 2 --check --quiet
if command -v man >/dev/null 2>&1; then
  MANWIDTH=80 man -l "$prefix/share/man/man1/vwalls.1" 2>&1 >/dev/null | { ! grep .; } ||
    fail "man reports problems in vwalls.1"
fi

step "pkg-config"
export PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig"
[ "$(pkg-config --modversion vwalls)" = "$version" ] || fail "pkg-config --modversion"
cflags=$(pkg-config --cflags vwalls)
libs=$(pkg-config --libs vwalls)
echo "cflags: $cflags"
echo "libs:   $libs"
ex=$prefix/$docdir/examples tu=$prefix/$docdir/tutorial
mkdir -p "$tmp/pc"
# shellcheck disable=SC2086
"$cc" -std=c11 -D_POSIX_C_SOURCE=200809L -Wall -Wextra -Werror $cflags -I"$ex" \
  "$here/examples_main.c" "$ex/pairs.c" "$ex/components.c" -o "$tmp/pc/examples" $libs -lm
# shellcheck disable=SC2086
"$cc" -std=c11 -Wall -Wextra -Werror $cflags "$tu/hello_cells.c" "$tu/hello_module.c" \
  -o "$tmp/pc/hello_cells" $libs
# Static: the archive instead of the shared library, plus the private requirements.
slibs=$(pkg-config --static --libs vwalls | sed 's/-lvwalls\b/-l:libvwalls.a/')
# shellcheck disable=SC2086
"$cc" -std=c11 -D_POSIX_C_SOURCE=200809L -Wall -Wextra -Werror $cflags -I"$ex" \
  "$here/examples_main.c" "$ex/pairs.c" "$ex/components.c" -o "$tmp/pc/examples_static" $slibs
ldd "$tmp/pc/examples_static" | grep -q libvwalls && fail "static build links libvwalls.so"
LD_LIBRARY_PATH="$prefix/$libdir" "$tmp/pc/examples" "$version"
LD_LIBRARY_PATH="$prefix/$libdir" "$tmp/pc/hello_cells" --points 20000 --cells 2x2x2 --workers 2
"$tmp/pc/examples_static" "$version"

step "find_package"
cmake -S "$here" -B "$tmp/cm" -DCMAKE_C_COMPILER="$cc" -DCMAKE_PREFIX_PATH="$prefix" \
  -DVW_EXPECT_VERSION="$version" -DVW_DOC_DIR="$prefix/$docdir" -DCMAKE_COMPILE_WARNING_AS_ERROR=ON >/dev/null
cmake --build "$tmp/cm" -j2 >/dev/null
"$tmp/cm/examples_shared" "$version"
"$tmp/cm/examples_static" "$version"
"$tmp/cm/hello_cells" --points 20000 --cells 4x2x1 --workers 3
if [ -x "$tmp/cm/own_mpi" ] && [ -n "$mpiexec" ]; then
  step "own MPI program under $mpiexec"
  "$mpiexec" "$npflag" 2 "$tmp/cm/own_mpi"
  "$mpiexec" "$npflag" 2 "$tmp/cm/hello_cells" --points 20000 --cells 2x2x2 --workers 1
fi

step "relocated prefix"
mv "$prefix" "$tmp/moved"
export PKG_CONFIG_PATH="$tmp/moved/$libdir/pkgconfig"
case "$(pkg-config --cflags vwalls)" in
  *"$tmp/moved/"*) ;;
  *) fail "pkg-config paths do not follow a moved prefix" ;;
esac
cmake -S "$here" -B "$tmp/cm2" -DCMAKE_PREFIX_PATH="$tmp/moved" -DVW_EXPECT_VERSION="$version" \
  -DVW_DOC_DIR="$tmp/moved/$docdir" >/dev/null
cmake --build "$tmp/cm2" -j2 --target examples_shared >/dev/null
"$tmp/cm2/examples_shared" "$version"
echo "install test: ok"
