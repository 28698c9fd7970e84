/* src/io/triangulate.c - a scene polygon as triangles (vw_polygon_triangulate).
 *
 * NFF and OBJ polygons may be concave: the SPD "gears" faces are, and so is any OBJ
 * n-gon a modeller exports. A fan from the first corner covers area outside such a
 * polygon, so concave polygons are ear-clipped in the plane of their Newell normal.
 * Convex ones keep the fan, corner for corner, so their triangles (and every image of
 * a convex scene) are what they were before concave polygons were told apart.
 */
#include <math.h>
#include <stdlib.h>

#include "io/io_internal.h"

/* Twice the signed area of (a, b, c) in the projection plane. */
static double orient(const double (*p)[2], int a, int b, int c)
{
    return (p[b][0] - p[a][0]) * (p[c][1] - p[a][1]) - (p[b][1] - p[a][1]) * (p[c][0] - p[a][0]);
}

static int same_point(const double (*p)[2], int a, int b)
{
    return p[a][0] == p[b][0] && p[a][1] == p[b][1];
}

/* Does corner x lie strictly inside the angle the triangle (a, b, c), counterclockwise,
   has at its corner `at` (0, 1, 2: a, b, c)? */
static int in_angle(const double (*p)[2], int a, int b, int c, int at, int x)
{
    const int t[3] = {a, b, c};
    int before = t[(at + 2) % 3], here = t[at], after = t[(at + 1) % 3];
    return orient(p, before, here, x) > 0 && orient(p, here, after, x) > 0;
}

/* Is (a, b, c), counterclockwise, an ear of the ring: strictly convex at b, no larger
   than the area the ring still encloses (twice that area is room), and no other corner
   of the ring inside it or on its edges? A corner at the same place as a, b or c (a
   repeated corner, or one the polygon passes twice) is not inside, but its ring edges
   must not enter the triangle there: where two parts of a polygon meet at a corner, a
   triangle from one part across that corner into the other covered the outside between
   them. A corner at the same place as a neighbour, or the tip of a spike (a and c at one
   place: the ring goes out to b and back), encloses nothing and is always cut off, as a
   triangle of no area. */
static int is_ear(const double (*p)[2], const int *next, const int *prev, int a, int b, int c,
                  double room)
{
    if (same_point(p, a, b) || same_point(p, b, c) || same_point(p, a, c))
        return 1;
    double o = orient(p, a, b, c);
    if (!(o > 0) || o > room)
        return 0;
    for (int r = next[c]; r != a; r = next[r]) {
        int at = same_point(p, r, a) ? 0 : same_point(p, r, b) ? 1 : same_point(p, r, c) ? 2 : -1;
        if (at >= 0) {
            if (in_angle(p, a, b, c, at, prev[r]) || in_angle(p, a, b, c, at, next[r]))
                return 0;
            continue;
        }
        if (orient(p, a, b, r) >= 0 && orient(p, b, c, r) >= 0 && orient(p, c, a, r) >= 0)
            return 0;
    }
    return 1;
}

VW_API void vw_polygon_normal(const double (*v)[3], int n, double out[3])
{
    out[0] = out[1] = out[2] = 0;
    for (int i = 0; i < n; i++) {
        const double *a = v[i], *b = v[(i + 1) % n];
        out[0] += (a[1] - b[1]) * (a[2] + b[2]);
        out[1] += (a[2] - b[2]) * (a[0] + b[0]);
        out[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
}

VW_API vw_status vw_polygon_triangulate(const double (*v)[3], int n, int (*tri)[3])
{
    if (!v || !tri || n < 3)
        return VW_E_INVAL;
    /* The Newell normal: its largest component names the axis to project along. */
    double nw[3];
    vw_polygon_normal(v, n, nw);
    int drop = fabs(nw[0]) > fabs(nw[1]) ? 0 : 1;
    if (fabs(nw[2]) > fabs(nw[drop]))
        drop = 2;
    int ax = (drop + 1) % 3, ay = (drop + 2) % 3;
    /* Seen from the side the normal points to, (ax, ay) is counterclockwise when the
       normal's component along drop is positive; otherwise swap them. */
    if (nw[drop] < 0) {
        int t = ax;
        ax = ay;
        ay = t;
    }
    double (*p)[2] = NULL;
    int convex = !(nw[drop] != 0) || n == 3;   /* no normal (or NaN): nothing to clip */
    if (!convex) {
        p = malloc((size_t)n * sizeof *p);
        if (!p)
            return VW_E_NOMEM;
        for (int i = 0; i < n; i++) {
            p[i][0] = v[i][ax];
            p[i][1] = v[i][ay];
        }
        /* The turn at every corner, between the corners before and after it that lie
           elsewhere: a repeated corner (a, b, b) turns by 0, and at a reflex corner
           given twice no triple of consecutive corners saw the turn, so an L whose
           inner corner a file repeats was fanned across its notch. */
        convex = 1;
        for (int i = 0; i < n && convex; i++) {
            int j = (i + 1) % n, k;
            while (j != i && same_point((const double (*)[2])p, i, j))
                j = (j + 1) % n;
            for (k = (j + 1) % n; k != i && same_point((const double (*)[2])p, j, k); k = (k + 1) % n)
                ;
            if (j != i && k != j)
                convex = orient((const double (*)[2])p, i, j, k) >= 0;
        }
    }
    if (convex) {
        free(p);
        for (int j = 1; j + 1 < n; j++) {
            tri[j - 1][0] = 0;
            tri[j - 1][1] = j;
            tri[j - 1][2] = j + 1;
        }
        return VW_OK;
    }
    int *next = malloc(2 * (size_t)n * sizeof *next);
    if (!next) {
        free(p);
        return VW_E_NOMEM;
    }
    int *prev = next + n;
    for (int i = 0; i < n; i++) {
        next[i] = (i + 1) % n;
        prev[i] = (i + n - 1) % n;
    }
    /* Ear clipping. A ring in which a whole turn finds no ear (a self-intersecting or
       degenerate polygon: no interior to keep) is fanned from where the turn ended,
       so there are always n - 2 triangles and the work stays O(n^3) at worst. */
    int k = 0, left = n, b = 0, tried = 0;
    /* Twice the area the ring still encloses, less each ear cut off: an ear larger than
       that lies outside the polygon. Where a polygon touches itself at a corner, the
       corners there do not count against an ear (they are its own corner), and once
       the parts around it were cut off, the ring left (area 0) took a triangle across
       the empty side (two squares meeting at a corner came out 3/2 their area). */
    /* Summed as a fan of differences, and compared with a slack of the polygon's size
       squared: products of the coordinates themselves lose the area to rounding far
       from the origin. */
    double room = 0, lo[2] = {p[0][0], p[0][1]}, hi[2] = {p[0][0], p[0][1]};
    for (int i = 1; i + 1 < n; i++)
        room += orient((const double (*)[2])p, 0, i, i + 1);
    for (int i = 1; i < n; i++)
        for (int a = 0; a < 2; a++)
            lo[a] = fmin(lo[a], p[i][a]), hi[a] = fmax(hi[a], p[i][a]);
    const double size = fmax(hi[0] - lo[0], hi[1] - lo[1]), slack = 1e-9 * size * size;
    while (left > 3) {
        int a = prev[b], c = next[b];
        if (is_ear((const double (*)[2])p, next, prev, a, b, c, room + slack)) {
            room -= orient((const double (*)[2])p, a, b, c);
            tri[k][0] = a;
            tri[k][1] = b;
            tri[k][2] = c;
            k++;
            next[a] = c;
            prev[c] = a;
            left--;
            b = c;
            tried = 0;
        } else if (++tried > left) {
            break;
        } else {
            b = c;
        }
    }
    for (int c = next[b]; next[c] != b; c = next[c]) {
        tri[k][0] = b;
        tri[k][1] = c;
        tri[k][2] = next[c];
        k++;
    }
    free(next);
    free(p);
    return VW_OK;
}
