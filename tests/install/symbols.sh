#!/bin/sh
# symbols.sh - the shared library exports exactly the functions the public headers
# declare with VW_API: no vw__ internals, nothing unprefixed, nothing missing.
#   usage: symbols.sh LIBVWALLS.so HEADER_DIR...
set -eu
lib=$1; shift
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
nm -D --defined-only "$lib" | awk '$2 ~ /^[TDBRVW]$/ {print $3}' | sort -u >"$tmp/exported"
# The name before the first "(" of every VW_API declaration.
find "$@" -name "*.h" -exec cat {} + | grep -h '^VW_API' | sed -n 's/^[^(]*[ *]\([A-Za-z_][A-Za-z0-9_]*\)(.*/\1/p' |
  sort -u >"$tmp/declared"
echo "exported: $(wc -l <"$tmp/exported"), declared: $(wc -l <"$tmp/declared")"
status=0
if grep -v '^vw_' "$tmp/exported" || grep '^vw__' "$tmp/exported"; then
  echo "symbols.sh: the lines above are exported but are not public vw_ names" >&2; status=1
fi
comm -23 "$tmp/exported" "$tmp/declared" >"$tmp/extra"
comm -13 "$tmp/exported" "$tmp/declared" >"$tmp/missing"
if [ -s "$tmp/extra" ]; then
  echo "symbols.sh: exported but not declared VW_API in a public header:" >&2; cat "$tmp/extra" >&2; status=1
fi
if [ -s "$tmp/missing" ]; then
  echo "symbols.sh: declared VW_API but not exported:" >&2; cat "$tmp/missing" >&2; status=1
fi
exit $status
