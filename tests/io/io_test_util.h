/* io_test_util.h - helpers for the io tests: bit-exact scene comparison, writing a
 * scene's NFF to a string, reading a test data file, a file size limit.
 */
#ifndef VW_IO_TEST_UTIL_H
#define VW_IO_TEST_UTIL_H

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <signal.h>
#include <sys/resource.h>

#include "vwalls/scene.h"

/* Limits the size of the files this process writes to `bytes` (as a full disk would
   stop a write), with SIGXFSZ ignored so the write fails with EFBIG instead of killing
   the process; *old gets the limit before, for file_size_restore. 0 on success. */
static inline int file_size_limit(rlim_t bytes, struct rlimit *old)
{
    struct rlimit lim;
    if (getrlimit(RLIMIT_FSIZE, old) != 0) return -1;
    lim = *old;
    lim.rlim_cur = bytes;
    signal(SIGXFSZ, SIG_IGN);
    return setrlimit(RLIMIT_FSIZE, &lim);
}

static inline int file_size_restore(const struct rlimit *old) { return setrlimit(RLIMIT_FSIZE, old); }

/* Bit-exact comparison, field by field (structs may have padding). Prints the first
   difference to stderr. */
static inline int scene_equal(const vw_scene *a, const vw_scene *b)
{
#define DIFF(what)                                                                  \
    do {                                                                            \
        fprintf(stderr, "scenes differ: %s\n", what);                               \
        return 0;                                                                   \
    } while (0)
    const vw_camera *ca = &a->camera, *cb = &b->camera;
    if (memcmp(ca->from, cb->from, sizeof ca->from) || memcmp(ca->at, cb->at, sizeof ca->at) ||
        memcmp(ca->up, cb->up, sizeof ca->up) || memcmp(&ca->angle, &cb->angle, 8) ||
        memcmp(&ca->hither, &cb->hither, 8) || ca->width != cb->width ||
        ca->height != cb->height || ca->valid != cb->valid)
        DIFF("camera");
    if (memcmp(a->background, b->background, sizeof a->background))
        DIFF("background");
    if (a->nlights != b->nlights)
        DIFF("number of lights");
    for (size_t i = 0; i < a->nlights; i++)
        if (memcmp(a->lights[i].pos, b->lights[i].pos, sizeof a->lights[i].pos) ||
            memcmp(a->lights[i].color, b->lights[i].color, sizeof a->lights[i].color))
            DIFF("a light");
    if (a->nmaterials != b->nmaterials)
        DIFF("number of materials");
    /* A material's values, not where it was defined (its file, line and name): a scene
       written out and read back comes from another file, and NFF has no names. */
    for (size_t i = 0; i < a->nmaterials; i++)
        if (memcmp(&a->materials[i], &b->materials[i], offsetof(vw_material, line)))
            DIFF("materials");
    if (a->nspheres != b->nspheres || a->ncones != b->ncones || a->npolygons != b->npolygons)
        DIFF("object counts");
    /* Every field but the line the object came from (a scene written out and read back
       has its objects on other lines), field by field: the records have padding. */
#define SAME_BITS(x, y) (!memcmp(&(x), &(y), sizeof(x)))
    for (size_t i = 0; i < a->nspheres; i++) {
        const vw_sphere *x = &a->spheres[i], *y = &b->spheres[i];
        if (x->id != y->id || x->material != y->material || !SAME_BITS(x->center, y->center) ||
            !SAME_BITS(x->radius, y->radius))
            DIFF("spheres");
    }
    for (size_t i = 0; i < a->ncones; i++) {
        const vw_cone *x = &a->cones[i], *y = &b->cones[i];
        if (x->id != y->id || x->material != y->material || !SAME_BITS(x->base, y->base) ||
            !SAME_BITS(x->base_radius, y->base_radius) || !SAME_BITS(x->apex, y->apex) ||
            !SAME_BITS(x->apex_radius, y->apex_radius))
            DIFF("cones");
    }
    for (size_t i = 0; i < a->npolygons; i++) {
        const vw_polygon *x = &a->polygons[i], *y = &b->polygons[i];
        if (x->id != y->id || x->material != y->material || x->first != y->first ||
            x->count != y->count || x->has_normals != y->has_normals)
            DIFF("polygons");
    }
#undef SAME_BITS
    if (a->nvertices != b->nvertices || a->nindices != b->nindices)
        DIFF("vertex or index counts");
    if (a->nvertices && memcmp(a->vertices, b->vertices, a->nvertices * sizeof *a->vertices))
        DIFF("vertices");
    if (a->nindices && memcmp(a->indices, b->indices, a->nindices * sizeof *a->indices))
        DIFF("indices");
    if (!a->normals != !b->normals)
        DIFF("presence of normals");
    if (a->normals && memcmp(a->normals, b->normals, a->nindices * sizeof *a->normals))
        DIFF("normals");
    return 1;
#undef DIFF
}

/* The scene's NFF as a malloc'd string. */
static inline char *nff_string(const vw_scene *s, size_t *len)
{
    char *buf = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&buf, &n);
    if (!f)
        return NULL;
    if (vw_scene_write_nff(s, f) != VW_OK) {
        fclose(f);
        free(buf);
        return NULL;
    }
    fclose(f);
    if (len)
        *len = n;
    return buf;
}

/* The mesh readers' fuzz targets (OBJ, PLY) end here with the reader's outcome: a
   refusal is one of the readers' statuses and leaves no scene; an accepted mesh indexes
   only its own vertices and its NFF reads back. Frees s; aborts on a violation. */
static inline void fuzz_check_mesh(vw_status st, vw_scene *s)
{
    if (st != VW_OK) {
        if (s || (st != VW_E_INPUT && st != VW_E_NOMEM && st != VW_E_LIMIT))
            abort();
        return;
    }
    double lo[3], hi[3];
    vw_scene_bounds(s, lo, hi);
    for (size_t i = 0; i < s->nindices; i++)
        if (s->indices[i] < 0 || (size_t)s->indices[i] >= s->nvertices)
            abort();
    size_t n = 0;
    char *text = nff_string(s, &n), err[256];
    vw_scene *back = NULL;
    if (!text || vw_scene_read_nff("mesh.nff", text, n, &back, err, sizeof err) != VW_OK) {
        fprintf(stderr, "converted mesh does not read back: %s\n", text ? err : "no NFF");
        abort();
    }
    free(text);
    vw_scene_free(back);
    vw_scene_free(s);
}

static inline char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *buf = NULL;
    size_t n = 0, cap = 0;
    int c;
    while ((c = fgetc(f)) != EOF) {
        if (n + 1 >= cap) {
            cap = cap ? cap * 2 : 4096;
            buf = realloc(buf, cap);
            if (!buf)
                exit(3);
        }
        buf[n++] = (char)c;
    }
    fclose(f);
    if (!buf)
        buf = calloc(1, 1);
    else
        buf[n] = '\0';
    *len = n;
    return buf;
}

#endif
