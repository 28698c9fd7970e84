/* tools/cmd_info.c - "vwalls info": reads a scene and prints its counts, bounds,
 * camera and lights; with --objects one line per object (id, kind, bounds, material),
 * with --materials one line per material (where it was defined, its values, its users)
 * and a warning line for each reflectance the radiosity solver clamps or warns about.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "commands.h"
#include "radiosity/radiosity.h"

static void info_usage(FILE *f)
{
    fprintf(f, "usage: vwalls info SCENE.(nff|obj|ply) [--objects] [--materials] [--stats FILE]\n"
               "\n"
               "Prints what the scene holds: object counts, bounds, camera and lights.\n"
               "  --objects    also one line per object: id, kind, bounds and material\n"
               "  --materials  also one line per material:\n"
               "                 material N: 'NAME' at FILE:LINE used by U (diffuse R G B, ...)\n"
               "               (the name for MTL only; 'at -' when from no file: a default, or\n"
               "               a usemtl name no library defined; U: spheres, cones and polygons\n"
               "               using it), and after it, for a reflectance (diffuse) the\n"
               "               radiosity solver clamps (outside [0, 1]) or warns about (1 or\n"
               "               more in a channel, not emitting), a line\n"
               "                 FILE:LINE: warning: material 'NAME': reflectance R G B ...\n"
               "  --stats FILE the stats JSON: the scene's counts and bounds, the time to\n"
               "               read it\n"
               "  --help       this text\n"
               "\nexit status: 0 success, 2 bad input or usage, 1 any other failure\n");
}

static const char *kind_name(vw_prim_kind k)
{
    return k == VW_PRIM_SPHERE ? "sphere" : k == VW_PRIM_CONE ? "cone" : "polygon";
}

static void print_object(const vw_scene *s, int id)
{
    vw_prim_kind kind;
    size_t i;
    if (vw_scene_find_object(s, id, &kind, &i) != VW_OK)
        return;
    double lo[3], hi[3];
    vw_scene_object_bounds(s, kind, i, lo, hi);
    int m = kind == VW_PRIM_SPHERE ? s->spheres[i].material
          : kind == VW_PRIM_CONE   ? s->cones[i].material : s->polygons[i].material;
    printf("%d %s", id, kind_name(kind));
    if (kind == VW_PRIM_POLYGON)
        printf(" %d vertices%s", s->polygons[i].count,
               s->polygons[i].has_normals ? " with normals" : "");
    printf(" bounds %g %g %g  %g %g %g material %d", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2],
           m);
    if (m >= 0 && (size_t)m < s->nmaterials) {
        const vw_material *t = &s->materials[m];
        printf(" (diffuse %g %g %g, specular %g %g %g, reflect %g %g %g, shine %g, transmit %g, "
               "ior %g", t->diffuse[0], t->diffuse[1], t->diffuse[2], t->specular[0],
               t->specular[1], t->specular[2], t->reflect[0], t->reflect[1], t->reflect[2],
               t->shine, t->transmit, t->ior);
        if (t->emission[0] || t->emission[1] || t->emission[2])
            printf(", emission %g %g %g", t->emission[0], t->emission[1], t->emission[2]);
        printf(")");
    }
    printf("\n");
}

/* A scene's string shown on one line (vw_text_shown): a name bounded as the readers'
   messages and the radiosity solver's warnings show it, a file whole (max 0), since its
   name is how the user finds it. */
static void print_shown(const char *s, size_t max)
{
    char buf[4100];
    fputs(vw_text_shown(s, strlen(s), max, buf, sizeof buf), stdout);
}

/* Where material m was defined, as the radiosity solver's warnings say it: FILE:LINE
   (FILE alone without a line), or the scene's path for one from no file. */
static void print_material_place(const vw_scene *s, const vw_material *t, const char *path)
{
    const char *file = vw_scene_string(s, t->file);
    print_shown(file ? file : path, 0);
    if (file && t->line > 0)
        printf(":%d", t->line);
}

static void print_material_name(const vw_scene *s, const vw_material *t, size_t k)
{
    const char *nm = vw_scene_string(s, t->name);
    if (nm) {
        fputs("material '", stdout);
        print_shown(nm, VW_SHOWN_NAME);
        putchar('\'');
    } else {
        printf("material %zu", k);
    }
}

/* uses[k] += how many spheres, cones and polygons use material k. */
static void count_uses(const vw_scene *s, size_t *uses)
{
    for (size_t i = 0; i < s->nspheres; i++)
        if (s->spheres[i].material >= 0 && (size_t)s->spheres[i].material < s->nmaterials)
            uses[s->spheres[i].material]++;
    for (size_t i = 0; i < s->ncones; i++)
        if (s->cones[i].material >= 0 && (size_t)s->cones[i].material < s->nmaterials)
            uses[s->cones[i].material]++;
    for (size_t i = 0; i < s->npolygons; i++)
        if (s->polygons[i].material >= 0 && (size_t)s->polygons[i].material < s->nmaterials)
            uses[s->polygons[i].material]++;
}

/* One line per material, then its warnings (uses[k] from count_uses). The checks are
   the radiosity solver's own (rad_material, rad_reflects_all), so that this list flags
   what a solve would warn about; the ray tracer clamps no material value (only the
   pixels it writes). Unlike the solve's warnings, a material no object uses is checked
   too: it is still a value in a library someone may use. */
static void print_materials(const vw_scene *s, const char *path, const size_t *uses)
{
    for (size_t k = 0; k < s->nmaterials; k++) {
        const vw_material *t = &s->materials[k];
        const char *nm = vw_scene_string(s, t->name);
        printf("material %zu:", k);
        if (nm) {
            fputs(" '", stdout);
            print_shown(nm, VW_SHOWN_NAME);
            putchar('\'');
        }
        fputs(" at ", stdout);
        if (vw_scene_string(s, t->file))
            print_material_place(s, t, path);
        else
            putchar('-');
        printf(" used by %zu (diffuse %g %g %g, specular %g %g %g, reflect %g %g %g, shine %g, "
               "transmit %g, ior %g, emission %g %g %g)\n",
               uses[k], t->diffuse[0], t->diffuse[1], t->diffuse[2], t->specular[0],
               t->specular[1], t->specular[2], t->reflect[0], t->reflect[1], t->reflect[2],
               t->shine, t->transmit, t->ior, t->emission[0], t->emission[1], t->emission[2]);
        double rho[3], emit[3];
        int clamped = rad_material(t, rho, emit);
        if (clamped) {
            print_material_place(s, t, path);
            fputs(": warning: ", stdout);
            print_material_name(s, t, k);
            printf(": reflectance %g %g %g is outside [0, 1]: the radiosity solver clamps it\n",
                   t->diffuse[0], t->diffuse[1], t->diffuse[2]);
        }
        if (rad_reflects_all(rho) && !(emit[0] + emit[1] + emit[2] > 0)) {
            print_material_place(s, t, path);
            fputs(": warning: ", stdout);
            print_material_name(s, t, k);
            printf(": reflectance %g %g %g is 1 or more in a channel, so it absorbs nothing "
                   "there: a closed scene's radiosity solve may be slow or stall\n",
                   t->diffuse[0], t->diffuse[1], t->diffuse[2]);
        }
    }
}

/* The stats JSON up to its times: the scene file, its counts and bounds, whether it
   gives a camera. 0 when out of memory. */
static int info_stats(char **buf, size_t *len, size_t *cap, const char *path, const vw_scene *s)
{
    int ok = vw_cli_stats_begin(buf, len, cap, "info", 1);
    ok = ok && vw_cli_appendf(buf, len, cap, ",\n  \"scene\": {\"file\": ");
    ok = ok && vw_cli_json_string(buf, len, cap, path);
    ok = ok && vw_cli_appendf(buf, len, cap, ", ");
    ok = ok && vw_cli_scene_json(buf, len, cap, s);
    return ok && vw_cli_appendf(buf, len, cap, ", \"camera\": %s}", s->camera.valid ? "true" : "false");
}

int vw_cmd_info(int argc, char **argv)
{
    const char *cmd = "info", *path = NULL, *stats = NULL;
    double t0 = vw_cli_now();
    int objects = 0, materials = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            info_usage(stdout);
            return VW_EXIT_OK;
        } else if (!strcmp(a, "--objects")) {
            objects = 1;
        } else if (!strcmp(a, "--materials")) {
            materials = 1;
        } else if (!strcmp(a, "--stats")) {
            if (!(stats = vw_cli_output(cmd, argc, argv, &i)))
                return VW_EXIT_USAGE;
        } else if (a[0] == '-' && a[1]) {
            vw_cli_error(cmd, "unknown option '%s' (try vwalls info --help)", a);
            return VW_EXIT_USAGE;
        } else if (path) {
            vw_cli_error(cmd, "unexpected argument '%s' (one scene only)", a);
            return VW_EXIT_USAGE;
        } else {
            path = a;
        }
    }
    if (!path) {
        vw_cli_error(cmd, "which scene? (try vwalls info --help)");
        return VW_EXIT_USAGE;
    }
    const char *opts[] = {"--stats"}, *paths[] = {stats}, *inputs[] = {path, NULL};
    if (stats) {
        int crc = vw_cli_check_files(cmd, inputs, opts, paths, 1);
        if (crc != VW_EXIT_OK) return crc;
    }
    char err[1024] = "";
    vw_scene *s = NULL;
    /* Under MPI every process reads the scene, as every command does; all stop if one
       cannot (a file missing on one host), and the output process says which and why:
       the others' messages are not printed, and it printed the description. */
    vw_status st = vw_engine_agree(vw_scene_read_file(path, &s, err, sizeof err), err, sizeof err);
    if (st != VW_OK) {
        vw_cli_error(cmd, "%s", err);
        vw_scene_free(s);
        return st == VW_E_INPUT || st == VW_E_INVAL ? VW_EXIT_USAGE : VW_EXIT_FAIL;
    }
    double t1 = vw_cli_now();
    if (stats) { /* not over one of its material libraries */
        int crc = vw_cli_check_scene_files(cmd, s, opts, paths, 1);
        if (crc != VW_EXIT_OK) {
            vw_scene_free(s);
            return crc;
        }
    }
    /* The stats are made before anything is printed, as the material uses are. */
    char *json = NULL;
    size_t jl = 0, jc = 0;
    if (stats && !info_stats(&json, &jl, &jc, path, s)) {
        vw_cli_error(cmd, "%s: out of memory", path);
        vw_scene_free(s);
        free(json);
        return VW_EXIT_FAIL;
    }
    /* Counted before anything is printed, so that running out of memory prints nothing. */
    size_t *uses = NULL;
    if (materials) {
        uses = calloc(s->nmaterials ? s->nmaterials : 1, sizeof *uses);
        if (!uses) {
            vw_cli_error(cmd, "%s: out of memory", path);
            vw_scene_free(s);
            free(json);
            return VW_EXIT_FAIL;
        }
        count_uses(s, uses);
    }
    double lo[3], hi[3];
    vw_scene_bounds(s, lo, hi);
    printf("scene: %s\n", path);
    printf("objects: %zu (spheres %zu, cones %zu, polygons %zu)\n", vw_scene_count_objects(s),
           s->nspheres, s->ncones, s->npolygons);
    printf("vertices: %zu\nmaterials: %zu\nlights: %zu\n", s->nvertices, s->nmaterials,
           s->nlights);
    printf("bounds: %g %g %g  %g %g %g\n", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    const vw_camera *c = &s->camera;
    if (c->valid)
        printf("camera: from %g %g %g at %g %g %g up %g %g %g angle %g hither %g "
               "resolution %dx%d\n",
               c->from[0], c->from[1], c->from[2], c->at[0], c->at[1], c->at[2], c->up[0],
               c->up[1], c->up[2], c->angle, c->hither, c->width, c->height);
    else
        printf("camera: none in the file (a default view is used)\n");
    printf("background: %g %g %g\n", s->background[0], s->background[1], s->background[2]);
    for (size_t i = 0; i < s->nlights; i++)
        printf("light %zu: at %g %g %g color %g %g %g\n", i, s->lights[i].pos[0],
               s->lights[i].pos[1], s->lights[i].pos[2], s->lights[i].color[0],
               s->lights[i].color[1], s->lights[i].color[2]);
    if (objects) {
        size_t n = vw_scene_count_objects(s);
        for (size_t id = 0; id < n; id++)
            print_object(s, (int)id);
    }
    if (materials)
        print_materials(s, path, uses);
    free(uses);
    vw_scene_free(s);
    int rc = VW_EXIT_OK; /* a failed write shows at the flush: main checks standard output */
    if (stats) {
        /* After the description has reached standard output (main would report its
           failure, and there must be no stats then). */
        fflush(stdout);
        if (!ferror(stdout)) {
            const char *names[] = {"load"};
            double secs[] = {t1 - t0};
            rc = vw_cli_stats_end(cmd, stats, &json, &jl, &jc, t0, names, secs, 1);
        }
    }
    free(json);
    return rc;
}
