/* staggered.c - the staggered balancer (the paper's "optimizing the cell shape"): the
 * world is cut into x slabs of equal load, each slab on its own into y columns of equal
 * load, each column on its own along z. A face may then have several neighbours, but
 * every cell gets 1/ncells of the load up to the resolution of the load field.
 *
 * The result is a kd-tree (kind staggered); cell (i, j, k) - slab i, column j, layer k -
 * gets id i + nx*(j + ny*k), as in a grid, so block mappings still see the layout.
 */
#include "balance/balance_internal.h"

#include <stdlib.h>
#include <string.h>

typedef struct stag {
    vw_kd_node *nodes;
    int nn;
    const int *dims;
    double minw[3];
    const double *share; /* each cell's wanted share of the load, or NULL: equal cells */
    double *piece;       /* room for one cut's pieces' shares (the most cells a side) */
    int thin; /* a slab or column too thin for its cuts at the doubles' resolution */
} stag;

/* The first of pts[0..n), sorted along axis, with x[axis] >= x (n if none). */
static long first_at(const vw__lpt *pts, long n, int axis, double x)
{
    long lo = 0, hi = n;
    while (lo < hi) {
        long mid = lo + (hi - lo) / 2;
        if (pts[mid].x[axis] < x)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

static int build(stag *s, vw__lpt *pts, long n, vw_box box, int axis, int idx[3]);

/* Nodes for pieces [i0, i1) of box along axis with boundaries b; returns node index.
   Piece i's points are pts[e[i] .. e[i + 1]): those with b[i] <= x[axis] < b[i + 1] (the
   last piece's also at or past b[parts]), found in the points sorted along axis before
   any piece's own cuts reorder its range. (Each piece scanned all the slab's points
   once: 4000x2x1 cells took seconds.) */
static int pieces(stag *s, vw__lpt *pts, const long *e, vw_box box, int axis, const double *b,
                  int i0, int i1, int idx[3])
{
    if (i1 - i0 == 1) {
        vw_box sub = box;
        sub.lo[axis] = b[i0];
        sub.hi[axis] = b[i1];
        idx[axis] = i0;
        return build(s, pts + e[i0], e[i1] - e[i0], sub, axis + 1, idx);
    }
    int me = s->nn++;
    int mid = (i0 + i1) / 2;
    s->nodes[me].axis = axis;
    s->nodes[me].split = b[mid];
    s->nodes[me].cell = -1;
    int l = pieces(s, pts, e, box, axis, b, i0, mid, idx);
    int r = l < 0 ? -1 : pieces(s, pts, e, box, axis, b, mid, i1, idx);
    if (r < 0) return -1;
    s->nodes[me].left = l;
    s->nodes[me].right = r;
    return me;
}

static int build(stag *s, vw__lpt *pts, long n, vw_box box, int axis, int idx[3])
{
    if (axis == 3) {
        int me = s->nn++;
        s->nodes[me].axis = -1;
        s->nodes[me].cell = idx[0] + s->dims[0] * (idx[1] + s->dims[1] * idx[2]);
        s->nodes[me].left = s->nodes[me].right = -1;
        s->nodes[me].split = 0;
        return me;
    }
    int parts = s->dims[axis];
    if (parts < 2) {
        idx[axis] = 0;
        return build(s, pts, n, box, axis + 1, idx);
    }
    double *b = malloc(sizeof(double) * (size_t)(parts + 1));
    if (!b) return -1;
    b[0] = box.lo[axis];
    b[parts] = box.hi[axis];
    /* This slab's (column's) own cut: only its points count. Every cut spans the world
       box on its axis, but that may be narrower than a double per cut (vw__cut): then
       there is no tree to build, and the balancer keeps the walls it has. */
    /* With shares, a piece's is the sum of its cells' in this slab (column): the cells
       whose indices below axis are idx's. Only those are visited, so each level of the
       tree reads every cell once. */
    const double *sh = NULL;
    if (s->share) {
        const int *d = s->dims;
        int lo[3], hi[3], ix[3];
        for (int a = 0; a < 3; a++) {
            lo[a] = a < axis ? idx[a] : 0;
            hi[a] = a < axis ? idx[a] + 1 : d[a];
        }
        for (int i = 0; i < parts; i++) s->piece[i] = 0;
        for (ix[2] = lo[2]; ix[2] < hi[2]; ix[2]++)
            for (ix[1] = lo[1]; ix[1] < hi[1]; ix[1]++)
                for (ix[0] = lo[0]; ix[0] < hi[0]; ix[0]++)
                    s->piece[ix[axis]] += s->share[ix[0] + (long)d[0] * (ix[1] + (long)d[1] * ix[2])];
        sh = s->piece;
    }
    if (!vw__cut_shares(pts, n, axis, box.lo[axis], box.hi[axis], parts, sh, s->minw[axis],
                        b + 1)) {
        s->thin = 1;
        free(b);
        return -1;
    }
    /* vw__cut sorted the points along axis: each piece's are a range of them. */
    long *e = malloc(sizeof(long) * (size_t)(parts + 1));
    if (!e) {
        free(b);
        return -1;
    }
    for (int i = 0; i < parts; i++) e[i] = first_at(pts, n, axis, b[i]);
    e[parts] = n;
    int me = pieces(s, pts, e, box, axis, b, 0, parts, idx);
    free(e);
    free(b);
    return me;
}

/* The staggered tree of dims over cur's world box in its frame, cells at the shares
   (NULL: equal); *out NULL where a slab or column is too thin for its cuts. */
static vw_status staggered(const vw_decomp *cur, const vw_load_field *f,
                           const vw_balance_params *p, const int dims[3], const double *share,
                           vw_decomp **out)
{
    *out = NULL;
    long ncells = (long)dims[0] * dims[1] * dims[2];
    if (ncells < 1 || ncells > VW_MAX_CELLS) return VW_E_LIMIT;
    const double *F = vw_decomp_frame(cur);
    vw__lpt *pts;
    long n = vw__field_points(f, F, &pts);
    if (n < 0) return VW_E_NOMEM;
    stag s;
    memset(&s, 0, sizeof s);
    s.dims = dims;
    s.share = share;
    s.nodes = calloc((size_t)(2 * ncells), sizeof *s.nodes);
    int most = dims[0] > dims[1] ? dims[0] : dims[1];
    s.piece = share ? malloc(sizeof(double) * (size_t)(most > dims[2] ? most : dims[2])) : NULL;
    if (!s.nodes || (share && !s.piece)) {
        free(s.nodes), free(s.piece);
        free(pts);
        return VW_E_NOMEM;
    }
    vw_box wb = vw_decomp_world(cur);
    for (int a = 0; a < 3; a++) s.minw[a] = p->min_width * (wb.hi[a] - wb.lo[a]);
    int idx[3] = {0, 0, 0};
    vw_status st = build(&s, pts, n, wb, 0, idx) < 0 ? VW_E_NOMEM : VW_OK;
    if (s.thin)
        st = VW_OK;
    else if (st == VW_OK)
        st = vw_decomp_create_kd(&wb, s.nodes, s.nn, F, VW_DECOMP_STAGGERED, out);
    free(s.nodes), free(s.piece);
    free(pts);
    return st;
}

vw_status vw__balance_staggered(const vw_decomp *cur, const vw_load_field *f,
                                const vw_balance_params *p, const int dims[3], vw_decomp **out)
{
    vw_status st = staggered(cur, f, p, dims, NULL, out);
    /* a balancer that cannot improve is no error: the walls stay */
    if (st == VW_OK && !*out) st = vw_decomp_clone(cur, out);
    return st;
}

vw_status vw__staggered_shaped(const vw_decomp *cur, const vw_load_field *f,
                               const vw_balance_params *p, const int dims[3],
                               const double *share, vw_decomp **out)
{
    return staggered(cur, f, p, dims, share, out);
}
