/* src/io/gen.c - scene generators, written from the scenes' geometric definitions:
 * Haines' sphereflake ("balls"), chain-mail rings, a recursive tree, random
 * non-overlapping spheres (the paper's uniform and clustered load cases), the
 * Cornell box from its published measurements, and a furnished room.
 *
 * Everything random comes from splitmix64 seeded by the caller, and the geometry
 * uses only IEEE-exact operations plus sin/cos/sqrt of fixed arguments, so a seed
 * gives the same scene everywhere.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/io_internal.h"
#include "vwalls/gen.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define MAX_OBJECTS 20000000   /* keeps generated scenes within a few GB */

static const char *const gen_names[] = {"balls", "rings", "tree", "spheres", "cornell",
                                        "room", NULL};

VW_API const char *vw_gen_name(size_t i)
{
    return i < sizeof gen_names / sizeof gen_names[0] ? gen_names[i] : NULL;
}

VW_API void vw_gen_params_init(vw_gen_params *p)
{
    if (!p)
        return;
    memset(p, 0, sizeof *p);
    p->seed = 1;
    p->width = p->height = 512;
}

/* ---- small helpers ------------------------------------------------------------ */

typedef struct rng {
    uint64_t x;
} rng;

static uint64_t rng_next(rng *r)
{
    uint64_t z = (r->x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1) with 53 random bits. */
static double rng_unit(rng *r)
{
    return (double)(rng_next(r) >> 11) * 0x1p-53;
}

static double rng_range(rng *r, double lo, double hi)
{
    return lo + (hi - lo) * rng_unit(r);
}

static void set3(double v[3], double x, double y, double z)
{
    v[0] = x;
    v[1] = y;
    v[2] = z;
}

static void normalize(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0)
        for (int k = 0; k < 3; k++)
            v[k] /= l;
}

static void cross(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* Two unit vectors u, v completing the unit vector w to a right-handed frame. */
static void frame(const double w[3], double u[3], double v[3])
{
    double a[3] = {0, 0, 0};
    a[fabs(w[0]) < 0.6 ? 0 : fabs(w[1]) < 0.6 ? 1 : 2] = 1.0;
    cross(w, a, u);
    normalize(u);
    cross(w, u, v);
}

static vw_material mat(float r, float g, float b, float ks, float shine)
{
    vw_material m;
    vw__default_material(&m);
    m.diffuse[0] = r;
    m.diffuse[1] = g;
    m.diffuse[2] = b;
    /* The scenes are NFF's: Ks weights the highlight and the mirror ray alike. */
    m.specular[0] = m.specular[1] = m.specular[2] = ks;
    m.reflect[0] = m.reflect[1] = m.reflect[2] = ks;
    m.shine = shine;
    return m;
}

static void camera(vw_scene *s, const vw_gen_params *p, double fx, double fy, double fz,
                   double ax, double ay, double az, double ux, double uy, double uz,
                   double angle, double hither)
{
    vw_camera *c = &s->camera;
    set3(c->from, fx, fy, fz);
    set3(c->at, ax, ay, az);
    set3(c->up, ux, uy, uz);
    c->angle = angle;
    c->hither = hither;
    c->width = p->width;
    c->height = p->height;
    c->valid = 1;
}

static vw_status light(vw__sb *b, double x, double y, double z, float intensity)
{
    double pos[3] = {x, y, z};
    float col[3] = {intensity, intensity, intensity};
    return vw__sb_add_light(b, pos, col);
}

/* A planar polygon of nc (3 or 4) corners whose normal (right-hand rule over the
   vertex order) points to the side of `ref` given by toward (+1) or away from it (-1).
   Radiosity shoots from the front side, so orientation matters there. The corners must
   lie in one plane: the radiosity mesher warns about (and flattens) any that do not. */
static vw_status face(vw__sb *b, int m, int nc, const double (*q)[3], const double ref[3],
                      int toward)
{
    double e1[3], e2[3], n[3], d = 0;
    for (int k = 0; k < 3; k++) {
        e1[k] = q[1][k] - q[0][k];
        e2[k] = q[2][k] - q[0][k];
    }
    cross(e1, e2, n);
    for (int k = 0; k < 3; k++)
        d += n[k] * (ref[k] - q[0][k]);
    if ((d > 0) == (toward > 0))
        return vw__sb_add_polygon(b, m, nc, q);
    double r[4][3];
    for (int i = 0; i < nc; i++)
        memcpy(r[i], q[nc - 1 - i], sizeof r[i]);
    return vw__sb_add_polygon(b, m, nc, (const double(*)[3])r);
}

/* A quad, as face(). */
static vw_status quad(vw__sb *b, int m, const double q[4][3], const double ref[3],
                      int toward)
{
    return face(b, m, 4, q, ref, toward);
}

enum { SKIP_XLO = 1, SKIP_XHI = 2, SKIP_YLO = 4, SKIP_YHI = 8, SKIP_ZLO = 16,
       SKIP_ZHI = 32 };

/* An axis-aligned box as up to six quads facing out (inward=1: facing in, for the
   room). Faces in `skip` are left out, e.g. the bottom of a leg on the floor, which
   nobody sees and which would be coplanar with the floor. */
static vw_status box(vw__sb *b, int m, double x0, double y0, double z0, double x1,
                     double y1, double z1, int skip, int inward)
{
    const double c[3] = {(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2};
    const double lo[3] = {x0, y0, z0}, hi[3] = {x1, y1, z1};
    for (int axis = 0; axis < 3; axis++)
        for (int side = 0; side < 2; side++) {
            if (skip & (1 << (2 * axis + side)))
                continue;
            int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
            double q[4][3];
            for (int i = 0; i < 4; i++) {
                q[i][axis] = side ? hi[axis] : lo[axis];
                q[i][a1] = (i == 1 || i == 2) ? hi[a1] : lo[a1];
                q[i][a2] = (i >= 2) ? hi[a2] : lo[a2];
            }
            vw_status st = quad(b, m, q, c, inward ? 1 : -1);
            if (st != VW_OK)
                return st;
        }
    return VW_OK;
}

static vw_status ground(vw__sb *b, int m, double half, double z)
{
    const double q[4][3] = {{half, half, z}, {-half, half, z}, {-half, -half, z},
                            {half, -half, z}};
    return vw__sb_add_polygon(b, m, 4, q);   /* counter-clockwise seen from +z */
}

#define TRY(x)                          \
    do {                                \
        vw_status st_ = (x);            \
        if (st_ != VW_OK)               \
            return st_;                 \
    } while (0)

/* ---- balls: the sphereflake ----------------------------------------------------- */

/* v turned about the unit axis a by the angle of cosine c and sine s (Rodrigues). */
static void turn(const double a[3], double c, double s, const double v[3], double out[3])
{
    double ax[3], d = a[0] * v[0] + a[1] * v[1] + a[2] * v[2];
    cross(a, v, ax);
    for (int k = 0; k < 3; k++) out[k] = v[k] * c + ax[k] * s + a[k] * d * (1 - c);
}

/* SPD's nine child directions about +z (see flake). */
static void flake_make_dirs(double dirs[9][3])
{
    const double h = 1 / sqrt(2.0), q = 1 / sqrt(3.0);
    const double trio[3][3] = {{h, h, 0}, {h, 0, -h}, {0, h, -h}};
    const double axis[3] = {h, -h, 0}, z[3] = {0, 0, 1};
    /* 120 and 240 degrees about z: cosine -1/2, sines +-sqrt(3)/2. */
    const double c3[3] = {1, -0.5, -0.5}, s3[3] = {0, sqrt(3.0) / 2, -sqrt(3.0) / 2};
    for (int i = 0; i < 3; i++) {
        double t[3];
        turn(axis, q, 2 / sqrt(6.0), trio[i], t); /* cos asin(2/sqrt 6) = 1/sqrt 3 */
        for (int k = 0; k < 3; k++) turn(z, c3[k], s3[k], t, dirs[3 * k + i]);
    }
}

/* Each sphere of radius r carries nine children of radius r/3 touching it (centres
   4r/3 from the parent's), as in SPD's balls.c (Haines): six around its equator,
   relative to the direction it grew in, 60 degrees apart, and three higher up, at
   elevation asin(sqrt(2/3)) = 54.7 degrees, each midway in azimuth between two of the
   six. SPD makes the nine directions once: the unit vectors (1,1,0), (1,0,-1) and
   (0,1,-1) over sqrt 2, turned by asin(2/sqrt 6) about (1,-1,0), and that trio turned by
   0, 120 and 240 degrees about z; a child's set is turned by the rotation taking +z to
   its direction about z x direction. The same is done here, with the rotations' sines
   and cosines from square roots (no libm angle of a computed argument), so the spheres
   are SPD's, sphere for sphere. Level n has 9^n spheres. A child's whole sub-flake
   stays within 2r/3 of its centre (r/3 + 2r/9 + ... < 2r/3), and every two children are
   at least 60 degrees apart, so sub-flakes cannot meet. dirs: flake_make_dirs. */
static vw_status flake(vw__sb *b, int m, const double (*dirs)[3], const double c[3],
                       double r, const double dir[3], int levels)
{
    TRY(vw__sb_add_sphere(b, m, c, r));
    if (levels == 0)
        return VW_OK;
    /* The rotation taking +z to dir: about z x dir, by the angle of cosine dir[2]. */
    double axis[3] = {-dir[1], dir[0], 0}, sn = sqrt(dir[0] * dir[0] + dir[1] * dir[1]);
    double cs = dir[2];
    if (sn > 0) {
        axis[0] /= sn;
        axis[1] /= sn;
    } else { /* along z: none, or half a turn about y (SPD's choice) */
        axis[1] = 1;
        cs = cs < 0 ? -1 : 1;
    }
    for (int i = 0; i < 9; i++) {
        double d[3], cc[3];
        turn(axis, cs, sn, dirs[i], d);
        for (int k = 0; k < 3; k++)
            cc[k] = c[k] + d[k] * (r + r / 3);
        TRY(flake(b, m, dirs, cc, r / 3, d, levels - 1));
    }
    return VW_OK;
}

int vw_gen_default_size(const char *name)
{
    return !name ? 0 : !strcmp(name, "balls") ? 4 : !strcmp(name, "rings") ? 5
         : !strcmp(name, "tree") ? 6 : 0;
}

static vw_status gen_balls(vw__sb *b, const vw_gen_params *p)
{
    int n = p->size ? p->size : vw_gen_default_size("balls");
    vw_scene *s = b->s;
    /* The classic SPD view, lights and colours (each of 3 lights at 1/sqrt(3)). */
    camera(s, p, 2.1, 1.3, 1.7, 0, 0, 0, 0, 0, 1, 45, 0.01);
    s->background[0] = 0.078f;
    s->background[1] = 0.361f;
    s->background[2] = 0.753f;
    float li = (float)(1.0 / sqrt(3.0));
    TRY(light(b, 4, 3, 2, li));
    TRY(light(b, 1, -4, 4, li));
    TRY(light(b, -3, 1, 5, li));
    int mground, mball;
    vw_material g = mat(0.8f, 0.6f, 0.264f, 0, 0);
    vw_material ball = mat(0.5f, 0.45f, 0.35f, 0.5f, 3.0827f);   /* mirror-ish */
    TRY(vw__sb_intern_material(b, &g, &mground));
    TRY(vw__sb_intern_material(b, &ball, &mball));
    TRY(ground(b, mground, 12, -0.5));
    const double c[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    double dirs[9][3];
    flake_make_dirs(dirs);
    return flake(b, mball, (const double(*)[3])dirs, c, 0.5, up, n);
}

/* ---- rings: a pyramid of chain-mail rings ---------------------------------------- */

/* A ring is a torus made of spheres joined by cylinders. Layer z of the pyramid holds
   (n-z)^2 rings on a grid whose spacing is less than a ring's diameter; the rings
   alternate between two tilts so that neighbours interlock like chain mail. */
static vw_status gen_rings(vw__sb *b, const vw_gen_params *p)
{
    int n = p->size ? p->size : vw_gen_default_size("rings");
    vw_scene *s = b->s;
    const double R = 1.0, tube = 0.18, spacing = 1.7 * R;
    const int segs = 12;
    double extent = n * spacing;
    camera(s, p, -1.0 * extent, -1.6 * extent, 1.3 * extent, extent / 2 - spacing / 2,
           extent / 2 - spacing / 2, n * 0.35, 0, 0, 1, 45, 0.01);
    s->background[0] = 0.3f;
    s->background[1] = 0.4f;
    s->background[2] = 0.5f;
    float li = (float)(1.0 / sqrt(3.0));
    TRY(light(b, -2 * extent, -1 * extent, 3 * extent, li));
    TRY(light(b, 2 * extent, -2 * extent, 2 * extent, li));
    TRY(light(b, 0.5 * extent, 3 * extent, 4 * extent, li));
    int mground, mring[3];
    vw_material g = mat(0.6f, 0.6f, 0.6f, 0.0f, 0);
    TRY(vw__sb_intern_material(b, &g, &mground));
    const float cols[3][3] = {{0.7f, 0.25f, 0.2f}, {0.25f, 0.6f, 0.3f}, {0.3f, 0.35f, 0.75f}};
    for (int i = 0; i < 3; i++) {
        vw_material m = mat(cols[i][0], cols[i][1], cols[i][2], 0.4f, 20);
        TRY(vw__sb_intern_material(b, &m, &mring[i]));
    }
    TRY(ground(b, mground, 4 * extent, -R - tube));
    for (int z = 0; z < n; z++) {
        int side = n - z;
        double off = z * spacing / 2;
        for (int i = 0; i < side; i++)
            for (int j = 0; j < side; j++) {
                double c[3] = {off + i * spacing, off + j * spacing, z * 1.6 * R};
                /* Tilted about x or y by 45 degrees, alternating like a checkerboard. */
                double a[3], bb[3];
                double t = M_PI / 4;
                if ((i + j + z) % 2 == 0) {
                    set3(a, 1, 0, 0);
                    set3(bb, 0, cos(t), sin(t));
                } else {
                    set3(a, cos(t), 0, -sin(t));
                    set3(bb, 0, 1, 0);
                }
                int m = mring[(i + j + z) % 3];
                double prev[3] = {0, 0, 0}, first[3] = {0, 0, 0};
                for (int k = 0; k <= segs; k++) {
                    double ang = 2 * M_PI * (k % segs) / segs, q[3];
                    for (int d = 0; d < 3; d++)
                        q[d] = c[d] + R * (cos(ang) * a[d] + sin(ang) * bb[d]);
                    if (k == 0)
                        memcpy(first, q, sizeof q);
                    if (k < segs)
                        TRY(vw__sb_add_sphere(b, m, q, tube));
                    if (k > 0)
                        TRY(vw__sb_add_cone(b, m, prev, tube * 0.7, k == segs ? first : q,
                                            tube * 0.7));
                    memcpy(prev, q, sizeof q);
                }
            }
    }
    return VW_OK;
}

/* ---- tree ------------------------------------------------------------------------ */

typedef struct tree_ctx {
    vw__sb *b;
    rng r;
    int mbark, mleaf;
} tree_ctx;

/* A branch is a cone from base to tip, narrowing by 0.7; at its tip a sphere hides
   the joint and three sub-branches grow, each 0.72 as long, spread 120 degrees
   around the branch (plus jitter) and tilted 25-45 degrees away from it. The last
   level ends in a leaf sphere instead. */
static vw_status branch(tree_ctx *t, const double base[3], const double dir[3], double len,
                        double radius, int level)
{
    double tip[3];
    for (int k = 0; k < 3; k++)
        tip[k] = base[k] + dir[k] * len;
    double rtip = radius * 0.7;
    TRY(vw__sb_add_cone(t->b, t->mbark, base, radius, tip, rtip));
    if (level == 0)
        return vw__sb_add_sphere(t->b, t->mleaf, tip, len * 0.45);
    TRY(vw__sb_add_sphere(t->b, t->mbark, tip, rtip));
    double u[3], v[3];
    frame(dir, u, v);
    double phase = rng_range(&t->r, 0, 2 * M_PI);
    for (int i = 0; i < 3; i++) {
        double az = phase + i * (2 * M_PI / 3) + rng_range(&t->r, -0.3, 0.3);
        double tilt = rng_range(&t->r, 25, 45) * (M_PI / 180);
        double d[3];
        for (int k = 0; k < 3; k++)
            d[k] = cos(tilt) * dir[k] + sin(tilt) * (cos(az) * u[k] + sin(az) * v[k]);
        /* Branches bend a little upward, as trees grow toward the light. */
        d[2] += 0.15;
        normalize(d);
        TRY(branch(t, tip, d, len * rng_range(&t->r, 0.66, 0.78), rtip, level - 1));
    }
    return VW_OK;
}

static vw_status gen_tree(vw__sb *b, const vw_gen_params *p)
{
    int n = p->size ? p->size : vw_gen_default_size("tree");
    vw_scene *s = b->s;
    camera(s, p, 0, -9, 3.2, 0, 0, 2.6, 0, 0, 1, 45, 0.01);
    s->background[0] = 0.55f;
    s->background[1] = 0.7f;
    s->background[2] = 0.9f;
    float li = (float)(1.0 / sqrt(2.0));
    TRY(light(b, -6, -8, 12, li));
    TRY(light(b, 8, -4, 8, li));
    tree_ctx t = {b, {p->seed}, 0, 0};
    vw_material g = mat(0.35f, 0.5f, 0.2f, 0, 0), bark = mat(0.45f, 0.3f, 0.15f, 0.05f, 5),
                leaf = mat(0.2f, 0.6f, 0.15f, 0.2f, 10);
    int mground;
    TRY(vw__sb_intern_material(b, &g, &mground));
    TRY(vw__sb_intern_material(b, &bark, &t.mbark));
    TRY(vw__sb_intern_material(b, &leaf, &t.mleaf));
    TRY(ground(b, mground, 20, 0));
    const double base[3] = {0, 0, 0}, up[3] = {0, 0, 1};
    return branch(&t, base, up, 1.6, 0.18, n);
}

/* ---- spheres: the paper's load cases ---------------------------------------------- */

/* Spheres are kept in a hash grid of cell size 2r, so checking a candidate against
   all placed spheres looks at 27 cells: placing N spheres costs O(N) expected. */
typedef struct sgrid {
    size_t nb;            /* buckets, a power of two */
    int *head;            /* bucket -> first sphere, -1 */
    int *next;            /* sphere -> next in its bucket */
    double (*c)[3];
    double cell;
} sgrid;

static size_t sgrid_bucket(const sgrid *g, long long ix, long long iy, long long iz)
{
    uint64_t h = (uint64_t)ix * 0x9E3779B97F4A7C15ull ^ (uint64_t)iy * 0xC2B2AE3D27D4EB4Full ^
                 (uint64_t)iz * 0x165667B19E3779F9ull;
    h ^= h >> 29;
    return (size_t)h & (g->nb - 1);
}

static int sgrid_free(const sgrid *g, const double c[3], double mind2)
{
    long long ix = (long long)floor(c[0] / g->cell), iy = (long long)floor(c[1] / g->cell),
              iz = (long long)floor(c[2] / g->cell);
    for (long long dx = -1; dx <= 1; dx++)
        for (long long dy = -1; dy <= 1; dy++)
            for (long long dz = -1; dz <= 1; dz++)
                for (int j = g->head[sgrid_bucket(g, ix + dx, iy + dy, iz + dz)]; j >= 0;
                     j = g->next[j]) {
                    double d2 = 0;
                    for (int k = 0; k < 3; k++)
                        d2 += (g->c[j][k] - c[k]) * (g->c[j][k] - c[k]);
                    if (d2 < mind2)
                        return 0;
                }
    return 1;
}

static vw_status gen_spheres(vw__sb *b, const vw_gen_params *p, char *err, size_t errlen)
{
    int n = p->count ? p->count : 1000;
    vw_scene *s = b->s;
    /* World: the cube [0,L]^3. The cluster region is the cube of side L/4 at
       [L/8, 3L/8]^3, inside one octant, so a 2x2x2 decomposition of this cube (vwalls
       render --world 0,0,0,10,10,10; the default world box is the spheres' bounds) sees
       the whole cluster in one cell. The radius is set by N alone, so the uniform and the
       clustered cases of one N differ only in placement; at full clustering the
       spheres fill 6.5% of the region, far below random packing's jamming limit. */
    const double L = 10.0, cl = L / 8, ch = 3 * L / 8;
    double r = 0.25 * (L / 4) / cbrt((double)n);
    int nclust = (int)floor(p->cluster * n + 0.5);
    double mid = L / 2;
    camera(s, p, mid - 0.9 * L, mid - 1.6 * L, mid + 1.1 * L, mid, mid, mid, 0, 0, 1, 45,
           0.01);
    s->background[0] = s->background[1] = s->background[2] = 0.1f;
    float li = (float)(1.0 / sqrt(2.0));
    TRY(light(b, -L, -2 * L, 3 * L, li));
    TRY(light(b, 3 * L, -L, 2 * L, li));
    int mats[6];
    const float cols[6][3] = {{0.8f, 0.2f, 0.2f}, {0.2f, 0.7f, 0.2f}, {0.2f, 0.3f, 0.8f},
                              {0.8f, 0.7f, 0.2f}, {0.7f, 0.3f, 0.7f}, {0.8f, 0.8f, 0.8f}};
    for (int i = 0; i < 6; i++) {
        vw_material m = mat(cols[i][0], cols[i][1], cols[i][2], 0.3f, 30);
        TRY(vw__sb_intern_material(b, &m, &mats[i]));
    }
    rng rg = {p->seed};
    sgrid g = {0};
    g.cell = 2 * r;
    g.nb = 64;
    while (g.nb < (size_t)n * 2)
        g.nb *= 2;
    g.head = malloc(g.nb * sizeof *g.head);
    g.next = malloc((size_t)n * sizeof *g.next);
    g.c = malloc((size_t)n * sizeof *g.c);
    vw_status st = VW_OK;
    if (!g.head || !g.next || !g.c)
        st = VW_E_NOMEM;
    else
        for (size_t i = 0; i < g.nb; i++)
            g.head[i] = -1;
    for (int i = 0; i < n && st == VW_OK; i++) {
        double lo = i < nclust ? cl : 0, hi = i < nclust ? ch : L, c[3];
        int placed = 0;
        /* Reject and retry; the cap only matters for parameters that cannot fit. */
        for (int attempt = 0; attempt < 100000 && !placed; attempt++) {
            for (int k = 0; k < 3; k++)
                c[k] = rng_range(&rg, lo + r, hi - r);
            placed = sgrid_free(&g, c, (2 * r) * (2 * r));
        }
        if (!placed) {
            vw__errf(err, errlen, "spheres: cannot place sphere %d of %d without overlap", i,
                     n);
            st = VW_E_LIMIT;
            break;
        }
        memcpy(g.c[i], c, sizeof c);
        size_t bk = sgrid_bucket(&g, (long long)floor(c[0] / g.cell),
                                 (long long)floor(c[1] / g.cell), (long long)floor(c[2] / g.cell));
        g.next[i] = g.head[bk];
        g.head[bk] = i;
        st = vw__sb_add_sphere(b, mats[rng_next(&rg) % 6], c, r);
    }
    free(g.head);
    free(g.next);
    free(g.c);
    return st;
}

/* ---- cornell: the Cornell box -------------------------------------------------------- */

/* Geometry from the Cornell University Program of Computer Graphics' published
   measurements (millimetres, y up, the camera looking along +z). The ceiling is cut
   into four pieces around the light's opening so no two polygons overlap. Colours
   are the usual RGB fits of the measured reflectance spectra. */
static vw_status gen_cornell(vw__sb *b, const vw_gen_params *p)
{
    vw_scene *s = b->s;
    /* 35 mm focal length over a 25 mm film: 2*atan(12.5/35) = 39.31 degrees. */
    camera(s, p, 278, 273, -800, 278, 273, 0, 0, 1, 0,
           2 * atan(12.5 / 35.0) * (180 / M_PI), 1);
    TRY(light(b, 278, 548.0, 279.5, 1.0f));   /* for ray tracing, under the lamp */
    int white, red, green, lamp;
    vw_material mw = mat(0.725f, 0.71f, 0.68f, 0, 0), mr = mat(0.63f, 0.065f, 0.05f, 0, 0),
                mg = mat(0.14f, 0.45f, 0.091f, 0, 0), ml = mat(0.78f, 0.78f, 0.78f, 0, 0);
    ml.emission[0] = 17;
    ml.emission[1] = 12;
    ml.emission[2] = 4;
    TRY(vw__sb_intern_material(b, &mw, &white));
    TRY(vw__sb_intern_material(b, &mr, &red));
    TRY(vw__sb_intern_material(b, &mg, &green));
    TRY(vw__sb_intern_material(b, &ml, &lamp));
    const double inside[3] = {278, 274.4, 279.6};
    const double floor_q[4][3] = {{552.8, 0, 0}, {0, 0, 0}, {0, 0, 559.2}, {549.6, 0, 559.2}};
    const double back[4][3] = {{549.6, 0, 559.2}, {0, 0, 559.2}, {0, 548.8, 559.2},
                               {556, 548.8, 559.2}};
    const double right[4][3] = {{0, 0, 559.2}, {0, 0, 0}, {0, 548.8, 0}, {0, 548.8, 559.2}};
    /* The red wall's published corners are not coplanar (0.8 mm off: its floor edge
       runs from x = 552.8 to 549.6, its ceiling edge stays at 556), and both edges are
       shared with the floor and the ceiling, so no planar quad closes the box. It is
       written as two triangles, each planar, with the published corners. */
    const double left_a[3][3] = {{552.8, 0, 0}, {549.6, 0, 559.2}, {556, 548.8, 559.2}};
    const double left_b[3][3] = {{552.8, 0, 0}, {556, 548.8, 559.2}, {556, 548.8, 0}};
    const double lamp_q[4][3] = {{343, 548.8, 227}, {343, 548.8, 332}, {213, 548.8, 332},
                                 {213, 548.8, 227}};
    TRY(quad(b, white, floor_q, inside, 1));
    /* ceiling: x in [0,556], z in [0,559.2], minus the opening [213,343]x[227,332] */
    const double ceil_parts[4][4] = {{0, 556, 0, 227}, {0, 556, 332, 559.2},
                                     {0, 213, 227, 332}, {343, 556, 227, 332}};
    for (int i = 0; i < 4; i++) {
        const double *c = ceil_parts[i];
        const double q[4][3] = {{c[0], 548.8, c[2]}, {c[1], 548.8, c[2]},
                                {c[1], 548.8, c[3]}, {c[0], 548.8, c[3]}};
        TRY(quad(b, white, q, inside, 1));
    }
    TRY(quad(b, lamp, lamp_q, inside, 1));
    TRY(quad(b, white, back, inside, 1));
    TRY(quad(b, green, right, inside, 1));
    TRY(face(b, red, 3, left_a, inside, 1));
    TRY(face(b, red, 3, left_b, inside, 1));
    /* The two blocks: top outlines (published), sides down to the floor. */
    const double blocks[2][4][2] = {{{130, 65}, {82, 225}, {240, 272}, {290, 114}},
                                    {{423, 247}, {265, 296}, {314, 456}, {472, 406}}};
    const double heights[2] = {165, 330};
    for (int k = 0; k < 2; k++) {
        double ctr[3] = {0, heights[k] / 2, 0};
        for (int i = 0; i < 4; i++) {
            ctr[0] += blocks[k][i][0] / 4;
            ctr[2] += blocks[k][i][1] / 4;
        }
        double top[4][3];
        for (int i = 0; i < 4; i++)
            set3(top[i], blocks[k][i][0], heights[k], blocks[k][i][1]);
        TRY(quad(b, white, (const double(*)[3])top, ctr, -1));
        for (int i = 0; i < 4; i++) {
            int j = (i + 1) % 4;
            const double q[4][3] = {{blocks[k][i][0], heights[k], blocks[k][i][1]},
                                    {blocks[k][j][0], heights[k], blocks[k][j][1]},
                                    {blocks[k][j][0], 0, blocks[k][j][1]},
                                    {blocks[k][i][0], 0, blocks[k][i][1]}};
            TRY(quad(b, white, q, ctr, -1));
        }
    }
    return VW_OK;
}

/* ---- room: a furnished room ---------------------------------------------------------- */

/* A 6 x 3 x 5 m room (y up) with a table, two chairs and a bookshelf, lit by one
   diffuse panel under the ceiling (radiosity) and a point light under it (the ray
   tracer). Everything is boxes made of quads; faces resting on the floor or against
   a wall are left out. */
static vw_status gen_room(vw__sb *b, const vw_gen_params *p)
{
    vw_scene *s = b->s;
    const double W = 6, H = 3, D = 5;
    camera(s, p, 5.4, 1.7, 4.6, 2.4, 0.7, 1.4, 0, 1, 0, 60, 0.01);
    /* 0.8 m under the ceiling: from 0.15 m the ceiling met its light at a grazing angle
       (cosine 0.05 two metres away) and rendered black. */
    TRY(light(b, 3, 2.2, 2.5, 1.0f));
    vw_material mwall = mat(0.75f, 0.73f, 0.68f, 0, 0), mfloor = mat(0.45f, 0.32f, 0.2f, 0.1f, 20),
                mceil = mat(0.8f, 0.8f, 0.8f, 0, 0), mwood = mat(0.55f, 0.36f, 0.2f, 0.1f, 15),
                mfabric = mat(0.2f, 0.3f, 0.6f, 0, 0), mpanel = mat(0.8f, 0.8f, 0.8f, 0, 0),
                maccent = mat(0.65f, 0.25f, 0.2f, 0, 0);
    mpanel.emission[0] = mpanel.emission[1] = mpanel.emission[2] = 10;
    int wall, flo, ceil, wood, fabric, panel, accent;
    TRY(vw__sb_intern_material(b, &mwall, &wall));
    TRY(vw__sb_intern_material(b, &mfloor, &flo));
    TRY(vw__sb_intern_material(b, &mceil, &ceil));
    TRY(vw__sb_intern_material(b, &mwood, &wood));
    TRY(vw__sb_intern_material(b, &mfabric, &fabric));
    TRY(vw__sb_intern_material(b, &mpanel, &panel));
    TRY(vw__sb_intern_material(b, &maccent, &accent));
    /* Shell, facing in: floor, ceiling and walls get their own materials. */
    TRY(box(b, flo, 0, 0, 0, W, H, D, ~SKIP_YLO & 63, 1));
    TRY(box(b, ceil, 0, 0, 0, W, H, D, ~SKIP_YHI & 63, 1));
    TRY(box(b, wall, 0, 0, 0, W, H, D, SKIP_YLO | SKIP_YHI | SKIP_XHI, 1));
    TRY(box(b, accent, 0, 0, 0, W, H, D, ~SKIP_XHI & 63, 1));
    /* The light panel hangs 2 cm under the ceiling, facing down. */
    const double pq[4][3] = {{2.4, H - 0.02, 2.0}, {3.6, H - 0.02, 2.0},
                             {3.6, H - 0.02, 3.0}, {2.4, H - 0.02, 3.0}};
    const double below[3] = {3.0, 0.0, 2.5};
    TRY(quad(b, panel, pq, below, 1));
    /* Table: top 1.6 x 0.9 at 0.75 m, four legs. */
    double tx0 = 1.6, tx1 = 3.2, tz0 = 1.8, tz1 = 2.7;
    TRY(box(b, wood, tx0, 0.72, tz0, tx1, 0.76, tz1, 0, 0));
    for (int i = 0; i < 4; i++) {
        double x = i & 1 ? tx1 - 0.1 : tx0 + 0.04, z = i & 2 ? tz1 - 0.1 : tz0 + 0.04;
        TRY(box(b, wood, x, 0, z, x + 0.06, 0.72, z + 0.06, SKIP_YLO | SKIP_YHI, 0));
    }
    /* Two chairs facing the table from either long side. */
    for (int c = 0; c < 2; c++) {
        double cx = 2.2, cz = c ? tz1 + 0.15 : tz0 - 0.6, sz = 0.45;
        TRY(box(b, fabric, cx, 0.42, cz, cx + sz, 0.47, cz + sz, 0, 0));
        for (int i = 0; i < 4; i++) {
            double x = i & 1 ? cx + sz - 0.04 : cx, z = i & 2 ? cz + sz - 0.04 : cz;
            TRY(box(b, wood, x, 0, z, x + 0.04, 0.42, z + 0.04, SKIP_YLO | SKIP_YHI, 0));
        }
        double bz = c ? cz + sz - 0.04 : cz;   /* the back, away from the table */
        TRY(box(b, wood, cx, 0.47, bz, cx + sz, 0.95, bz + 0.04, SKIP_YLO, 0));
    }
    /* Bookshelf against the back wall (z = 0): two sides and five boards. */
    double sx0 = 4.3, sx1 = 5.5, sd = 0.35, sh = 2.0;
    TRY(box(b, wood, sx0, 0, 0, sx0 + 0.03, sh, sd, SKIP_YLO | SKIP_ZLO, 0));
    TRY(box(b, wood, sx1 - 0.03, 0, 0, sx1, sh, sd, SKIP_YLO | SKIP_ZLO, 0));
    for (int i = 0; i < 5; i++) {
        double y = 0.05 + i * (sh - 0.08) / 4;
        TRY(box(b, wood, sx0 + 0.03, y, 0, sx1 - 0.03, y + 0.03, sd,
                SKIP_XLO | SKIP_XHI | SKIP_ZLO, 0));
    }
    return VW_OK;
}

/* ---- dispatch -------------------------------------------------------------------------- */

/* Renumbers materials in order of first use by object id and drops unused ones. That
   is the order an NFF reader creates them in, so a generated scene equals its own NFF
   read back, bit for bit (the tests rely on it). */
static vw_status canonical_materials(vw_scene *s)
{
    size_t nm = s->nmaterials;
    if (nm == 0)
        return VW_OK;
    int *map = malloc(nm * sizeof *map);
    vw_material *mats = malloc(nm * sizeof *mats);
    if (!map || !mats) {
        free(map);
        free(mats);
        return VW_E_NOMEM;
    }
    for (size_t i = 0; i < nm; i++)
        map[i] = -1;
    int used = 0;
    size_t is = 0, ic = 0, ip = 0;
    for (;;) {
        int *m = NULL, best = INT32_MAX, which = -1;
        if (is < s->nspheres && s->spheres[is].id < best)
            best = s->spheres[is].id, which = 0;
        if (ic < s->ncones && s->cones[ic].id < best)
            best = s->cones[ic].id, which = 1;
        if (ip < s->npolygons && s->polygons[ip].id < best)
            best = s->polygons[ip].id, which = 2;
        if (which < 0)
            break;
        m = which == 0 ? &s->spheres[is++].material
          : which == 1 ? &s->cones[ic++].material : &s->polygons[ip++].material;
        if (map[*m] < 0) {
            mats[used] = s->materials[*m];
            map[*m] = used++;
        }
        *m = map[*m];
    }
    memcpy(s->materials, mats, (size_t)used * sizeof *mats);
    s->nmaterials = (size_t)used;
    free(map);
    free(mats);
    return VW_OK;
}

VW_API vw_status vw_gen(const char *name, const vw_gen_params *params, vw_scene **out,
                        char *err, size_t errlen)
{
    if (out)
        *out = NULL;
    if (!name || !out) {
        vw__errf(err, errlen, "vw_gen: NULL argument");
        return VW_E_INVAL;
    }
    vw_gen_params p;
    vw_gen_params_init(&p);
    if (params)
        p = *params;
    if (p.width == 0)
        p.width = 512;
    if (p.height == 0)
        p.height = 512;
    if (p.width < 0 || p.height < 0 || p.width > (1 << 20) || p.height > (1 << 20)) {
        vw__errf(err, errlen, "%s: resolution %dx%d out of range", name, p.width, p.height);
        return VW_E_INVAL;
    }
    if (p.count < 0 || p.count > MAX_OBJECTS) {
        vw__errf(err, errlen, "%s: count %d out of range (1..%d)", name, p.count, MAX_OBJECTS);
        return VW_E_INVAL;
    }
    if (!(p.cluster >= 0.0 && p.cluster <= 1.0)) {
        vw__errf(err, errlen, "%s: cluster fraction %g out of range (0..1)", name, p.cluster);
        return VW_E_INVAL;
    }
    /* Size limits keep the object count under MAX_OBJECTS: 9^7 spheres, ~3^14 tree
       parts, ~n^3/3 * 24 ring parts. */
    int maxsize = !strcmp(name, "balls") ? 7 : !strcmp(name, "tree") ? 13
                : !strcmp(name, "rings") ? 120 : 1000;
    if (p.size < 0 || p.size > maxsize) {
        vw__errf(err, errlen, "%s: size %d out of range (1..%d)", name, p.size, maxsize);
        return VW_E_INVAL;
    }
    vw__sb b;
    vw_status st = vw__sb_init(&b);
    if (st != VW_OK) {
        vw__errf(err, errlen, "%s: out of memory", name);
        return st;
    }
    if (err && errlen)
        err[0] = '\0';
    if (!strcmp(name, "balls"))
        st = gen_balls(&b, &p);
    else if (!strcmp(name, "rings"))
        st = gen_rings(&b, &p);
    else if (!strcmp(name, "tree"))
        st = gen_tree(&b, &p);
    else if (!strcmp(name, "spheres"))
        st = gen_spheres(&b, &p, err, errlen);
    else if (!strcmp(name, "cornell"))
        st = gen_cornell(&b, &p);
    else if (!strcmp(name, "room"))
        st = gen_room(&b, &p);
    else {
        vw__errf(err, errlen, "unknown generator '%s' (balls, rings, tree, spheres, cornell, room)",
                 name);
        st = VW_E_INVAL;
    }
    if (st != VW_OK) {
        if (err && errlen && !err[0])
            vw__errf(err, errlen, "%s: %s", name,
                     st == VW_E_NOMEM ? "out of memory" : "scene too large");
        vw__sb_abort(&b);
        return st;
    }
    *out = vw__sb_finish(&b);
    if ((st = canonical_materials(*out)) != VW_OK) {
        vw_scene_free(*out);
        *out = NULL;
        vw__errf(err, errlen, "%s: out of memory", name);
        return st;
    }
    return VW_OK;
}
