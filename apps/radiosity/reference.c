/* reference.c - the full-matrix reference for the progressive solver (bench and tests):
 * hemicube form factors from every patch to every patch on one cell, then the system
 * P = E + diag(rho) F^T P solved by Gauss-Seidel to convergence.
 *
 * The form factors are a shot's (module.c, process_shot) with one cell and nothing
 * upstream: the same hemicube and delta form factors, the same orientation (that of
 * the patch's first shot), the same culling of patches behind the shooter plane, the
 * same per-pixel nearest element, and the same facing rule (an element hit from behind
 * absorbs, so it gets no form factor). A shot's power reaches element e with the delta
 * form factors of the pixels it wins, and what e reflects joins its patch's unshot
 * power; so with P_j the power leaving patch j (emitted plus reflected) and F_kj the sum
 * over j's elements of what k's hemicube gives them, the converged progressive solution
 * solves P_j = E_j A_j + rho_j sum_k F_kj P_k, and a polygon's radiosity is the sum of
 * its patches' P over its area. Progressive refinement differs from this only by the
 * power it leaves unshot and by turning the hemicube between shots of a patch.
 *
 * Dense: n^2 doubles for n patches (the furnished room meshed into 3952: 125 MB).
 */
#include "radiosity/radiosity.h"
#include "radiosity/vec.h"

#include <math.h>
#include <stdint.h>
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

/* Level-0 receiver elements of every piece, made exactly as cell_build makes them. */
typedef struct elems {
    size_t n, cap, nv, capv;
    int64_t *piece;
    int *vfirst, *nvert;
    double (*v)[3];
} elems;

static int elems_add(elems *E, int64_t piece, const rad_poly *p)
{
    if (E->n == E->cap) {
        size_t c = E->cap ? 2 * E->cap : 1024;
        int64_t *a = realloc(E->piece, sizeof *a * c);
        if (a) E->piece = a;
        int *b = realloc(E->vfirst, sizeof *b * c);
        if (b) E->vfirst = b;
        int *d = realloc(E->nvert, sizeof *d * c);
        if (d) E->nvert = d;
        if (!a || !b || !d) return -1;
        E->cap = c;
    }
    if (E->nv + (size_t)p->n > E->capv) {
        size_t c = E->capv ? 2 * E->capv : 4096;
        while (E->nv + (size_t)p->n > c) c *= 2;
        double (*v)[3] = realloc(E->v, sizeof *v * c);
        if (!v) return -1;
        E->v = v, E->capv = c;
    }
    E->piece[E->n] = piece;
    E->vfirst[E->n] = (int)E->nv;
    E->nvert[E->n] = p->n;
    memcpy(E->v + E->nv, p->v, sizeof(double) * 3 * (size_t)p->n);
    E->nv += (size_t)p->n;
    E->n++;
    return 0;
}

static void elems_free(elems *E) { free(E->piece), free(E->vfirst), free(E->nvert), free(E->v); }

void rad_reference_free(rad_reference *r)
{
    if (r) free(r->P);
}

vw_status rad_reference_solve(const rad_mesh *m, const vw_box *world, int res, double tol, int max_sweeps,
                              rad_reference *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    size_t n = m->npieces;
    if (n == 0 || n > ((size_t)1 << 31) || n > SIZE_MAX / sizeof(double) / n) {
        snprintf(err, errlen, "%zu patches: no matrix of that size", n);
        return VW_E_LIMIT;
    }
    rad_hemicube hc;
    if (rad_hemicube_init(&hc, res) != VW_OK) {
        snprintf(err, errlen, "--hemicube %d: must be even and between 2 and %d", res, RAD_MAX_RES);
        return VW_E_INVAL;
    }
    double t0 = now();
    out->n = n;
    out->matrix_bytes = n * n * sizeof(double);
    /* G[j*n + k]: form factor from shooter k to receiver patch j (rows are receivers,
       so a Gauss-Seidel update reads one contiguous row). */
    double *G = calloc(n * n, sizeof *G);
    elems E;
    memset(&E, 0, sizeof E);
    size_t np = (size_t)hc.npix;
    double *depth = malloc(sizeof(double) * np);
    int32_t *owner = malloc(sizeof(int32_t) * np);
    uint32_t *stamp = calloc(np, sizeof(uint32_t));
    uint8_t *mask = calloc(rad_hemicube_bitmap_bytes(res), 1);
    char *pvis = malloc(n);
    out->P = calloc(n, sizeof *out->P);
    vw_status st = VW_OK;
    if (!G || !depth || !owner || !stamp || !mask || !pvis || !out->P) {
        snprintf(err, errlen, "%zu patches: out of memory for the %.0f MB matrix", n, out->matrix_bytes / 1e6);
        st = VW_E_NOMEM;
        goto done;
    }
    for (size_t j = 0; j < n && st == VW_OK; j++) {
        const rad_piece *pc = &m->pieces[j];
        int lo[2], hi[2];
        rad_piece_grid(pc, lo, hi);
        for (int gi = lo[0]; gi <= hi[0]; gi++)
            for (int gj = lo[1]; gj <= hi[1]; gj++) {
                rad_poly p;
                if (rad_elem_polygon(pc, 0, gi, gj, &p) < 3) continue;
                if (!(rad_poly_area(&p, NULL, NULL) > 1e-14 * pc->area)) continue;
                if (elems_add(&E, (int64_t)j, &p)) {
                    snprintf(err, errlen, "out of memory for the elements");
                    st = VW_E_NOMEM;
                }
            }
    }
    if (st != VW_OK) goto done;
    double *won = calloc(E.n ? E.n : 1, sizeof *won);
    int *touched = malloc(sizeof(int) * (E.n ? E.n : 1));
    if (!won || !touched) {
        free(won), free(touched);
        snprintf(err, errlen, "out of memory for the elements");
        st = VW_E_NOMEM;
        goto done;
    }
    double ext = 0;
    for (int a = 0; a < 3; a++) ext = fmax(ext, world->hi[a] - world->lo[a]);
    const double eps = 1e-9 * ext;
    rad_zbuf z = {depth, owner, stamp, 0};
    for (size_t k = 0; k < n; k++) {
        const rad_piece *sh = &m->pieces[k];
        double ax[3][3];
        rad_hemicube_orientation(sh->normal, rad_shot_seed(sh->id, 0), ax[0]);
        rad_cross(sh->normal, ax[0], ax[1]);
        memcpy(ax[2], sh->normal, sizeof ax[2]);
        z.cur++;
        for (size_t j = 0; j < n; j++) {
            const rad_piece *pc = &m->pieces[j];
            pvis[j] = 0;
            if (j == k) continue;
            for (int i = 0; i < pc->nv && !pvis[j]; i++) {
                double r[3];
                rad_sub(pc->v[i], sh->centroid, r);
                pvis[j] = rad_dot(r, sh->normal) > eps;
            }
        }
        for (size_t e = 0; e < E.n; e++) {
            if (!pvis[E.piece[e]]) continue;
            double hv[RAD_MAXV][3];
            int front = 0;
            for (int i = 0; i < E.nvert[e]; i++) {
                double r[3];
                rad_sub(E.v[E.vfirst[e] + i], sh->centroid, r);
                for (int a = 0; a < 3; a++) hv[i][a] = rad_dot(r, ax[a]);
                front |= hv[i][2] > eps;
            }
            if (front) rad_hemicube_raster(&hc, (const double(*)[3])hv, E.nvert[e], mask, &z, (int32_t)e, eps);
        }
        int nt = 0;
        for (size_t px = 0; px < np; px++) {
            if (stamp[px] != z.cur) continue;
            int e = owner[px];
            if (won[e] == 0) touched[nt++] = e;
            won[e] += hc.dff[px];
        }
        for (int t = 0; t < nt; t++) {
            int e = touched[t];
            size_t j = (size_t)E.piece[e];
            double r[3];
            rad_sub(sh->centroid, E.v[E.vfirst[e]], r);
            if (rad_dot(r, m->pieces[j].normal) > 0) G[j * n + k] += won[e];
            won[e] = 0;
        }
    }
    free(won), free(touched);
    double t1 = now();
    out->ff_s = t1 - t0;

    /* Gauss-Seidel on the power leaving each patch, all three channels per sweep. */
    double emitted = rad_sum3(m->emitted);
    for (size_t j = 0; j < n; j++)
        for (int c = 0; c < 3; c++) out->P[j][c] = m->pieces[j].emit[c] * m->pieces[j].area;
    out->change = INFINITY;
    while (out->sweeps < max_sweeps && !(out->change < tol)) {
        double change = 0;
        for (size_t j = 0; j < n; j++) {
            const rad_piece *pc = &m->pieces[j];
            const double *row = G + j * n;
            double s0 = 0, s1 = 0, s2 = 0;
            for (size_t k = 0; k < n; k++) {
                s0 += row[k] * out->P[k][0];
                s1 += row[k] * out->P[k][1];
                s2 += row[k] * out->P[k][2];
            }
            double s[3] = {s0, s1, s2};
            for (int c = 0; c < 3; c++) {
                double v = pc->emit[c] * pc->area + pc->rho[c] * s[c];
                change = fmax(change, fabs(v - out->P[j][c]));
                out->P[j][c] = v;
            }
        }
        out->change = change / emitted;
        out->sweeps++;
    }
    out->solve_s = now() - t1;
    if (!(out->change < tol)) {
        snprintf(err, errlen, "Gauss-Seidel did not converge in %d sweeps (change %.3g)", max_sweeps,
                 out->change);
        st = VW_E_LIMIT;
    }
done:
    free(G), free(depth), free(owner), free(stamp), free(mask), free(pvis);
    elems_free(&E);
    rad_hemicube_free(&hc);
    if (st != VW_OK) rad_reference_free(out), out->P = NULL;
    return st;
}

rad_elem_result *rad_reference_elements(const rad_mesh *m, const rad_reference *r)
{
    rad_elem_result *e = calloc(r->n ? r->n : 1, sizeof *e);
    if (!e) return NULL;
    for (size_t j = 0; j < r->n; j++) {
        const rad_piece *pc = &m->pieces[j];
        e[j].piece = pc->id;
        e[j].poly = pc->poly;
        e[j].area = pc->area;
        for (int c = 0; c < 3; c++) e[j].B[c] = r->P[j][c] / pc->area;
    }
    return e;
}
