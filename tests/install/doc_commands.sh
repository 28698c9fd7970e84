#!/bin/sh
# doc_commands.sh - the commands the docs show are commands vwalls takes. Every
# `vwalls SUBCOMMAND ...` in a fenced code block or an inline code span of README.md,
# BENCHMARKS.md and docs/*.md (and of docs/man/vwalls.1: its .nf blocks and its bold
# text) is checked:
#   - the subcommand is one `vwalls --help` lists (or help, --help, --version);
#   - every option it uses (--long or -x; in a synopsis, each of "-o|--output" and the
#     options inside [brackets]) is one that `vwalls SUBCOMMAND --help` shows;
#   - a command with no placeholder is run as it stands with one more argument,
#     --doc-check-end, which no command knows: each command reads its arguments in
#     order and stops at the first bad one, so it must stop at that last one ("unknown
#     option '--doc-check-end'", status 2) having done no work. That checks the values
#     as well as the names (--size 512 where WxH is wanted, a missing value, a second
#     scene) without an option for it in the command. What a command checks only once
#     all its arguments are read (a missing -o, animate's --balance strategy) is not
#     checked here, but for gen's scene name: one of those its --help names.
# `./run X` must be a command `./run help` lists (`./run bench NAME` also needs
# bench/NAME.sh, and the options after `./run demo`, which go to vwalls render, are
# render's), and every bench/NAME.sh (.py, .c, .awk) the docs name must exist.
#
# Skipped, each on purpose (the only skips):
#   - `vwalls SUB: ...`: the subcommand followed by a colon is a message the command
#     prints (docs/edit-language.md quotes several), not a command line;
#   - `vwalls COMMAND ...`: an upper-case subcommand is a placeholder for any of them;
#   - the run (not the name check) of a line with a placeholder: an upper-case word
#     (SCENE, OUT.ply, FILE, S, WxH, X,Y,Z), [optional] parts, a|b alternatives,
#     (groups) or "...": a synopsis or a fragment of prose (`vwalls render --balance S`);
#   - the value of an option that ends a command: prose names an option so
#     (`vwalls render --steal`);
#   - vwalls where it is not the program a command runs (its first word, or after
#     mpirun/srun/env/time and their options): "tools/  the vwalls command" in a
#     listing, `pkg-config --libs vwalls`;
#   - inside a fenced block, what follows a '#' that starts a word (a shell comment).
# A command written in prose without its scene and -o (`vwalls render --farm all`)
# is run too: it stops at --doc-check-end before it would miss them.
#   usage: doc_commands.sh VWALLS SRCDIR
set -eu
vwalls=$1 src=$2
case $vwalls in /*) ;; *) vwalls=$PWD/$vwalls ;; esac
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/cwd"   # the runs' working directory: empty, so no input they name is found
us=$(printf '\037')  # separates the words of a command in the list below
tab=$(printf '\t')

# The man page as the markdown below reads it, line for line: its .nf ... .fi blocks
# as code (each line marked with ```), its bold text (\fB...\fP) as code spans.
sed -e 's/\\-/-/g' -e 's/\\(aq/'"'"'/g' "$src/docs/man/vwalls.1" |
  awk '/^\.nf/ { f = 1; print ""; next } /^\.fi/ { f = 0 }
       f { gsub(/\\f[BIPR]/, ""); print "```" $0; next }
       { out = ""; t = $0
         while (match(t, /\\fB[^\\]*\\f[PR]/)) {
           out = out " `" substr(t, RSTART + 3, RLENGTH - 6) "`"; t = substr(t, RSTART + RLENGTH)
         }
         print out }' >"$tmp/vwalls.1.md"

# Lines "FILE:LINE<tab>KIND<tab>WORDS": KIND vwalls (WORDS: what follows vwalls), run
# (what follows ./run) or bench (WORDS: a bench/ file named anywhere in the text).
cd "$src"
set -- README.md BENCHMARKS.md docs/*.md
awk -v US="$us" -v SQ="'" -v man="$tmp/vwalls.1.md" '
  # The words of shell text s, with quotes taken off; a separator (; && || |) ends a
  # command, a redirection and its file are dropped, and in code a word starting with
  # # ends the line. Each command holding vwalls or ./run is printed.
  function shell(s, loc, incode,    i, c, q, w, have, n, words) {
    n = 0; w = ""; have = 0; q = ""
    for (i = 1; i <= length(s); i++) {
      c = substr(s, i, 1)
      if (q != "") { if (c == q) q = ""; else w = w c; continue }
      if (c == SQ || c == "\"") { q = c; have = 1; continue }
      if (c == " " || c == "\t" || c == ";") {
        if (have) words[++n] = w
        w = ""; have = 0
        if (c == ";") { command(words, n, loc); n = 0 }
        continue
      }
      if (c == "#" && !have && incode) break
      w = w c; have = 1
    }
    if (have) words[++n] = w
    command(words, n, loc)
  }
  # The program a command runs is its first word, after VAR=value settings or a
  # launcher and its options (mpirun -np 2 vwalls ...); elsewhere vwalls is a word of
  # prose ("tools/  the vwalls command") or an argument (pkg-config --libs vwalls).
  function command(words, n, loc,    i, out, kind, first, lead) {
    kind = ""; out = ""; first = 1; lead = 0
    for (i = 1; i <= n; i++) {
      if (words[i] == "|" || words[i] == "&&" || words[i] == "||") {
        emit(loc, kind, out)
        kind = ""; out = ""; first = 1; lead = 0; continue
      }
      if (words[i] ~ /^[0-9&]?(>>?|<)/) {               # 2>/dev/null, > file, <in
        if (words[i] ~ /^[0-9&]?(>>?|<)&?$/) i++         # the operator alone: its file next
        continue
      }
      if (kind != "") { out = out (out == "" ? "" : US) words[i]; continue }
      if (!first && !lead) continue
      if (first && words[i] ~ /^[A-Za-z_][A-Za-z_0-9]*=/) continue
      if (words[i] == "vwalls" || words[i] ~ /\/vwalls$/) { kind = "vwalls"; continue }
      if (words[i] == "./run") { kind = "run"; continue }
      if (first && words[i] ~ /^(mpirun|mpiexec|srun|time|timeout|env|valgrind)$/) lead = 1
      first = 0
    }
    emit(loc, kind, out)
  }
  function emit(loc, kind, out) { if (kind != "" && out != "") printf "%s\t%s\t%s\n", loc, kind, out }
  function benchrefs(s, loc,    t) {
    t = s
    while (match(t, /(^|[^A-Za-z0-9_\/.-])bench\/[A-Za-z0-9_-]+\.(sh|py|c|awk)/)) {
      ref = substr(t, RSTART, RLENGTH); sub(/^[^b]/, "", ref)
      printf "%s\tbench\t%s\n", loc, ref
      t = substr(t, RSTART + RLENGTH)
    }
  }
  FNR == 1 { flush(); fence = 0; span = ""; open = 0
             name = FILENAME == man ? "docs/man/vwalls.1" : FILENAME }
  { loc = name ":" FNR; benchrefs($0, loc) }
  # A line of code goes on after a backslash, and over the indented lines after it (a
  # synopsis laid out on several lines).
  function code(line) {
    if (line ~ /^[ \t]/ && cont != "") { cont = cont " " line; more = line ~ /\\$/ }
    else if (more) { cont = cont " " line; more = line ~ /\\$/ }
    else { flush(); cont = line; contloc = loc; more = line ~ /\\$/ }
    if (more) cont = substr(cont, 1, length(cont) - 1)
  }
  function flush() { if (cont != "") shell(cont, contloc, 1); cont = ""; more = 0 }
  /^[ \t]*```/ && FILENAME != man { flush(); fence = !fence; next }
  FILENAME == man && substr($0, 1, 3) == "```" { code(substr($0, 4)); next }
  FILENAME == man { flush() }
  fence { line = $0; sub(/^\$ /, "", line); code(line); next }
  # Prose: inline code spans, which may go on over the next lines of the paragraph.
  /^[ \t]*$/ { open = 0; span = ""; next }
  {
    line = $0
    while (line != "") {
      k = index(line, "`")
      if (!open) {
        if (!k) break
        open = 1; span = ""; spanloc = loc; line = substr(line, k + 1)
      } else if (!k) {
        span = span line " "; break
      } else {
        span = span substr(line, 1, k - 1); open = 0
        shell(span, spanloc, 0); line = substr(line, k + 1)
      }
    }
  }
  END { flush() }
' "$@" "$tmp/vwalls.1.md" >"$tmp/found"

status=0
fail() { echo "$1: $2" >&2; status=1; }
"$vwalls" --help | sed -n 's/^  \([a-z][a-z-]*\)  .*/\1/p' >"$tmp/commands"
{ echo help; bash ./run help | sed -n 's/^  \([a-z][a-z-]*\) .*/\1/p'; } >"$tmp/run-commands"

# The options `vwalls CMD --help` shows, one a line, in $tmp/opts.CMD.
options() {
  [ -f "$tmp/opts.$1" ] && return
  { "$vwalls" "$1" --help | grep -o -- '--[a-z][a-z-]*'
    "$vwalls" "$1" --help | sed -n 's/^ *\(-[a-zA-Z]\)[, ].*/\1/p'; } | sort -u >"$tmp/opts.$1"
}

# Is the word a placeholder or synopsis notation (see the header)?
placeholder() {
  case $1 in
    *'['* | *']'* | *'|'* | *'('* | *')'* | *...* | *[A-Z][A-Z]* | [A-Z] | [A-Z]x[A-Z]) return 0 ;;
  esac
  case $1 in *[a-z0-9]*) return 1 ;; *[A-Z]*) return 0 ;; esac
  return 1
}

checked=0 ran=0
set -f
while IFS=$tab read -r loc kind words; do
  IFS=$us
  # shellcheck disable=SC2086 # split on purpose, into the words (globbing is off)
  set -- $words
  IFS=' '
  case $kind in
  bench)
    [ -f "$1" ] || fail "$loc" "$1: no such file in the source tree"
    continue ;;
  run)
    case $1 in [A-Z]* | -*) continue ;; esac
    if ! grep -qxF -- "$1" "$tmp/run-commands"; then
      fail "$loc" "./run $1: not a command of './run help'"
    elif [ "$1" = bench ] && [ $# -gt 1 ] && ! placeholder "$2" && [ ! -f "bench/$2.sh" ]; then
      fail "$loc" "./run bench $2: there is no bench/$2.sh"
    elif [ "$1" = demo ]; then
      options render
      shift
      for o in "$@"; do
        case $o in -[a-zA-Z]* | --[a-zA-Z]*)
          grep -qxF -- "$o" "$tmp/opts.render" ||
            fail "$loc" "./run demo $o: not an option of 'vwalls render --help'" ;;
        esac
      done
    fi
    continue ;;
  esac
  sub=$1; shift
  case $sub in
  *:) continue ;;                                  # a message: "vwalls animate: ..."
  --help | -h | --version) continue ;;
  -*) fail "$loc" "vwalls $sub: not an option of vwalls itself (--help, --version)"; continue ;;
  help)
    if [ $# -ne 1 ] || { ! placeholder "$1" && ! grep -qxF -- "$1" "$tmp/commands"; }; then
      fail "$loc" "vwalls help $*: expected one command of 'vwalls --help'"
    fi
    continue ;;
  esac
  case $sub in *[!a-z-]*) continue ;; esac        # COMMAND: any subcommand
  checked=$((checked + 1))
  if ! grep -qxF -- "$sub" "$tmp/commands"; then
    fail "$loc" "vwalls $sub: not a command of 'vwalls --help'"; continue
  fi
  options "$sub"
  # gen's scene, which it checks only after its options: one of its usage line's names.
  if [ "$sub" = gen ] && [ $# -gt 0 ] && [ "${1#-}" = "$1" ] && ! placeholder "$1" &&
     ! "$vwalls" gen --help | sed -n 's/^usage: vwalls gen \([a-z|]*\) .*/\1/p' | tr '|' '\n' |
       grep -qxF -- "$1"; then
    fail "$loc" "vwalls gen $1: not a scene of 'vwalls gen --help'"
  fi
  concrete=1 help=0
  for w in "$@"; do
    placeholder "$w" && concrete=0
    case $w in --help | -h) help=1 ;; esac
    # "[--light" "-o|--output" "[-q|--quiet]" "--image F.png|F.pfm": each option in it
    for o in $(printf '%s\n' "$w" | tr '|[]()' '     '); do
      o=${o%%=*}
      case $o in
        --[a-zA-Z]* | -[a-zA-Z]*)
          case $o in *[!a-zA-Z0-9-]*) continue ;; esac
          grep -qxF -- "$o" "$tmp/opts.$sub" ||
            fail "$loc" "vwalls $sub $o: not an option of 'vwalls $sub --help'" ;;
      esac
    done
  done
  [ $concrete = 1 ] || continue
  ran=$((ran + 1))
  rc=0
  (cd "$tmp/cwd" && timeout 60 "$vwalls" "$sub" "$@" --doc-check-end) \
    </dev/null >/dev/null 2>"$tmp/err" || rc=$?
  if [ $help = 1 ] && [ $rc = 0 ]; then continue; fi
  # Prose names an option by the command and the option alone (`vwalls render --steal`).
  last=; for last in "$@"; do :; done
  case $last in
    -*) grep -qxF -- "vwalls $sub: $last needs a value, not the option '--doc-check-end'" \
          "$tmp/err" && continue ;;
  esac
  if [ $rc != 2 ] || ! grep -q "unknown option '--doc-check-end'" "$tmp/err"; then
    fail "$loc" "vwalls $sub $*: refused (status $rc): $(head -n 3 "$tmp/err")"
  fi
done <"$tmp/found"
set +f

if [ $checked = 0 ]; then fail "$0" "found no vwalls command in the docs under $src"; fi
echo "doc_commands.sh: $checked vwalls commands checked ($ran run up to their last argument)"
exit $status
