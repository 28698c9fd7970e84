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
    int thin; /* a slab or column too thin for its cuts at the doubles' resolution */
} stag;

/* Points of pts[0..n) with lo <= x[axis] < hi moved to the front; returns their count. */
static long partition(vw__lpt *pts, long n, int axis, double lo, double hi)
{
    long m = 0;
    for (long i = 0; i < n; i++)
        if (pts[i].x[axis] >= lo && pts[i].x[axis] < hi) {
            vw__lpt t = pts[m];
            pts[m++] = pts[i];
            pts[i] = t;
        }
    return m;
}

static int build(stag *s, vw__lpt *pts, long n, vw_box box, int axis, int idx[3]);

/* Nodes for pieces [i0, i1) of box along axis with boundaries b; returns node index. */
static int pieces(stag *s, vw__lpt *pts, long n, vw_box box, int axis, const double *b, int i0,
                  int i1, int idx[3])
{
    if (i1 - i0 == 1) {
        vw_box sub = box;
        sub.lo[axis] = b[i0];
        sub.hi[axis] = b[i1];
        idx[axis] = i0;
        long m = partition(pts, n, axis, b[i0], i1 == s->dims[axis] ? b[i1] + 1e300 : b[i1]);
        return build(s, pts, m, sub, axis + 1, idx);
    }
    int me = s->nn++;
    int mid = (i0 + i1) / 2;
    s->nodes[me].axis = axis;
    s->nodes[me].split = b[mid];
    s->nodes[me].cell = -1;
    int l = pieces(s, pts, n, box, axis, b, i0, mid, idx);
    int r = l < 0 ? -1 : pieces(s, pts, n, box, axis, b, mid, i1, idx);
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
    if (!vw__cut(pts, n, axis, box.lo[axis], box.hi[axis], parts, s->minw[axis], b + 1)) {
        s->thin = 1;
        free(b);
        return -1;
    }
    int me = pieces(s, pts, n, box, axis, b, 0, parts, idx);
    free(b);
    return me;
}

vw_status vw__balance_staggered(const vw_decomp *cur, const vw_load_field *f,
                                const vw_balance_params *p, const int dims[3], vw_decomp **out)
{
    long ncells = (long)dims[0] * dims[1] * dims[2];
    if (ncells < 1 || ncells > VW_MAX_CELLS) return VW_E_LIMIT;
    const double *F = vw_decomp_frame(cur);
    vw__lpt *pts;
    long n = vw__field_points(f, F, &pts);
    if (n < 0) return VW_E_NOMEM;
    stag s;
    memset(&s, 0, sizeof s);
    s.dims = dims;
    s.nodes = calloc((size_t)(2 * ncells), sizeof *s.nodes);
    if (!s.nodes) {
        free(pts);
        return VW_E_NOMEM;
    }
    vw_box wb = vw_decomp_world(cur);
    for (int a = 0; a < 3; a++) s.minw[a] = p->min_width * (wb.hi[a] - wb.lo[a]);
    int idx[3] = {0, 0, 0};
    vw_status st = build(&s, pts, n, wb, 0, idx) < 0 ? VW_E_NOMEM : VW_OK;
    if (s.thin) /* a balancer that cannot improve is no error: the walls stay */
        st = vw_decomp_clone(cur, out);
    else if (st == VW_OK)
        st = vw_decomp_create_kd(&wb, s.nodes, s.nn, F, VW_DECOMP_STAGGERED, out);
    free(s.nodes);
    free(pts);
    return st;
}
