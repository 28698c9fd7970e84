/* tensor.c - the tensor balancer (the paper's "division by hyperplanes in all
 * dimensions", walls moved as whole hyperplanes) and frame rotation ("rotating the
 * scene": the principal axis of the load made axis-parallel, then tensor; of the
 * candidate frames, and the unrotated one, the one predicting the lowest lambda wins).
 *
 * Tensor keeps a grid a grid: every cell keeps exactly one neighbour per face, because
 * a wall is moved as a whole. Per axis, the walls go where the marginal load (the load
 * projected onto that axis) splits into equal slabs (or, where the workers hold unequal
 * numbers of cells or differ in speed, slabs at their cells' shares: vw__balance_shaped,
 * chosen by vw_balance_world); load that is concentrated in one
 * corner therefore cannot be evened out per cell, which is what rotation and the
 * staggered balancer improve on.
 */
#include "balance/balance_internal.h"
#include "vwalls/map.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

vw_status vw__tensor_walls(const vw_load_field *f, const double *F, const vw_box *wb,
                           const int dims[3], double minw_frac, const double *share,
                           double *walls[3], int *fits)
{
    vw__lpt *pts;
    *fits = 1;
    long n = vw__field_points(f, F, &pts);
    if (n < 0) return VW_E_NOMEM;
    double *slab = NULL;
    if (share) {
        int most = dims[0] > dims[1] ? dims[0] : dims[1];
        most = most > dims[2] ? most : dims[2];
        if (!(slab = malloc(sizeof(double) * (size_t)most))) {
            free(pts);
            return VW_E_NOMEM;
        }
    }
    for (int a = 0; a < 3; a++) {
        if (dims[a] < 2) continue;
        /* A slab's share: its cells' (the wall is one for the whole slab). */
        for (int i = 0; slab && i < dims[a]; i++) slab[i] = 0;
        for (long c = 0; slab && c < (long)dims[0] * dims[1] * dims[2]; c++) {
            long ix[3] = {c % dims[0], (c / dims[0]) % dims[1], c / ((long)dims[0] * dims[1])};
            slab[ix[a]] += share[c];
        }
        double ext = wb->hi[a] - wb->lo[a];
        if (!vw__cut_shares(pts, n, a, wb->lo[a], wb->hi[a], dims[a], slab, minw_frac * ext,
                            walls[a]))
            *fits = 0;
    }
    free(slab);
    free(pts);
    return VW_OK;
}

/* The tensor walls in frame F over wb as a grid; *out NULL (and VW_OK) when they do not
   fit: wb is too thin on some axis for its cells at the resolution of the doubles. */
static vw_status tensor_in_frame(const vw_load_field *f, const double *F, const vw_box *wb,
                                 const int dims[3], double minw, const double *share,
                                 vw_decomp **out)
{
    double *walls[3] = {0};
    vw_status st = VW_OK;
    int fits = 0;
    *out = NULL;
    for (int a = 0; a < 3 && st == VW_OK; a++) {
        walls[a] = malloc(sizeof(double) * (size_t)(dims[a] > 1 ? dims[a] - 1 : 1));
        if (!walls[a]) st = VW_E_NOMEM;
    }
    if (st == VW_OK) st = vw__tensor_walls(f, F, wb, dims, minw, share, walls, &fits);
    if (st == VW_OK && fits) {
        const double *cw[3] = {walls[0], walls[1], walls[2]};
        st = vw_decomp_create_grid_walls(wb, dims, cw, F, out);
    }
    for (int a = 0; a < 3; a++) free(walls[a]);
    return st;
}

/* The world box in world coordinates' corners, as points (vw_decomp_from_frame). */
static void world_corners(const vw_decomp *cur, double P[8][3])
{
    vw_box b = vw_decomp_world(cur);
    for (int i = 0; i < 8; i++) {
        double q[3] = {(i & 1) ? b.hi[0] : b.lo[0], (i & 2) ? b.hi[1] : b.lo[1],
                       (i & 4) ? b.hi[2] : b.lo[2]};
        vw_decomp_from_frame(cur, q, P[i]);
    }
}

vw_status vw__balance_tensor(const vw_decomp *cur, const vw_load_field *f,
                             const vw_balance_params *p, const int dims[3], vw_decomp **out)
{
    vw_box wb = vw_decomp_world(cur);
    vw_status st = tensor_in_frame(f, vw_decomp_frame(cur), &wb, dims, p->min_width, NULL, out);
    /* Walls that cannot be moved are kept: a balancer that cannot improve is no error. */
    if (st == VW_OK && !*out) st = vw_decomp_clone(cur, out);
    return st;
}

vw_status vw__balance_shaped(const vw_decomp *cur, const vw_load_field *f,
                             const vw_balance_params *p, const int dims[3], vw_decomp_kind kind,
                             const double *share, vw_decomp **out)
{
    *out = NULL;
    if (kind == VW_DECOMP_STAGGERED) return vw__staggered_shaped(cur, f, p, dims, share, out);
    vw_box wb = vw_decomp_world(cur);
    return tensor_in_frame(f, vw_decomp_frame(cur), &wb, dims, p->min_width, share, out);
}

/* Eigen-decomposition of a symmetric 3x3 matrix by Jacobi rotations: columns of V are
   the eigenvectors, ev the eigenvalues. */
static void jacobi3(double A[3][3], double V[3][3], double ev[3])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) V[i][j] = i == j;
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = fabs(A[0][1]) + fabs(A[0][2]) + fabs(A[1][2]);
        if (off < 1e-300) break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (fabs(A[p][q]) < 1e-300) continue;
                double th = 0.5 * (A[q][q] - A[p][p]) / A[p][q];
                double t = (th >= 0 ? 1.0 : -1.0) / (fabs(th) + sqrt(th * th + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; k++) {
                    double akp = A[k][p], akq = A[k][q];
                    A[k][p] = c * akp - s * akq;
                    A[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) {
                    double apk = A[p][k], aqk = A[q][k];
                    A[p][k] = c * apk - s * aqk;
                    A[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; k++) {
                    double vkp = V[k][p], vkq = V[k][q];
                    V[k][p] = c * vkp - s * vkq;
                    V[k][q] = s * vkp + c * vkq;
                }
            }
    }
    for (int i = 0; i < 3; i++) ev[i] = A[i][i];
}

/* The predicted lambda of the field's loads on d's cells, by the one definition
   (vw__lambda, through vw_balance_imbalance). Without worker speeds, one cell per
   worker: max / mean of the cells' loads. With speeds, the cells mapped onto the
   p->gworkers workers by speed, longest first (as divide maps its cells), each worker's
   time its load over its speed: max / mean of the cells told nothing there, and chose a
   frame of even cells that the fast workers finish early over one whose uneven cells
   match the speeds. ld and map hold VW_MAX_CELLS entries. */
static double cells_lambda(const vw_load_field *f, const vw_decomp *d,
                           const vw_balance_params *p, double *ld, int *map)
{
    int nc = vw_decomp_cell_count(d);
    vw_load_field_cell_loads(f, d, ld);
    if (!p->speeds) return vw_balance_imbalance(ld, NULL, nc, nc, NULL);
    int gw = p->gworkers > 0 ? p->gworkers : nc;
    if (vw_map_greedy(d, ld, gw, p->speeds, 0.0, map) != VW_OK) return INFINITY;
    return vw_balance_imbalance(ld, map, nc, gw, p->speeds);
}

/* The candidates of rotate are scored on at most this many points of the field. */
#define VW_ROTATE_POINTS 16384

/* The field coarsened to at most VW_ROTATE_POINTS points: each run of k consecutive
   points (a cell's grid of samples, or part of one) becomes one at their weighted
   centre carrying their total weight (the plain centre when they weigh nothing). The
   total and its spread over the cells stay; NULL without memory. */
static vw_load_field *coarse_field(const vw_load_field *f)
{
    size_t k = (f->n + VW_ROTATE_POINTS - 1) / VW_ROTATE_POINTS;
    vw_load_field *c;
    if (vw_load_field_create(&c) != VW_OK) return NULL;
    for (size_t i = 0; i < f->n; i += k) {
        size_t e = i + k < f->n ? i + k : f->n;
        double q[3] = {0, 0, 0}, mid[3] = {0, 0, 0}, w = 0;
        for (size_t j = i; j < e; j++) {
            for (int a = 0; a < 3; a++) {
                q[a] += f->w[j] * f->p[j][a];
                mid[a] += f->p[j][a] / (double)(e - i);
            }
            w += f->w[j];
        }
        for (int a = 0; a < 3; a++) q[a] = w > 0 ? q[a] / w : mid[a];
        if (vw_load_field_add_point(c, q, w) != VW_OK) {
            vw_load_field_free(c);
            return NULL;
        }
    }
    return c;
}

vw_status vw__balance_rotate(const vw_decomp *cur, const vw_load_field *f,
                             const vw_balance_params *p, const int dims[3], vw_decomp **out)
{
    /* A decomposition already rotated keeps its frame: later rounds only move its walls
       (refitting a field measured in another frame would make the frame wander). */
    if (vw_decomp_frame(cur)) return vw__balance_tensor(cur, f, p, dims, out);
    /* 1. Load-weighted centre of gravity of every cell of the current decomposition. */
    int nc = vw_decomp_cell_count(cur);
    double(*cg)[4] = calloc((size_t)nc, sizeof *cg);
    if (!cg) return VW_E_NOMEM;
    for (size_t i = 0; i < f->n; i++) {
        int c = vw_decomp_locate(cur, f->p[i], NULL);
        if (c < 0) continue;
        for (int a = 0; a < 3; a++) cg[c][a] += f->w[i] * f->p[i][a];
        cg[c][3] += f->w[i];
    }
    /* 2. Weighted straight-line fit through the centres: the principal axis of their
       weighted scatter matrix. With one loaded cell (nothing to fit) use the field's
       points themselves. */
    int loaded = 0;
    for (int c = 0; c < nc; c++) loaded += cg[c][3] > 0;
    double m[3] = {0, 0, 0}, W = 0, S[3][3] = {{0}};
    if (loaded >= 3) {
        for (int c = 0; c < nc; c++)
            if (cg[c][3] > 0) {
                for (int a = 0; a < 3; a++) m[a] += cg[c][a];
                W += cg[c][3];
            }
        for (int a = 0; a < 3; a++) m[a] /= W;
        for (int c = 0; c < nc; c++) {
            if (!(cg[c][3] > 0)) continue;
            double d[3];
            for (int a = 0; a < 3; a++) d[a] = cg[c][a] / cg[c][3] - m[a];
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++) S[a][b] += cg[c][3] * d[a] * d[b];
        }
    } else {
        for (size_t i = 0; i < f->n; i++) {
            for (int a = 0; a < 3; a++) m[a] += f->w[i] * f->p[i][a];
            W += f->w[i];
        }
        if (W > 0)
            for (int a = 0; a < 3; a++) m[a] /= W;
        for (size_t i = 0; i < f->n; i++)
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++)
                    S[a][b] += f->w[i] * (f->p[i][a] - m[a]) * (f->p[i][b] - m[b]);
    }
    free(cg);
    double V[3][3], ev[3];
    jacobi3(S, V, ev);
    /* 3. The frame: the principal axis becomes the axis with the most cells, the second
       axis the next, so the long direction of the load gets the most walls. */
    int order[3] = {0, 1, 2}; /* eigenvectors by decreasing eigenvalue */
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            if (ev[order[j]] > ev[order[i]]) {
                int t = order[i];
                order[i] = order[j];
                order[j] = t;
            }
    int axes[3] = {0, 1, 2}; /* frame axes by decreasing cell count (stable) */
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            if (dims[axes[j]] > dims[axes[i]]) {
                int t = axes[i];
                axes[i] = axes[j];
                axes[j] = t;
            }
    /* 4. Candidates: the principal axes onto the frame axes (the principal axis onto
       the axis with most cells first), turned about the principal axis in steps of 15
       degrees (when the load is round about its axis the fit fixes no second axis),
       and the unrotated frame. The one whose tensor walls give the lowest predicted
       lambda (cells_lambda) wins, so rotation never predicts worse than tensor.
       From a large field (many cells) the candidates are cut and scored coarsened
       (coarse_field): each of the 73 sorts the field three times and locates every
       point in its cells, which took 23 s for 16x16x16 cells (five rounds of rotate,
       145 k points) and 457 s for 32x32x32. The winner's walls are then cut again from
       the whole field, and a rotated one wins only if the whole field still predicts
       it better than the unrotated walls. */
    double best_lam = INFINITY;
    vw_decomp *best = NULL;
    vw_load_field *coarse = f->n > VW_ROTATE_POINTS ? coarse_field(f) : NULL;
    const vw_load_field *fs = coarse ? coarse : f; /* the field the candidates are cut from */
    if (f->n > VW_ROTATE_POINTS && !coarse) return VW_E_NOMEM;
    vw_status st = vw__balance_tensor(cur, fs, p, dims, &best);
    if (st != VW_OK) {
        vw_load_field_free(coarse);
        return st;
    }
    double *ld = malloc(sizeof(double) * VW_MAX_CELLS);
    int *map = malloc(sizeof(int) * VW_MAX_CELLS);
    if (!ld || !map) {
        free(ld), free(map);
        vw_load_field_free(coarse);
        vw_decomp_free(best);
        return VW_E_NOMEM;
    }
    best_lam = cells_lambda(fs, best, p, ld, map);
    double bestF[9];
    vw_box best_wb;
    int turned = 0; /* the best is a rotated candidate (its frame and box above) */
    double P[8][3];
    world_corners(cur, P);
    for (int perm = 0; perm < 6 && st == VW_OK; perm++) {
        static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
        for (int step = 0; step < 12 && st == VW_OK; step++) {
            double th = step * (M_PI / 12.0), c = cos(th), sn = sin(th);
            double e[3][3]; /* principal axes, the 2nd and 3rd turned by th */
            for (int k = 0; k < 3; k++) {
                e[0][k] = V[k][order[0]];
                e[1][k] = c * V[k][order[1]] + sn * V[k][order[2]];
                e[2][k] = -sn * V[k][order[1]] + c * V[k][order[2]];
            }
            double F[9];
            for (int i = 0; i < 3; i++)
                for (int k = 0; k < 3; k++) F[3 * axes[perms[perm][i]] + k] = e[i][k];
            vw_box wb;
            for (int a = 0; a < 3; a++) wb.lo[a] = INFINITY, wb.hi[a] = -INFINITY;
            for (int i = 0; i < 8; i++)
                for (int a = 0; a < 3; a++) {
                    double q = F[3 * a] * P[i][0] + F[3 * a + 1] * P[i][1] + F[3 * a + 2] * P[i][2];
                    wb.lo[a] = fmin(wb.lo[a], q);
                    wb.hi[a] = fmax(wb.hi[a], q);
                }
            /* A hair of padding: rounding in the rotation must not push a corner outside. */
            for (int a = 0; a < 3; a++) {
                double pad = 1e-9 * (wb.hi[a] - wb.lo[a]);
                wb.lo[a] -= pad;
                wb.hi[a] += pad;
            }
            vw_decomp *d = NULL;
            st = tensor_in_frame(fs, F, &wb, dims, p->min_width, NULL, &d);
            if (st != VW_OK) break;
            if (!d) continue; /* too thin in this frame for its cells: not a candidate */
            double lam = cells_lambda(fs, d, p, ld, map);
            if (lam < best_lam - 1e-9) {
                vw_decomp_free(best);
                best = d;
                best_lam = lam;
                memcpy(bestF, F, sizeof bestF);
                best_wb = wb;
                turned = 1;
            } else {
                vw_decomp_free(d);
            }
        }
    }
    if (st == VW_OK && coarse) {
        /* The winner's walls cut from the whole field, against the unrotated walls. */
        vw_decomp *d = NULL, *flat = NULL;
        vw_decomp_free(best);
        best = NULL;
        if (turned) st = tensor_in_frame(f, bestF, &best_wb, dims, p->min_width, NULL, &d);
        if (st == VW_OK) st = vw__balance_tensor(cur, f, p, dims, &flat);
        if (st == VW_OK && d &&
            cells_lambda(f, d, p, ld, map) < cells_lambda(f, flat, p, ld, map) - 1e-9) {
            best = d;
            vw_decomp_free(flat);
        } else {
            best = flat;
            vw_decomp_free(d);
        }
    }
    free(ld), free(map);
    vw_load_field_free(coarse);
    if (st != VW_OK) {
        vw_decomp_free(best);
        return st;
    }
    *out = best;
    return VW_OK;
}
