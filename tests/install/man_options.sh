#!/bin/sh
# man_options.sh - the man page keeps up with the command: every subcommand listed by
# `vwalls --help` has a section, and every option its `--help` shows is in the page.
#   usage: man_options.sh VWALLS MANPAGE
set -eu
vwalls=$1 page=$2
text=$(sed -e 's/\\-/-/g' -e 's/\\f[BIPR]//g' "$page")
status=0
for cmd in $("$vwalls" --help | sed -n 's/^  \([a-z][a-z-]*\)  .*/\1/p'); do
  if ! printf '%s\n' "$text" | grep -q "^\.SS vwalls $cmd\b"; then
    echo "man_options.sh: $page has no section for 'vwalls $cmd'" >&2; status=1; continue
  fi
  for opt in $("$vwalls" "$cmd" --help | grep -o -- '--[a-z][a-z-]*' | sort -u); do
    if ! printf '%s\n' "$text" | grep -q -- "$opt\b"; then
      echo "man_options.sh: 'vwalls $cmd $opt' is missing from $page" >&2; status=1
    fi
  done
done
exit $status
