/* view.c - the pinhole camera of the NFF 'v' block: eye rays through pixel centres and
 * the projection of world points to the screen (for primary-pixel ownership and the
 * wall overlay). The angle is the full vertical field of view, edge to edge.
 */
#include <math.h>
#include "raytrace/raytrace.h"

static void normalize(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0) {
        v[0] /= l;
        v[1] /= l;
        v[2] /= l;
    }
}

static void cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

void rt_view_init(rt_view *v, const vw_camera *cam, int width, int height)
{
    for (int a = 0; a < 3; a++) {
        v->eye[a] = cam->from[a];
        v->fwd[a] = cam->at[a] - cam->from[a];
    }
    normalize(v->fwd);
    /* right = fwd x up (a right-handed frame: the NFF convention), up' = right x fwd. */
    cross(v->fwd, cam->up, v->right);
    if (!(v->right[0] * v->right[0] + v->right[1] * v->right[1] + v->right[2] * v->right[2] >
          1e-24)) {
        /* up parallel to the view direction: pick any perpendicular. */
        double alt[3] = {fabs(v->fwd[0]) < 0.9 ? 1.0 : 0.0, fabs(v->fwd[0]) < 0.9 ? 0.0 : 1.0,
                         0.0};
        cross(v->fwd, alt, v->right);
    }
    normalize(v->right);
    cross(v->right, v->fwd, v->up);
    normalize(v->up);
    /* Every angle the NFF reader accepts, 0 to 180 exclusive, is used as given; 45
       degrees only for a camera that has none (a zeroed vw_camera). */
    double angle = cam->angle > 0 && cam->angle < 180 ? cam->angle : 45.0;
    v->tan_half = tan(angle * 0.5 * 3.14159265358979323846 / 180.0);
    v->width = width;
    v->height = height;
    v->aspect = (double)width / (double)height;
}

void rt_view_ray(const rt_view *v, int px, int py, double dir[3])
{
    double sx = ((px + 0.5) / v->width * 2.0 - 1.0) * v->tan_half * v->aspect;
    double sy = (1.0 - (py + 0.5) / v->height * 2.0) * v->tan_half;
    for (int a = 0; a < 3; a++) dir[a] = v->fwd[a] + sx * v->right[a] + sy * v->up[a];
    normalize(dir);
}

int rt_view_project(const rt_view *v, const double p[3], double *sx, double *sy)
{
    double d[3] = {p[0] - v->eye[0], p[1] - v->eye[1], p[2] - v->eye[2]};
    double z = d[0] * v->fwd[0] + d[1] * v->fwd[1] + d[2] * v->fwd[2];
    if (!(z > 1e-12)) return 0;
    double x = (d[0] * v->right[0] + d[1] * v->right[1] + d[2] * v->right[2]) / z;
    double y = (d[0] * v->up[0] + d[1] * v->up[1] + d[2] * v->up[2]) / z;
    /* Inverse of rt_view_ray: pixel centre px + 0.5 maps to x. */
    *sx = (x / (v->tan_half * v->aspect) + 1.0) * 0.5 * v->width;
    *sy = (1.0 - y / v->tan_half) * 0.5 * v->height;
    return 1;
}

int rt_view_outline(const rt_view *v, const vw_box *b, const vw_decomp *d, double lo[2],
                    double hi[2])
{
    lo[0] = lo[1] = INFINITY;
    hi[0] = hi[1] = -INFINITY;
    for (int i = 0; i < 8; i++) {
        double q[3] = {(i & 1) ? b->hi[0] : b->lo[0], (i & 2) ? b->hi[1] : b->lo[1],
                       (i & 4) ? b->hi[2] : b->lo[2]};
        double p[3], sx, sy;
        vw_decomp_from_frame(d, q, p);
        if (!rt_view_project(v, p, &sx, &sy) || !isfinite(sx) || !isfinite(sy)) return 0;
        lo[0] = fmin(lo[0], sx);
        hi[0] = fmax(hi[0], sx);
        lo[1] = fmin(lo[1], sy);
        hi[1] = fmax(hi[1], sy);
    }
    return 1;
}
