/* solve.c - the solve loop of the radiosity solver: rounds of vw_world_run, the energy
 * ledger, gathering results on the output process, checkpoints and resuming.
 *
 * A round posts GO(round, budget) to every cell and runs to quiescence: each cell
 * shoots up to `budget` patches above the threshold, and every shot ends within the
 * run. The first message of a round a cell handles makes it report the state the last
 * round left, so after run r the output process knows the exact quiescent state at the
 * start of round r. A round in which no cell shot (a global counter, the same on every
 * process) means every patch is below the threshold: converged, and the reports of
 * that round describe the final state.
 */
#include "radiosity/solver_internal.h"
#include "radiosity/vec.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void piece_bounds(const void *obj, vw_box *out, void *user)
{
    const rad_piece *pc = obj;
    (void)user;
    for (int a = 0; a < 3; a++) out->lo[a] = INFINITY, out->hi[a] = -INFINITY;
    for (int i = 0; i < pc->nv; i++)
        for (int a = 0; a < 3; a++) {
            out->lo[a] = fmin(out->lo[a], pc->v[i][a]);
            out->hi[a] = fmax(out->hi[a], pc->v[i][a]);
        }
}

/* Level-0 receiver elements per cell: the grid squares of each piece that cell_build's
   add_elem keeps (a polygon of 3 or more vertices and more than 1e-14 of the piece's
   area), counted on the piece's owner cell. The same on every process (every process
   meshes the whole scene). */
static void cell_elements(const rad_mesh *m, int ncells, double *load)
{
    for (int c = 0; c < ncells; c++) load[c] = 0;
    for (size_t i = 0; i < m->npieces; i++) {
        const rad_piece *pc = &m->pieces[i];
        int lo[2], hi[2];
        if (m->owner[i] < 0 || m->owner[i] >= ncells) continue;
        rad_piece_grid(pc, lo, hi);
        for (int gi = lo[0]; gi <= hi[0]; gi++)
            for (int gj = lo[1]; gj <= hi[1]; gj++) {
                rad_poly poly;
                if (rad_elem_polygon(pc, 0, gi, gj, &poly) >= 3 &&
                    rad_poly_area(&poly, NULL, NULL) > 1e-14 * pc->area)
                    load[m->owner[i]] += 1;
            }
    }
}

/* Maps the cells onto the workers by their element counts, longest first, instead of
   the runtime's contiguous blocks. A cell's work is rasterising its elements for every
   shot that reaches it, and nearly every shot reaches every cell, so it is nearly
   proportional to its element count (busy time per element within 5 % over the room's
   cells), in every round alike. The room's 2x2x2 cells on 2 workers: blocks give the
   busier worker 9 % more than the mean (the cells of the lower half hold the furniture),
   this mapping 1-2 %. Neighbour preference is off (slack 0): a bitmap to a cell on
   another worker of this process costs a queue push, not a network message, and a few
   percent of imbalance cost more than that. With no more cells than workers every
   mapping is one cell per worker, and the runtime's is kept. */
/* The mapping by element counts, or *map NULL when the block mapping stays (a cell or
   fewer per worker). Local: the caller agrees before the remap. */
static vw_status map_by_elements(rad_solver *s, const rad_mesh *m, const vw_decomp *d, int **map)
{
    *map = NULL;
    int ncells = vw_decomp_cell_count(d);
    int gworkers = vw_world_processes(s->w) * vw_world_workers(s->w);
    if (gworkers < 2 || ncells <= gworkers) return VW_OK;
    double *load = malloc(sizeof(double) * (size_t)ncells);
    *map = malloc(sizeof(int) * (size_t)ncells);
    vw_status st = load && *map ? VW_OK : VW_E_NOMEM;
    if (st == VW_OK) {
        cell_elements(m, ncells, load);
        st = vw_map_greedy(d, load, gworkers, NULL, 0.0, *map);
    }
    free(load);
    return st;
}

static vw_status run_world(rad_solver *s, char *err, size_t errlen)
{
    memset(&s->rep, 0, sizeof s->rep);
    s->nreports = 0;
    vw_status st = vw_world_run(s->w);
    if (st != VW_OK) snprintf(err, errlen, "radiosity run failed: %s", vw_world_errmsg(s->w));
    return st;
}

/* The ledger from the last run's reports (output process). */
static void update_ledger(rad_solver *s)
{
    rad_ledger *L = &s->ledger;
    L->error = 0;
    for (int k = 0; k < 3; k++) {
        L->emitted[k] = s->mesh->emitted[k];
        L->absorbed[k] = s->base_absorbed[k] + s->rep.absorbed[k];
        L->unshot[k] = s->rep.unshot[k];
        L->escaped[k] = s->base_escaped[k] + s->rep.shot[k] - s->rep.won[k];
        double scale = fmax(L->emitted[k], 1e-300 + 1e-12 * s->emitted_sum);
        double e = fabs(L->emitted[k] - (L->absorbed[k] + L->unshot[k] + L->escaped[k])) / scale;
        /* A NaN anywhere is an unbalanced ledger, not a balanced one (NaN > x is false). */
        if (!(e <= L->error)) L->error = isnan(e) ? INFINITY : e;
    }
    s->ratio = s->rep.max_unshot / s->emitted_sum;
}

/* ---- checkpoints ---- */

static int cmp_elem(const void *a, const void *b);

/* Checkpoint file, native byte order (resume on the same kind of machine):
     "VWRADCK2"                  8 bytes
     pieces, fingerprint         u64, u64: the mesh (ck_fingerprint)
     round, shots                i32, i64
     absorbed[3], escaped[3]     f64: the ledger of the shots so far (absorbed[0] at
                                 byte 36, where format 1 had it too)
     patch size, elements, hemicube, cells[3], max level, subdivide, neighbourhood
                                 f64, i32, i32, 3 i32, i32, f64, f64: what the state
                                 depends on besides the mesh (ck_compatible)
     patches                     u64, then one rad_patch_result per piece, by piece
     elements                    u64, then rad_elem_result by piece, level, gi, gj
     checksum                    u64: FNV-1a of every byte before it
   Written atomically: a kill while writing leaves the previous one. The checksum finds
   a damaged file whose numbers still look plausible; the reader checks the numbers
   first, so that what is wrong can be named. */
#define CK_MAGIC "VWRADCK2"
#define CK_HEAD_BYTES 132

typedef struct ck_head {
    uint64_t npieces, fingerprint;
    int32_t round;
    int64_t shots;
    double absorbed[3], escaped[3];
    double patch_size;
    int32_t elements, hemicube, cells[3], max_level;
    double subdivide, neighbourhood;
} ck_head;

#define FNV_BASIS 1469598103934665603ull
static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) h = (h ^ b[i]) * 1099511628211ull;
    return h;
}

/* Every field of every piece that the solution depends on: geometry, the polygon's frame
   and element size, reflectance and emission. The same scene meshed with the same
   --patch-size, --elements and --cells gives the same bits. */
static uint64_t ck_fingerprint(const rad_mesh *m)
{
    uint64_t h = FNV_BASIS;
    for (size_t i = 0; i < m->npieces; i++) {
        const rad_piece *pc = &m->pieces[i];
        h = fnv(h, &pc->poly, sizeof pc->poly);
        h = fnv(h, &pc->nv, sizeof pc->nv);
        h = fnv(h, &pc->pi, sizeof pc->pi);
        h = fnv(h, &pc->pj, sizeof pc->pj);
        h = fnv(h, pc->v, sizeof(double) * 3 * (size_t)pc->nv);
        h = fnv(h, pc->normal, sizeof pc->normal);
        h = fnv(h, pc->centroid, sizeof pc->centroid);
        h = fnv(h, &pc->area, sizeof pc->area);
        h = fnv(h, pc->origin, sizeof pc->origin);
        h = fnv(h, pc->uax, sizeof pc->uax);
        h = fnv(h, pc->vax, sizeof pc->vax);
        h = fnv(h, &pc->elem, sizeof pc->elem);
        h = fnv(h, pc->rho, sizeof pc->rho);
        h = fnv(h, pc->emit, sizeof pc->emit);
    }
    return h;
}

/* The header this run would write (round, shots and ledger from the solver). */
static void ck_head_of(const rad_solver *s, ck_head *h)
{
    memset(h, 0, sizeof *h);
    h->npieces = s->mesh->npieces;
    h->fingerprint = ck_fingerprint(s->mesh);
    h->round = s->round;
    h->shots = s->shots;
    for (int k = 0; k < 3; k++) h->absorbed[k] = s->ledger.absorbed[k], h->escaped[k] = s->ledger.escaped[k];
    h->patch_size = s->mesh->patch_size;
    h->elements = s->opt.elem_split;
    h->hemicube = s->opt.res;
    for (int a = 0; a < 3; a++) h->cells[a] = s->opt.dims[a];
    /* Without --subdivide the level limit plays no part. */
    h->subdivide = s->opt.subdivide > 0 ? s->opt.subdivide : 0;
    h->max_level = h->subdivide > 0 ? s->opt.max_level : 0;
    h->neighbourhood = s->opt.neighbourhood > 0 ? s->opt.neighbourhood : 0;
}

#define CK_FIELDS(X)                                                                   \
    X(npieces, 8) X(fingerprint, 8) X(round, 4) X(shots, 8) X(absorbed, 24)             \
    X(escaped, 24) X(patch_size, 8) X(elements, 4) X(hemicube, 4) X(cells, 12)          \
    X(max_level, 4) X(subdivide, 8) X(neighbourhood, 8)

#define X(f, n) _Static_assert(sizeof(((ck_head *)0)->f) == n, "checkpoint field " #f);
CK_FIELDS(X)
#undef X
#define X(f, n) +n
_Static_assert(8 CK_FIELDS(X) == CK_HEAD_BYTES, "checkpoint header size");
#undef X
/* The records are written as they are: no padding, so no uninitialised bytes. */
_Static_assert(sizeof(rad_patch_result) == 40 && sizeof(rad_elem_result) == 80, "checkpoint records");

static void ck_put(unsigned char *p, const ck_head *h)
{
    memcpy(p, CK_MAGIC, 8), p += 8;
#define X(f, n) memcpy(p, &h->f, n), p += n;
    CK_FIELDS(X)
#undef X
}

static void ck_get(const unsigned char *p, ck_head *h)
{
    p += 8;
#define X(f, n) memcpy(&h->f, p, n), p += n;
    CK_FIELDS(X)
#undef X
}

/* Why a checkpoint with header c cannot continue this run (mine), in why; 0 when it
   can. Everything the restored state depends on must match: the mesh (scene, patch
   size, elements, cells: the fingerprint), and the options that decide what the state
   means: elements (their grid), hemicube (the form factors the powers came from),
   subdivision (leaves deeper than this run's fine cells cannot be restored), the
   neighbourhood (which shots reached which cells). --sf, --per-round, --max-shots and
   the workers may change. */
/* An option's value for a message: the shortest form that reads back to it (so 0.3,
   not 0.29999999999999999), "none" for an option not given. */
static const char *opt_value(double x, char *buf, size_t n)
{
    if (!(x > 0)) {
        snprintf(buf, n, "none");
        return buf;
    }
    for (int digits = 6; digits <= 17; digits++) {
        snprintf(buf, n, "%.*g", digits, x);
        if (strtod(buf, NULL) == x) break;
    }
    return buf;
}

static int ck_incompatible(const ck_head *c, const ck_head *mine, char *why, size_t n)
{
    char a[32], b[32];
    if (c->cells[0] != mine->cells[0] || c->cells[1] != mine->cells[1] || c->cells[2] != mine->cells[2])
        snprintf(why, n, "--cells %dx%dx%d there, %dx%dx%d here", c->cells[0], c->cells[1], c->cells[2],
                 mine->cells[0], mine->cells[1], mine->cells[2]);
    else if (c->patch_size != mine->patch_size)
        snprintf(why, n, "--patch-size %s there, %s here", opt_value(c->patch_size, a, sizeof a),
                 opt_value(mine->patch_size, b, sizeof b));
    else if (c->elements != mine->elements)
        snprintf(why, n, "--elements %d there, %d here", c->elements, mine->elements);
    else if (c->hemicube != mine->hemicube)
        snprintf(why, n, "--hemicube %d there, %d here", c->hemicube, mine->hemicube);
    else if (c->subdivide != mine->subdivide)
        snprintf(why, n, "--subdivide %s there, %s here", opt_value(c->subdivide, a, sizeof a),
                 opt_value(mine->subdivide, b, sizeof b));
    else if (c->max_level != mine->max_level)
        snprintf(why, n, "--max-level %d there, %d here", c->max_level, mine->max_level);
    else if (c->neighbourhood != mine->neighbourhood)
        snprintf(why, n, "--neighbourhood %s there, %s here", opt_value(c->neighbourhood, a, sizeof a),
                 opt_value(mine->neighbourhood, b, sizeof b));
    else if (c->npieces != mine->npieces || c->fingerprint != mine->fingerprint)
        snprintf(why, n, "the scene or its meshing differs: %llu pieces there, %llu here",
                 (unsigned long long)c->npieces, (unsigned long long)mine->npieces);
    else
        return 0;
    return 1;
}

/* Reads the whole file at path into *buf (*len bytes; *buf NULL on failure). */
static vw_status load_checkpoint(const char *path, unsigned char **buf, size_t *len, char *err,
                                 size_t errlen)
{
    *buf = NULL;
    *len = 0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errlen, "%s: cannot open checkpoint: %s", path, strerror(errno));
        return VW_E_IO;
    }
    size_t cap = 1 << 16, n = 0, k;
    unsigned char *b = malloc(cap);
    while (b && (k = fread(b + n, 1, cap - n, f)) > 0) {
        n += k;
        if (n == cap) {
            unsigned char *nb = realloc(b, 2 * cap);
            if (!nb) free(b);
            b = nb, cap *= 2;
        }
    }
    int rerr = ferror(f);
    fclose(f);
    if (!b) {
        snprintf(err, errlen, "%s: out of memory reading the checkpoint", path);
        return VW_E_NOMEM;
    }
    if (rerr) {
        snprintf(err, errlen, "%s: cannot read checkpoint: %s", path, strerror(errno));
        free(b);
        return VW_E_IO;
    }
    *buf = b, *len = n;
    return VW_OK;
}

/* Checks that the n bytes at b, the checkpoint s->opt.resume, can continue this run, and
   reads its header into *h. */
static vw_status check_checkpoint(rad_solver *s, const unsigned char *b, size_t n, ck_head *h,
                                  char *err, size_t errlen)
{
    const char *path = s->opt.resume;
    const rad_mesh *m = s->mesh;
#define CORRUPT(...)                                                                     \
    do {                                                                                 \
        char what_[256];                                                                 \
        snprintf(what_, sizeof what_, __VA_ARGS__);                                      \
        snprintf(err, errlen, "%s: truncated or corrupt checkpoint (%s)", path, what_);  \
        return VW_E_INPUT;                                                               \
    } while (0)
    if (n >= 8 && !memcmp(b, "VWRADCK1", 8)) {
        snprintf(err, errlen, "%s: a checkpoint of an older vwalls (format 1, which does not record "
                 "the meshing options): start the run again", path);
        return VW_E_INPUT;
    }
    if (n < 8 || memcmp(b, CK_MAGIC, 8)) {
        snprintf(err, errlen, "%s: not a radiosity checkpoint", path);
        return VW_E_INPUT;
    }
    if (n < CK_HEAD_BYTES + 8) CORRUPT("%zu bytes, shorter than its header", n);
    ck_get(b, h);
    ck_head mine;
    ck_head_of(s, &mine);
    char why[256];
    if (ck_incompatible(h, &mine, why, sizeof why)) {
        snprintf(err, errlen,
                 "%s: checkpoint of a different scene or meshing (%s; use the same scene, --cells, "
                 "--patch-size, --elements, --hemicube, --subdivide, --max-level and --neighbourhood "
                 "as the run that wrote it; without --cells the layout follows the number of "
                 "workers)", path, why);
        return VW_E_INPUT;
    }
    /* Every number is checked before any is used: a NaN or a negative power would go
       through the solve unnoticed (NaN compares false with every bound) into the
       outputs, an index out of range would be used as one. */
    if (h->round < 0 || h->round > INT32_MAX / 2 || h->shots < 0) CORRUPT("round %d, %lld shots", (int)h->round, (long long)h->shots);
    const char *const ch = "rgb";
    for (int k = 0; k < 3; k++) {
        /* escaped = shot - won: a closed scene's is a rounding error either way of 0 */
        double tol = 1e-6 * fmax(m->emitted[k], 1e-12 * rad_sum3(m->emitted));
        if (!isfinite(h->absorbed[k]) || h->absorbed[k] < 0)
            CORRUPT("absorbed power %c %g", ch[k], h->absorbed[k]);
        if (!isfinite(h->escaped[k]) || h->escaped[k] < -tol)
            CORRUPT("escaped power %c %g", ch[k], h->escaped[k]);
    }
    uint64_t np, ne;
    memcpy(&np, b + CK_HEAD_BYTES, 8);
    if (np != m->npieces) CORRUPT("%llu patches for %zu pieces", (unsigned long long)np, m->npieces);
    size_t at_ne = CK_HEAD_BYTES + 8 + (size_t)np * sizeof(rad_patch_result);
    if (n < at_ne + 8) CORRUPT("%zu bytes, shorter than its %llu patches", n, (unsigned long long)np);
    memcpy(&ne, b + at_ne, 8);
    if (ne > (n - at_ne - 16) / sizeof(rad_elem_result) ||
        n != at_ne + 8 + (size_t)ne * sizeof(rad_elem_result) + 8)
        CORRUPT("%zu bytes for %llu elements", n, (unsigned long long)ne);
    /* Patches: one per piece, in piece order (as collected). */
    double unshot[3] = {0, 0, 0};
    int64_t nshots = 0;
    for (uint64_t i = 0; i < np; i++) {
        rad_patch_result r;
        memcpy(&r, b + CK_HEAD_BYTES + 8 + i * sizeof r, sizeof r);
        if (r.piece != (int64_t)i) CORRUPT("patch %llu: piece %lld", (unsigned long long)i, (long long)r.piece);
        if (r.nshots < 0 || r.nshots > h->shots - nshots)
            CORRUPT("patch %llu: %lld shots", (unsigned long long)i, (long long)r.nshots);
        nshots += r.nshots;
        for (int k = 0; k < 3; k++) {
            if (!isfinite(r.unshot[k]) || r.unshot[k] < 0)
                CORRUPT("patch %llu: unshot power %c %g", (unsigned long long)i, ch[k], r.unshot[k]);
            unshot[k] += r.unshot[k];
        }
    }
    if (nshots != h->shots)
        CORRUPT("the patches' shots sum to %lld, not %lld", (long long)nshots, (long long)h->shots);
    /* The ledger as the run left it: emitted = absorbed + unshot + escaped. */
    for (int k = 0; k < 3; k++) {
        double scale = fmax(m->emitted[k], 1e-300 + 1e-12 * rad_sum3(m->emitted));
        double off = fabs(m->emitted[k] - (h->absorbed[k] + unshot[k] + h->escaped[k])) / scale;
        if (!(off <= 1e-6)) CORRUPT("energy ledger off by %.3g in %c", off, ch[k]);
    }
    /* Elements: leaves of this run's grid, sorted by piece, level, gi, gj, each once. */
    int max_level = h->subdivide > 0 ? h->max_level : 0;
    rad_elem_result prev;
    memset(&prev, 0, sizeof prev);
    for (uint64_t i = 0; i < ne; i++) {
        rad_elem_result r;
        memcpy(&r, b + at_ne + 8 + i * sizeof r, sizeof r);
        if (r.piece < 0 || (uint64_t)r.piece >= np)
            CORRUPT("element %llu: piece %lld", (unsigned long long)i, (long long)r.piece);
        const rad_piece *pc = &m->pieces[r.piece];
        int lo[2], hi[2];
        rad_piece_grid(pc, lo, hi);
        if (r.poly != pc->poly || r.level < 0 || r.level > max_level)
            CORRUPT("element %llu: polygon %d, level %d", (unsigned long long)i, (int)r.poly, (int)r.level);
        int64_t sc = (int64_t)1 << r.level;
        if (r.gi < lo[0] * sc || r.gi >= (hi[0] + 1) * sc || r.gj < lo[1] * sc || r.gj >= (hi[1] + 1) * sc)
            CORRUPT("element %llu: grid square %d %d off its piece", (unsigned long long)i, (int)r.gi, (int)r.gj);
        if (i > 0 && cmp_elem(&prev, &r) >= 0)
            CORRUPT("element %llu out of order", (unsigned long long)i);
        if (!isfinite(r.area) || r.area <= 0 || r.area > pc->area * (1 + 1e-9))
            CORRUPT("element %llu: area %g", (unsigned long long)i, r.area);
        for (int k = 0; k < 3; k++)
            if (!isfinite(r.B[k]) || r.B[k] < 0 || !isfinite(r.incident[k]) || r.incident[k] < 0)
                CORRUPT("element %llu: radiosity %c %g, incident power %g", (unsigned long long)i, ch[k],
                        r.B[k], r.incident[k]);
        prev = r;
    }
    uint64_t sum;
    memcpy(&sum, b + n - 8, 8);
    if (sum != fnv(FNV_BASIS, b, n - 8)) CORRUPT("checksum mismatch");
#undef CORRUPT
    return VW_OK;
}

/* Posts the records of a checked checkpoint to their owner cells. */
static void post_checkpoint(rad_solver *s, const unsigned char *b)
{
    const rad_mesh *m = s->mesh;
    uint64_t np, ne;
    memcpy(&np, b + CK_HEAD_BYTES, 8);
    size_t at_ne = CK_HEAD_BYTES + 8 + (size_t)np * sizeof(rad_patch_result);
    memcpy(&ne, b + at_ne, 8);
    for (uint64_t i = 0; i < np; i++) {
        rad_patch_result r;
        memcpy(&r, b + CK_HEAD_BYTES + 8 + i * sizeof r, sizeof r);
        vw_world_post(s->w, m->owner[r.piece], RAD_K_RESTORE_PATCH, &r);
    }
    for (uint64_t i = 0; i < ne; i++) {
        rad_elem_result r;
        memcpy(&r, b + at_ne + 8 + i * sizeof r, sizeof r);
        vw_world_post(s->w, m->owner[r.piece], RAD_K_RESTORE_ELEM, &r);
    }
}

vw_status rad_solver_create(const rad_mesh *m, const vw_decomp *d, const rad_options *o,
                            rad_solver **out, char *err, size_t errlen)
{
    *out = NULL;
    if (errlen) err[0] = 0;
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = o->workers;
    rad_solver *s = vw_test_fault("solver-nomem") ? NULL : calloc(1, sizeof *s);
    vw_status st = s ? rad_hemicube_init(&s->hc, o->res) : VW_E_NOMEM;
    if (st == VW_E_INVAL)
        snprintf(err, errlen, "--hemicube %d: must be even and between 2 and %d", o->res, RAD_MAX_RES);
    else if (st != VW_OK)
        snprintf(err, errlen, "cannot set up the radiosity solver: %s", vw_status_message(st));
    /* Memory is each process's own: all fail, or none waits for one in the world's
       creation. */
    st = vw_config_agree(&cfg, st, err, errlen);
    if (st != VW_OK) {
        rad_solver_free(s);
        return st;
    }
    s->mesh = m;
    s->d = d;
    s->opt = *o;
    s->bitmap_bytes = rad_hemicube_bitmap_bytes(o->res);
    rad_module_setup(s);
    s->mod.object_bounds = piece_bounds;
    s->emitted_sum = rad_sum3(m->emitted);
    s->thr = o->sf * s->emitted_sum;
    vw_box wb = vw_decomp_world(d);
    double ext = 0;
    for (int a = 0; a < 3; a++) ext = fmax(ext, wb.hi[a] - wb.lo[a]);
    s->near_eps = 1e-9 * ext;
    st = vw_world_create(&s->mod, s, d, &cfg, &s->w);
    int *map = NULL;
    if (st == VW_OK) {
        vw_status local = map_by_elements(s, m, d, &map);
        size_t gw = (size_t)vw_world_processes(s->w) * (size_t)vw_world_workers(s->w);
        s->slots = vw_test_fault("solver-slots-nomem")
                       ? NULL
                       : aligned_alloc(_Alignof(rad_worker_slot), gw * sizeof *s->slots);
        s->nslots = s->slots ? gw : 0;
        if (s->slots) memset(s->slots, 0, gw * sizeof *s->slots);
        s->stepwork = calloc((size_t)vw_decomp_cell_count(d), 1);
        s->fault_solve_nomem = vw_test_fault("solve-nomem");
        s->fault_collect_nomem = vw_test_fault("collect-nomem");
        if (local == VW_OK && (!s->slots || !s->stepwork)) local = VW_E_NOMEM;
        if (local != VW_OK)
            snprintf(err, errlen, "cannot set up the radiosity world: %s", vw_status_message(local));
        /* All of it is local: all fail, or none waits in the remap or the placement. */
        st = vw_world_agree(s->w, local, err, errlen);
        if (st != VW_OK) {
            free(map);
            rad_solver_free(s);
            return st;
        }
    }
    if (st == VW_OK && map) st = vw_world_remap(s->w, map);
    free(map);
    if (st == VW_OK) st = vw_world_add_objects(s->w, m->pieces, m->npieces);
    if (st == VW_OK) st = vw_world_commit(s->w);
    if (st != VW_OK) {
        snprintf(err, errlen, "cannot set up the radiosity world: %s",
                 vw_world_errmsg(s->w)); /* s->w NULL: why it was not made */
        rad_solver_free(s);
        return st;
    }
    if (o->resume) {
        /* The output process alone reads the file and hands its bytes to the others:
           it is the process that wrote it, on its host alone when the hosts share no
           file system, and a copy that differed on another host (an older checkpoint of
           the same scene) made that process resume from another state, which only the
           energy ledger at the end of the whole solve found. Every process then checks
           the same bytes against the same mesh, alike; each step ends in agreement, so
           one that fails (a file rank 0 cannot read, memory another lacks) leaves none
           waiting in a collective call. vw_engine_broadcast is MPI_COMM_WORLD's, the
           communicator of this world (its vw_config names none). */
        unsigned char *buf = NULL;
        size_t len = 0;
        ck_head h;
        int out = vw_world_is_output(s->w);
        st = vw_world_agree(s->w, out ? load_checkpoint(o->resume, &buf, &len, err, errlen) : VW_OK,
                            err, errlen);
        if (st == VW_OK && vw_world_processes(s->w) > 1) {
            uint64_t n64 = len;
            vw_engine_broadcast(&n64, sizeof n64);
            vw_status local = VW_OK;
            if (!out) {
                buf = n64 < SIZE_MAX ? malloc(n64 ? (size_t)n64 : 1) : NULL;
                len = (size_t)n64;
                if (!buf) {
                    local = VW_E_NOMEM;
                    snprintf(err, errlen, "%s: out of memory for the checkpoint (%llu bytes)",
                             o->resume, (unsigned long long)n64);
                }
            }
            st = vw_world_agree(s->w, local, err, errlen);
            if (st == VW_OK) vw_engine_broadcast(buf, len);
        }
        if (st == VW_OK)
            st = vw_world_agree(s->w, check_checkpoint(s, buf, len, &h, err, errlen), err, errlen);
        if (st == VW_OK) {
            post_checkpoint(s, buf);
            s->round = h.round;
            s->base_shots = h.shots;
            memcpy(s->base_absorbed, h.absorbed, sizeof h.absorbed);
            memcpy(s->base_escaped, h.escaped, sizeof h.escaped);
            st = run_world(s, err, errlen);
        }
        free(buf);
        if (st != VW_OK) {
            rad_solver_free(s);
            return st;
        }
    }
    s->shots = s->base_shots;
    *out = s;
    return VW_OK;
}

void rad_solver_free(rad_solver *s)
{
    if (!s) return;
    vw_world_free(s->w);
    rad_hemicube_free(&s->hc);
    free(s->elems);
    free(s->patches);
    for (size_t i = 0; s->slots && i < s->nslots; i++) {
        rad_worker_slot *sl = &s->slots[i];
        free(sl->z.depth), free(sl->z.owner), free(sl->z.stamp), free(sl->z.written), free(sl->pcls);
    }
    free(s->slots);
    free(s->stepwork);
    free(s);
}

void rad_solver_on_round(rad_solver *s, rad_round_fn fn, void *user)
{
    s->on_round = fn;
    s->on_round_user = user;
}

/* Collective: every process learns the output process's yes or no. A decision taken on
   a clock (is a checkpoint due?) would differ between processes, and a checkpoint is a
   collect every process must join; agreement carries rank 0's answer to all (an
   Allreduce when the answer is no, plus a Bcast when it is yes, once per round). */
static int output_says_yes(rad_solver *s, int yes)
{
    char msg[16] = "";
    vw_status mine = vw_world_is_output(s->w) && yes ? VW_E_STATE : VW_OK;
    return vw_world_agree(s->w, mine, msg, sizeof msg) != VW_OK;
}

/* The power the shots so far have spent (absorbed or let escape), r+g+b, as the last
   reports tell it (output process). */
static double lost_sum(const rad_solver *s)
{
    const rad_ledger *L = &s->ledger;
    return rad_sum3(L->absorbed) + rad_sum3(L->escaped);
}

/* The stall rule, after a round on every process: is it time to stop because the
   shots no longer spend the unshot power? Every stall_shots shots (the global count,
   which every process knows) the output process compares the power lost since the
   last check with sf of the emitted power, and all agree on its answer (one agreement
   a check, not one a round). A shot carries at least sf of the emitted power (the
   threshold), so a scene whose every shot absorbs or lets escape at least
   1/stall_shots of its power loses sf over the stretch and is never stopped; only a
   surface of reflectance (nearly) 1 in a closed scene keeps the power circulating, and
   there the largest patch's share may stay above sf for ever. The powers are the
   reports', which lag by a round (they describe the round's start), on both ends of
   the stretch alike. Walls change the rounds and the order of the shots, not the
   rule: every layout stops, within a round of each other. */
static int stall_check(rad_solver *s)
{
    int64_t every = s->opt.stall_shots > 0 ? s->opt.stall_shots : RAD_STALL_SHOTS;
    int out = vw_world_is_output(s->w);
    int64_t reported = s->base_shots + s->rep.nshots;
    if (out && s->stall_at_reported < 0) { /* the first round's reports: the run's start */
        s->stall_at_reported = reported;
        s->stall_lost_at = lost_sum(s);
    }
    if (s->shots - s->stall_at < every) return 0;
    s->stall_at = s->shots;
    /* A stretch the reports saw only part of (the first, after rounds larger than
       stall_shots) is too short to judge: the next check judges. */
    double lost = out ? lost_sum(s) - s->stall_lost_at : 0;
    int64_t span = reported - s->stall_at_reported;
    int yes = output_says_yes(s, out && span >= every / 2 && !(lost >= s->opt.sf * s->emitted_sum));
    if (out) {
        s->stall_span = span;
        s->stall_lost = s->emitted_sum > 0 ? lost / s->emitted_sum : 0;
        s->stall_at_reported = reported;
        s->stall_lost_at = lost_sum(s);
    }
    return yes;
}

int rad_solver_stalled(const rad_solver *s, int64_t *span, double *lost)
{
    if (span) *span = s->stall_span;
    if (lost) *lost = s->stall_lost;
    return s->stalled;
}

vw_status rad_solver_run(rad_solver *s, rad_progress_fn progress, void *user, int *converged,
                         char *err, size_t errlen)
{
    *converged = 0;
    int ncells = vw_decomp_cell_count(s->d);
    double last_ck = now();
    int rounds = 0;
    s->stalled = 0;
    s->stall_at = s->shots;
    s->stall_at_reported = -1;
    for (;;) {
        rad_go_msg g;
        memset(&g, 0, sizeof g);
        g.round = ++s->round;
        g.budget = s->opt.per_round > 0 ? s->opt.per_round : 1;
        g.thr = s->thr;
        if (s->opt.subdivide > 0) {
            g.sub_rel = s->opt.subdivide;
            g.sub_floor = 0.01 * s->opt.subdivide * s->emitted_sum / 3 / s->mesh->area;
            g.max_level = s->opt.max_level;
        }
        for (int c = 0; c < ncells; c++) vw_world_post(s->w, c, RAD_K_GO, &g);
        int64_t before = vw_world_counter(s->w, RAD_C_SHOTS);
        vw_status st = run_world(s, err, errlen);
        if (st != VW_OK) return st;
        int64_t after = vw_world_counter(s->w, RAD_C_SHOTS);
        s->shots = s->base_shots + after;
        rounds++;
        if (vw_world_is_output(s->w)) {
            update_ledger(s);
            /* The reports describe the start of this round: pair the ratio with the
               shots made by then, not with the count after the round. */
            if (progress) progress(user, s->ratio, s->base_shots + s->rep.nshots);
        }
        /* On every process: the hook may collect, which is a run everybody joins. */
        if (s->on_round) s->on_round(s->on_round_user, s, s->round);
        if (after == before) {
            *converged = 1;
            break;
        }
        if (s->opt.max_shots > 0 && s->shots >= s->opt.max_shots) break;
        if (stall_check(s)) {
            s->stalled = 1;
            break;
        }
        if (s->opt.checkpoint && output_says_yes(s, now() - last_ck >= s->opt.checkpoint_every)) {
            st = rad_solver_checkpoint(s, s->opt.checkpoint, err, errlen);
            if (st != VW_OK) return st;
            last_ck = now();
        }
        if (s->opt.max_rounds > 0 && rounds >= s->opt.max_rounds) break;
    }
    return VW_OK;
}

static int cmp_elem(const void *a, const void *b)
{
    const rad_elem_result *x = a, *y = b;
    if (x->piece != y->piece) return x->piece < y->piece ? -1 : 1;
    if (x->level != y->level) return x->level < y->level ? -1 : 1;
    if (x->gi != y->gi) return x->gi < y->gi ? -1 : 1;
    if (x->gj != y->gj) return x->gj < y->gj ? -1 : 1;
    return 0;
}

static int cmp_patch(const void *a, const void *b)
{
    const rad_patch_result *x = a, *y = b;
    return x->piece < y->piece ? -1 : x->piece > y->piece;
}

vw_status rad_solver_collect(rad_solver *s, char *err, size_t errlen)
{
    s->nelems = s->npatches = 0;
    s->collect_nomem = 0;
    rad_collect_msg m = {0, 0};
    int ncells = vw_decomp_cell_count(s->d);
    for (int c = 0; c < ncells; c++) vw_world_post(s->w, c, RAD_K_COLLECT, &m);
    vw_status st = run_world(s, err, errlen);
    if (st != VW_OK) return st;
    /* The output handlers' failure (rank 0's), agreed: every process joins the next
       collective step or none does. */
    char msg[160] = "";
    if (s->collect_nomem)
        snprintf(msg, sizeof msg, "out of memory (%zu bytes) collecting the solution",
                 s->collect_nomem);
    st = vw_world_agree(s->w, s->collect_nomem ? VW_E_NOMEM : VW_OK, msg, sizeof msg);
    if (st != VW_OK) {
        snprintf(err, errlen, "radiosity run failed: %s", msg);
        return st;
    }
    if (vw_world_is_output(s->w)) {
        qsort(s->elems, s->nelems, sizeof *s->elems, cmp_elem);
        qsort(s->patches, s->npatches, sizeof *s->patches, cmp_patch);
        update_ledger(s);
    }
    return VW_OK;
}

const rad_elem_result *rad_solver_elements(const rad_solver *s, size_t *n)
{
    *n = s->nelems;
    return s->elems;
}

const rad_patch_result *rad_solver_patches(const rad_solver *s, size_t *n)
{
    *n = s->npatches;
    return s->patches;
}

rad_ledger rad_solver_ledger(const rad_solver *s) { return s->ledger; }
int64_t rad_solver_shots(const rad_solver *s) { return s->shots; }
double rad_solver_unshot_ratio(const rad_solver *s) { return s->ratio; }
vw_world *rad_solver_world(rad_solver *s) { return s->w; }

void rad_solver_traffic(const rad_solver *s, int64_t *shot_msgs, int64_t *shot_bytes, int64_t *full_msgs)
{
    *shot_msgs = vw_world_counter(s->w, RAD_C_SHOT_MSGS);
    *shot_bytes = vw_world_counter(s->w, RAD_C_SHOT_BYTES);
    *full_msgs = vw_world_counter(s->w, RAD_C_FULL_MSGS);
}

vw_status rad_solver_checkpoint(rad_solver *s, const char *path, char *err, size_t errlen)
{
    vw_status st = rad_solver_collect(s, err, errlen);
    if (st != VW_OK) return st;
    if (vw_world_is_output(s->w)) st = rad_solver_write_checkpoint(s, path, err, errlen);
    /* A failed write fails every process, so none waits for the others' next round. */
    return vw_world_agree(s->w, st, err, errlen);
}

/* Writes the format described at ck_head (output process). */
vw_status rad_solver_write_checkpoint(const rad_solver *s, const char *path, char *err, size_t errlen)
{
    if (!vw_world_is_output(s->w)) return VW_OK;
    size_t len = CK_HEAD_BYTES + 8 + s->npatches * sizeof(rad_patch_result) + 8 +
                 s->nelems * sizeof(rad_elem_result) + 8;
    unsigned char *buf = malloc(len), *p = buf;
    if (!buf) return VW_E_NOMEM;
    ck_head h;
    ck_head_of(s, &h);
    uint64_t np = s->npatches, ne = s->nelems;
    ck_put(p, &h);
    p += CK_HEAD_BYTES;
#define PUT(x, n) (memcpy(p, (x), (n)), p += (n))
    PUT(&np, 8);
    PUT(s->patches, s->npatches * sizeof(rad_patch_result));
    PUT(&ne, 8);
    PUT(s->elems, s->nelems * sizeof(rad_elem_result));
    uint64_t sum = fnv(FNV_BASIS, buf, len - 8);
    PUT(&sum, 8);
#undef PUT
    vw_status st = vw_outfile_write(path, buf, len, err, errlen);
    free(buf);
    return st;
}

void rad_polygon_sums(const rad_elem_result *e, size_t n, size_t npoly, double *area,
                      double (*B)[3], double (*incident)[3])
{
    for (size_t i = 0; i < npoly; i++) {
        area[i] = 0;
        for (int k = 0; k < 3; k++) B[i][k] = incident[i][k] = 0;
    }
    for (size_t i = 0; i < n; i++) {
        if (e[i].poly < 0 || (size_t)e[i].poly >= npoly) continue;
        area[e[i].poly] += e[i].area;
        for (int k = 0; k < 3; k++) {
            B[e[i].poly][k] += e[i].B[k] * e[i].area;
            incident[e[i].poly][k] += e[i].incident[k];
        }
    }
    for (size_t i = 0; i < npoly; i++)
        if (area[i] > 0)
            for (int k = 0; k < 3; k++) B[i][k] /= area[i];
}
