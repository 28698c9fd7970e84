/* host.c - what the host gives this process: the cores it may run on (the default
 * worker count) and the memory it has left (what a solve may allocate).
 *
 * Besides the CPU affinity and /proc/meminfo, a container or a batch system says it with
 * control groups: a CPU quota (cgroup v2 cpu.max, v1 cpu.cfs_quota_us over
 * cpu.cfs_period_us) and a memory limit (v2 memory.max, v1 memory.limit_in_bytes), set
 * on the process's own group or on any group above it. The tightest of them holds, so
 * every group from the process's own up to the hierarchy's mount is read.
 *
 * The process's group is its path in /proc/self/cgroup, relative to the root of the
 * hierarchy's mount in /proc/self/mountinfo: a container without a cgroup namespace
 * sees its group as "/docker/ID" and has that group mounted at /sys/fs/cgroup; one with
 * a namespace sees "/" and the same mount. Both v2 and v1 hierarchies are read, so a
 * hybrid host (v1 controllers beside an empty v2 tree) counts too.
 *
 * Every file name is read under a root prefix (vw__host_probe), so a test can lay out a
 * host's /proc and /sys in a directory.
 */
#include <math.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <unistd.h>

#include "core/world_internal.h"
#include "vwalls/engine.h"

enum { HOST_PATH = 4096 };

/* Undoes mountinfo's octal escapes (a space is \040) in place. */
static void unescape(char *s)
{
    char *o = s;
    for (char *p = s; *p; p++) {
        if (p[0] == '\\' && p[1] >= '0' && p[1] <= '3' && p[2] >= '0' && p[2] <= '7' &&
            p[3] >= '0' && p[3] <= '7') {
            *o++ = (char)((p[1] - '0') * 64 + (p[2] - '0') * 8 + (p[3] - '0'));
            p += 3;
        } else {
            *o++ = *p;
        }
    }
    *o = 0;
}

/* Whether the comma-separated list has the item. */
static int has_item(const char *list, const char *item)
{
    size_t n = strlen(item);
    for (const char *p = list; p && *p;) {
        const char *e = strchr(p, ',');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        if (len == n && !strncmp(p, item, n)) return 1;
        p = e ? e + 1 : NULL;
    }
    return 0;
}

/* Up to len - 1 bytes of the file at path, NUL-terminated; 0 when it cannot be read.
   (No stdio: a probe reads a dozen small files, and their syscalls are its cost.) */
static int slurp(const char *path, char *buf, size_t len)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return 0;
    size_t n = 0;
    ssize_t r;
    while (n + 1 < len && (r = read(fd, buf + n, len - 1 - n)) > 0) n += (size_t)r;
    close(fd);
    buf[n] = 0;
    return n > 0;
}

/* What the process's control groups are: /proc/self/cgroup and /proc/self/mountinfo,
   read once per probe. */
typedef struct host_groups {
    char cgroup[16384], mountinfo[1 << 18]; /* (a host with many mounts lists many) */
} host_groups;

/* Copies the next line of *p (without its newline, cut to len - 1 bytes) to line and
   moves *p past it; 0 at the end. */
static int next_line(const char **p, char *line, size_t len)
{
    if (!**p) return 0;
    size_t n = strcspn(*p, "\n");
    size_t k = n < len - 1 ? n : len - 1;
    memcpy(line, *p, k);
    line[k] = 0;
    *p += n + ((*p)[n] == '\n');
    return 1;
}

/* The process's group of controller `ctrl` (NULL: the v2 hierarchy) as a directory under
   root: `dir`, and `top`, its hierarchy's mount, where the walk up stops. 0 when the
   process has no such group or it is not mounted. */
static int cgroup_dir(const host_groups *g, const char *root, const char *ctrl, char *dir, char *top)
{
    char line[HOST_PATH], group[HOST_PATH] = "";
    int found = 0;
    /* "ID:CONTROLLERS:PATH"; v2's line is "0::PATH". */
    for (const char *p = g->cgroup; !found && next_line(&p, line, sizeof line);) {
        char *c1 = strchr(line, ':'), *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
        if (!c2) continue;
        *c1 = *c2 = 0;
        const char *ctrls = c1 + 1;
        if (ctrl ? has_item(ctrls, ctrl) : (!strcmp(line, "0") && !*ctrls)) {
            snprintf(group, sizeof group, "%s", c2 + 1);
            found = 1;
        }
    }
    if (!found) return 0;

    found = 0;
    /* "ID PARENT MAJ:MIN ROOT MOUNTPOINT OPTIONS [TAGS] - FSTYPE SOURCE SUPEROPTIONS" */
    for (const char *p = g->mountinfo; !found && next_line(&p, line, sizeof line);) {
        char *dash = strstr(line, " - ");
        if (!dash) continue;
        *dash = 0;
        char mroot[HOST_PATH], mpoint[HOST_PATH], fstype[64], source[HOST_PATH],
            opts[HOST_PATH] = "";
        if (sscanf(line, "%*s %*s %*s %4095s %4095s", mroot, mpoint) != 2) continue;
        if (sscanf(dash + 3, "%63s %4095s %4095s", fstype, source, opts) < 2) continue;
        if (ctrl ? strcmp(fstype, "cgroup") || !has_item(opts, ctrl) : !!strcmp(fstype, "cgroup2"))
            continue;
        unescape(mroot);
        unescape(mpoint);
        /* The group's path below the mount's root; a group outside what the mount shows
           is read at the mount itself. */
        size_t n = strlen(mroot);
        const char *rel = group;
        if (!strcmp(mroot, "/"))
            rel = group;
        else if (!strncmp(group, mroot, n) && (group[n] == '/' || !group[n]))
            rel = group + n;
        else
            rel = "";
        snprintf(top, HOST_PATH, "%s%s", root, mpoint);
        snprintf(dir, HOST_PATH, "%s%s", top, rel);
        /* (no trailing slash: the walk up cuts at the last one) */
        size_t d = strlen(dir);
        while (d > strlen(top) && dir[d - 1] == '/') dir[--d] = 0;
        found = 1;
    }
    return found;
}

/* The first line of dir/name, or 0 when it cannot be read. */
static int read_line(const char *dir, const char *name, char *buf, size_t len)
{
    char path[HOST_PATH + 64];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return slurp(path, buf, len);
}

/* Calls fn(dir, user) for the group directory and each one above it up to the mount. */
static void walk_up(char *dir, const char *top, void (*fn)(const char *dir, void *user), void *user)
{
    size_t ntop = strlen(top);
    for (;;) {
        fn(dir, user);
        size_t n = strlen(dir);
        if (n <= ntop) return;
        char *slash = strrchr(dir + ntop, '/');
        if (!slash) return;
        *slash = 0;
    }
}

/* ---- CPU quota ------------------------------------------------------------------------ */

static void cpu_v2(const char *dir, void *user)
{
    double *cores = user;
    char buf[128];
    long long quota, period;
    if (read_line(dir, "cpu.max", buf, sizeof buf) && sscanf(buf, "%lld %lld", &quota, &period) == 2 &&
        quota > 0 && period > 0 && (*cores == 0 || (double)quota / (double)period < *cores))
        *cores = (double)quota / (double)period;
}

static void cpu_v1(const char *dir, void *user)
{
    double *cores = user;
    char q[64], p[64];
    long long quota, period;
    if (read_line(dir, "cpu.cfs_quota_us", q, sizeof q) && read_line(dir, "cpu.cfs_period_us", p, sizeof p) &&
        sscanf(q, "%lld", &quota) == 1 && sscanf(p, "%lld", &period) == 1 && quota > 0 && period > 0 &&
        (*cores == 0 || (double)quota / (double)period < *cores))
        *cores = (double)quota / (double)period;
}

/* ---- memory limit --------------------------------------------------------------------- */

/* The least room left under a limit, 0 while none is seen. */
static void mem_left(const char *dir, const char *max_name, const char *cur_name, uint64_t *left)
{
    char m[64], c[64];
    unsigned long long max, cur;
    /* v2 says "max" for no limit, v1 a number near 2^63. */
    if (!read_line(dir, max_name, m, sizeof m) || sscanf(m, "%llu", &max) != 1 ||
        max >= (uint64_t)1 << 60)
        return;
    if (!read_line(dir, cur_name, c, sizeof c) || sscanf(c, "%llu", &cur) != 1) cur = 0;
    uint64_t room = max > cur ? max - cur : 1; /* (1: full, yet known) */
    if (*left == 0 || room < *left) *left = room;
}
static void mem_v2(const char *dir, void *user) { mem_left(dir, "memory.max", "memory.current", user); }
static void mem_v1(const char *dir, void *user)
{
    mem_left(dir, "memory.limit_in_bytes", "memory.usage_in_bytes", user);
}

void vw__host_probe(const char *root, double *quota_cores, uint64_t *cgroup_mem, uint64_t *meminfo_mem)
{
    static const char *const ctrl[2] = {"cpu", "memory"};
    void (*const v2[2])(const char *, void *) = {cpu_v2, mem_v2};
    void (*const v1[2])(const char *, void *) = {cpu_v1, mem_v1};
    void *out[2] = {quota_cores, cgroup_mem};
    if (quota_cores) *quota_cores = 0;
    if (cgroup_mem) *cgroup_mem = 0;
    if (meminfo_mem) *meminfo_mem = 0;
    host_groups *g = malloc(sizeof *g);
    char dir[HOST_PATH], top[HOST_PATH], path[HOST_PATH];
    snprintf(path, sizeof path, "%s/proc/self/cgroup", root);
    if (g && slurp(path, g->cgroup, sizeof g->cgroup)) {
        snprintf(path, sizeof path, "%s/proc/self/mountinfo", root);
        if (!slurp(path, g->mountinfo, sizeof g->mountinfo)) g->mountinfo[0] = 0;
        for (int k = 0; k < 2; k++) {
            if (!out[k]) continue;
            if (cgroup_dir(g, root, NULL, dir, top)) walk_up(dir, top, v2[k], out[k]);
            if (cgroup_dir(g, root, ctrl[k], dir, top)) walk_up(dir, top, v1[k], out[k]);
        }
    }
    free(g);
    if (!meminfo_mem) return;
    char info[8192];
    snprintf(path, sizeof path, "%s/proc/meminfo", root);
    const char *m = slurp(path, info, sizeof info) ? strstr(info, "MemAvailable:") : NULL;
    unsigned long long kb;
    if (m && sscanf(m, "MemAvailable: %llu kB", &kb) == 1) *meminfo_mem = (uint64_t)kb * 1024;
}

/* A positive number from the environment, at most max; 0 when unset or bad. */
static uint64_t env_count(const char *name, uint64_t max)
{
    const char *s = getenv(name);
    if (!s || !*s) return 0;
    char *end;
    unsigned long long v = strtoull(s, &end, 10);
    return *end == 0 && v >= 1 && v <= max ? (uint64_t)v : 0;
}

/* The CPU quota in cores, read once (0: none; -1: not read yet): a world asks at its
   creation, and the files take a tenth of a millisecond. The affinity, one system call,
   is read every time: a program may change it between two worlds. */
static _Atomic double probed_quota = -1;

/* Set once the bad VW_CORES was reported: a program makes many worlds. */
static atomic_flag cores_warned = ATOMIC_FLAG_INIT;

int vw_host_cores(void)
{
    uint64_t c = env_count("VW_CORES", 1024);
    if (c) return (int)c;
    /* A value out of range (0, 5000) or not a number ("abc", "-1") is a mistake the
       user should hear of: it used to be ignored without a word. */
    const char *bad = getenv("VW_CORES");
    int n = 0;
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0) n = CPU_COUNT(&set);
    if (n < 1) {
        long m = sysconf(_SC_NPROCESSORS_ONLN);
        n = m < 1 ? 1 : m > 1 << 20 ? 1 << 20 : (int)m;
    }
    double quota = atomic_load(&probed_quota);
    if (quota < 0) {
        vw__host_probe("", &quota, NULL, NULL);
        atomic_store(&probed_quota, quota); /* (two threads that race store the same) */
    }
    /* A quota of 1.5 cores runs two workers: the half core is there to take. */
    if (quota > 0 && ceil(quota) < n) n = (int)ceil(quota);
    if (n < 1) n = 1;
    /* Under MPI the first process alone says it, as it says everything (every process
       reads the same environment from the launcher). */
    if (bad && *bad && vw_engine_rank() == 0 && !atomic_flag_test_and_set(&cores_warned))
        fprintf(stderr, "vwalls: warning: VW_CORES='%s' is not a whole number from 1 to 1024: "
                        "ignored, counting the %d core%s this process may use\n", bad, n,
                n == 1 ? "" : "s");
    return n;
}

int vw__host_cores_given(void) { return env_count("VW_CORES", 1024) != 0; }

uint64_t vw_host_memory(void)
{
    uint64_t env = env_count("VW_MEM_AVAILABLE", UINT64_MAX);
    if (env) return env;
    uint64_t mem, meminfo;
    vw__host_probe("", NULL, &mem, &meminfo);
    return mem && (!meminfo || mem < meminfo) ? mem : meminfo;
}
