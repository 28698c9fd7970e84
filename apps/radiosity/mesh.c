/* mesh.c - meshing for the radiosity solver: polygons are cut into patches (the shooters)
 * along a square grid in each polygon's own frame, and the patches are clipped at the
 * walls (Sutherland-Hodgman against the planes of the cell boxes) into pieces. Spheres
 * and cones become polygons first: a fixed set of facets each (add_curved).
 *
 * A piece is kept only by the cell vw_decomp_locate() gives for its centroid with the
 * piece normal as direction, so a piece lying in a wall plane is kept once, by the cell
 * it faces. Receiver elements are not stored here: every cell cuts them from its pieces
 * along the same polygon grid (rad_elem_polygon), so element boundaries do not depend
 * on the decomposition except where walls cut them.
 */
#include "radiosity/radiosity.h"
#include "radiosity/vec.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

void rad_options_init(rad_options *o)
{
    memset(o, 0, sizeof *o);
    o->sf = 1e-3;
    o->res = 64;
    o->elem_split = 2;
    o->dims[0] = o->dims[1] = o->dims[2] = 1;
    o->per_round = 16;
    o->max_level = 3;
    o->checkpoint_every = 60;
    o->stall_shots = RAD_STALL_SHOTS;
}

int rad_material(const vw_material *mt, double rho[3], double emit[3])
{
    int clamped = 0;
    for (int k = 0; k < 3; k++) {
        double d = mt ? mt->diffuse[k] : 0.5;
        clamped |= !(d >= 0 && d <= 1);
        rho[k] = d >= 0 ? fmin(d, 1) : 0;
        emit[k] = mt && mt->emission[k] > 0 ? mt->emission[k] : 0;
    }
    return clamped;
}

int rad_reflects_all(const double rho[3])
{
    return rho[0] >= 1 || rho[1] >= 1 || rho[2] >= 1;
}

/* ---- polygon clipping ---- */

/* Keeps the part of p where dot(a, x) >= b (one Sutherland-Hodgman pass). */
static void clip_plane(const rad_poly *p, const double a[3], double b, rad_poly *out)
{
    out->n = 0;
    for (int i = 0; i < p->n; i++) {
        const double *s = p->v[i], *e = p->v[(i + 1) % p->n];
        double ds = rad_dot(a, s) - b, de = rad_dot(a, e) - b;
        if (ds >= 0 && out->n < RAD_MAXV) memcpy(out->v[out->n++], s, sizeof(double) * 3);
        if ((ds >= 0) != (de >= 0) && out->n < RAD_MAXV) {
            double t = ds / (ds - de);
            for (int k = 0; k < 3; k++) out->v[out->n][k] = s[k] + t * (e[k] - s[k]);
            out->n++;
        }
    }
    /* Drop repeated vertices (a vertex on the plane is emitted twice). */
    int k = 0;
    for (int i = 0; i < out->n; i++) {
        const double *prev = k ? out->v[k - 1] : NULL;
        if (prev && prev[0] == out->v[i][0] && prev[1] == out->v[i][1] && prev[2] == out->v[i][2]) continue;
        if (k != i) memcpy(out->v[k], out->v[i], sizeof(double) * 3);
        k++;
    }
    while (k > 1 && !memcmp(out->v[0], out->v[k - 1], sizeof(double) * 3)) k--;
    out->n = k < 3 ? 0 : k;
}

/* Clips p to the square [u0,u1] x [v0,v1] of the frame (origin, ua, va). */
static void clip_rect(const rad_poly *p, const double origin[3], const double ua[3],
                      const double va[3], double u0, double u1, double v0, double v1, rad_poly *out)
{
    rad_poly t;
    double ou = rad_dot(ua, origin), ov = rad_dot(va, origin);
    double nua[3] = {-ua[0], -ua[1], -ua[2]}, nva[3] = {-va[0], -va[1], -va[2]};
    clip_plane(p, ua, ou + u0, &t);
    clip_plane(&t, nua, -(ou + u1), out);
    clip_plane(out, va, ov + v0, &t);
    clip_plane(&t, nva, -(ov + v1), out);
}

/* Clips p to a cell box given in frame coordinates (frame rows are the box axes). */
static void clip_box(const rad_poly *p, const vw_box *b, const double *frame, rad_poly *out)
{
    rad_poly t = *p;
    for (int a = 0; a < 3; a++) {
        double ax[3] = {a == 0, a == 1, a == 2};
        if (frame) memcpy(ax, frame + 3 * a, sizeof ax);
        double nax[3] = {-ax[0], -ax[1], -ax[2]};
        clip_plane(&t, ax, b->lo[a], out);
        clip_plane(out, nax, -b->hi[a], &t);
    }
    *out = t;
}

double rad_poly_area(const rad_poly *p, double normal[3], double centroid[3])
{
    double nw[3], c[3] = {0, 0, 0}, total = 0;
    vw_polygon_normal((const double (*)[3])p->v, p->n, nw);
    double area = 0.5 * rad_norm(nw);
    if (normal) {
        memcpy(normal, nw, sizeof nw);
        rad_normalize(normal);
    }
    if (centroid) {
        /* Area-weighted fan: exact for convex polygons, which every piece and element
           is (concave polygons are meshed in convex parts, mesh_concave). */
        for (int i = 1; i + 1 < p->n; i++) {
            double e1[3], e2[3], x[3];
            rad_sub(p->v[i], p->v[0], e1);
            rad_sub(p->v[i + 1], p->v[0], e2);
            rad_cross(e1, e2, x);
            double w = 0.5 * rad_norm(x);
            for (int k = 0; k < 3; k++) c[k] += w * (p->v[0][k] + p->v[i][k] + p->v[i + 1][k]) / 3;
            total += w;
        }
        for (int k = 0; k < 3; k++)
            centroid[k] = total > 0 ? c[k] / total : (p->n ? p->v[0][k] : 0);
    }
    return area;
}

/* The piece's extent in its polygon's (u, v) frame: {umin, umax, vmin, vmax}. */
static void piece_extent(const rad_piece *pc, double ext[4])
{
    ext[0] = ext[2] = INFINITY, ext[1] = ext[3] = -INFINITY;
    for (int i = 0; i < pc->nv; i++) {
        double d[3];
        rad_sub(pc->v[i], pc->origin, d);
        double u = rad_dot(d, pc->uax), v = rad_dot(d, pc->vax);
        ext[0] = fmin(ext[0], u), ext[1] = fmax(ext[1], u);
        ext[2] = fmin(ext[2], v), ext[3] = fmax(ext[3], v);
    }
}

void rad_piece_grid(const rad_piece *pc, int lo[2], int hi[2])
{
    double e[4];
    piece_extent(pc, e);
    lo[0] = (int)floor(e[0] / pc->elem), hi[0] = (int)floor(e[1] / pc->elem);
    lo[1] = (int)floor(e[2] / pc->elem), hi[1] = (int)floor(e[3] / pc->elem);
}

double rad_mesh_solve_bytes(const rad_mesh *m, const rad_options *o, double *elements)
{
    /* The level-0 squares each piece's extent covers, its edges pulled in by a millionth
       of a square: a patch edge lies on a grid line, and the square beyond it (a sliver
       the solver drops) is not counted. Still an upper bound for pieces that are not
       rectangles. */
    double n = 0;
    for (size_t p = 0; p < m->npieces; p++) {
        const rad_piece *pc = &m->pieces[p];
        double e[4], tol = 1e-6 * pc->elem;
        piece_extent(pc, e);
        double nu = floor((e[1] - tol) / pc->elem) - floor((e[0] + tol) / pc->elem) + 1;
        double nv = floor((e[3] - tol) / pc->elem) - floor((e[2] + tol) / pc->elem) + 1;
        n += fmax(nu, 1) * fmax(nv, 1);
    }
    if (elements) *elements = n;
    double fine = o->subdivide > 0 && o->max_level > 0
                      ? (double)(1 << 2 * (o->max_level < RAD_MAX_LEVEL ? o->max_level : RAD_MAX_LEVEL))
                      : 0;
    return n * (RAD_ELEM_BYTES + fine * RAD_FINE_BYTES);
}

int rad_elem_polygon(const rad_piece *pc, int level, int gi, int gj, rad_poly *out)
{
    rad_poly p;
    p.n = pc->nv;
    memcpy(p.v, pc->v, sizeof(double) * 3 * (size_t)pc->nv);
    double h = pc->elem / (double)(1 << level);
    clip_rect(&p, pc->origin, pc->uax, pc->vax, gi * h, (gi + 1) * h, gj * h, (gj + 1) * h, out);
    /* A piece edge on a grid line (every patch edge is one) is computed a few ulps of
       the coordinates off it, so the square beyond it clips to a sliver some 1e-13 of an
       element wide, or to nothing, as the rounding of the world's position falls: the
       Cornell box had 2889 elements and 7 to 115 such slivers (2900 to 3004 elements)
       as it was scaled or moved. A sliver wins no pixel, so its radiosity stays 0, and
       subdivision split its neighbours for differing from it. Squares covering no more
       than 1e-9 of themselves are no elements: rounding stays below that while the
       coordinates are under about 1e6 element sides. But only when they are also at
       most a millionth of their piece: a piece far smaller than an element square
       (a small polygon under a large --patch-size) is no sliver, and dropping it left
       it without elements (--patch-size 1e30 kept no element at all, not even the
       emitter's). A rounding sliver is some 1e-13 of the piece wide. */
    double a = out->n >= 3 ? rad_poly_area(out, NULL, NULL) : 0;
    if (out->n >= 3 && !(a > 1e-9 * h * h) && !(a > 1e-6 * pc->area)) out->n = 0;
    return out->n;
}

/* ---- scene-level helpers ---- */

vw_box rad_world_box(const vw_scene *s)
{
    vw_box b;
    vw_scene_bounds(s, b.lo, b.hi);
    double ext = 0;
    for (int k = 0; k < 3; k++) ext = fmax(ext, b.hi[k] - b.lo[k]);
    double pad = 1e-3 * (ext > 0 ? ext : 1);
    for (int k = 0; k < 3; k++) b.lo[k] -= pad, b.hi[k] += pad;
    return b;
}

double rad_default_patch_size(const vw_scene *s)
{
    double lo[3], hi[3], ext = 0;
    vw_scene_bounds(s, lo, hi);
    for (int k = 0; k < 3; k++) ext = fmax(ext, hi[k] - lo[k]);
    return ext > 0 ? ext / 10 : 1;
}

/* Where polygon pg (the k-th) of the meshed scene came from: file:line as its reader
   recorded it, a facet's from its sphere or cone (the first nfile are the file's
   polygons), or its index when no file gave it (a generated scene). */
static void where(char *out, size_t len, const char *path, const vw_polygon *pg, size_t k,
                  size_t nfile, const rad_mesh *m)
{
    const char *name = path ? path : "scene";
    int n = pg->line > 0 ? snprintf(out, len, "%s:%d", name, pg->line) : snprintf(out, len, "%s", name);
    if (n < 0 || (size_t)n >= len) return;
    if (k >= nfile)
        snprintf(out + n, len - (size_t)n, ": object %d (a sphere or cone, as facets)",
                 m->facet_object[pg->id - m->facet_base]);
    else if (pg->line <= 0)
        snprintf(out + n, len - (size_t)n, ": polygon %zu", k);
}

/* How the two reflectance warnings begin, and which polygon they name. A material read
   from a file is named where it was defined, "FILE:LINE: warning: material 'NAME': "
   (an MTL Kd line, an NFF 'f'), so that the user finds the value to change; the first
   polygon that uses it is then given as ", PATH:LINE" after its id (polyref). One from
   no file (a generated scene, a default) is named by that polygon, as where() does. */
static void material_where(char *head, size_t hlen, char *name, size_t nlen, char *polyref,
                           size_t plen, const vw_scene *s, const vw_material *mat,
                           const char *path, const vw_polygon *pg, size_t k, size_t nfile,
                           const rad_mesh *m)
{
    const char *file = vw_scene_string(s, mat->file), *nm = vw_scene_string(s, mat->name);
    name[0] = polyref[0] = '\0';
    if (!file) {
        where(head, hlen, path, pg, k, nfile, m);
        return;
    }
    /* A file (and a name in it) may hold anything: shown printable, on one line. */
    char shown[400], nshown[VW_SHOWN_NAME + 4];
    vw_text_shown(file, strlen(file), 0, shown, sizeof shown);
    if (mat->line > 0)
        snprintf(head, hlen, "%s:%d", shown, mat->line);
    else
        snprintf(head, hlen, "%s", shown);
    if (nm)
        snprintf(name, nlen, "material '%s': ",
                 vw_text_shown(nm, strlen(nm), VW_SHOWN_NAME, nshown, sizeof nshown));
    if (pg->line > 0) snprintf(polyref, plen, ", %s:%d", path ? path : "scene", pg->line);
}

/* A warning about the material of the k-th polygon of the meshed scene s (the first
   nfile from the file), placed and named by material_where: "AT: warning: [material
   'NAME': ]reflectance R G B of polygon (id N[, FILE:LINE]) " and then fmt's text. */
static void material_warning(const vw_scene *s, size_t nfile, const char *path,
                             const rad_mesh *m, size_t k, const char *fmt, ...)
    __attribute__((format(printf, 6, 7)));
static void material_warning(const vw_scene *s, size_t nfile, const char *path,
                             const rad_mesh *m, size_t k, const char *fmt, ...)
{
    const vw_polygon *pg = &s->polygons[k];
    const vw_material *mat = &s->materials[pg->material];
    char at[512], name[64], polyref[512];
    material_where(at, sizeof at, name, sizeof name, polyref, sizeof polyref, s, mat, path, pg,
                   k, nfile, m);
    int facet = k >= nfile;
    fprintf(stderr, "%s: warning: %sreflectance %g %g %g of %s (id %d%s) ", at, name,
            mat->diffuse[0], mat->diffuse[1], mat->diffuse[2], facet ? "object" : "polygon",
            facet ? (int)m->facet_object[pg->id - m->facet_base] : pg->id, polyref);
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

static int push_piece(rad_mesh *m, size_t *cap, const rad_piece *pc, int owner)
{
    if (m->npieces == *cap) {
        size_t nc = *cap ? 2 * *cap : 256;
        rad_piece *np = realloc(m->pieces, nc * sizeof *np);
        int *no = realloc(m->owner, nc * sizeof *no);
        if (np) m->pieces = np;
        if (no) m->owner = no;
        if (!np || !no) return -1;
        *cap = nc;
    }
    m->pieces[m->npieces] = *pc;
    m->pieces[m->npieces].id = (int64_t)m->npieces;
    m->owner[m->npieces] = owner;
    m->npieces++;
    return 0;
}

/* Invariant: every piece appended lies in the box of the cell it is appended for, and
   that cell is the one vw_decomp_locate() gives for its centroid and normal. */
static vw_status mesh_polygon(rad_mesh *m, size_t *cap, const vw_decomp *d, const rad_poly *poly,
                              const double normal[3], const double origin[3], const double ua[3],
                              const double va[3], double S, double elem, int id,
                              const vw_material *mat, int *cells, int ncap, double tiny,
                              double *squares)
{
    double umin = INFINITY, umax = -INFINITY, vmin = INFINITY, vmax = -INFINITY;
    for (int i = 0; i < poly->n; i++) {
        double q[3];
        rad_sub(poly->v[i], origin, q);
        double u = rad_dot(q, ua), v = rad_dot(q, va);
        umin = fmin(umin, u), umax = fmax(umax, u), vmin = fmin(vmin, v), vmax = fmax(vmax, v);
    }
    /* The squares of side S over the polygon's extent, counted before they are visited
       (and before their indices are made ints): a patch size far below the scene's
       would take forever or overflow. */
    *squares += (floor(umax / S) - floor(umin / S) + 1) * (floor(vmax / S) - floor(vmin / S) + 1);
    if (!(*squares <= RAD_MAX_SQUARES)) return VW_E_LIMIT;
    const double *frame = vw_decomp_frame(d);
    for (int i = (int)floor(umin / S); i <= (int)floor(umax / S); i++)
        for (int j = (int)floor(vmin / S); j <= (int)floor(vmax / S); j++) {
            rad_poly patch, piece;
            clip_rect(poly, origin, ua, va, i * S, (i + 1) * S, j * S, (j + 1) * S, &patch);
            double patch_area;
            if (patch.n < 3 || (patch_area = rad_poly_area(&patch, NULL, NULL)) <= tiny) continue;
            vw_box pb = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
            for (int k = 0; k < patch.n; k++)
                for (int a = 0; a < 3; a++) {
                    pb.lo[a] = fmin(pb.lo[a], patch.v[k][a]);
                    pb.hi[a] = fmax(pb.hi[a], patch.v[k][a]);
                }
            int nc = vw_decomp_cells_overlapping(d, &pb, 0, cells, ncap);
            for (int c = 0; c < nc && c < ncap; c++) {
                vw_box cb = vw_decomp_cell_box(d, cells[c]);
                clip_box(&patch, &cb, frame, &piece);
                double area, cen[3];
                if (piece.n < 3 || (area = rad_poly_area(&piece, NULL, cen)) <= tiny) continue;
                int owner = vw_decomp_locate(d, cen, normal);
                if (owner != cells[c]) continue;
                rad_piece pc;
                memset(&pc, 0, sizeof pc);
                pc.poly = id;
                pc.nv = piece.n;
                pc.pi = i, pc.pj = j;
                memcpy(pc.v, piece.v, sizeof(double) * 3 * (size_t)piece.n);
                memcpy(pc.normal, normal, sizeof pc.normal);
                memcpy(pc.centroid, cen, sizeof cen);
                pc.area = area;
                /* An uncut patch is its one piece: clip_box leaves its vertices as they
                   are, so both areas are the same number and a one-cell run shoots as it
                   did before. fmax: a cut piece is never larger than its patch, rounding
                   aside. */
                pc.patch_area = fmax(patch_area, area);
                memcpy(pc.origin, origin, sizeof pc.origin);
                memcpy(pc.uax, ua, sizeof pc.uax);
                memcpy(pc.vax, va, sizeof pc.vax);
                pc.elem = elem;
                rad_material(mat, pc.rho, pc.emit);
                for (int k = 0; k < 3; k++) m->emitted[k] += pc.emit[k] * area;
                m->area += area;
                if (push_piece(m, cap, &pc, owner)) return VW_E_NOMEM;
            }
        }
    return VW_OK;
}

/* The most corners of a polygon handed to mesh_polygon: clipping to a patch square and
   a cell box adds at most 10 (see RAD_MAXV). */
#define CHUNK (RAD_MAXV - 10)

/* Does the polygon (on its plane, normal n) turn left, or go straight on, at every
   corner? A turn to the right by more than rounding makes it concave. The turn is taken
   between corners at different places: a corner given twice turns by 0 with its copy,
   and an L whose inner corner a file repeats was meshed as convex, its corner piece
   concave. */
static int is_convex(const double (*v)[3], int nv, const double n[3])
{
    for (int i = 0; i < nv; i++) {
        int j = (i + 1) % nv, k;
        while (j != i && !memcmp(v[j], v[i], sizeof v[i])) j = (j + 1) % nv;
        for (k = (j + 1) % nv; k != i && !memcmp(v[k], v[j], sizeof v[j]);) k = (k + 1) % nv;
        if (j == i || k == j) continue;
        double e1[3], e2[3], x[3];
        rad_sub(v[j], v[i], e1);
        rad_sub(v[k], v[j], e2);
        rad_cross(e1, e2, x);
        if (rad_dot(x, n) < -1e-12 * rad_norm(e1) * rad_norm(e2)) return 0;
    }
    return 1;
}

/* An edge of a polygon in its plane's (u, v) coordinates, for crosses_itself. */
typedef struct flat_edge {
    double a[2], b[2];
    double ulo, uhi, vlo, vhi;
    int i; /* from corner i to corner i + 1 */
} flat_edge;

static int by_ulo(const void *x, const void *y)
{
    double p = ((const flat_edge *)x)->ulo, q = ((const flat_edge *)y)->ulo;
    return (p > q) - (p < q);
}

/* The side of line a->b that c is on: 1 left, -1 right, 0 on it (within rounding). */
static int side2(const double a[2], const double b[2], const double c[2])
{
    double e[2] = {b[0] - a[0], b[1] - a[1]}, f[2] = {c[0] - a[0], c[1] - a[1]};
    double x = e[0] * f[1] - e[1] * f[0];
    double tol = 1e-12 * (fabs(e[0]) + fabs(e[1])) * (fabs(f[0]) + fabs(f[1]));
    return x > tol ? 1 : x < -tol ? -1 : 0;
}

/* Do two edges of the polygon (corners v on its plane, axes ua, va) cross, each passing
   strictly through the other? Then it has no one inside: a pentagram turns left at
   every corner, passes as convex, and fanned covers its centre twice; a bow tie is
   ear-clipped into nonsense. Edges that only touch (a corner on another edge, a
   keyhole's two sides of one cut) do not count. The edges are swept by their least u,
   so a polygon with many corners costs about n log n. *e1, *e2: the corners (from 1)
   where the two edges start. -1 when out of memory. */
static int crosses_itself(const double (*v)[3], int nv, const double ua[3], const double va[3],
                          int *e1, int *e2)
{
    if (nv < 4) return 0;
    flat_edge *e = malloc(sizeof *e * (size_t)nv);
    if (!e) return -1;
    for (int i = 0; i < nv; i++) {
        const double *p = v[i], *q = v[(i + 1) % nv];
        flat_edge *x = &e[i];
        x->a[0] = rad_dot(p, ua), x->a[1] = rad_dot(p, va);
        x->b[0] = rad_dot(q, ua), x->b[1] = rad_dot(q, va);
        x->ulo = fmin(x->a[0], x->b[0]), x->uhi = fmax(x->a[0], x->b[0]);
        x->vlo = fmin(x->a[1], x->b[1]), x->vhi = fmax(x->a[1], x->b[1]);
        x->i = i;
    }
    qsort(e, (size_t)nv, sizeof *e, by_ulo);
    int found = 0;
    for (int i = 0; i < nv && !found; i++)
        for (int j = i + 1; j < nv && e[j].ulo <= e[i].uhi && !found; j++) {
            const flat_edge *x = &e[i], *y = &e[j];
            int d = abs(x->i - y->i);
            if (d == 1 || d == nv - 1 || y->vlo > x->vhi || y->vhi < x->vlo) continue;
            if (side2(x->a, x->b, y->a) * side2(x->a, x->b, y->b) < 0 &&
                side2(y->a, y->b, x->a) * side2(y->a, y->b, x->b) < 0) {
                found = 1;
                *e1 = 1 + (x->i < y->i ? x->i : y->i);
                *e2 = 1 + (x->i < y->i ? y->i : x->i);
            }
        }
    free(e);
    return found;
}

/* A convex part of a concave polygon, as corner numbers in the polygon's winding. */
typedef struct part {
    int n;
    int c[CHUNK];
} part;

/* Adds triangle t (corner numbers, polygon winding) to part p when they share an edge
   and the union is still convex with at most CHUNK corners. */
static int part_merge(part *p, const int t[3], const double (*v)[3], const double n[3])
{
    if (p->n >= CHUNK) return 0;
    for (int i = 0; i < p->n; i++) {
        int a = p->c[i], b = p->c[(i + 1) % p->n];
        for (int k = 0; k < 3; k++) {
            if (t[k] != b || t[(k + 1) % 3] != a) continue;
            /* t runs b -> a -> w: w goes between a and b. */
            part q;
            q.n = 0;
            for (int j = 0; j <= i; j++) q.c[q.n++] = p->c[j];
            q.c[q.n++] = t[(k + 2) % 3];
            for (int j = i + 1; j < p->n; j++) q.c[q.n++] = p->c[j];
            double (*w)[3] = malloc(sizeof *w * (size_t)q.n);
            if (!w) return 0;
            for (int j = 0; j < q.n; j++) memcpy(w[j], v[q.c[j]], sizeof w[j]);
            int ok = is_convex((const double (*)[3])w, q.n, n);
            free(w);
            if (ok) *p = q;
            return ok;
        }
    }
    return 0;
}

/* Meshes a concave polygon (corners v on its plane) as convex parts: its ear-clipped
   triangles (vw_polygon_triangulate), each merged into one of the last few parts when
   the union stays convex. Every piece must be convex: the hemicube rasteriser and the
   picture fill a polygon by its edge functions (the intersection of the half planes),
   rad_poly_area's centroid fans it, and fanning a concave polygon from one corner
   covers area outside it (a gear's faces were filled in between the teeth). The parts
   tile the polygon, so its area and its patch grid are the polygon's; a patch square
   the parts divide is several pieces, as one a wall cuts is. */
static vw_status mesh_concave(rad_mesh *m, size_t *cap, const vw_decomp *d, const double (*v)[3], int nv,
                              const double normal[3], const double origin[3], const double ua[3],
                              const double va[3], double S, double elem, int id,
                              const vw_material *mat, int *cells, int ncap, double tiny,
                              double *squares)
{
    if (nv < 3) return VW_OK; /* no area (is_convex takes every smaller polygon anyway) */
    int (*tri)[3] = malloc(sizeof *tri * (size_t)(nv - 2));
    part *parts = malloc(sizeof *parts * (size_t)(nv - 2));
    vw_status st = tri && parts ? vw_polygon_triangulate(v, nv, tri) : VW_E_NOMEM;
    int np = 0;
    for (int t = 0; t < nv - 2 && st == VW_OK; t++) {
        rad_poly tp = {.n = 3};
        for (int k = 0; k < 3; k++) memcpy(tp.v[k], v[tri[t][k]], sizeof tp.v[k]);
        if (rad_poly_area(&tp, NULL, NULL) <= tiny) continue;
        /* Ear clipping walks along the boundary: a triangle shares an edge with one of
           the parts just made, so looking back a few keeps this linear. */
        int merged = 0;
        for (int p = np - 1; p >= 0 && p >= np - 8 && !merged; p--) merged = part_merge(&parts[p], tri[t], v, normal);
        if (!merged) parts[np++] = (part){.n = 3, .c = {tri[t][0], tri[t][1], tri[t][2]}};
    }
    for (int p = 0; p < np && st == VW_OK; p++) {
        rad_poly all;
        all.n = parts[p].n;
        for (int k = 0; k < all.n; k++) memcpy(all.v[k], v[parts[p].c[k]], sizeof all.v[k]);
        st = mesh_polygon(m, cap, d, &all, normal, origin, ua, va, S, elem, id, mat, cells, ncap, tiny, squares);
    }
    free(tri);
    free(parts);
    return st;
}

/* ---- spheres and cones, as facets ---- */

/* The fixed subdivision of spheres and cones: a sphere is RAD_SPHERE_LON x
   RAD_SPHERE_LAT facets between meridians and parallels (triangles at the poles, planar
   trapezoids between), a cone RAD_SPHERE_LON trapezoids around its axis (no caps, as
   NFF's). Corners lie on the surface, so the facets are inscribed: a sphere's area is
   96.8 % of the true one, a cylinder's 99.4 %. Fixed, so that a scene meshes the same
   on every process and in every run, whatever --patch-size; a facet larger than a
   patch is cut into patches as any polygon. */
#define RAD_SPHERE_LON 16
#define RAD_SPHERE_LAT 8

double rad_mesh_facets(const vw_scene *s)
{
    return (double)s->nspheres * RAD_SPHERE_LON * RAD_SPHERE_LAT + (double)s->ncones * RAD_SPHERE_LON;
}

typedef struct facet_sink {
    vw_scene *t;        /* the scene being extended */
    size_t capv, capi, capp;
    rad_mesh *m;
    size_t capf;
    int line; /* of the sphere or cone being cut into facets */
} facet_sink;

/* Appends the polygon v[0..n) as a facet of object obj (material mat), its winding
   turned so that its normal points along out (away from the surface's inside). */
static int add_facet(facet_sink *k, const double (*v)[3], int n, const double out[3], int obj, int mat)
{
    vw_scene *t = k->t;
    double nw[3];
    vw_polygon_normal(v, n, nw);
    int flip = rad_dot(nw, out) < 0;
    if (t->nvertices + (size_t)n > k->capv) {
        size_t c = 2 * (t->nvertices + (size_t)n) + 64;
        double (*q)[3] = realloc(t->vertices, sizeof *q * c);
        if (!q) return -1;
        t->vertices = q, k->capv = c;
    }
    if (t->nindices + (size_t)n > k->capi) {
        size_t c = 2 * (t->nindices + (size_t)n) + 64;
        int *q = realloc(t->indices, sizeof *q * c);
        if (!q) return -1;
        t->indices = q, k->capi = c;
    }
    if (t->npolygons + 1 > k->capp) {
        size_t c = 2 * t->npolygons + 64;
        vw_polygon *q = realloc(t->polygons, sizeof *q * c);
        if (!q) return -1;
        t->polygons = q, k->capp = c;
    }
    if (k->m->nfacets + 1 > k->capf) {
        size_t c = 2 * k->m->nfacets + 64;
        int32_t *q = realloc(k->m->facet_object, sizeof *q * c);
        if (!q) return -1;
        k->m->facet_object = q, k->capf = c;
    }
    vw_polygon *pg = &t->polygons[t->npolygons++];
    memset(pg, 0, sizeof *pg);
    pg->id = k->m->facet_base + (int)k->m->nfacets;
    pg->material = mat;
    pg->line = k->line;
    pg->first = (int)t->nindices;
    pg->count = n;
    for (int i = 0; i < n; i++) {
        memcpy(t->vertices[t->nvertices], v[flip ? n - 1 - i : i], sizeof v[0]);
        t->indices[t->nindices++] = (int)t->nvertices++;
    }
    k->m->facet_object[k->m->nfacets++] = obj;
    return 0;
}

/* Two unit vectors perpendicular to w and to each other. */
static void perp_frame(const double w[3], double u[3], double v[3])
{
    double a[3] = {fabs(w[0]) < 0.9 ? 1 : 0, fabs(w[0]) < 0.9 ? 0 : 1, 0};
    rad_cross(w, a, u);
    rad_normalize(u);
    rad_cross(w, u, v);
}

/* The scene t: s's polygons followed by the facets of its spheres and cones, ids from
   m->facet_base on (m->facet_object maps them back). t's arrays are its own (free them
   with free_facets), its other fields s's. Degenerate facets (a cone's apex) are left
   to the mesher, which skips zero areas. */
static vw_status add_curved(const vw_scene *s, vw_scene *t, rad_mesh *m)
{
    *t = *s;
    t->normals = NULL; /* the mesher reads none; the new corners have none */
    t->polygons = NULL, t->vertices = NULL, t->indices = NULL;
    facet_sink k = {t, 0, 0, 0, m, 0, 0};
    size_t nv = s->nvertices, ni = s->nindices, np = s->npolygons;
    t->vertices = malloc(sizeof *t->vertices * (nv + 1));
    t->indices = malloc(sizeof *t->indices * (ni + 1));
    t->polygons = malloc(sizeof *t->polygons * (np + 1));
    if (!t->vertices || !t->indices || !t->polygons) return VW_E_NOMEM;
    if (nv) memcpy(t->vertices, s->vertices, sizeof *t->vertices * nv);
    if (ni) memcpy(t->indices, s->indices, sizeof *t->indices * ni);
    if (np) memcpy(t->polygons, s->polygons, sizeof *t->polygons * np);
    k.capv = nv + 1, k.capi = ni + 1, k.capp = np + 1;
    int base = 0;
    for (size_t i = 0; i < np; i++) base = s->polygons[i].id >= base ? s->polygons[i].id + 1 : base;
    for (size_t i = 0; i < s->nspheres; i++) base = s->spheres[i].id >= base ? s->spheres[i].id + 1 : base;
    for (size_t i = 0; i < s->ncones; i++) base = s->cones[i].id >= base ? s->cones[i].id + 1 : base;
    m->facet_base = base;
    const double pi = 3.14159265358979323846;
    for (size_t i = 0; i < s->nspheres; i++) {
        const vw_sphere *sp = &s->spheres[i];
        k.line = sp->line;
        double r = fabs(sp->radius), sign = sp->radius < 0 ? -1 : 1; /* negative: seen from inside */
        for (int a = 0; a < RAD_SPHERE_LAT; a++)
            for (int b = 0; b < RAD_SPHERE_LON; b++) {
                double q[4][3], th[2] = {pi * a / RAD_SPHERE_LAT, pi * (a + 1) / RAD_SPHERE_LAT};
                double ph[2] = {2 * pi * b / RAD_SPHERE_LON, 2 * pi * (b + 1) / RAD_SPHERE_LON};
                static const int corner[4][2] = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
                int n = 0;
                for (int c = 0; c < 4; c++) {
                    double t0 = th[corner[c][0]], p0 = ph[corner[c][1]];
                    double x[3] = {sp->center[0] + r * sin(t0) * cos(p0), sp->center[1] + r * cos(t0),
                                   sp->center[2] + r * sin(t0) * sin(p0)};
                    /* A pole is one corner, not two. */
                    if ((a == 0 && c == 1) || (a == RAD_SPHERE_LAT - 1 && c == 3)) continue;
                    memcpy(q[n++], x, sizeof x);
                }
                double cen[3] = {0, 0, 0}, out[3];
                for (int c = 0; c < n; c++)
                    for (int j = 0; j < 3; j++) cen[j] += q[c][j] / n;
                for (int j = 0; j < 3; j++) out[j] = sign * (cen[j] - sp->center[j]);
                if (add_facet(&k, (const double (*)[3])q, n, out, sp->id, sp->material)) return VW_E_NOMEM;
            }
    }
    for (size_t i = 0; i < s->ncones; i++) {
        const vw_cone *cn = &s->cones[i];
        k.line = cn->line;
        double w[3], u[3], v[3];
        rad_sub(cn->apex, cn->base, w);
        if (!rad_normalize(w)) continue; /* no axis: nothing to mesh */
        perp_frame(w, u, v);
        double rb = fabs(cn->base_radius), ra = fabs(cn->apex_radius);
        double sign = cn->base_radius < 0 || cn->apex_radius < 0 ? -1 : 1;
        for (int b = 0; b < RAD_SPHERE_LON; b++) {
            double q[4][3], ph[2] = {2 * pi * b / RAD_SPHERE_LON, 2 * pi * (b + 1) / RAD_SPHERE_LON};
            int n = 0;
            for (int c = 0; c < 4; c++) {
                int top = c >= 2, side = c == 1 || c == 2;
                double rr = top ? ra : rb, p0 = ph[side];
                if (rr == 0 && (c == 1 || c == 2)) continue; /* a point end: a triangle */
                for (int j = 0; j < 3; j++)
                    q[n][j] = (top ? cn->apex[j] : cn->base[j]) + rr * (cos(p0) * u[j] + sin(p0) * v[j]);
                n++;
            }
            double pm = 0.5 * (ph[0] + ph[1]), out[3];
            for (int j = 0; j < 3; j++) out[j] = sign * (cos(pm) * u[j] + sin(pm) * v[j]);
            if (n >= 3 && add_facet(&k, (const double (*)[3])q, n, out, cn->id, cn->material)) return VW_E_NOMEM;
        }
    }
    return VW_OK;
}

static void free_facets(vw_scene *t)
{
    free(t->vertices), free(t->indices), free(t->polygons);
}

static int is_ply(const char *path)
{
    size_t n = path ? strlen(path) : 0;
    return n >= 4 && !strcasecmp(path + n - 4, ".ply");
}

vw_status rad_mesh_build(const vw_scene *s, const char *path, const vw_decomp *d,
                         const rad_options *o, rad_mesh *m, char *err, size_t errlen)
{
    memset(m, 0, sizeof *m);
    /* From here on s is the scene with its spheres and cones as facets (after its own
       polygons, so that polygon k < s0->npolygons is the file's k-th). */
    const vw_scene *s0 = s;
    /* Refused before the facets are made: 66430 spheres would be 8.5 million facets
       (a gigabyte of corners) before the patch count below refused them. */
    double nfacets = rad_mesh_facets(s);
    if (nfacets > RAD_MAX_SQUARES) {
        snprintf(err, errlen,
                 "%s: %zu spheres and %zu cones are %.0f facets (%d a sphere, %d a cone), more "
                 "than the %d patches radiosity meshes", path ? path : "scene", s->nspheres,
                 s->ncones, nfacets, RAD_SPHERE_LON * RAD_SPHERE_LAT, RAD_SPHERE_LON, RAD_MAX_SQUARES);
        return VW_E_LIMIT;
    }
    vw_scene aug;
    if (add_curved(s0, &aug, m) != VW_OK) {
        free_facets(&aug);
        rad_mesh_free(m);
        snprintf(err, errlen, "%s: out of memory while meshing", path ? path : "scene");
        return VW_E_NOMEM;
    }
    s = &aug;
    size_t cap = 0;
    double S = o->patch_size > 0 ? o->patch_size : rad_default_patch_size(s);
    double elem = S / (o->elem_split > 0 ? o->elem_split : 1);
    double lo[3], hi[3], diag = 0;
    vw_scene_bounds(s, lo, hi);
    for (int k = 0; k < 3; k++) diag += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    diag = sqrt(diag);
    double tiny = 1e-14 * diag * diag;
    int ncells = vw_decomp_cell_count(d);
    int *cells = malloc(sizeof(int) * (size_t)ncells);
    if (!cells) {
        free_facets(&aug);
        rad_mesh_free(m);
        return VW_E_NOMEM;
    }
    vw_status st = VW_OK;
    int max_id = -1;
    double squares = 0; /* of the patch grid over every polygon so far */
    size_t nclamped = 0, first_clamped = 0; /* polygons whose reflectance is clamped */
    size_t nwhite = 0, first_white = 0;     /* non-emitters reflecting all of a channel */
    for (size_t k = 0; k < s->npolygons && st == VW_OK; k++) {
        const vw_polygon *pg = &s->polygons[k];
        if (pg->id > max_id) max_id = pg->id;
        rad_poly all;
        int nv = pg->count;
        /* The corners (flattened onto the polygon's plane further down), and the plane
           from Newell's method over all of them. */
        double (*flat)[3] = malloc(sizeof *flat * (size_t)(nv > 0 ? nv : 1));
        if (!flat) {
            st = VW_E_NOMEM;
            break;
        }
        for (int i = 0; i < nv; i++) memcpy(flat[i], s->vertices[s->indices[pg->first + i]], sizeof flat[i]);
        double nw[3], cen[3] = {0, 0, 0}, size = 0;
        vw_polygon_normal((const double (*)[3])flat, nv, nw);
        for (int i = 0; i < nv; i++)
            for (int c = 0; c < 3; c++) cen[c] += flat[i][c] / nv;
        for (int i = 0; i < nv; i++) {
            double q[3];
            rad_sub(s->vertices[s->indices[pg->first + i]], cen, q);
            size = fmax(size, rad_norm(q));
        }
        double area = 0.5 * rad_norm(nw), normal[3] = {nw[0], nw[1], nw[2]};
        char at[512];
        if (!(area > tiny) || !rad_normalize(normal)) {
            if (!o->quiet && k < s0->npolygons) { /* a facet: a cone's point end */
                where(at, sizeof at, path, pg, k, s0->npolygons, m);
                fprintf(stderr, "%s: warning: zero-area polygon (id %d) skipped\n", at, pg->id);
            }
            free(flat);
            continue;
        }
        /* Measured data (the Cornell box) is a little off planar: up to 5% of the
           polygon's size is flattened onto its Newell plane with a warning, more is an
           error. */
        double off = 0;
        int worst = 0;
        for (int i = 0; i < nv; i++) {
            double q[3];
            rad_sub(s->vertices[s->indices[pg->first + i]], cen, q);
            if (fabs(rad_dot(q, normal)) > off) off = fabs(rad_dot(q, normal)), worst = i;
        }
        if (off > 0.05 * size) {
            where(at, sizeof at, path, pg, k, s0->npolygons, m);
            snprintf(err, errlen, "%s: polygon (id %d) is not planar (vertex %d is %.3g off its plane)", at,
                     pg->id, worst + 1, off);
            st = VW_E_INPUT;
        } else if (off > 1e-3 * size && !o->quiet) {
            where(at, sizeof at, path, pg, k, s0->npolygons, m);
            fprintf(stderr, "%s: warning: polygon (id %d) is not planar (%.3g off), flattened\n", at, pg->id, off);
        }
        if (st != VW_OK) {
            free(flat);
            break;
        }
        /* The polygon frame: u along its longest edge, origin at that edge's start, so
           patches of rectangles are rectangles. */
        double origin[3], ua[3] = {0, 0, 0}, va[3];
        memcpy(origin, s->vertices[s->indices[pg->first]], sizeof origin);
        for (int i = 0; i < nv; i++) {
            double e[3];
            const double *a = s->vertices[s->indices[pg->first + i]];
            rad_sub(s->vertices[s->indices[pg->first + (i + 1) % nv]], a, e);
            if (rad_norm(e) > rad_norm(ua)) memcpy(ua, e, sizeof e), memcpy(origin, a, sizeof origin);
        }
        {
            double q[3];
            rad_sub(origin, cen, q);
            double dd = rad_dot(q, normal);
            for (int c = 0; c < 3; c++) origin[c] -= dd * normal[c];
        }
        double proj = rad_dot(ua, normal);
        for (int c = 0; c < 3; c++) ua[c] -= proj * normal[c];
        rad_normalize(ua);
        rad_cross(normal, ua, va);
        const vw_material *mat =
            pg->material >= 0 && (size_t)pg->material < s->nmaterials ? &s->materials[pg->material] : NULL;
        double rho_used[3], emit_used[3];
        if (rad_material(mat, rho_used, emit_used) && nclamped++ == 0) first_clamped = k;
        /* Emitters are not counted: lights of Kd 1 are the rule in NFF files, and the
           other surfaces absorb what such a light reflects unless they reflect all too. */
        if (rad_reflects_all(rho_used) && !(rad_sum3(emit_used) > 0) && nwhite++ == 0) first_white = k;
        /* The corners onto the Newell plane. */
        for (int i = 0; i < nv; i++) {
            double q[3];
            rad_sub(flat[i], cen, q);
            double dd = rad_dot(q, normal);
            for (int c = 0; c < 3; c++) flat[i][c] -= dd * normal[c];
        }
        int c1 = 0, c2 = 0, crossed = crosses_itself((const double (*)[3])flat, nv, ua, va, &c1, &c2);
        if (crossed < 0) {
            free(flat);
            st = VW_E_NOMEM;
            break;
        }
        if (crossed) {
            where(at, sizeof at, path, pg, k, s0->npolygons, m);
            snprintf(err, errlen,
                     "%s: polygon (id %d) crosses itself (its edges from corners %d and %d): "
                     "radiosity takes simple polygons only; split it",
                     at, pg->id, c1, c2);
            free(flat);
            st = VW_E_INPUT;
            break;
        }
        if (is_convex(flat, nv, normal)) {
            /* Large polygons are fanned into chunks that fit RAD_MAXV after clipping. */
            for (int first = 1; first + 1 < nv && st == VW_OK; first += CHUNK - 2) {
                all.n = 0;
                memcpy(all.v[all.n++], flat[0], sizeof(double) * 3);
                for (int i = first; i < nv && all.n < CHUNK; i++) memcpy(all.v[all.n++], flat[i], sizeof(double) * 3);
                if (all.n < 3 || rad_poly_area(&all, NULL, NULL) <= tiny) continue;
                st = mesh_polygon(m, &cap, d, &all, normal, origin, ua, va, S, elem, pg->id, mat, cells,
                                  ncells, tiny, &squares);
                if (all.n < CHUNK) break;
            }
        } else {
            st = mesh_concave(m, &cap, d, flat, nv, normal, origin, ua, va, S, elem, pg->id, mat, cells,
                              ncells, tiny, &squares);
        }
        free(flat);
    }
    free(cells);
    m->npolys = (size_t)(max_id + 1);
    m->patch_size = S;
    /* Once, not per polygon: a scene usually shares a few materials among many. */
    if (st == VW_OK && nclamped && !o->quiet)
        material_warning(s, s0->npolygons, path, m, first_clamped,
                         "is outside [0, 1], clamped (%zu polygon%s in all); the solver and "
                         "the CSV use the clamped values", nclamped, nclamped == 1 ? "" : "s");
    /* A surface of reflectance 1 absorbs nothing in that channel: in a closed scene of
       them the emitted power is never spent, only spread over the patches, and the
       largest patch's share may stay above --sf for ever (a closed box of Kd 1 and 27
       patches: the largest held 7.7 % of the emitted power after 12000 shots, against
       --sf 1e-3). Said before the solve, with what to do; the solve itself stops as
       stalled (solve.c, stall_check). */
    if (st == VW_OK && nwhite && !o->quiet)
        material_warning(s, s0->npolygons, path, m, first_white,
                         "is 1 or more in a channel, so it absorbs nothing there (%zu polygon%s "
                         "in all, lights not counted): in a closed scene the solve may be slow "
                         "or not reach --sf %g; it stops, stalled, when %lld shots "
                         "(--stall-shots) absorb or let escape less than sf of the emitted "
                         "power. Give --max-shots, or a reflectance below 1 (Kd 0.9, say)",
                         nwhite, nwhite == 1 ? "" : "s", o->sf,
                         (long long)(o->stall_shots > 0 ? o->stall_shots : RAD_STALL_SHOTS));
    if (st == VW_E_NOMEM) snprintf(err, errlen, "%s: out of memory while meshing", path ? path : "scene");
    if (st == VW_E_LIMIT)
        snprintf(err, errlen,
                 "%s: patch size %g is too small for this scene: more than %d patch squares "
                 "(the default is %g)", path ? path : "scene", S, RAD_MAX_SQUARES,
                 rad_default_patch_size(s));
    free_facets(&aug);
    if (st == VW_OK && m->npieces == 0) {
        snprintf(err, errlen, "%s: no polygon to mesh (radiosity needs polygons, spheres or cones)",
                 path ? path : "scene");
        st = VW_E_INPUT;
    }
    if (st == VW_OK && !(rad_sum3(m->emitted) > 0)) {
        snprintf(err, errlen,
                 "%s: no emitter: give some material an emission (MTL 'Ke r g b', NFF '#vw Ke r g b'%s)",
                 path ? path : "scene", is_ply(path) ? "; PLY has no emission: convert the scene to OBJ+MTL or NFF" : "");
        st = VW_E_INPUT;
    }
    if (st != VW_OK) rad_mesh_free(m);
    return st;
}

void rad_mesh_free(rad_mesh *m)
{
    if (!m) return;
    free(m->pieces);
    free(m->owner);
    free(m->facet_object);
    memset(m, 0, sizeof *m);
}
