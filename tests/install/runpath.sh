#!/bin/sh
# runpath.sh - no binary searches the current directory for its libraries: an empty
# entry in RPATH/RUNPATH (CMake pads the build tree's with ':' when it edits it in place
# at install) means ".", so a libz.so.1 in the user's directory would be loaded.
# Usage: runpath.sh ELF...
set -u
status=0
for f in "$@"; do
  paths=$(readelf -d "$f" | sed -n 's/.*(R[UN]*PATH).*\[\(.*\)\]$/\1/p')
  [ -z "$paths" ] && continue
  case ":$paths:" in
  *::*) echo "FAIL: $f: empty entry in its library search path '$paths'" >&2; status=1 ;;
  esac
  case ":$paths:" in
  *:.:* | *:./*) echo "FAIL: $f: relative entry in its library search path '$paths'" >&2; status=1 ;;
  esac
done
[ $status -eq 0 ] && echo "runpath ok: $#"
exit $status
