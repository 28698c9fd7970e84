#!/bin/sh
# cli_stats.sh VWALLS TMPDIR - DESIGN's section 9: every command accepts --stats FILE.
# Every command that vwalls --help lists names --stats in its help text; gen and info
# (which run no world) write the stats JSON's common members (command, version, engine,
# time_s with its total) and the scene's counts and bounds, the counts those info prints;
# a stats file that cannot be written fails the command and leaves no other output
# (gen's scene), a failed scene write leaves no stats, and --stats over the input file or
# one of its material libraries is a usage error.
set -u
V=$1 T=$2 D=$(cd "$(dirname "$0")/../data/good" && pwd)
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }

# Every command's help names --stats.
cmds=$("$V" --help | awk '/^commands:/ { on = 1; next } on && /^  [a-z]/ { print $1 } /^$/ { on = 0 }')
[ "$(echo "$cmds" | wc -w)" -ge 9 ] || fail "vwalls --help lists only: $cmds"
for c in $cmds; do
  "$V" "$c" --help | grep -q -- '--stats' || fail "vwalls $c --help has no --stats"
done

# gen: to a file and to standard output, the same scene; the counts are info's.
"$V" gen tree --size 3 -o t.nff --stats g.json || fail "gen -o --stats"
"$V" gen tree --size 3 --stats g2.json > t2.nff || fail "gen --stats to stdout"
cmp -s t.nff t2.nff || fail "gen: the scene differs with -o and on stdout"
"$V" info t.nff --stats i.json > info.txt || fail "info --stats"
python3 - g.json g2.json i.json info.txt <<'PY' || fail "stats JSON"
import json, re, sys
g, g2, i = (json.load(open(f)) for f in sys.argv[1:4])
text = open(sys.argv[4]).read()
for j, cmd in ((g, "gen"), (g2, "gen"), (i, "info")):
    assert j["command"] == cmd and j["version"], j
    e = j["engine"]
    assert e["kind"] == "threads" and e["processes"] == 1 and e["workers"] == 1, e
    t = j["time_s"]
    assert t["total"] >= 0 and all(v <= t["total"] + 1e-9 for v in t.values()), t
assert set(g["time_s"]) == {"generate", "write", "total"}, g["time_s"]
assert set(i["time_s"]) == {"load", "total"}, i["time_s"]
s = g["scene"]
assert s["generator"] == "tree" and s["size"] == 3 and s["seed"] == 1, s
assert g2["scene"] == s and i["scene"]["file"] == "t.nff", (g2, i)
m = re.search(r"objects: (\d+) \(spheres (\d+), cones (\d+), polygons (\d+)\)", text)
want = dict(zip(("objects", "spheres", "cones", "polygons"), map(int, m.groups())))
want["lights"] = int(re.search(r"lights: (\d+)", text).group(1))
for j in (g, i):
    for k, v in want.items():
        assert j["scene"][k] == v, (k, j["scene"][k], v)
b = [float(x) for x in re.search(r"bounds: (.*)", text).group(1).split()]
got = i["scene"]["bounds"][0] + i["scene"]["bounds"][1]
assert all(abs(x - y) <= 1e-5 * max(1, abs(y)) for x, y in zip(got, b)), (got, b)
assert i["scene"]["camera"] is True, i
PY
# A generator's default size is reported as the size it used.
"$V" gen balls --stats b.json > /dev/null && grep -q '"size": 4' b.json || fail "balls: size not 4"
"$V" gen spheres --count 20 --stats s.json > /dev/null &&
  grep -q '"count": 20, "cluster": 0, "seed": 1' s.json || { cat s.json; fail "spheres' parameters"; }

# Failures: no stats with a scene not written, no scene with stats not written.
"$V" gen balls --stats f1.json > /dev/full 2> err.txt
[ $? -eq 1 ] && [ ! -e f1.json ] || fail "gen > /dev/full: status or stats written"
[ "$(grep -c 'cannot write to standard output' err.txt)" -eq 1 ] || { cat err.txt; fail "gen > /dev/full: message"; }
"$V" gen balls -o f2.nff --stats /dev/full 2> err.txt
[ $? -eq 1 ] && [ ! -e f2.nff ] || fail "gen --stats /dev/full: status or the scene written"
"$V" gen balls -o f3.nff --stats nodir/f.json 2> err.txt
[ $? -eq 1 ] && [ ! -e f3.nff ] && grep -q 'nodir' err.txt || fail "gen --stats nodir/: before generating"
"$V" gen balls -o f4.nff --stats f4.nff 2> err.txt
[ $? -eq 2 ] && [ ! -e f4.nff ] || fail "gen: -o and --stats one file"
"$V" info t.nff --stats /dev/full > out.txt 2> err.txt
[ $? -eq 1 ] && grep -q '/dev/full' err.txt || fail "info --stats /dev/full"
"$V" info t.nff --stats f5.json > /dev/full 2> /dev/null
[ $? -eq 1 ] && [ ! -e f5.json ] || fail "info > /dev/full: status or stats written"
cp t.nff keep.nff
"$V" info t.nff --stats t.nff > /dev/null 2> err.txt
[ $? -eq 2 ] && cmp -s t.nff keep.nff || fail "info --stats over its scene"
cp "$D/cube.obj" "$D/cube.mtl" .
"$V" info cube.obj --stats cube.mtl > /dev/null 2> err.txt
[ $? -eq 2 ] && cmp -s cube.mtl "$D/cube.mtl" || { cat err.txt; fail "info --stats over its library"; }
"$V" info cube.obj --stats "" > /dev/null 2> err.txt
[ $? -eq 2 ] || fail "info --stats '': not a usage error"
"$V" info missing.nff --stats m.json > /dev/null 2> err.txt
[ $? -eq 2 ] && [ ! -e m.json ] || fail "info missing.nff: status or stats written"
echo ok
