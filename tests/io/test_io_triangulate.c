/* test_io_triangulate.c - vw_polygon_triangulate on many random polygons, concave,
 * with repeated corners and corners passed twice, near and far from the origin: the
 * n - 2 triangles use corners 0..n-1, none turns against the polygon, and their areas
 * add up to the polygon's (a triangle outside it would add its area, a reversed one too).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "vw_test.h"
#include "vwalls/scene.h"

enum { MAXN = 40 };
static const double PI = 3.14159265358979323846;

/* Twice the signed area of (a, b, c) in the xy plane, from differences (exact enough
   far from the origin, where products of the coordinates are not). */
static double orient(const double (*v)[3], int a, int b, int c)
{
    return (v[b][0] - v[a][0]) * (v[c][1] - v[a][1]) - (v[b][1] - v[a][1]) * (v[c][0] - v[a][0]);
}

static uint64_t rng = 88172645463325252ull;
static unsigned rnd(unsigned n)
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return (unsigned)(rng % n);
}

/* A star-shaped polygon (so simple) on a grid of 1/8, counterclockwise: radii 1 or
   random, so that corners fall on one another after rounding; some corners given
   twice. Or two such polygons meeting at one corner, given as one ring that passes that
   corner twice. */
static int polygon(double (*v)[3], double off)
{
    int m = 0, parts = rnd(4) == 0 ? 2 : 1;
    for (int part = 0; part < parts; part++) {
        /* (Four corners at least in a part of two: three may come out clockwise.) */
        int n = (parts == 2 ? 4 : 3) + (int)rnd(10), start = m;
        double cx = part ? 2 : 0;
        for (int i = 0; i < n; i++) {
            double t = 2 * PI * (i + rnd(900) / 1000.0) / n + (part ? PI : 0);
            double r = rnd(3) == 0 ? 0.3 + rnd(700) / 1000.0 : 1;
            if (parts == 2 && i == 0) r = 1, t = part ? PI : 0; /* the shared corner (1, 0) */
            v[m][0] = cx + round(8 * r * cos(t)) / 8, v[m][1] = round(8 * r * sin(t)) / 8, v[m][2] = 0;
            m++;
            if (rnd(8) == 0 && m < MAXN - 12) v[m][0] = v[m - 1][0], v[m][1] = v[m - 1][1], v[m][2] = 0, m++;
        }
        if (part) {
            /* Close at the shared corner: the second ring starts there too. */
            v[m][0] = v[start][0], v[m][1] = v[start][1], v[m][2] = 0;
            m++;
        }
    }
    for (int i = 0; i < m; i++) v[i][0] += off, v[i][1] += off;
    return m;
}

int main(void)
{
    const double offs[] = {0, 1e6, 1e9};
    long bad = 0, tried = 0;
    for (int o = 0; o < 3; o++)
        for (int it = 0; it < 30000; it++) {
            double v[MAXN][3];
            int tri[MAXN][3];
            int n = polygon(v, offs[o]);
            CHECK(vw_polygon_triangulate((const double (*)[3])v, n, tri) == VW_OK);
            double area = 0, sum = 0;
            int reversed = 0;
            for (int i = 1; i + 1 < n; i++) area += 0.5 * orient((const double (*)[3])v, 0, i, i + 1);
            /* (Three corners may come out clockwise: the triangles follow the polygon.) */
            const double sign = area < 0 ? -1 : 1;
            area = fabs(area);
            for (int k = 0; k < n - 2; k++) {
                for (int c = 0; c < 3; c++) CHECK(tri[k][c] >= 0 && tri[k][c] < n);
                double a = 0.5 * orient((const double (*)[3])v, tri[k][0], tri[k][1], tri[k][2]);
                sum += fabs(a);
                reversed += sign * a < -1e-9;
            }
            tried++;
            int wrong = reversed || !(fabs(sum - area) <= 1e-9 * area);
            if (wrong && bad < 3) {
                fprintf(stderr, "offset %g, polygon %d (%d corners): area %.17g, triangles %.17g, %d reversed\n",
                        offs[o], it, n, area, sum, reversed);
                for (int i = 0; i < n; i++) fprintf(stderr, "  %.17g %.17g\n", v[i][0] - offs[o], v[i][1] - offs[o]);
            }
            bad += wrong;
        }
    EXPECT(bad == 0, "%ld of %ld polygons triangulated wrong", bad, tried);
    TEST_DONE();
}
