#!/bin/sh
# hello_nomem.sh - the tutorial's hello_cells without memory for its points: the lack is
# agreed on before the world (vw_config_agree) and named, exit status 1. It used to
# return 1 without a word (and, under mpirun, before the others' vw_world_create).
# Skipped (77) where a small address space does not even run it (ASan's shadow memory).
# usage: hello_nomem.sh HELLO_CELLS
hello=$1
(ulimit -v 2000000 && exec "$hello" --points 10 --cells 1 --workers 1) >/dev/null 2>&1 || exit 77
out=$( (ulimit -v 2000000 && exec "$hello" --points 200000000 --workers 1) 2>&1)
rc=$?
echo "$out"
[ "$rc" -eq 1 ] || { echo "FAIL: status $rc, expected 1"; exit 1; }
printf '%s\n' "$out" | grep -q '^hello_cells: out of memory' ||
  { echo "FAIL: no 'hello_cells: out of memory'"; exit 1; }
echo ok
