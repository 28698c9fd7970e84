/* tools/cmd_info.c - "vwalls info": reads a scene and prints its counts, bounds,
 * camera and lights; with --objects one line per object (id, kind, bounds, material).
 */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "commands.h"

static void info_usage(FILE *f)
{
    fprintf(f, "usage: vwalls info SCENE.(nff|obj|ply) [--objects]\n"
               "\n"
               "Prints what the scene holds: object counts, bounds, camera and lights.\n"
               "  --objects   also one line per object: id, kind, bounds and material\n"
               "  --help      this text\n"
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

int vw_cmd_info(int argc, char **argv)
{
    const char *cmd = "info", *path = NULL;
    int objects = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            info_usage(stdout);
            return VW_EXIT_OK;
        } else if (!strcmp(a, "--objects")) {
            objects = 1;
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
    vw_scene_free(s);
    return VW_EXIT_OK; /* a failed write shows at the flush: main checks standard output */
}
