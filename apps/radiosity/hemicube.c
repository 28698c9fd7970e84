/* hemicube.c - the hemicube: delta form factors, the pixel layout shared by every cell
 * (so coverage bitmaps merge by OR), and the rasteriser that projects a polygon onto
 * the five faces with an exact per-pixel depth.
 *
 * Layout for resolution R (even): the top face is R x R pixels, index j*R + i; the four
 * half side faces (+x, -x, +y, -y, in this order) are R x R/2 each, index
 * R^2 + k*R*R/2 + j*R + i with row j = 0 at the horizon. 3 R^2 pixels in all.
 * Face coordinates: top (s,t) = (x/z, y/z) in [-1,1]^2; side +x (s,t) = (y/x, z/x),
 * -x (y/-x, z/-x), +y (x/y, z/y), -y (x/-y, z/-y), with t in [0,1].
 */
#include "radiosity/radiosity.h"
#include "radiosity/vec.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

size_t rad_hemicube_bitmap_bytes(int res) { return ((size_t)3 * (size_t)res * (size_t)res + 7) / 8; }

vw_status rad_hemicube_init(rad_hemicube *h, int res)
{
    memset(h, 0, sizeof *h);
    if (res < 2 || res > RAD_MAX_RES || (res & 1)) return VW_E_INVAL;
    h->res = res;
    h->npix = 3 * res * res;
    h->dff = malloc(sizeof(double) * (size_t)h->npix);
    if (!h->dff) return VW_E_NOMEM;
    double n = res / 2.0, c = 1.0 / (M_PI * n * n), sum = 0;
    for (int j = 0; j < res; j++)
        for (int i = 0; i < res; i++) {
            double x = -1 + (i + 0.5) / n, y = -1 + (j + 0.5) / n, r = x * x + y * y + 1;
            sum += h->dff[j * res + i] = c / (r * r);
        }
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < res / 2; j++)
            for (int i = 0; i < res; i++) {
                double x = -1 + (i + 0.5) / n, z = (j + 0.5) / n, r = x * x + z * z + 1;
                sum += h->dff[res * res + k * res * res / 2 + j * res + i] = c * z / (r * r);
            }
    /* Normalised so that a shot hands out exactly its power: the discretisation error
       (about 1e-4 at res 64) would otherwise leak out of closed scenes as "escaped". */
    h->raw_sum = sum;
    for (int p = 0; p < h->npix; p++) h->dff[p] /= sum;
    return VW_OK;
}

void rad_hemicube_free(rad_hemicube *h)
{
    if (h) free(h->dff);
}

/* (a, s, t) of hemicube point x for face f: a is the depth along the face axis. */
static void face_coords(int f, const double x[3], double o[3])
{
    switch (f) {
    case 0: o[0] = x[2], o[1] = x[0], o[2] = x[1]; break;
    case 1: o[0] = x[0], o[1] = x[1], o[2] = x[2]; break;
    case 2: o[0] = -x[0], o[1] = x[1], o[2] = x[2]; break;
    case 3: o[0] = x[1], o[1] = x[0], o[2] = x[2]; break;
    default: o[0] = -x[1], o[1] = x[0], o[2] = x[2]; break;
    }
}

/* Hemicube direction of face f's point (s, t) at depth 1. */
static void face_dir(int f, double s, double t, double d[3])
{
    switch (f) {
    case 0: d[0] = s, d[1] = t, d[2] = 1; break;
    case 1: d[0] = 1, d[1] = s, d[2] = t; break;
    case 2: d[0] = -1, d[1] = s, d[2] = t; break;
    case 3: d[0] = s, d[1] = 1, d[2] = t; break;
    default: d[0] = s, d[1] = -1, d[2] = t; break;
    }
}

void rad_hemicube_raster(const rad_hemicube *h, const double (*hv)[3], int nv, const uint8_t *mask,
                         rad_zbuf *z, int32_t id, double near_eps)
{
    const int R = h->res;
    const double n = R / 2.0;
    /* The polygon's plane in hemicube coordinates gives the exact depth along any ray. */
    double m[3];
    vw_polygon_normal(hv, nv, m);
    double c = rad_dot(m, hv[0]);
    if (fabs(c) <= 1e-300) return; /* the plane passes through the shooter: seen edge-on */
    /* A polygon seen from behind (the shooter on its back side: c > 0, as the module's
       facing test) loses a depth tie to one seen from the front: its depth counts
       RAD_BACK_BIAS (relative) farther. A two-sided panel is two coincident polygons
       back to back, and a tie decided by the order of the elements gave the light to
       the back face whenever it came first, which absorbs it: the side facing the
       shooter stayed dark, whatever its reflectance. A back face nearer than that
       (1e-9 of the distance) still hides a front face behind it. */
    const double bias = c > 0 ? 1 + RAD_BACK_BIAS : 1;
    for (int f = 0; f < 5; f++) {
        double P[RAD_MAXV + 6][3], Q[RAD_MAXV + 6][3];
        int np = 0, any = 0;
        for (int i = 0; i < nv; i++) {
            face_coords(f, hv[i], P[i]);
            any |= P[i][0] > near_eps;
        }
        if (!any) continue;
        /* Clip to the face's frustum (widened by a margin) and to a >= near_eps, so the
           projected coordinates stay bounded: edge functions through a vertex projected
           from near the apex would otherwise lose all precision and open cracks. */
        const double mg = 1e-3, tl = f == 0 ? -(1 + mg) : -mg;
        const double planes[5][4] = {
            {1, 0, 0, -near_eps},      /* a >= near_eps */
            {1 + mg, 1, 0, 0},         /* s >= -(1+mg) a */
            {1 + mg, -1, 0, 0},        /* s <= (1+mg) a */
            {-tl, 0, 1, 0},            /* t >= tl a */
            {1 + mg, 0, -1, 0},        /* t <= (1+mg) a */
        };
        int nin = nv;
        double (*src)[3] = P, (*dst)[3] = Q;
        for (int pl = 0; pl < 5 && nin >= 3; pl++) {
            const double *k = planes[pl];
            np = 0;
            for (int i = 0; i < nin; i++) {
                const double *s0 = src[i], *e0 = src[(i + 1) % nin];
                double ds = k[0] * s0[0] + k[1] * s0[1] + k[2] * s0[2] + k[3];
                double de = k[0] * e0[0] + k[1] * e0[1] + k[2] * e0[2] + k[3];
                if (ds >= 0 && np < RAD_MAXV + 6) memcpy(dst[np++], s0, sizeof(double) * 3);
                if ((ds >= 0) != (de >= 0) && np < RAD_MAXV + 6) {
                    double t = ds / (ds - de);
                    for (int c2 = 0; c2 < 3; c2++) dst[np][c2] = s0[c2] + t * (e0[c2] - s0[c2]);
                    np++;
                }
            }
            nin = np;
            double (*tmp)[3] = src;
            src = dst, dst = tmp;
        }
        np = nin;
        if (np >= 3 && src != Q) memcpy(Q, src, sizeof(double) * 3 * (size_t)np);
        if (np < 3) continue;
        double X[RAD_MAXV + 6], Y[RAD_MAXV + 6], xmin = INFINITY, xmax = -INFINITY,
                                                 ymin = INFINITY, ymax = -INFINITY, area = 0;
        /* Project, dropping vertices that (nearly) repeat the previous one: clipping
           makes such pairs, and an edge of length 1e-17 has no meaningful direction,
           so its edge function would reject pixels at random. */
        int kept = 0;
        for (int i = 0; i < np; i++) {
            double x = Q[i][1] / Q[i][0], y = Q[i][2] / Q[i][0];
            if (kept && fabs(x - X[kept - 1]) + fabs(y - Y[kept - 1]) < 1e-12) continue;
            X[kept] = x, Y[kept] = y, kept++;
        }
        while (kept > 1 && fabs(X[0] - X[kept - 1]) + fabs(Y[0] - Y[kept - 1]) < 1e-12) kept--;
        np = kept;
        if (np < 3) continue;
        /* Comparisons, not fmin/fmax: gcc calls libm for those (their NaN rules), ~3 %
           of a solve; a NaN is skipped either way. */
        for (int i = 0; i < np; i++) {
            if (X[i] < xmin) xmin = X[i];
            if (X[i] > xmax) xmax = X[i];
            if (Y[i] < ymin) ymin = Y[i];
            if (Y[i] > ymax) ymax = Y[i];
        }
        for (int i = 0; i < np; i++) {
            int k = (i + 1) % np;
            area += X[i] * Y[k] - X[k] * Y[i];
        }
        if (area == 0 || !isfinite(area)) continue;
        double sg = area > 0 ? 1 : -1;
        int rows = f == 0 ? R : R / 2;
        double t0 = f == 0 ? -1 : 0;
        double fi0 = ceil((xmin + 1) * n - 0.5), fi1 = floor((xmax + 1) * n - 0.5);
        double fj0 = ceil((ymin - t0) * n - 0.5), fj1 = floor((ymax - t0) * n - 0.5);
        int i0 = fi0 < 0 ? 0 : (int)fi0, i1 = fi1 > R - 1 ? R - 1 : (int)fi1;
        int j0 = fj0 < 0 ? 0 : (int)fj0, j1 = fj1 > rows - 1 ? rows - 1 : (int)fj1;
        if (i0 > i1 || j0 > j1) continue;
        int base = f == 0 ? 0 : R * R + (f - 1) * R * R / 2;
        double ex[RAD_MAXV + 6], ey[RAD_MAXV + 6], tol[RAD_MAXV + 6];
        for (int i = 0; i < np; i++) {
            int k = (i + 1) % np;
            ex[i] = X[k] - X[i], ey[i] = Y[k] - Y[i];
            /* Edges are inclusive (with a little slack), so a pixel centre on an edge
               shared by two polygons is claimed by both and the depth decides: no
               pixel falls through a crack between neighbours. */
            tol[i] = 1e-9 * (fabs(ex[i]) + fabs(ey[i]));
        }
        for (int j = j0; j <= j1; j++) {
            double py = t0 + (j + 0.5) / n;
            for (int i = i0; i <= i1; i++) {
                int p = base + j * R + i;
                if (mask && (mask[p >> 3] >> (p & 7) & 1)) continue;
                double px = -1 + (i + 0.5) / n;
                int inside = 1;
                for (int e = 0; e < np && inside; e++)
                    inside = sg * (ex[e] * (py - Y[e]) - ey[e] * (px - X[e])) >= -tol[e];
                if (!inside) continue;
                double d[3];
                face_dir(f, px, py, d);
                double md = rad_dot(m, d);
                if (md == 0) continue;
                double depth = c / md;
                if (!(depth > 0)) continue;
                depth *= bias;
                if (z->stamp[p] != z->cur || depth < z->depth[p]) {
                    if (z->written && z->stamp[p] != z->cur) z->written[p >> 6] |= (uint64_t)1 << (p & 63);
                    z->stamp[p] = z->cur;
                    z->depth[p] = depth;
                    z->owner[p] = id;
                }
            }
        }
    }
}

int rad_hemicube_pixel(const rad_hemicube *h, const double x[3], double fxy[2])
{
    const int R = h->res;
    const double n = R / 2.0;
    double ax = fabs(x[0]), ay = fabs(x[1]), a, s, t;
    int f;
    if (!(x[2] > 0)) return -1;
    if (x[2] >= ax && x[2] >= ay) f = 0, a = x[2], s = x[0] / a, t = x[1] / a;
    else if (ax >= ay) f = x[0] > 0 ? 1 : 2, a = ax, s = x[1] / a, t = x[2] / a;
    else f = x[1] > 0 ? 3 : 4, a = ay, s = x[0] / a, t = x[2] / a;
    int rows = f == 0 ? R : R / 2;
    fxy[0] = (s + 1) * n, fxy[1] = (f == 0 ? t + 1 : t) * n;
    int i = (int)floor(fxy[0]), j = (int)floor(fxy[1]);
    i = i < 0 ? 0 : i > R - 1 ? R - 1 : i;
    j = j < 0 ? 0 : j > rows - 1 ? rows - 1 : j;
    return (f == 0 ? 0 : R * R + (f - 1) * R * R / 2) + j * R + i;
}

void rad_hemicube_pixel_dir(const rad_hemicube *h, int px, double d[3])
{
    const int R = h->res;
    const double n = R / 2.0;
    if (px < R * R) {
        face_dir(0, -1 + (px % R + 0.5) / n, -1 + (px / R + 0.5) / n, d);
        return;
    }
    int f = 1 + (px - R * R) / (R * R / 2), rel = (px - R * R) % (R * R / 2);
    face_dir(f, -1 + (rel % R + 0.5) / n, (rel / R + 0.5) / n, d);
}

void rad_hemicube_orientation(const double n[3], uint64_t seed, double u[3])
{
    double t[3] = {1, 0, 0};
    if (fabs(n[0]) > 0.6) t[0] = 0, t[1] = 1;
    double a[3], b[3];
    rad_cross(n, t, a);
    rad_normalize(a);
    rad_cross(n, a, b);
    uint64_t z = seed * 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z ^= z >> 31;
    double ang = 2 * M_PI * (double)(z >> 11) * 0x1.0p-53;
    for (int k = 0; k < 3; k++) u[k] = cos(ang) * a[k] + sin(ang) * b[k];
}
