/* tools/cmd_gen.c - "vwalls gen": writes a generated scene (balls, rings, tree,
 * spheres, cornell, room) as NFF to stdout or, atomically, to a file.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "vwalls/gen.h"

static void gen_usage(FILE *f)
{
    fprintf(f,
            "usage: vwalls gen balls|rings|tree|spheres|cornell|room [options]\n"
            "\n"
            "Writes a generated scene as NFF (to stdout unless -o is given).\n"
            "  balls    Haines' sphereflake: 1+9+...+9^size spheres (size 4: 7381), ground, 3 lights\n"
            "  rings    a pyramid of chain-mail rings of spheres and cylinders (size: layers, 5)\n"
            "  tree     a recursive tree of cones with sphere joints and leaves (size: depth, 6)\n"
            "  spheres  --count random non-overlapping spheres in a box; --cluster F of them\n"
            "           in one sub-region (the paper's 50%%/100%% clustered load cases): the\n"
            "           box is [0,10]^3, the region [1.25,3.75]^3 in one octant of it (render\n"
            "           --world 0,0,0,10,10,10 cuts the box, not the spheres' bounds)\n"
            "  cornell  the Cornell box as polygons, with an emitting light (for radiosity)\n"
            "  room     a furnished room (table, chairs, shelf) with one ceiling light\n"
            "\noptions:\n"
            "  --size N          size or depth of balls, rings, tree (default per scene;\n"
            "                    at most 7 for balls, 120 for rings, 13 for tree)\n"
            "  --count N         number of spheres for 'spheres', at most 20000000\n"
            "                    (default 1000)\n"
            "  --seed S          random seed of spheres and tree, 0 to 2^64-1 in decimal\n"
            "                    (default 1); the same seed gives the same scene\n"
            "  --cluster F       fraction of spheres in the cluster region, 0..1 (default 0)\n"
            "                    (an option the scene has no use for is an error)\n"
            "  --resolution WxH  camera resolution (default 512x512)\n"
            "  -o, --output FILE write to FILE, a .nff name (atomically), instead of stdout;\n"
            "                    under mpirun the first process alone writes it\n"
            "  --stats FILE      the stats JSON: the generator, its parameters, the scene's\n"
            "                    counts and bounds, the time taken\n"
            "  --help            this text\n"
            "\nexit status: 0 success, 2 bad input or usage, 1 any other failure\n");
}

/* The stats JSON up to its times: the generator and the parameters it used (those it
   takes: --size of balls, rings, tree; --count and --cluster of spheres; --seed of
   spheres and tree), then the scene's counts and bounds. 0 when out of memory. */
static int gen_stats(char **buf, size_t *len, size_t *cap, const char *name,
                     const vw_gen_params *p, const vw_scene *s, int sized, int seeded, int random)
{
    char n[32];
    int ok = vw_cli_stats_begin(buf, len, cap, "gen", 1);
    ok = ok && vw_cli_appendf(buf, len, cap, ",\n  \"scene\": {\"generator\": ");
    ok = ok && vw_cli_json_string(buf, len, cap, name);
    if (sized)
        ok = ok && vw_cli_appendf(buf, len, cap, ", \"size\": %d",
                                  p->size ? p->size : vw_gen_default_size(name));
    if (random)
        ok = ok && vw_cli_appendf(buf, len, cap, ", \"count\": %d, \"cluster\": %s",
                                  p->count ? p->count : 1000, vw_cli_json_number(p->cluster, n));
    if (seeded)
        ok = ok && vw_cli_appendf(buf, len, cap, ", \"seed\": %llu", (unsigned long long)p->seed);
    ok = ok && vw_cli_appendf(buf, len, cap, ", ");
    ok = ok && vw_cli_scene_json(buf, len, cap, s);
    return ok && vw_cli_appendf(buf, len, cap, "}");
}

int vw_cmd_gen(int argc, char **argv)
{
    const char *cmd = "gen", *name = NULL, *out = NULL, *stats = NULL, *v;
    double t0 = vw_cli_now();
    int seed_given = 0, cluster_given = 0;
    vw_gen_params p;
    vw_gen_params_init(&p);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        long n;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            gen_usage(stdout);
            return VW_EXIT_OK;
        } else if (!strcmp(a, "--size")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) || vw_cli_int(cmd, a, v, 1, 1000, &n))
                return VW_EXIT_USAGE;
            p.size = (int)n;
        } else if (!strcmp(a, "--count")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) ||
                vw_cli_int(cmd, a, v, 1, 20000000, &n))
                return VW_EXIT_USAGE;
            p.count = (int)n;
        } else if (!strcmp(a, "--seed")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)))
                return VW_EXIT_USAGE;
            /* Decimal digits only: strtoull alone also takes leading blanks, a sign
               (" -1" wrapped to 2^64-1) and, base 0, hex and octal ("010" was 8). */
            char *end;
            errno = 0;
            unsigned long long s = strtoull(v, &end, 10);
            if (!*v || v[strspn(v, "0123456789")] || errno) {
                vw_cli_error(cmd, "%s: bad value '%s' (expected a whole number from 0 to "
                                  "18446744073709551615)", a, v);
                return VW_EXIT_USAGE;
            }
            p.seed = (uint64_t)s;
            seed_given = 1;
        } else if (!strcmp(a, "--cluster")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) ||
                vw_cli_double(cmd, a, v, 0.0, 1.0, &p.cluster))
                return VW_EXIT_USAGE;
            cluster_given = 1;
        } else if (!strcmp(a, "--resolution")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) ||
                vw_cli_size(cmd, a, v, &p.width, &p.height))
                return VW_EXIT_USAGE;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            if (!(out = vw_cli_output(cmd, argc, argv, &i)))
                return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--stats")) {
            if (!(stats = vw_cli_output(cmd, argc, argv, &i)))
                return VW_EXIT_USAGE;
        } else if (a[0] == '-' && a[1]) {
            vw_cli_error(cmd, "unknown option '%s' (try vwalls gen --help)", a);
            return VW_EXIT_USAGE;
        } else if (name) {
            vw_cli_error(cmd, "unexpected argument '%s' (one scene name only)", a);
            return VW_EXIT_USAGE;
        } else {
            name = a;
        }
    }
    /* vwalls reads a scene file by its name's ending: NFF written as x.obj would be
       read back as OBJ and fail at its second line. */
    if (out && vw_cli_scene_output(cmd, "-o", out, ".nff", "NFF")) return VW_EXIT_USAGE;
    if (!name) {
        vw_cli_error(cmd, "which scene? balls, rings, tree, spheres, cornell or room "
                          "(try vwalls gen --help)");
        return VW_EXIT_USAGE;
    }
    /* An unknown name first: "gen random --count 5" is not a misplaced --count. */
    size_t k = 0;
    while (vw_gen_name(k) && strcmp(vw_gen_name(k), name)) k++;
    if (!vw_gen_name(k)) {
        vw_cli_error(cmd, "unknown generator '%s' (balls, rings, tree, spheres, cornell, "
                          "room)", name);
        return VW_EXIT_USAGE;
    }
    /* An option the scene has no use for is a mistake, not a no-op. */
    int sized = !strcmp(name, "balls") || !strcmp(name, "rings") || !strcmp(name, "tree");
    int random = !strcmp(name, "spheres");
    int seeded = random || !strcmp(name, "tree");
    const char *unused = p.size && !sized ? "--size" : p.count && !random ? "--count"
                       : cluster_given && !random ? "--cluster"
                       : seed_given && !seeded ? "--seed" : NULL;
    if (unused) {
        vw_cli_error(cmd, "%s: '%s' takes no such option (--size: balls, rings, tree; "
                          "--count, --cluster: spheres; --seed: spheres, tree)", unused, name);
        return VW_EXIT_USAGE;
    }
    if (out || stats) { /* before generating: a big scene was made, then not written */
        const char *opts[] = {"-o", "--stats"}, *paths[] = {out, stats};
        int rc = vw_cli_check_outputs(cmd, opts, paths, 2);
        if (rc != VW_EXIT_OK) return rc;
    }
    char err[512] = "";
    vw_scene *s;
    vw_status st = vw_gen(name, &p, &s, err, sizeof err);
    if (st != VW_OK) {
        vw_cli_error(cmd, "%s", err);
        return st == VW_E_INVAL || st == VW_E_LIMIT ? VW_EXIT_USAGE : VW_EXIT_FAIL;
    }
    double t1 = vw_cli_now();
    /* The stats are made before the scene is written, so that running out of memory
       for them leaves no scene file either. */
    char *json = NULL;
    size_t jl = 0, jc = 0;
    if (stats && !gen_stats(&json, &jl, &jc, name, &p, s, sized, seeded, random)) {
        vw_cli_error(cmd, "out of memory for the stats");
        vw_scene_free(s);
        free(json);
        return VW_EXIT_FAIL;
    }
    /* The scene and the stats appear together or not at all (vw_outfile_hold). */
    int held = out && stats && vw_cli_is_output();
    if (held) vw_outfile_hold();
    if (out) {
        /* Under mpirun only the output process writes the file, as every command writes
           its outputs (the others wrote the same bytes over it); all exit with its status
           (vw_cli_job_status). */
        st = vw_cli_is_output() ? vw_scene_write_nff_file(s, out, err, sizeof err) : VW_OK;
    } else {
        st = vw_scene_write_nff(s, stdout);
        snprintf(err, sizeof err, "cannot write to standard output");
        /* main reports a failed standard output (and says why); with --stats it must
           be known here, or the stats would tell of a scene that was not written. */
        if (stats) fflush(stdout);
        if (ferror(stdout)) st = VW_E_IO, err[0] = 0;
    }
    vw_scene_free(s);
    int rc = VW_EXIT_OK;
    if (st != VW_OK) {
        if (err[0]) vw_cli_error(cmd, "%s", err);
        rc = VW_EXIT_FAIL;
    } else if (stats) {
        const char *names[] = {"generate", "write"};
        double secs[] = {t1 - t0, vw_cli_now() - t1};
        rc = vw_cli_stats_end(cmd, stats, &json, &jl, &jc, t0, names, secs, 2);
    }
    if (held && vw_outfile_release(rc == VW_EXIT_OK, err, sizeof err) != VW_OK && rc == VW_EXIT_OK) {
        vw_cli_error(cmd, "%s", err);
        rc = VW_EXIT_FAIL;
    }
    free(json);
    return rc;
}
