#!/bin/sh
# two_hosts.sh - two "machines" on one box: two network namespaces joined by a veth
# pair with their own addresses, one MPI process in each, talking over TCP only.
# mpirun runs in the first namespace; Open MPI's rsh launcher reaches the second through
# an agent script that runs the daemon inside that namespace (with its own host name).
# The example module must give the threads engine's answer, and the ray tracer (when
# built, given a scene) the threads engine's image bit for bit. Exit 77 (ctest SKIP) where
# namespaces cannot be made or entered (not root, no CAP_NET_ADMIN, no iproute2, a chroot).
# usage: two_hosts.sh VWALLS MPIEXEC [SCENE.nff]
vwalls=$1 mpiexec=$2 scene=$3
skip() { echo "two_hosts.sh: SKIP: $*"; exit 77; }
command -v ip >/dev/null 2>&1 || skip "no 'ip' command (iproute2)"
command -v unshare >/dev/null 2>&1 || skip "no 'unshare' command"
id=$$
nsa=vwA$id nsb=vwB$id
a=10.231.$((id % 200)).1 b=10.231.$((id % 200)).2 net=10.231.$((id % 200)).0/24
dir=$(mktemp -d)
cleanup() {
    ip netns del "$nsa" 2>/dev/null
    ip netns del "$nsb" 2>/dev/null
    rm -rf "$dir"
}
trap cleanup EXIT INT TERM
ip netns add "$nsa" 2>/dev/null || skip "cannot create network namespaces (need root / CAP_NET_ADMIN)"
ip netns add "$nsb" || skip "cannot create a second namespace"
# Entering one remounts /sys there, which fails where / is no mount point (a plain
# chroot): the namespaces exist but no process can run in them.
ip netns exec "$nsa" true 2>/dev/null || skip "cannot run a process in a network namespace (ip netns exec)"
ip link add "va$id" type veth peer name "vb$id" || skip "cannot create a veth pair"
ip link set "va$id" netns "$nsa" && ip link set "vb$id" netns "$nsb" || exit 1
ip -n "$nsa" addr add "$a/24" dev "va$id" && ip -n "$nsa" link set "va$id" up && ip -n "$nsa" link set lo up || exit 1
ip -n "$nsb" addr add "$b/24" dev "vb$id" && ip -n "$nsb" link set "vb$id" up && ip -n "$nsb" link set lo up || exit 1
if command -v ping >/dev/null 2>&1 && ! ip netns exec "$nsa" ping -c 1 -W 2 "$b" >/dev/null 2>&1; then
    echo "two_hosts.sh: (ping $a -> $b failed; trying anyway)"
fi

# The launcher agent: like ssh, it gets the host then the command words for a shell.
cat >"$dir/agent.sh" <<AGENT
#!/bin/sh
host=\$1; shift
case \$host in
$a) ns=$nsa name=vwhosta ;;
$b) ns=$nsb name=vwhostb ;;
*) echo "agent: unknown host \$host" >&2; exit 1 ;;
esac
exec ip netns exec \$ns unshare --uts sh -c "hostname \$name; \$*"
AGENT
chmod +x "$dir/agent.sh"
printf '%s slots=1\n%s slots=1\n' "$a" "$b" >"$dir/hosts"

launch() {
    ip netns exec "$nsa" timeout 120 "$mpiexec" -np 2 --hostfile "$dir/hosts" --map-by node \
        --mca btl tcp,self --mca btl_tcp_if_include "$net" --mca oob_tcp_if_include "$net" \
        --mca plm_rsh_agent "$dir/agent.sh" --mca plm_rsh_no_tree_spawn 1 \
        -x OMPI_ALLOW_RUN_AS_ROOT -x OMPI_ALLOW_RUN_AS_ROOT_CONFIRM -x PATH "$@"
}
args="example-pairs --spheres 4000 --radius 0.03 --seed 3 --cells 2x2x2 --workers 2"
# shellcheck disable=SC2086
want=$("$vwalls" $args --quiet) || exit 1
# shellcheck disable=SC2086
got=$(launch "$vwalls" $args --stats "$dir/s.json" --quiet 2>"$dir/err")
rc=$?
cat "$dir/err"
echo "two_hosts.sh: threads engine: $want; two hosts ($a, $b): $got (status $rc)"
[ $rc -eq 0 ] || exit 1
[ "$want" = "$got" ] || { echo "two_hosts.sh: FAIL: results differ"; exit 1; }
grep -q '"processes": 2' "$dir/s.json" || { echo "two_hosts.sh: FAIL: not 2 processes"; exit 1; }
grep -o '"messages": {[^}]*}' "$dir/s.json"
grep -Eq '"remote_bytes": [1-9]' "$dir/s.json" || { echo "two_hosts.sh: FAIL: nothing crossed"; exit 1; }
if [ -n "$scene" ] && "$vwalls" render --help >/dev/null 2>&1; then
    ropts="--size 160x120 --cells 2x2x2 --workers 2 --quiet"
    # shellcheck disable=SC2086
    "$vwalls" render "$scene" -o "$dir/threads.png" $ropts || exit 1
    # shellcheck disable=SC2086
    launch "$vwalls" render "$scene" -o "$dir/hosts.png" $ropts || exit 1
    cmp "$dir/threads.png" "$dir/hosts.png" || { echo "two_hosts.sh: FAIL: images differ"; exit 1; }
    echo "two_hosts.sh: render of $scene identical on two hosts"
fi
exit 0
