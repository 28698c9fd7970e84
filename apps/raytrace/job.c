/* job.c - one whole render: scene -> records, world box and grid decomposition, the
 * world run to quiescence, and the pixel sums turned into images, the load overlay
 * and the ray members of the stats JSON. The command line and the tests drive this.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "raytrace/geometry.h"
#include "raytrace/raytrace.h"

struct rt_job {
    rt_shared sh;
    vw_decomp *decomp;
    vw_world *world;
    int *owner;          /* cell of each pixel's eye ray, -1 = misses (every process:
                            cell_build reads it, see rt_shared.owner) */
    vw_decomp *owner_decomp; /* the decomposition owner[] was computed on */
    int *owner_first, *owner_pixels; /* owner[] by cell (rt_shared.owner_first) */
    int64_t primary;     /* pixels with an owner */
    int ran;
    int farm_copies;     /* the copies made before the objects (rt_params.farm_first) */
};

int rt_job_farm_copies(const rt_job *j) { return j ? j->farm_copies : 0; }

void rt_job_free(rt_job *j)
{
    if (!j) return;
    vw_world_free(j->world); /* (releases the cells' geometry) */
    vw_decomp_free(j->decomp);
    rt_geo_cache_free(j->sh.geo_cache);
    rt_device_free(j->sh.device);
    free(j->sh.lights);
    free(j->sh.accum);
    free(j->sh.eye_worker);
    free(j->sh.hit_cell);
    free(j->owner);
    free(j->owner_first);
    free(j->owner_pixels);
    vw_decomp_free(j->owner_decomp);
    free(j);
}

/* Threads for a serial phase of the process (the pixel map, the 8-bit image): as many
   as it has workers, which are idle then. */
enum { RT_MAX_PARTS = 64 };
static int serial_parts(const rt_job *j)
{
    int n = vw_world_workers(j->world);
    return n < 1 ? 1 : n > RT_MAX_PARTS ? RT_MAX_PARTS : n;
}

/* The pixel-ownership map is made by tiles of RT_TILE x RT_TILE pixels: a tile whose
   four corner rays show that every ray of the tile enters the world through one cell
   (vw_decomp_cone_cell) takes that cell without a walk per pixel, and a tile that lies
   a pixel or more outside the world box's outline on the screen misses it. Only the
   tiles that a wall's or the box's outline crosses walk every pixel: 133 of 4096 on
   the sphereflake at 512x512 on 2x2x2 cells, none on one cell. A walk per pixel took
   5-7 ms there (on two threads), the largest serial phase of the render; by tiles,
   about 1. The map is the same: test_decomp checks the cones, rt_test each cell's
   eye rays against a walk per pixel. */
#define RT_TILE 8

typedef struct owners_map {
    rt_job *j;
    const vw_decomp *d;
    int outline;          /* the world box is in front of the eye: outline[] bounds it */
    double lo[2], hi[2];  /* on the screen, in pixel units (rt_view_project) */
} owners_map;

/* One thread's rows of the pixel-ownership map. */
typedef struct owners_part {
    const owners_map *map;
    int y0, y1;       /* rows [y0, y1) */
    int64_t primary;  /* pixels of these rows with an owner */
} owners_part;

/* The cell of pixel (x, y)'s eye ray by its walk, -1 when it misses the world. */
static int pixel_owner(const owners_map *m, int x, int y)
{
    const rt_view *v = &m->j->sh.view;
    double dir[3];
    vw_segment seg;
    rt_view_ray(v, x, y, dir);
    return vw_decomp_first_segment(m->d, v->eye, dir, 0.0, INFINITY, &seg) ? seg.cell : -1;
}

/* The owner of every pixel of the tile [x0, x1] x [y0, y1], or -2 when they differ or
   that is not sure: ask each pixel. */
static int tile_owner(const owners_map *m, int x0, int y0, int x1, int y1)
{
    /* Pixel x is centred at x + 0.5; a pixel of margin absorbs rounding. */
    if (m->outline && (x1 + 0.5 < m->lo[0] - 1 || x0 + 0.5 > m->hi[0] + 1 ||
                       y1 + 0.5 < m->lo[1] - 1 || y0 + 0.5 > m->hi[1] + 1))
        return -1;
    const rt_view *v = &m->j->sh.view;
    double dirs[4][3];
    rt_view_ray(v, x0, y0, dirs[0]);
    rt_view_ray(v, x1, y0, dirs[1]);
    rt_view_ray(v, x0, y1, dirs[2]);
    rt_view_ray(v, x1, y1, dirs[3]);
    int c = vw_decomp_cone_cell(m->d, v->eye, (const double(*)[3])dirs, 4);
    return c >= 0 ? c : -2;
}

static void owners_rows(int i, void *arg)
{
    owners_part *p = (owners_part *)arg + i;
    const owners_map *m = p->map;
    int w = m->j->sh.view.width, *owner = m->j->owner;
    int64_t primary = 0; /* (not p->primary per pixel: the parts share cache lines) */
    for (int ty = p->y0; ty < p->y1; ty += RT_TILE) {
        int ye = ty + RT_TILE < p->y1 ? ty + RT_TILE : p->y1;
        for (int tx = 0; tx < w; tx += RT_TILE) {
            int xe = tx + RT_TILE < w ? tx + RT_TILE : w;
            int c = tile_owner(m, tx, ty, xe - 1, ye - 1);
            for (int y = ty; y < ye; y++)
                for (int x = tx; x < xe; x++) {
                    int o = c > -2 ? c : pixel_owner(m, x, y);
                    owner[(size_t)y * w + x] = o;
                    primary += o >= 0;
                }
        }
    }
    p->primary = primary;
}

/* The cell owning each pixel's eye ray, by the walk cell_build would do (on the
   world's current decomposition). Computed once per process and decomposition, before
   the cells are built: each cell then picks its pixels from the map instead of walking
   every candidate pixel itself (with the eye beside or inside the world box, every
   cell would walk every pixel). Kept until the walls move. */
static vw_status owners(rt_job *j)
{
    const vw_decomp *d = vw_world_decomp(j->world);
    if (j->owner_decomp && vw_decomp_equal(j->owner_decomp, d)) return VW_OK;
    int w = j->sh.view.width, h = j->sh.view.height;
    j->sh.owner = NULL;
    j->sh.owner_decomp = NULL;
    j->sh.owner_first = j->sh.owner_pixels = NULL;
    vw_decomp_free(j->owner_decomp);
    j->owner_decomp = NULL;
    free(j->owner_first);
    j->owner_first = malloc(((size_t)vw_decomp_cell_count(d) + 1) * sizeof *j->owner_first);
    if (!j->owner_first) return VW_E_NOMEM;
    if (!j->owner) j->owner = malloc((size_t)w * (size_t)h * sizeof *j->owner);
    if (!j->owner_pixels) j->owner_pixels = malloc((size_t)w * (size_t)h * sizeof *j->owner_pixels);
    if (!j->owner || !j->owner_pixels) return VW_E_NOMEM;
    /* A serial phase of every render: the rows are shared among threads. */
    int nparts = serial_parts(j);
    nparts = nparts > h ? h : nparts;
    owners_map map = {j, d, 0, {0, 0}, {0, 0}};
    vw_box world = vw_decomp_world(d);
    map.outline = rt_view_outline(&j->sh.view, &world, d, map.lo, map.hi);
    owners_part part[RT_MAX_PARTS];
    for (int i = 0; i < nparts; i++)
        part[i] = (owners_part){&map, (int)((int64_t)h * i / nparts),
                                (int)((int64_t)h * (i + 1) / nparts), 0};
    vw_parallel(nparts, owners_rows, part);
    j->primary = 0;
    for (int i = 0; i < nparts; i++) j->primary += part[i].primary;
    /* Sorted by cell (a counting sort, which keeps each cell's pixels in order): every
       cell takes its own slice, where each would otherwise scan the whole map. */
    int ncells = vw_decomp_cell_count(d);
    int *first = j->owner_first;
    size_t npix = (size_t)w * (size_t)h;
    memset(first, 0, ((size_t)ncells + 1) * sizeof *first);
    for (size_t i = 0; i < npix; i++)
        if (j->owner[i] >= 0) first[j->owner[i] + 1]++;
    for (int c = 0; c < ncells; c++) first[c + 1] += first[c];
    for (size_t i = 0; i < npix; i++)
        if (j->owner[i] >= 0) j->owner_pixels[first[j->owner[i]]++] = (int)i;
    for (int c = ncells; c > 0; c--) first[c] = first[c - 1]; /* back to the starts */
    first[0] = 0;
    vw_status st = vw_decomp_clone(d, &j->owner_decomp);
    if (st != VW_OK) return st;
    j->sh.owner = j->owner;
    j->sh.owner_decomp = j->owner_decomp;
    j->sh.owner_first = j->owner_first;
    j->sh.owner_pixels = j->owner_pixels;
    return VW_OK;
}

vw_config rt_job_config(const rt_params *p)
{
    vw_config cfg;
    if (p->config)
        cfg = *p->config;
    else
        vw_config_init(&cfg);
    if (p->workers > 0) cfg.workers = p->workers;
    return cfg;
}

/* The part of rt_job_create that needs nobody else: checks, the view, the lights, the
   records, the world box and the decomposition, and the Embree device. Each process
   does it on its own copy of the scene, so it can fail on one process only; the caller
   agrees on the outcome before the world (collective) is made. */
static vw_status job_prepare(rt_job *j, const vw_scene *s, const rt_params *p, int threads,
                             char *err, size_t errlen)
{
    rt_shared *sh = &j->sh;
    double lo[3], hi[3];
    vw_scene_bounds(s, lo, hi);
    double diag = 0;
    for (int a = 0; a < 3; a++) diag += (hi[a] - lo[a]) * (hi[a] - lo[a]);
    diag = sqrt(diag);
    if (diag > 0 && diag < RT_MIN_SIZE) {
        snprintf(err, errlen, "the scene is %g across: the ray tracer needs at least %g",
                 diag, RT_MIN_SIZE);
        return VW_E_INVAL;
    }
    if (p->scale > 0) diag = p->scale;
    if (!(diag > 0)) diag = 1;

    vw_camera cam;
    if (p->camera)
        cam = *p->camera;
    else if (s->camera.valid)
        cam = s->camera;
    else {
        /* OBJ: a view framing the bounds (the scene library's convention). */
        memset(&cam, 0, sizeof cam);
        vw_scene_default_camera(s, &cam);
    }
    int w = p->width > 0 ? p->width : cam.width > 0 ? cam.width : 512;
    int h = p->height > 0 ? p->height : cam.height > 0 ? cam.height : 512;
    if (w > 16384 || h > 16384) {
        snprintf(err, errlen, "image size %dx%d too large (at most 16384 on a side)", w, h);
        return VW_E_INVAL;
    }
    rt_view_init(&sh->view, &cam, w, h);
    sh->max_depth = p->depth > 0 ? p->depth : 5;
    for (int k = 0; k < 3; k++) sh->background[k] = s->background[k];

    size_t nl = s->nlights ? s->nlights : 1;
    sh->lights = calloc(nl, sizeof *sh->lights);
    if (!sh->lights) return VW_E_NOMEM;
    if (s->nlights) {
        for (size_t i = 0; i < s->nlights; i++)
            for (int a = 0; a < 3; a++) {
                sh->lights[i].pos[a] = s->lights[i].pos[a];
                sh->lights[i].color[a] = s->lights[i].color[a];
            }
    } else {
        /* A scene without lights (OBJ): one white light above the eye. */
        for (int a = 0; a < 3; a++) {
            sh->lights[0].pos[a] = cam.from[a] + 0.5 * diag * sh->view.up[a];
            sh->lights[0].color[a] = 1.0;
        }
    }
    sh->nlights = (int)nl;

    vw_status st;
    /* The world box: the scene bounds padded so no primitive touches the outer walls,
       and so a flat scene still gives cells of positive volume. A scene a trillion times
       its size or more from the origin on an axis keeps nothing of a pad relative to its
       size there, nor perhaps its own extent (a sphere 1e-20 across at x = 1 has lo = hi
       = 1), and its box came out flat: no cell could be made. So the pad is also at
       least 8 units in the last place of the axis's coordinates per cell across it,
       which leaves the grid's walls several representable values apart; where the
       relative pad is larger (every scene nearer than that) the box is as before. */
    vw_box world;
    for (int a = 0; a < 3; a++) {
        double pad = fmax(1e-3 * diag, 1e-3 * (hi[a] - lo[a]));
        double mag = fmax(fabs(lo[a]), fabs(hi[a]));
        double ulp = nextafter(mag, INFINITY) - mag; /* (NaN for an infinite bound: refused below) */
        pad = fmax(pad, 8.0 * (p->dims[a] > 1 ? p->dims[a] : 1) * ulp);
        world.lo[a] = lo[a] - pad;
        world.hi[a] = hi[a] + pad;
    }
    if (p->world_min)
        for (int a = 0; a < 3; a++) {
            world.lo[a] = fmin(world.lo[a], p->world_min->lo[a]);
            world.hi[a] = fmax(world.hi[a], p->world_min->hi[a]);
        }
    if (p->world) world = *p->world;
    sh->ff = rt_float_frame_of(cam.from, &world);
    /* A cell's search runs past its far wall by `overlap` (walk_ray), so that a hit on
       the wall, which Embree's float arithmetic can place a little on either side of it,
       is not missed by both cells. The overlap is ten times that error, which is about
       1e-7 of the magnitudes involved, at most 3m (every ray starts at the eye or inside
       the world, whose coordinate sums m bounds, measured in Embree's float frame from
       its origin; see cell_reach). Objects are
       placed with their bounds widened by twice that, so a cell holds every object a
       ray can hit within the overlap past its walls: what it finds there is the ray's
       first hit, as one cell would find it. */
    double m = rt_float_frame_norm1(&sh->ff, cam.from);
    for (int i = 0; i < 8; i++) {
        double corner[3] = {(i & 1) ? world.hi[0] : world.lo[0], (i & 2) ? world.hi[1] : world.lo[1],
                            (i & 4) ? world.hi[2] : world.lo[2]};
        m = fmax(m, rt_float_frame_norm1(&sh->ff, corner));
    }
    /* Every ray starts at the eye or inside the world box, all of it within `far` of the
       origin on every axis, which RT_MAX_COORD bounds for the shading's doubles (Embree
       sees it in its float frame, sh->ff). */
    double far = 0;
    for (int a = 0; a < 3; a++)
        far = fmax(far, fmax(fabs(cam.from[a]), fmax(fabs(world.lo[a]), fabs(world.hi[a]))));
    if (!(far <= RT_MAX_COORD)) {
        snprintf(err, errlen, "the %s lies %g from the origin on an axis: the ray tracer takes "
                              "coordinates up to %g",
                 fmax(fabs(cam.from[0]), fmax(fabs(cam.from[1]), fabs(cam.from[2]))) == far ? "eye"
                                                                                          : "scene",
                 far, RT_MAX_COORD);
        return VW_E_INVAL;
    }
    sh->overlap = 1e-6 * 3 * m;
    /* The least t of a search, what keeps a secondary ray off its own surface: ten times
       Embree's float error (1e-7 of the coordinates measured in its frame, mrel) and at
       least 16 half-units in the last place of the doubles' coordinates (mabs), which a
       scene a billion units from the origin needs. Not relative to the scene's size:
       1e-4 of the diagonal, as it was, skipped every surface closer than that to a ray's
       origin, so a sphere 0.1 across on a floor 2000 wide cast no shadow and showed no
       floor in its mirror, and the smallest spheres of `gen balls --size 5` (radius
       0.002 under a floor 34 across: eps 0.0034) none of their neighbours. A ray leaving
       its surface at a grazing angle starts farther off (shade(), ray_eps). */
    double mrel = 0, mabs = 0;
    for (int i = 0; i < 9; i++) {
        double q[3];
        for (int a = 0; a < 3; a++)
            q[a] = i == 8 ? cam.from[a] : ((i >> a) & 1) ? world.hi[a] : world.lo[a];
        double r = 0, s1 = 0;
        for (int a = 0; a < 3; a++) {
            r += fabs(q[a] - sh->ff.origin[a]);
            s1 += fabs(q[a]);
        }
        mrel = fmax(mrel, r);
        mabs = fmax(mabs, s1);
    }
    sh->eps = fmax(1e-6 * mrel, 0x1p-49 * mabs);
    sh->bpad = fmax(1e-6 * diag, 2 * sh->overlap);
    int dims[3];
    for (int a = 0; a < 3; a++) dims[a] = p->dims[a] > 0 ? p->dims[a] : 1;
    st = vw_decomp_create_grid(&world, dims, &j->decomp);
    if (st != VW_OK) {
        snprintf(err, errlen, "cannot create the %dx%dx%d decomposition: %s", dims[0], dims[1],
                 dims[2], vw_status_message(st));
        return st;
    }
    /* Embree's threads: the process's workers (before the world that would say it). */
    sh->device = rt_device_new(threads);
    sh->geo_cache = sh->device ? rt_geo_cache_new(&sh->ff) : NULL;
    if (!sh->device || !sh->geo_cache) {
        snprintf(err, errlen, "cannot create the Embree device");
        return VW_E_STATE;
    }
    return VW_OK;
}

/* The scene's records into the world a part at a time: all of them at once beside the
   world's own copy were the load's peak (200,000 spheres: 45 MB twice, the peak of every
   process under MPI). Each part's conversion is agreed (a process out of memory for it
   stops all) before the part is added, so every process adds as many parts. */
enum { RT_PART_RECORDS = 16384 };
static vw_status add_scene_objects(vw_world *w, const vw_scene *s, char *err, size_t errlen)
{
    size_t widest, next = 0, count = rt_objects_count(s);
    rt_objects_room(s, &widest);
    size_t room = widest > RT_PART_RECORDS ? widest : RT_PART_RECORDS;
    rt_object *part = vw_test_fault("job-records-nomem") ? NULL : malloc(room * sizeof *part);
    vw_status st = part ? VW_OK : VW_E_NOMEM;
    for (;;) {
        size_t n = 0;
        if (st == VW_OK) st = rt_objects_next(s, &next, part, room, &n);
        if (st != VW_OK) snprintf(err, errlen, "the scene's records: %s", vw_status_message(st));
        if ((st = vw_world_agree(w, st, err, errlen)) != VW_OK) break;
        if (n && (st = vw_world_add_objects(w, part, n)) != VW_OK) break;
        if (next >= count) break;
    }
    free(part);
    return st;
}

vw_status rt_job_create(const vw_scene *s, const rt_params *p, rt_job **out, char *err,
                        size_t errlen)
{
    *out = NULL;
    if (errlen) err[0] = 0;
    vw_config cfg = rt_job_config(p);
    rt_job *j = vw_test_fault("job-nomem") ? NULL : calloc(1, sizeof *j);
    if (j) {
        atomic_init(&j->sh.pixels_done, 0);
        atomic_init(&j->sh.entries, 0);
        atomic_init(&j->sh.rays, 0);
    }
    /* Embree's threads: the workers the world will run, its default under MPI included
       (a share of the host's cores). Collective, so every process asks before anything
       can fail on one alone. */
    int threads = vw_engine_workers(cfg.workers);
    vw_status st = j ? job_prepare(j, s, p, threads, err, errlen) : VW_E_NOMEM;
    if (st != VW_OK && errlen && !err[0]) snprintf(err, errlen, "%s", vw_status_message(st));
    /* What failed on one process alone fails on all (with the lowest failing rank's
       message), before the world: the others would otherwise wait for it there. */
    st = vw_config_agree(&cfg, st, err, errlen);
    if (st != VW_OK) {
        rt_job_free(j);
        return st;
    }
    rt_shared *sh = &j->sh;
    st = vw_world_create(&rt_module, sh, j->decomp, &cfg, &j->world);
    if (st != VW_OK) {
        snprintf(err, errlen, "cannot create the world: %s", vw_world_errmsg(NULL)); /* why not */
        rt_job_free(j);
        return st;
    }
    /* The initial mapping is the block mapping (docs/balancing.md, Mapping), made before
       any object is added, so nothing moves. The world's own, runs of cell ids, was in
       use while the stats said "block": 4x4x1 cells on 4 workers with --farm none sent
       7143 messages between workers, 3873 mapped by blocks, and a balancer's "before"
       was measured on one mapping and its "after" on the other. */
    if (!cfg.cell_worker) st = rt_job_map(j, VW_MAP_BLOCK, NULL, NULL, err, errlen);
    if (st != VW_OK) {
        rt_job_free(j);
        return st;
    }
    /* The copies first, when the caller farms the initial mapping: then under MPI each
       process keeps, as the objects come, the records its copies need (those of its own
       cells; a process that hosts no cell farms every cell, and keeps every record), and
       the commit fetches none. */
    if (p->farm_first) st = rt_job_farm(j, p->farm, &j->farm_copies, err, errlen);
    if (st == VW_OK)
        st = p->objects ? vw_world_add_objects(j->world, p->objects, p->nobjects)
                        : add_scene_objects(j->world, s, err, errlen);
    if (st != VW_OK) {
        if (!err[0]) snprintf(err, errlen, "%s", vw_world_errmsg(j->world));
        rt_job_free(j);
        return st;
    }
    /* The image sums are the output process's alone, and the pixel owners are computed
       by each process: the caller's next step is collective, so all agree first. */
    if (vw_world_is_output(j->world)) {
        size_t npix = (size_t)sh->view.width * (size_t)sh->view.height;
        sh->accum = vw_test_fault("job-accum-nomem") ? NULL : calloc(npix, sizeof *sh->accum);
        if (!sh->accum) {
            st = VW_E_NOMEM;
            snprintf(err, errlen, "out of memory for the %dx%d image", sh->view.width, sh->view.height);
        }
    }
    if (st == VW_OK && (st = owners(j)) != VW_OK)
        snprintf(err, errlen, "the pixels' cells: %s", vw_status_message(st));
    st = vw_world_agree(j->world, st, err, errlen);
    if (st != VW_OK) {
        rt_job_free(j);
        return st;
    }
    *out = j;
    return VW_OK;
}

vw_status rt_job_commit(rt_job *j, char *err, size_t errlen)
{
    vw_status st = owners(j); /* the walls may have moved since the last commit */
    if (st != VW_OK) snprintf(err, errlen, "the pixels' cells: %s", vw_status_message(st));
    /* (each process computes them: all fail, or none waits in the commit for one) */
    if ((st = vw_world_agree(j->world, st, err, errlen)) != VW_OK) return st;
    st = vw_world_commit(j->world);
    if (st != VW_OK) snprintf(err, errlen, "building the cells: %s", vw_world_errmsg(j->world));
    return st;
}

vw_status rt_job_run(rt_job *j, char *err, size_t errlen)
{
    j->sh.frame++;
    vw_status st = vw_world_run(j->world);
    if (st != VW_OK) {
        snprintf(err, errlen, "rendering: %s", vw_world_errmsg(j->world));
        return st;
    }
    if (j->sh.accum && !j->ran) {
        /* Pixels whose eye ray misses the world have no cell: the background is added
           here, once, as the same fixed-point value a cell would have sent. */
        int64_t bg[3];
        for (int k = 0; k < 3; k++) bg[k] = (int64_t)llround(j->sh.background[k] * RT_FIX_ONE);
        size_t np = (size_t)j->sh.view.width * j->sh.view.height;
        for (size_t i = 0; i < np; i++)
            if (j->owner[i] < 0)
                for (int k = 0; k < 3; k++) j->sh.accum[i][k] += bg[k];
    }
    j->ran = 1;
    return VW_OK;
}

void rt_job_set_sample(rt_job *j, int stride) { j->sh.sample = stride > 1 ? stride : 1; }

vw_status rt_job_reset(rt_job *j)
{
    if (j->sh.accum)
        memset(j->sh.accum, 0, sizeof *j->sh.accum * (size_t)j->sh.view.width * j->sh.view.height);
    if (j->sh.hit_cell)
        for (size_t i = 0; i < (size_t)j->sh.view.width * j->sh.view.height; i++) j->sh.hit_cell[i] = -1;
    /* Each process computes the owners: all fail, or none waits for one in the
       collective step that follows (a commit, a redecomposition). */
    char msg[64] = "";
    vw_status st = vw_world_agree(j->world, owners(j), msg, sizeof msg);
    if (st != VW_OK) return st;
    atomic_store(&j->sh.pixels_done, 0);
    atomic_store(&j->sh.entries, 0);
    atomic_store(&j->sh.rays, 0);
    j->ran = 0;
    vw_world_reset_stats(j->world);
    return VW_OK;
}

vw_world *rt_job_world(rt_job *j) { return j->world; }
const rt_shared *rt_job_shared(const rt_job *j) { return &j->sh; }
int rt_job_is_output(const rt_job *j) { return vw_world_is_output(j->world); }
int64_t rt_job_primary_pixels(const rt_job *j) { return j->primary; }
const int64_t *rt_job_sums(const rt_job *j) { return j->sh.accum ? &j->sh.accum[0][0] : NULL; }

void rt_job_progress(const rt_job *j, int64_t *pixels_done, int64_t *rays)
{
    rt_job *m = (rt_job *)j; /* atomics are read-only here, but C11 wants non-const */
    if (pixels_done) *pixels_done = atomic_load(&m->sh.pixels_done);
    if (rays) *rays = atomic_load(&m->sh.rays);
}

/* One thread's share of rt_job_rgb8. */
typedef struct rgb8_part {
    const int64_t *sums;
    uint8_t *out;
    size_t n;  /* values in all */
    int parts;
} rgb8_part;

static void rgb8_range(int i, void *arg)
{
    const rgb8_part *p = arg;
    size_t a = p->n * (size_t)i / (size_t)p->parts, b = p->n * (size_t)(i + 1) / (size_t)p->parts;
    if (!p->sums) {
        memset(p->out + a, 0, b - a);
        return;
    }
    for (size_t k = a; k < b; k++) p->out[k] = rt_fix_to_u8(p->sums[k]);
}

void rt_job_rgb8(const rt_job *j, uint8_t *out)
{
    /* A serial phase after the run (the sums, 24 bytes a pixel, are read once), shared
       out as the PNG's blocks are. */
    rgb8_part p = {rt_job_sums(j), out, (size_t)j->sh.view.width * j->sh.view.height * 3,
                   serial_parts(j)};
    vw_parallel(p.parts, rgb8_range, &p);
}

void rt_job_rgbf(const rt_job *j, float *out)
{
    size_t n = (size_t)j->sh.view.width * j->sh.view.height * 3;
    const int64_t *s = rt_job_sums(j);
    for (size_t i = 0; i < n; i++) out[i] = s ? (float)((double)s[i] / RT_FIX_ONE) : 0.0f;
}

/* ---- the overlay ---------------------------------------------------------------------- */

static void put(uint8_t *img, int w, int h, int x, int y, const uint8_t c[3])
{
    if (x < 0 || y < 0 || x >= w || y >= h) return;
    memcpy(&img[((size_t)y * w + x) * 3], c, 3);
}

static void line(uint8_t *img, int w, int h, double x0, double y0, double x1, double y1,
                 const uint8_t c[3])
{
    /* Clip generously first so huge projected coordinates cannot loop for long. */
    double lim = 4.0 * (w + h);
    if (fabs(x0) > lim || fabs(y0) > lim || fabs(x1) > lim || fabs(y1) > lim) {
        int n = 0;
        while ((fabs(x0) > lim || fabs(y0) > lim || fabs(x1) > lim || fabs(y1) > lim) && n < 60) {
            /* Shorten towards the midpoint from whichever end is far. */
            double mx = 0.5 * (x0 + x1), my = 0.5 * (y0 + y1);
            if (fabs(x0) > lim || fabs(y0) > lim) {
                x0 = mx;
                y0 = my;
            } else {
                x1 = mx;
                y1 = my;
            }
            n++;
        }
    }
    double dx = x1 - x0, dy = y1 - y0;
    int steps = (int)ceil(fmax(fabs(dx), fabs(dy)));
    if (steps < 1) steps = 1;
    for (int i = 0; i <= steps; i++) {
        double t = (double)i / steps;
        put(img, w, h, (int)floor(x0 + t * dx), (int)floor(y0 + t * dy), c);
    }
}

static void draw_walls(const rt_job *j, uint8_t *out);

void rt_job_overlay(const rt_job *j, uint8_t *out)
{
    const rt_view *v = &j->sh.view;
    int w = v->width, h = v->height;
    rt_job_rgb8(j, out);
    int nc = vw_decomp_cell_count(vw_world_decomp(j->world));
    double *load = calloc((size_t)nc, sizeof *load);
    if (!load) return;
    double maxl = 0, minl = INFINITY;
    for (int c = 0; c < nc; c++) {
        vw_cell_stats cs;
        if (vw_world_cell_stats(j->world, c, &cs) == VW_OK) load[c] = cs.load;
        maxl = fmax(maxl, load[c]);
        minl = fmin(minl, load[c]);
    }
    /* Tint: green for the lightest cell, red for the heaviest, half-transparent. */
    const int *cell = j->sh.hit_cell ? j->sh.hit_cell : j->owner;
    if (cell)
        for (size_t i = 0; i < (size_t)w * h; i++) {
            int c = cell[i];
            if (c < 0 || c >= nc) continue;
            double f = maxl > minl ? (load[c] - minl) / (maxl - minl) : 0.0;
            double tint[3] = {255.0 * f, 255.0 * (1.0 - f), 0.0};
            for (int k = 0; k < 3; k++)
                out[i * 3 + k] = (uint8_t)lround(0.55 * out[i * 3 + k] + 0.45 * tint[k]);
        }
    free(load);
    draw_walls(j, out);
}

/* A map of one int a pixel, all -1 ("none"), in *map: made once, on the output process
   only (the one that keeps the image and reads the overlays' maps). */
static vw_status pixel_map(const rt_job *j, int **map)
{
    if (!j->sh.accum || *map) return VW_OK;
    size_t np = (size_t)j->sh.view.width * (size_t)j->sh.view.height;
    if (!(*map = malloc(np * sizeof **map))) return VW_E_NOMEM;
    for (size_t i = 0; i < np; i++) (*map)[i] = -1;
    return VW_OK;
}

vw_status rt_job_record_hit_cells(rt_job *j)
{
    j->sh.record_hit_cells = 1;
    return pixel_map(j, &j->sh.hit_cell);
}

vw_status rt_job_record_eye_workers(rt_job *j)
{
    j->sh.record_eye_workers = 1;
    return pixel_map(j, &j->sh.eye_worker);
}

int rt_job_eye_workers(const rt_job *j, int *worker)
{
    if (!j->sh.eye_worker || !j->owner) return 0;
    size_t np = (size_t)j->sh.view.width * (size_t)j->sh.view.height;
    for (size_t i = 0; i < np; i++) worker[i] = j->owner[i] < 0 ? -1 : j->sh.eye_worker[i];
    return 1;
}

/* Tint by the worker that made each pixel's eye ray: a fixed palette of well-separated
   hues (golden-angle steps), so the mapping (which cells share a worker) and the
   copies' turns can be seen at a glance. */
void rt_job_overlay_workers(const rt_job *j, uint8_t *out)
{
    const rt_view *v = &j->sh.view;
    size_t np = (size_t)v->width * (size_t)v->height;
    rt_job_rgb8(j, out);
    int *worker = malloc(np * sizeof *worker);
    if (worker && rt_job_eye_workers(j, worker))
        for (size_t i = 0; i < np; i++) {
            int g = worker[i];
            if (g < 0) continue;
            double hh = fmod(g * 137.508, 360.0) / 60.0, f = hh - floor(hh);
            static const double ramp[6][3][2] = { /* (constant, slope) per channel */
                {{1, 0}, {0, 1}, {0, 0}}, {{1, -1}, {1, 0}, {0, 0}}, {{0, 0}, {1, 0}, {0, 1}},
                {{0, 0}, {1, -1}, {1, 0}}, {{0, 1}, {0, 0}, {1, 0}}, {{1, 0}, {0, 0}, {1, -1}}};
            int sx = (int)hh % 6;
            double rgb[3];
            for (int k = 0; k < 3; k++) rgb[k] = ramp[sx][k][0] + ramp[sx][k][1] * f;
            for (int k = 0; k < 3; k++)
                out[i * 3 + k] = (uint8_t)lround(0.5 * out[i * 3 + k] + 0.5 * 255.0 * rgb[k]);
        }
    free(worker);
    draw_walls(j, out);
}

static void draw_walls(const rt_job *j, uint8_t *out)
{
    const rt_view *v = &j->sh.view;
    int w = v->width, h = v->height;
    const vw_decomp *d = vw_world_decomp(j->world);
    int nc = vw_decomp_cell_count(d);
    /* Walls: the edges of every cell box, clipped to the half-space in front of the eye. */
    static const uint8_t white[3] = {255, 255, 255};
    double near = 1e-6;
    for (int c = 0; c < nc; c++) {
        vw_box b = vw_decomp_cell_box(d, c);
        double P[8][3];
        for (int i = 0; i < 8; i++) {
            double q[3] = {(i & 1) ? b.hi[0] : b.lo[0], (i & 2) ? b.hi[1] : b.lo[1],
                           (i & 4) ? b.hi[2] : b.lo[2]};
            vw_decomp_from_frame(d, q, P[i]);
        }
        for (int i = 0; i < 8; i++)
            for (int bit = 1; bit < 8; bit <<= 1) {
                if (i & bit) continue;
                double A[3], B[3];
                memcpy(A, P[i], sizeof A);
                memcpy(B, P[i | bit], sizeof B);
                double za = 0, zb = 0;
                for (int a = 0; a < 3; a++) {
                    za += (A[a] - v->eye[a]) * v->fwd[a];
                    zb += (B[a] - v->eye[a]) * v->fwd[a];
                }
                if (za <= near && zb <= near) continue;
                if (za <= near || zb <= near) {
                    double t = (near - za) / (zb - za) * 1.0001;
                    double Cp[3];
                    for (int a = 0; a < 3; a++) Cp[a] = A[a] + t * (B[a] - A[a]);
                    if (za <= near)
                        memcpy(A, Cp, sizeof A);
                    else
                        memcpy(B, Cp, sizeof B);
                }
                double ax, ay, bx, by;
                if (rt_view_project(v, A, &ax, &ay) && rt_view_project(v, B, &bx, &by))
                    line(out, w, h, ax, ay, bx, by, white);
            }
    }
}

/* ---- stats ------------------------------------------------------------------------------- */

char *rt_job_stats_json(const rt_job *j)
{
    int nc = vw_decomp_cell_count(vw_world_decomp(j->world));
    size_t cap = 512 + (size_t)nc * 24;
    char *s = malloc(cap);
    if (!s) return NULL;
    size_t n = (size_t)snprintf(
        s, cap,
        "\"rays\": {\"eye\": %lld, \"reflect\": %lld, \"refract\": %lld, \"shadow\": %lld, "
        "\"ended\": %lld, \"segments\": %lld},\n  \"image\": {\"width\": %d, \"height\": %d, "
        "\"depth\": %d, \"primary_pixels\": %lld},\n  \"pixels_per_cell\": [",
        (long long)vw_world_counter(j->world, RT_C_EYE),
        (long long)vw_world_counter(j->world, RT_C_REFLECT),
        (long long)vw_world_counter(j->world, RT_C_REFRACT),
        (long long)vw_world_counter(j->world, RT_C_SHADOW),
        (long long)vw_world_counter(j->world, RT_C_ENDED),
        (long long)vw_world_counter(j->world, RT_C_SEGMENTS), j->sh.view.width,
        j->sh.view.height, j->sh.max_depth, (long long)vw_world_counter(j->world, RT_C_PIXELS));
    for (int c = 0; c < nc && n < cap; c++)
        n += (size_t)snprintf(s + n, cap - n, "%s%lld", c ? ", " : "",
                              (long long)vw_world_cell_counter(j->world, c, RT_C_PIXELS));
    if (n < cap) snprintf(s + n, cap - n, "]");
    return s;
}
