/* output.c - what the radiosity solver writes: a vertex-coloured PLY, a per-polygon CSV
 * and a picture from a camera (its own small z-buffer rasteriser of the elements,
 * Gouraud shaded), as PNG or as PFM (the same picture in linear radiosity, not tone
 * mapped). Every file is written through vw_outfile (vwalls/outfile.h): complete under
 * its name or not at all.
 *
 * Display colours: radiosity plus the ambient term of progressive refinement (the
 * unshot power spread evenly, Cohen et al. 1988) for display only, scaled so that the
 * 95th percentile of the non-emitting elements maps to 0.85, gamma 2.2.
 */
#include "radiosity/radiosity.h"
#include "radiosity/vec.h"

#include <stdarg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "vwalls/image.h"
#include "vwalls/outfile.h"

/* A growing text buffer. */
typedef struct sbuf {
    char *s;
    size_t n, cap;
    int oom;
} sbuf;

static void sb_printf(sbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void sb_printf(sbuf *b, const char *fmt, ...)
{
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int k = vsnprintf(b->s ? b->s + b->n : NULL, b->s ? b->cap - b->n : 0, fmt, ap);
        va_end(ap);
        if (k < 0) return;
        if (b->s && b->n + (size_t)k < b->cap) {
            b->n += (size_t)k;
            return;
        }
        size_t nc = b->cap ? 2 * b->cap : 1 << 16;
        while (nc < b->n + (size_t)k + 1) nc *= 2;
        char *ns = realloc(b->s, nc);
        if (!ns) {
            b->oom = 1;
            return;
        }
        b->s = ns, b->cap = nc;
    }
}

void rad_ambient(const rad_mesh *m, const rad_patch_result *p, size_t np, double out[3])
{
    double rho[3] = {0, 0, 0}, un[3] = {0, 0, 0};
    for (size_t i = 0; i < m->npieces; i++)
        for (int k = 0; k < 3; k++) rho[k] += m->pieces[i].rho[k] * m->pieces[i].area;
    for (size_t i = 0; i < np; i++)
        for (int k = 0; k < 3; k++) un[k] += p[i].unshot[k];
    for (int k = 0; k < 3; k++) {
        double r = m->area > 0 ? rho[k] / m->area : 0;
        out[k] = m->area > 0 ? un[k] / m->area / (1 - fmin(r, 0.999)) : 0;
    }
}

/* Per element vertex: display radiosity averaged over the elements of the same polygon
   meeting at that point (so the PLY and the image are smooth inside a polygon). */
typedef struct vkey {
    int32_t poly;
    int64_t q[3];
    size_t slot;
} vkey;

static int cmp_vkey(const void *a, const void *b)
{
    const vkey *x = a, *y = b;
    if (x->poly != y->poly) return x->poly < y->poly ? -1 : 1;
    for (int k = 0; k < 3; k++)
        if (x->q[k] != y->q[k]) return x->q[k] < y->q[k] ? -1 : 1;
    return 0;
}

typedef struct shaded {
    size_t n;             /* elements */
    size_t *first;        /* first vertex slot of element i */
    int *nv;
    double (*v)[3];       /* slot positions */
    float (*col)[3];      /* slot colours, 0..1 after tone mapping */
} shaded;

static void shaded_free(shaded *s)
{
    free(s->first), free(s->nv), free(s->v), free(s->col);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The slots at the vertex key of point x in polygon poly: [*lo, *hi) of keys, found
   with a tolerance of one quantum per axis (x comes from interpolation, not clipping). */
static int find_key(const vkey *keys, size_t ns, int32_t poly, const double x[3], double quant, size_t *lo,
                    size_t *hi)
{
    vkey k;
    k.poly = poly;
    int64_t q0[3];
    for (int a = 0; a < 3; a++) q0[a] = (int64_t)llround(x[a] / quant);
    for (int d = 0; d < 27; d++) {
        for (int a = 0; a < 3; a++) k.q[a] = q0[a] + (d / (a == 0 ? 1 : a == 1 ? 3 : 9)) % 3 - 1;
        size_t l = 0, h = ns;
        while (l < h) {
            size_t mid = (l + h) / 2;
            if (cmp_vkey(&keys[mid], &k) < 0) l = mid + 1;
            else h = mid;
        }
        if (l < ns && cmp_vkey(&keys[l], &k) == 0) {
            size_t r = l;
            while (r < ns && cmp_vkey(&keys[r], &k) == 0) r++;
            *lo = l, *hi = r;
            return 1;
        }
    }
    return 0;
}

/* After subdivision a fine element's corner can lie inside the edge of a coarser
   neighbour (a T-junction). Averaging alone leaves a crack in the shading there: the
   coarse element interpolates its edge between its two corners, the fine ones use the
   T-vertex's own value. So every vertex inside the edge of a coarser element of the same
   polygon takes the value interpolated along that edge; elements are visited coarse to
   fine, so a T-vertex on an edge whose corner is itself a T-vertex follows the coarser
   edge too. Only edges along the polygon's grid (u or v constant) can hold T-vertices.
   Display only: the radiosities in the results are untouched. */
static void fix_t_junctions(const rad_mesh *m, const rad_elem_result *e, size_t n, const shaded *sh,
                            const vkey *keys, size_t ns, double quant, double (*lin)[3])
{
    int32_t maxl = 0;
    for (size_t i = 0; i < n; i++) maxl = e[i].level > maxl ? e[i].level : maxl;
    if (maxl == 0) return;
    /* The finest have no finer neighbours. */
    for (int32_t lev = 0; lev < maxl; lev++) {
        for (size_t i = 0; i < n; i++) {
            if (e[i].level != lev) continue;
            const rad_piece *pc = &m->pieces[e[i].piece];
            if (rad_sum3(pc->emit) > 0) continue;
            double hf = pc->elem / (double)(1 << maxl);
            int nv = sh->nv[i];
            for (int v = 0; v < nv; v++) {
                size_t sa = sh->first[i] + (size_t)v, sb = sh->first[i] + (size_t)((v + 1) % nv);
                const double *A = sh->v[sa], *B = sh->v[sb];
                double da[3], db[3];
                rad_sub(A, pc->origin, da);
                rad_sub(B, pc->origin, db);
                double ua = rad_dot(da, pc->uax) / hf, va = rad_dot(da, pc->vax) / hf;
                double ub = rad_dot(db, pc->uax) / hf, vb = rad_dot(db, pc->vax) / hf;
                double ta, tb;
                if (fabs(va - vb) < 1e-6) ta = ua, tb = ub;
                else if (fabs(ua - ub) < 1e-6) ta = va, tb = vb;
                else continue;
                double lo = fmin(ta, tb), hi = fmax(ta, tb);
                for (double g = floor(lo + 1e-6) + 1; g < hi - 1e-6; g += 1) {
                    double t = (g - ta) / (tb - ta), x[3];
                    for (int k = 0; k < 3; k++) x[k] = A[k] + t * (B[k] - A[k]);
                    size_t l, h;
                    if (!find_key(keys, ns, e[i].poly, x, quant, &l, &h)) continue;
                    for (size_t c = l; c < h; c++)
                        for (int k = 0; k < 3; k++) lin[keys[c].slot][k] = (1 - t) * lin[sa][k] + t * lin[sb][k];
                }
            }
        }
    }
}

/* linear: col holds the display radiosity itself (for PFM); else tone-mapped 0..1. */
static int shade(const rad_mesh *m, const rad_elem_result *e, size_t n, const double amb[3], int linear,
                 shaded *out)
{
    memset(out, 0, sizeof *out);
    out->n = n;
    out->first = malloc(sizeof(size_t) * (n + 1));
    out->nv = malloc(sizeof(int) * (n ? n : 1));
    size_t cap = n * 6 + 16, ns = 0;
    out->v = malloc(sizeof *out->v * cap);
    double (*rad)[3] = malloc(sizeof *rad * (n ? n : 1));
    if (!out->first || !out->nv || !out->v || !rad) goto oom;
    double ext = 0;
    for (size_t i = 0; i < m->npieces; i++)
        for (int k = 0; k < 3; k++) ext = fmax(ext, fabs(m->pieces[i].centroid[k]));
    double quant = 1e-7 * (ext > 0 ? ext : 1);
    /* Display radiosity per element, and the exposure from non-emitters. */
    double *lum = malloc(sizeof(double) * (n ? n : 1));
    size_t nl = 0;
    if (!lum) goto oom;
    for (size_t i = 0; i < n; i++) {
        const rad_piece *pc = &m->pieces[e[i].piece];
        for (int k = 0; k < 3; k++) rad[i][k] = e[i].B[k] + pc->rho[k] * amb[k];
        if (rad_sum3(pc->emit) == 0) lum[nl++] = rad_sum3(rad[i]) / 3;
    }
    double expo = 1;
    if (nl) {
        qsort(lum, nl, sizeof(double), cmp_double);
        double p95 = lum[(size_t)(0.95 * (double)(nl - 1))];
        expo = p95 > 0 ? 0.85 / p95 : 1;
    }
    free(lum);
    for (size_t i = 0; i < n; i++) {
        rad_poly poly;
        const rad_piece *pc = &m->pieces[e[i].piece];
        int k = rad_elem_polygon(pc, e[i].level, e[i].gi, e[i].gj, &poly);
        if (ns + (size_t)k > cap) {
            while (ns + (size_t)k > cap) cap *= 2;
            void *nv = realloc(out->v, sizeof *out->v * cap);
            if (!nv) goto oom;
            out->v = nv;
        }
        out->first[i] = ns;
        out->nv[i] = k;
        memcpy(out->v + ns, poly.v, sizeof(double) * 3 * (size_t)k);
        ns += (size_t)k;
    }
    out->first[n] = ns;
    vkey *keys = malloc(sizeof *keys * (ns ? ns : 1));
    size_t *owner = malloc(sizeof(size_t) * (ns ? ns : 1));
    out->col = malloc(sizeof *out->col * (ns ? ns : 1));
    if (!keys || !owner || !out->col) {
        free(keys), free(owner);
        goto oom;
    }
    for (size_t i = 0; i < n; i++)
        for (size_t s = out->first[i]; s < out->first[i + 1]; s++) {
            keys[s].poly = e[i].poly;
            for (int k = 0; k < 3; k++) keys[s].q[k] = (int64_t)llround(out->v[s][k] / quant);
            keys[s].slot = s;
            owner[s] = i;
        }
    qsort(keys, ns, sizeof *keys, cmp_vkey);
    double (*lin)[3] = malloc(sizeof *lin * (ns ? ns : 1));
    if (!lin) {
        free(keys), free(owner);
        goto oom;
    }
    for (size_t a = 0; a < ns;) {
        size_t b = a;
        double acc[3] = {0, 0, 0}, w = 0;
        while (b < ns && cmp_vkey(&keys[a], &keys[b]) == 0) {
            size_t i = owner[keys[b].slot];
            for (int k = 0; k < 3; k++) acc[k] += rad[i][k] * e[i].area;
            w += e[i].area;
            b++;
        }
        for (size_t c = a; c < b; c++) {
            size_t i = owner[keys[c].slot];
            const rad_piece *pc = &m->pieces[e[i].piece];
            /* Emitters keep their own colour (a light is not blurred into its frame). */
            for (int k = 0; k < 3; k++) lin[keys[c].slot][k] = rad_sum3(pc->emit) > 0 ? rad[i][k] : acc[k] / w;
        }
        a = b;
    }
    fix_t_junctions(m, e, n, out, keys, ns, quant, lin);
    for (size_t sl = 0; sl < ns; sl++)
        for (int k = 0; k < 3; k++) {
            double x = fmin(fmax(lin[sl][k] * expo, 0), 1);
            out->col[sl][k] = linear ? (float)lin[sl][k] : (float)pow(x, 1 / 2.2);
        }
    free(lin);
    free(keys), free(owner), free(rad);
    return 0;
oom:
    free(rad);
    shaded_free(out);
    return -1;
}

vw_status rad_write_ply(const char *path, const rad_mesh *m, const rad_elem_result *e, size_t n,
                        const double ambient[3], char *err, size_t errlen)
{
    shaded sh;
    if (shade(m, e, n, ambient, 0, &sh)) return VW_E_NOMEM;
    sbuf b = {0};
    size_t nv = sh.first[n];
    sb_printf(&b, "ply\nformat ascii 1.0\ncomment vwalls radiosity: %zu elements\n"
                  "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n"
                  "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                  "element face %zu\nproperty list uchar int vertex_indices\nend_header\n",
              n, nv, n);
    for (size_t s = 0; s < nv; s++)
        sb_printf(&b, "%.9g %.9g %.9g %d %d %d\n", sh.v[s][0], sh.v[s][1], sh.v[s][2],
                  (int)lround(255 * sh.col[s][0]), (int)lround(255 * sh.col[s][1]),
                  (int)lround(255 * sh.col[s][2]));
    for (size_t i = 0; i < n; i++) {
        sb_printf(&b, "%d", sh.nv[i]);
        for (int k = 0; k < sh.nv[i]; k++) sb_printf(&b, " %zu", sh.first[i] + (size_t)k);
        sb_printf(&b, "\n");
    }
    shaded_free(&sh);
    vw_status st = b.oom ? VW_E_NOMEM : vw_outfile_write(path, b.s, b.n, err, errlen);
    free(b.s);
    return st;
}

vw_status rad_write_csv(const char *path, const rad_mesh *m, const vw_scene *sc,
                        const rad_elem_result *e, size_t n, char *err, size_t errlen)
{
    size_t np = m->npolys;
    double *area = malloc(sizeof(double) * (np ? np : 1));
    double (*B)[3] = malloc(sizeof *B * (np ? np : 1)), (*inc)[3] = malloc(sizeof *inc * (np ? np : 1));
    if (!area || !B || !inc) {
        free(area), free(B), free(inc);
        return VW_E_NOMEM;
    }
    rad_polygon_sums(e, n, np, area, B, inc);
    sbuf b = {0};
    sb_printf(&b, "polygon,area,rho_r,rho_g,rho_b,emit_r,emit_g,emit_b,B_r,B_g,B_b\n");
    for (size_t k = 0; k < sc->npolygons; k++) {
        const vw_polygon *pg = &sc->polygons[k];
        if (pg->id < 0 || (size_t)pg->id >= np || area[pg->id] <= 0) continue;
        const vw_material *mt =
            pg->material >= 0 && (size_t)pg->material < sc->nmaterials ? &sc->materials[pg->material] : NULL;
        double rho[3], emit[3];
        rad_material(mt, rho, emit); /* what the solver used, not what the file said */
        sb_printf(&b, "%d,%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.9g,%.9g,%.9g\n", pg->id, area[pg->id],
                  rho[0], rho[1], rho[2], emit[0], emit[1], emit[2], B[pg->id][0], B[pg->id][1],
                  B[pg->id][2]);
        area[pg->id] = 0; /* once per polygon */
    }
    /* Spheres and cones, each summed over its facets (their ids are the mesh's own). */
    size_t nobj = m->nfacets ? (size_t)m->facet_base : 0;
    double *oa = calloc(nobj ? nobj : 1, sizeof *oa), (*oB)[3] = calloc(nobj ? nobj : 1, sizeof *oB);
    if (!oa || !oB) b.oom = 1;
    for (size_t j = 0; oa && oB && j < m->nfacets; j++) {
        size_t id = (size_t)m->facet_base + j;
        int32_t obj = m->facet_object[j];
        if (id >= np || obj < 0 || (size_t)obj >= nobj) continue;
        oa[obj] += area[id];
        for (int k = 0; k < 3; k++) oB[obj][k] += B[id][k] * area[id];
    }
    for (size_t k = 0; oa && oB && k < sc->nspheres + sc->ncones; k++) {
        int id = k < sc->nspheres ? sc->spheres[k].id : sc->cones[k - sc->nspheres].id;
        int mi = k < sc->nspheres ? sc->spheres[k].material : sc->cones[k - sc->nspheres].material;
        if (id < 0 || (size_t)id >= nobj || oa[id] <= 0) continue;
        const vw_material *mt = mi >= 0 && (size_t)mi < sc->nmaterials ? &sc->materials[mi] : NULL;
        double rho[3], emit[3];
        rad_material(mt, rho, emit);
        sb_printf(&b, "%d,%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.9g,%.9g,%.9g\n", id, oa[id], rho[0], rho[1],
                  rho[2], emit[0], emit[1], emit[2], oB[id][0] / oa[id], oB[id][1] / oa[id], oB[id][2] / oa[id]);
    }
    free(oa), free(oB);
    free(area), free(B), free(inc);
    vw_status st = b.oom ? VW_E_NOMEM : vw_outfile_write(path, b.s, b.n, err, errlen);
    free(b.s);
    return st;
}

/* ---- the image: perspective z-buffer over triangles with Gouraud colour ---- */

/* Relative depth handicap of an element seen from behind (float depths: 8 ulps). */
#define RAD_IMAGE_BACK_BIAS 1e-6

vw_status rad_write_image(const char *path, const vw_camera *cam, const rad_mesh *m,
                          const rad_elem_result *e, size_t n, const double ambient[3], char *err,
                          size_t errlen)
{
    int W = cam->width > 0 ? cam->width : 512, H = cam->height > 0 ? cam->height : 512;
    vw_image_format format = vw_image_format_of(path);
    if (format == VW_IMAGE_NONE) {
        snprintf(err, errlen, "%s: the picture must end in .png or .pfm", path);
        return VW_E_INVAL;
    }
    int pfm = format == VW_IMAGE_PFM;
    shaded sh;
    if (shade(m, e, n, ambient, pfm, &sh)) return VW_E_NOMEM;
    float *zb = malloc(sizeof(float) * (size_t)W * (size_t)H);
    uint8_t *img = pfm ? NULL : calloc((size_t)W * (size_t)H * 3, 1);
    float *fimg = pfm ? calloc((size_t)W * (size_t)H * 3, sizeof(float)) : NULL;
    if (!zb || (!img && !fimg)) {
        free(zb), free(img), free(fimg), shaded_free(&sh);
        return VW_E_NOMEM;
    }
    for (size_t i = 0; i < (size_t)W * (size_t)H; i++) zb[i] = INFINITY;
    double fw[3], rt[3], up[3];
    rad_sub(cam->at, cam->from, fw);
    rad_normalize(fw);
    rad_cross(fw, cam->up, rt);
    if (!rad_normalize(rt)) rt[0] = 1, rt[1] = rt[2] = 0;
    rad_cross(rt, fw, up);
    double f = 1 / tan(0.5 * (cam->angle > 0 ? cam->angle : 45) * M_PI / 180);
    double hither = cam->hither > 0 ? cam->hither : 1e-3;
    for (size_t i = 0; i < n; i++) {
        /* Camera space (x right, y up, z forward), clipped at the near plane. */
        double P[RAD_MAXV + 2][6], Q[RAD_MAXV + 2][6];
        int nv = sh.nv[i], nq = 0;
        /* Seen from behind, an element loses a depth tie (RAD_IMAGE_BACK_BIAS relative,
           above float rounding) to one seen from the front: a two-sided panel (two
           coincident polygons back to back) showed the side listed first in the
           scene, from both sides. */
        double bias = 1;
        if (e[i].piece >= 0 && (size_t)e[i].piece < m->npieces && nv > 0) {
            double r0[3];
            rad_sub(cam->from, sh.v[sh.first[i]], r0);
            if (!(rad_dot(r0, m->pieces[e[i].piece].normal) > 0)) bias = 1 + RAD_IMAGE_BACK_BIAS;
        }
        for (int k = 0; k < nv; k++) {
            double r[3];
            rad_sub(sh.v[sh.first[i] + k], cam->from, r);
            P[k][0] = rad_dot(r, rt), P[k][1] = rad_dot(r, up), P[k][2] = rad_dot(r, fw);
            for (int c = 0; c < 3; c++) P[k][3 + c] = sh.col[sh.first[i] + k][c];
        }
        for (int k = 0; k < nv; k++) {
            const double *s = P[k], *t = P[(k + 1) % nv];
            double ds = s[2] - hither, dt = t[2] - hither;
            if (ds >= 0) memcpy(Q[nq++], s, sizeof Q[0]);
            if ((ds >= 0) != (dt >= 0)) {
                double a = ds / (ds - dt);
                for (int c = 0; c < 6; c++) Q[nq][c] = s[c] + a * (t[c] - s[c]);
                nq++;
            }
        }
        if (nq < 3) continue;
        double X[RAD_MAXV + 2], Y[RAD_MAXV + 2], iz[RAD_MAXV + 2];
        for (int k = 0; k < nq; k++) {
            iz[k] = 1 / Q[k][2];
            X[k] = 0.5 * W + 0.5 * H * f * Q[k][0] * iz[k];
            Y[k] = 0.5 * H - 0.5 * H * f * Q[k][1] * iz[k];
        }
        for (int t = 1; t + 1 < nq; t++) {
            int a = 0, b = t, c = t + 1;
            double area = (X[b] - X[a]) * (Y[c] - Y[a]) - (X[c] - X[a]) * (Y[b] - Y[a]);
            if (area == 0) continue;
            int x0 = (int)fmax(0, floor(fmin(X[a], fmin(X[b], X[c])))),
                x1 = (int)fmin(W - 1, ceil(fmax(X[a], fmax(X[b], X[c]))));
            int y0 = (int)fmax(0, floor(fmin(Y[a], fmin(Y[b], Y[c])))),
                y1 = (int)fmin(H - 1, ceil(fmax(Y[a], fmax(Y[b], Y[c]))));
            for (int y = y0; y <= y1; y++)
                for (int x = x0; x <= x1; x++) {
                    double px = x + 0.5, py = y + 0.5;
                    double w0 = ((X[b] - px) * (Y[c] - py) - (X[c] - px) * (Y[b] - py)) / area;
                    double w1 = ((X[c] - px) * (Y[a] - py) - (X[a] - px) * (Y[c] - py)) / area;
                    double w2 = 1 - w0 - w1;
                    if (w0 < -1e-9 || w1 < -1e-9 || w2 < -1e-9) continue;
                    /* Perspective-correct: interpolate attribute/z and 1/z. */
                    double izp = w0 * iz[a] + w1 * iz[b] + w2 * iz[c];
                    float depth = (float)(bias / izp);
                    size_t pix = (size_t)y * (size_t)W + (size_t)x;
                    if (!(depth < zb[pix])) continue;
                    zb[pix] = depth;
                    for (int ch = 0; ch < 3; ch++) {
                        double v = (w0 * Q[a][3 + ch] * iz[a] + w1 * Q[b][3 + ch] * iz[b] +
                                    w2 * Q[c][3 + ch] * iz[c]) / izp;
                        if (pfm) fimg[3 * pix + (size_t)ch] = (float)v;
                        else img[3 * pix + (size_t)ch] = (uint8_t)lround(255 * fmin(fmax(v, 0), 1));
                    }
                }
        }
    }
    vw_status st = pfm ? vw_image_write_pfm(path, W, H, fimg, err, errlen)
                       : vw_image_write_png(path, W, H, img, err, errlen);
    free(zb), free(img), free(fimg), shaded_free(&sh);
    return st;
}
