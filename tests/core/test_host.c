/* test_host.c - what the host gives the process (host.c): hosts laid out in a directory
 * (their /proc/self/cgroup, /proc/self/mountinfo, /proc/meminfo and cgroup files), each
 * a way a container or batch system says its CPU quota and memory limit: cgroup v2 with
 * and without a namespace, a limit on a group above the process's, cgroup v1 with the
 * controllers mounted together or apart, a group mounted as its hierarchy's root, and a
 * mount point with a space. Then this host itself, and the environment's overrides.
 */
#include <errno.h>
#include <sched.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/world_internal.h"
#include "vw_test.h"
#include "vwalls/engine.h"

static char base[256];

/* Writes text to root/rel, making its directories. */
static void put(const char *root, const char *rel, const char *text)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", root, rel);
    for (char *p = path + strlen(root) + 1; *p; p++)
        if (*p == '/') {
            *p = 0;
            CHECK(mkdir(path, 0755) == 0 || errno == EEXIST);
            *p = '/';
        }
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    fputs(text, f);
    CHECK(fclose(f) == 0);
}

/* A group's two files of one kind: its limit and its usage (memory), or its quota and
   period (v1 CPU), each value a line. */
static void put2(const char *root, const char *dir, const char *kind, const char *v1, const char *v2)
{
    static const char *const names[][2] = {{"memory.limit_in_bytes", "memory.usage_in_bytes"},
                                           {"memory.max", "memory.current"},
                                           {"cpu.cfs_quota_us", "cpu.cfs_period_us"}};
    int k = !strcmp(kind, "v1 memory") ? 0 : !strcmp(kind, "v2 memory") ? 1 : 2;
    const char *v[2] = {v1, v2};
    for (int i = 0; i < 2; i++) {
        char rel[512], line[64];
        snprintf(rel, sizeof rel, "%s/%s", dir, names[k][i]);
        snprintf(line, sizeof line, "%s\n", v[i]);
        put(root, rel, line);
    }
}

/* A fresh host directory named `name`. */
static const char *host(const char *name)
{
    static char root[512];
    snprintf(root, sizeof root, "%s/%s", base, name);
    CHECK(mkdir(root, 0755) == 0);
    return root;
}

static void probe(const char *root, double *q, uint64_t *mem, uint64_t *meminfo)
{
    vw__host_probe(root, q, mem, meminfo);
    printf("%s: quota %g cores, cgroup memory %llu, MemAvailable %llu\n", root + strlen(base) + 1, *q,
           (unsigned long long)*mem, (unsigned long long)*meminfo);
}

#define V2_MOUNT "30 23 0:26 / /sys/fs/cgroup rw,nosuid - cgroup2 cgroup2 rw,nsdelegate\n"

int main(void)
{
    snprintf(base, sizeof base, "/tmp/vw_test_host.XXXXXX");
    CHECK(mkdtemp(base) != NULL);
    double q;
    uint64_t mem, mi;

    /* cgroup v2 in a container with a cgroup namespace: its group is the mount's root. */
    const char *r = host("v2-namespace");
    put(r, "proc/self/cgroup", "0::/\n");
    put(r, "proc/self/mountinfo", "22 1 0:21 / / rw - overlay overlay rw\n" V2_MOUNT);
    put(r, "proc/meminfo", "MemTotal: 4000 kB\nMemFree: 100 kB\nMemAvailable: 2000 kB\n");
    put(r, "sys/fs/cgroup/cpu.max", "150000 100000\n");
    put2(r, "sys/fs/cgroup", "v2 memory", "1000000", "400000");
    probe(r, &q, &mem, &mi);
    CHECK_NEAR(q, 1.5, 1e-12);
    CHECK_EQ_INT(mem, 600000);
    CHECK_EQ_INT(mi, 2000 * 1024);

    /* cgroup v2, a batch job's group below a limited one: the tightest limit on the way
       up holds, whichever level sets it; "max" is no limit. */
    r = host("v2-nested");
    put(r, "proc/self/cgroup", "0::/batch/job7\n");
    put(r, "proc/self/mountinfo", V2_MOUNT);
    put(r, "sys/fs/cgroup/batch/job7/cpu.max", "max 100000\n");
    put(r, "sys/fs/cgroup/batch/cpu.max", "50000 100000\n");
    put(r, "sys/fs/cgroup/cpu.max", "400000 100000\n");
    put2(r, "sys/fs/cgroup/batch/job7", "v2 memory", "max", "7000");
    put2(r, "sys/fs/cgroup/batch", "v2 memory", "5000000", "1000000");
    probe(r, &q, &mem, &mi);
    CHECK_NEAR(q, 0.5, 1e-12);
    CHECK_EQ_INT(mem, 4000000);
    CHECK_EQ_INT(mi, 0); /* no /proc/meminfo */

    /* cgroup v1 as on this project's build machines: cpu and cpuacct mounted together,
       the memory group nested, its parent limited, its own limit v1's "none" (a number
       near 2^63), and no CPU quota (-1). */
    r = host("v1-nested");
    put(r, "proc/self/cgroup", "5:pids:/\n4:memory:/process_api/abc\n2:cpu,cpuacct:/\n0::/\n");
    put(r, "proc/self/mountinfo",
        "31 23 0:28 / /sys/fs/cgroup rw,relatime - tmpfs tmpfs rw,mode=755\n"
        "32 31 0:29 / /sys/fs/cgroup/cpu,cpuacct rw,relatime - cgroup cgroup rw,cpu,cpuacct\n"
        "35 31 0:32 / /sys/fs/cgroup/memory rw,relatime - cgroup cgroup rw,memory\n"
        "41 31 0:38 / /sys/fs/cgroup/unified rw,relatime - cgroup2 cgroup2 rw\n");
    put2(r, "sys/fs/cgroup/cpu,cpuacct", "v1 cpu", "-1", "100000");
    put2(r, "sys/fs/cgroup/memory/process_api/abc", "v1 memory", "9223372036854771712", "1000");
    put2(r, "sys/fs/cgroup/memory/process_api", "v1 memory", "3000000", "1000000");
    put2(r, "sys/fs/cgroup/memory", "v1 memory", "9223372036854771712", "99999999");
    probe(r, &q, &mem, &mi);
    CHECK_NEAR(q, 0, 0);
    CHECK_EQ_INT(mem, 2000000);

    /* cgroup v1 in a container without a namespace: /proc/self/cgroup names the host's
       groups, the container's mounted as the hierarchy's root: the process's group
       (memory) lies below it, the quota is set on the container's. A group full to its
       limit leaves 1 byte (known to be full), not 0 (not said). */
    r = host("v1-docker");
    put(r, "proc/self/cgroup", "3:cpu:/docker/xyz\n2:memory:/docker/xyz/task\n");
    put(r, "proc/self/mountinfo",
        "40 31 0:29 /docker/xyz /sys/fs/cgroup/cpu ro,nosuid - cgroup cgroup rw,cpu\n"
        "41 31 0:30 /docker/xyz /sys/fs/cgroup/memory ro,nosuid - cgroup cgroup rw,memory\n");
    put2(r, "sys/fs/cgroup/cpu", "v1 cpu", "250000", "100000");
    put2(r, "sys/fs/cgroup/memory", "v1 memory", "80000", "1000");
    put2(r, "sys/fs/cgroup/memory/task", "v1 memory", "8000", "9000");
    probe(r, &q, &mem, &mi);
    CHECK_NEAR(q, 2.5, 1e-12);
    CHECK_EQ_INT(mem, 1);

    /* A mount point with a space (mountinfo writes it \040). */
    r = host("v2-space");
    put(r, "proc/self/cgroup", "0::/a\n");
    put(r, "proc/self/mountinfo", "30 23 0:26 / /sys/fs/cg\\040root rw - cgroup2 cgroup2 rw\n");
    put(r, "sys/fs/cg root/a/cpu.max", "300000 100000\n");
    probe(r, &q, &mem, &mi);
    CHECK_NEAR(q, 3, 1e-12);

    /* Nothing said: no cgroup files at all. */
    r = host("bare");
    probe(r, &q, &mem, &mi);
    CHECK(q == 0 && mem == 0 && mi == 0);

    /* This host: at least one core, no more than the affinity; some memory. */
    cpu_set_t set;
    CHECK(sched_getaffinity(0, sizeof set, &set) == 0);
    unsetenv("VW_CORES");
    unsetenv("VW_MEM_AVAILABLE");
    int cores = vw_host_cores();
    uint64_t bytes = vw_host_memory();
    vw__host_probe("", &q, &mem, &mi);
    printf("this host: %d cores (affinity %d, quota %g), %llu bytes (cgroup %llu, MemAvailable %llu)\n",
           cores, CPU_COUNT(&set), q, (unsigned long long)bytes, (unsigned long long)mem,
           (unsigned long long)mi);
    CHECK(cores >= 1 && cores <= CPU_COUNT(&set));
    CHECK(bytes > 0); /* (MemAvailable moves between two readings) */
    CHECK_EQ_INT(vw_engine_workers(0), cores);
    /* The affinity is read at every call (a program may change it between worlds). */
    if (CPU_COUNT(&set) > 1) {
        cpu_set_t one;
        CPU_ZERO(&one);
        for (int c = 0; c < CPU_SETSIZE; c++)
            if (CPU_ISSET(c, &set)) {
                CPU_SET(c, &one);
                break;
            }
        CHECK(sched_setaffinity(0, sizeof one, &one) == 0);
        CHECK_EQ_INT(vw_host_cores(), 1);
        CHECK(sched_setaffinity(0, sizeof set, &set) == 0);
        CHECK_EQ_INT(vw_host_cores(), cores);
    }
    /* The overrides, and bad ones ignored. */
    setenv("VW_CORES", "3", 1);
    setenv("VW_MEM_AVAILABLE", "12345", 1);
    CHECK_EQ_INT(vw_host_cores(), 3);
    CHECK_EQ_INT(vw_host_memory(), 12345);
    setenv("VW_CORES", "0", 1);
    setenv("VW_MEM_AVAILABLE", "12k", 1);
    CHECK_EQ_INT(vw_host_cores(), cores);
    CHECK(vw_host_memory() > 0 && vw_host_memory() != 12345);

    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", base);
    CHECK(system(cmd) == 0);
    printf("test_host: %d checks passed\n", vw_test_checks);
    return 0;
}
