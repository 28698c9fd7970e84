/* shape.c - the pairwise tests of the dynamic-scene handler: spheres, triangles and
 * boxes, at rest or swept along a translation. Closed-form distances where a sphere is
 * involved (point/segment against point/triangle), the separating axis theorem for
 * everything made of flat faces.
 */
#include <math.h>
#include <string.h>
#include "dynamic/dynamic_internal.h"

static double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static void sub(const double a[3], const double b[3], double o[3])
{
    for (int k = 0; k < 3; k++) o[k] = a[k] - b[k];
}
static void cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
static double clamp01(double x) { return x < 0 ? 0 : x > 1 ? 1 : x; }

/* ---- distances ---------------------------------------------------------------------- */

/* Squared distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5:
   Voronoi regions of the vertices, edges and face). Degenerate triangles work too: the
   face region is never chosen when the area is zero, and an edge region is taken only
   when its edge has a length (a == b made the AB branch 0/0: a NaN distance, so a
   sphere through a polygon whose first two corners coincide was never hit). */
static double dist2_point_tri(const double p[3], const double a[3], const double b[3],
                              const double c[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3], q[3], t[3];
    sub(b, a, ab), sub(c, a, ac), sub(p, a, ap);
    double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return dot(ap, ap);
    sub(p, b, bp);
    double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return dot(bp, bp);
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0 && d1 - d3 > 0) {
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; k++) q[k] = a[k] + v * ab[k];
        sub(p, q, t);
        return dot(t, t);
    }
    sub(p, c, cp);
    double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return dot(cp, cp);
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0 && d2 - d6 > 0) {
        double w = d2 / (d2 - d6);
        for (int k = 0; k < 3; k++) q[k] = a[k] + w * ac[k];
        sub(p, q, t);
        return dot(t, t);
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0 && (d4 - d3) + (d5 - d6) > 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; k++) q[k] = b[k] + w * (c[k] - b[k]);
        sub(p, q, t);
        return dot(t, t);
    }
    double den = va + vb + vc;
    if (!(den > 0)) { /* degenerate: the nearest of the three edges */
        double best = INFINITY;
        const double *e[3][2] = {{a, b}, {b, c}, {c, a}};
        for (int i = 0; i < 3; i++) {
            double u[3], w[3];
            sub(e[i][1], e[i][0], u), sub(p, e[i][0], w);
            double uu = dot(u, u), s = uu > 0 ? clamp01(dot(w, u) / uu) : 0;
            for (int k = 0; k < 3; k++) t[k] = w[k] - s * u[k];
            double d = dot(t, t);
            if (d < best) best = d;
        }
        return best;
    }
    double v = vb / den, w = vc / den;
    for (int k = 0; k < 3; k++) q[k] = a[k] + ab[k] * v + ac[k] * w;
    sub(p, q, t);
    return dot(t, t);
}

/* Squared distance between segments p1q1 and p2q2 (Ericson 5.1.9). */
static double dist2_seg_seg(const double p1[3], const double q1[3], const double p2[3],
                            const double q2[3])
{
    double d1[3], d2[3], r[3];
    sub(q1, p1, d1), sub(q2, p2, d2), sub(p1, p2, r);
    double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
    double s, t;
    if (a <= 0 && e <= 0) {
        s = t = 0;
    } else if (a <= 0) {
        s = 0;
        t = clamp01(f / e);
    } else {
        double c = dot(d1, r);
        if (e <= 0) {
            t = 0;
            s = clamp01(-c / a);
        } else {
            double b = dot(d1, d2), den = a * e - b * b;
            s = den > 0 ? clamp01((b * f - c * e) / den) : 0;
            t = (b * s + f) / e;
            if (t < 0) {
                t = 0;
                s = clamp01(-c / a);
            } else if (t > 1) {
                t = 1;
                s = clamp01((b - c) / a);
            }
        }
    }
    double x[3];
    for (int k = 0; k < 3; k++) x[k] = (p1[k] + d1[k] * s) - (p2[k] + d2[k] * t);
    return dot(x, x);
}

/* Squared distance between segment pq and triangle abc: zero when the segment pierces
   the triangle, else the nearest of its end points to the triangle and of the segment
   to the three edges (the minimum of a convex pair lies on one of those features).
   Piercing is decided by signs, not by a distance: the point where the segment meets
   the plane is off the plane by rounding, so its distance to the triangle was never
   exactly 0, and a small sphere flying through a tilted triangle's middle passed. */
static double dist2_seg_tri(const double p[3], const double q[3], const double a[3],
                            const double b[3], const double c[3])
{
    double ab[3], ac[3], n[3];
    sub(b, a, ab), sub(c, a, ac);
    cross(ab, ac, n);
    double nn = dot(n, n);
    if (nn > 0) {
        double ap[3], aq[3];
        sub(p, a, ap), sub(q, a, aq);
        double sp = dot(ap, n), sq = dot(aq, n);
        if (((sp <= 0 && sq >= 0) || (sp >= 0 && sq <= 0)) && sp != sq) {
            /* The line pq passes inside the triangle when the three scalar triple
               products of pq with the corners taken in pairs share a sign (Ericson
               5.3.4); a pierce near an edge that rounding puts outside is caught by
               the edge distances below, which are then about zero. */
            double pq[3], pa[3], pb[3], pc[3], m[3], w3[3];
            sub(q, p, pq), sub(a, p, pa), sub(b, p, pb), sub(c, p, pc);
            cross(pq, pc, m);
            double u = dot(pb, m), v = -dot(pa, m);
            cross(pq, pb, w3);
            double w = dot(pa, w3);
            if ((u >= 0 && v >= 0 && w >= 0) || (u <= 0 && v <= 0 && w <= 0)) return 0;
        }
    }
    double best = dist2_point_tri(p, a, b, c);
    double d = dist2_point_tri(q, a, b, c);
    if (d < best) best = d;
    const double *e[3][2] = {{a, b}, {b, c}, {c, a}};
    for (int i = 0; i < 3; i++) {
        d = dist2_seg_seg(p, q, e[i][0], e[i][1]);
        if (d < best) best = d;
    }
    return best;
}

/* ---- separating axes ----------------------------------------------------------------- */

/* A convex polytope as its points, the directions of its edges and its face normals. */
typedef struct poly {
    double pt[16][3];
    int npt;
    double edge[4][3];
    int nedge;
    double face[8][3];
    int nface;
} poly;

static void poly_faces(poly *P)
{
    /* Every face normal of a polytope is the cross product of two of its edge
       directions; taking all pairs may add axes, and an extra axis never breaks the
       test (any axis that separates proves separation). */
    P->nface = 0;
    for (int i = 0; i < P->nedge; i++)
        for (int j = i + 1; j < P->nedge && P->nface < 8; j++)
            cross(P->edge[i], P->edge[j], P->face[P->nface++]);
}

/* Shape a (swept by d when d is not NULL) as a polytope. Spheres become their box. */
static void poly_of(const vw_shape *s, const double *d, poly *P)
{
    memset(P, 0, sizeof *P);
    if (s->kind == VW_SHAPE_TRIANGLE) {
        for (int i = 0; i < 3; i++) memcpy(P->pt[i], s->p[i], sizeof P->pt[i]);
        P->npt = 3;
        sub(s->p[1], s->p[0], P->edge[0]);
        sub(s->p[2], s->p[1], P->edge[1]);
        sub(s->p[0], s->p[2], P->edge[2]);
        P->nedge = 3;
    } else {
        double lo[3], hi[3];
        for (int k = 0; k < 3; k++) {
            lo[k] = s->kind == VW_SHAPE_SPHERE ? s->p[0][k] - s->r : s->p[0][k];
            hi[k] = s->kind == VW_SHAPE_SPHERE ? s->p[0][k] + s->r : s->p[1][k];
        }
        for (int i = 0; i < 8; i++) {
            P->pt[i][0] = (i & 1) ? hi[0] : lo[0];
            P->pt[i][1] = (i & 2) ? hi[1] : lo[1];
            P->pt[i][2] = (i & 4) ? hi[2] : lo[2];
        }
        P->npt = 8;
        for (int k = 0; k < 3; k++) P->edge[k][k] = 1;
        P->nedge = 3;
    }
    if (d && (d[0] != 0 || d[1] != 0 || d[2] != 0)) {
        int n = P->npt;
        for (int i = 0; i < n; i++)
            for (int k = 0; k < 3; k++) P->pt[n + i][k] = P->pt[i][k] + d[k];
        P->npt = 2 * n;
        memcpy(P->edge[P->nedge++], d, sizeof P->edge[0]);
    }
    poly_faces(P);
}

/* Does axis u (any length) separate A and B, i.e. do their projections overlap by at
   most tol (the penetration along u)? Axes too short to carry a direction are skipped (they prove nothing). */
static int separates(const poly *A, const poly *B, const double u[3], double tol)
{
    double len2 = dot(u, u);
    if (!(len2 > 1e-300)) return 0;
    double inv = 1.0 / sqrt(len2);
    double amin = INFINITY, amax = -INFINITY, bmin = INFINITY, bmax = -INFINITY;
    for (int i = 0; i < A->npt; i++) {
        double x = dot(A->pt[i], u) * inv;
        amin = fmin(amin, x), amax = fmax(amax, x);
    }
    for (int i = 0; i < B->npt; i++) {
        double x = dot(B->pt[i], u) * inv;
        bmin = fmin(bmin, x), bmax = fmax(bmax, x);
    }
    /* Both flat across u (coplanar faces): overlapping in their plane is a collision of
       two surfaces, not a touch, so only a real gap separates here. */
    if (amax - amin <= tol && bmax - bmin <= tol) return amin > bmax + tol || bmin > amax + tol;
    return amax - bmin <= tol || bmax - amin <= tol;
}

/* A cross product is kept as an axis only when it is not tiny against its factors:
   nearly parallel edges give a direction dominated by rounding. */
static int axis_of(const double a[3], const double b[3], double out[3])
{
    cross(a, b, out);
    return dot(out, out) > 1e-24 * dot(a, a) * dot(b, b);
}

static int polys_collide(const poly *A, const poly *B, double tol)
{
    double u[3];
    for (int i = 0; i < A->nface; i++)
        if (separates(A, B, A->face[i], tol)) return 0;
    for (int i = 0; i < B->nface; i++)
        if (separates(A, B, B->face[i], tol)) return 0;
    for (int i = 0; i < A->nedge; i++)
        for (int j = 0; j < B->nedge; j++)
            if (axis_of(A->edge[i], B->edge[j], u) && separates(A, B, u, tol)) return 0;
    /* In-plane normals of the edges: they separate flat polytopes lying in one plane,
       where every cross product above is the common normal. */
    const poly *PP[2] = {A, B};
    for (int s = 0; s < 2; s++)
        for (int f = 0; f < PP[s]->nface; f++)
            for (int t = 0; t < 2; t++)
                for (int e = 0; e < PP[t]->nedge; e++)
                    if (axis_of(PP[s]->face[f], PP[t]->edge[e], u) && separates(A, B, u, tol))
                        return 0;
    return 1;
}

/* ---- the public tests ----------------------------------------------------------------- */

void vw_shape_bounds(const vw_shape *s, const double d[3], vw_box *out)
{
    for (int k = 0; k < 3; k++) {
        double lo, hi;
        switch (s->kind) {
        case VW_SHAPE_SPHERE:
            lo = s->p[0][k] - s->r, hi = s->p[0][k] + s->r;
            break;
        case VW_SHAPE_TRIANGLE:
            lo = fmin(s->p[0][k], fmin(s->p[1][k], s->p[2][k]));
            hi = fmax(s->p[0][k], fmax(s->p[1][k], s->p[2][k]));
            break;
        case VW_SHAPE_BOX:
            lo = s->p[0][k], hi = s->p[1][k];
            break;
        default: /* no shape: an inverted box overlaps nothing */
            lo = INFINITY, hi = -INFINITY;
            break;
        }
        if (d && s->kind != VW_SHAPE_NONE) {
            if (d[k] < 0) lo += d[k];
            else hi += d[k];
        }
        out->lo[k] = lo;
        out->hi[k] = hi;
    }
}

static int within(double dist2, double rsum, double tol)
{
    double lim = rsum - tol;
    return lim > 0 && dist2 < lim * lim;
}

int vw_shape_collide(const vw_shape *a, const double d[3], const vw_shape *b, double tol)
{
    if (!a || !b || a->kind == VW_SHAPE_NONE || b->kind == VW_SHAPE_NONE) return 0;
    static const double zero[3] = {0, 0, 0};
    const double *dd = d ? d : zero;
    double e[3];
    if (a->kind == VW_SHAPE_SPHERE && b->kind == VW_SHAPE_SPHERE) {
        /* Capsule against sphere: the path of a's centre against b's centre. */
        for (int k = 0; k < 3; k++) e[k] = a->p[0][k] + dd[k];
        return within(dist2_seg_seg(a->p[0], e, b->p[0], b->p[0]), a->r + b->r, tol);
    }
    if (a->kind == VW_SHAPE_SPHERE && b->kind == VW_SHAPE_TRIANGLE) {
        for (int k = 0; k < 3; k++) e[k] = a->p[0][k] + dd[k];
        return within(dist2_seg_tri(a->p[0], e, b->p[0], b->p[1], b->p[2]), a->r, tol);
    }
    if (a->kind == VW_SHAPE_TRIANGLE && b->kind == VW_SHAPE_SPHERE) {
        /* A triangle sweeping past a sphere is the sphere sweeping back past the
           triangle: the same relative motion. */
        for (int k = 0; k < 3; k++) e[k] = b->p[0][k] - dd[k];
        return within(dist2_seg_tri(b->p[0], e, a->p[0], a->p[1], a->p[2]), b->r, tol);
    }
    /* Triangle pairs exactly; anything with a box conservatively, as boxes. */
    poly A, B;
    poly_of(a, d, &A);
    poly_of(b, NULL, &B);
    return polys_collide(&A, &B, tol);
}

/* Whether a, swept by d, goes deeper into b than it starts, by more than tol: for the
   pairs with a sphere, whose nearest approach (centre to centre, or centre to triangle)
   is a distance convex along the path, the path comes nearer than the start. Leaving
   or sliding along keeps the start's distance; going through does not. 0 for the other
   pairs (no depth is measured along their path). */
int vw__shape_sweep_deepens(const vw_shape *a, const double d[3], const vw_shape *b, double tol)
{
    if (!a || !b || !d) return 0;
    const vw_shape *sp, *o;
    double dir[3];
    if (a->kind == VW_SHAPE_SPHERE && (b->kind == VW_SHAPE_SPHERE || b->kind == VW_SHAPE_TRIANGLE)) {
        sp = a, o = b;
        for (int k = 0; k < 3; k++) dir[k] = d[k];
    } else if (a->kind == VW_SHAPE_TRIANGLE && b->kind == VW_SHAPE_SPHERE) {
        sp = b, o = a; /* the same relative motion, backwards */
        for (int k = 0; k < 3; k++) dir[k] = -d[k];
    } else {
        return 0;
    }
    double e[3], d0, dm;
    for (int k = 0; k < 3; k++) e[k] = sp->p[0][k] + dir[k];
    if (o->kind == VW_SHAPE_SPHERE) {
        d0 = dist2_seg_seg(sp->p[0], sp->p[0], o->p[0], o->p[0]);
        dm = dist2_seg_seg(sp->p[0], e, o->p[0], o->p[0]);
    } else {
        d0 = dist2_point_tri(sp->p[0], o->p[0], o->p[1], o->p[2]);
        dm = dist2_seg_tri(sp->p[0], e, o->p[0], o->p[1], o->p[2]);
    }
    return sqrt(dm) < sqrt(d0) - tol;
}
