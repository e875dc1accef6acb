/* sy_pick_ray.c — the pick ray and its hit on one triangle (see sy_pick_ray.h). */
#include "sy_pick_ray.h"

#include <math.h>

static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

void sy_pick_ray(const sy_camera_view *v, uint32_t width, uint32_t height, uint32_t x, uint32_t y, double org[3],
                 double dir[3], double forward[3])
{
    const float *m = v->camera_to_world.m, *w = v->window;
    double sx = w[0] + ((double)x + 0.5) / (double)width * ((double)w[1] - w[0]);
    double sy = w[3] - ((double)y + 0.5) / (double)height * ((double)w[3] - w[2]);
    double len = sqrt((double)m[8] * m[8] + (double)m[9] * m[9] + (double)m[10] * m[10]);
    for (int i = 0; i < 3; ++i) {
        forward[i] = len > 0.0 ? -(double)m[8 + i] / len : 0.0;
        if (v->projection == SY_PROJECTION_ORTHOGRAPHIC) {
            org[i] = (double)m[12 + i] + (double)m[i] * sx + (double)m[4 + i] * sy;
            dir[i] = -(double)m[8 + i];
        } else {
            org[i] = m[12 + i];
            dir[i] = (double)m[i] * sx + (double)m[4 + i] * sy - (double)m[8 + i];
        }
    }
}

bool sy_pick_triangle(const sy_camera_view *view, uint32_t width, uint32_t height, uint32_t x, uint32_t y,
                      const float world[16], const float p[3][3], sy_pick_result *out)
{
    double o[3], d[3], fw[3], q[3][3];
    sy_pick_ray(view, width, height, x, y, o, d, fw);
    for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 3; ++i)
            q[k][i] = (double)world[i] * p[k][0] + (double)world[4 + i] * p[k][1] + (double)world[8 + i] * p[k][2] +
                      (double)world[12 + i];
    double e1[3], e2[3], n[3], ao[3];
    for (int i = 0; i < 3; ++i) e1[i] = q[1][i] - q[0][i], e2[i] = q[2][i] - q[0][i], ao[i] = o[i] - q[0][i];
    cross3(e1, e2, n);
    double nn = sqrt(dot3(n, n)), dn = dot3(d, n);
    if (!(nn > 0.0) || !isfinite(nn) || fabs(dn) <= 1e-300) return false;
    double t = -dot3(ao, n) / dn;
    if (!(t > 0.0) || !isfinite(t)) return false;
    double h[3];
    for (int i = 0; i < 3; ++i) h[i] = ao[i] + t * d[i]; /* the plane hit, relative to vertex 0 */
    /* barycentrics of h in the triangle (least squares in its plane) */
    double d11 = dot3(e1, e1), d12 = dot3(e1, e2), d22 = dot3(e2, e2), h1 = dot3(h, e1), h2 = dot3(h, e2);
    double den = d11 * d22 - d12 * d12;
    if (!(den > 0.0)) return false;
    double b1 = (d22 * h1 - d12 * h2) / den, b2 = (d11 * h2 - d12 * h1) / den, b0 = 1.0 - b1 - b2;
    if (b0 < 0.0 || b1 < 0.0 || b2 < 0.0) { /* just outside (an edge pixel): the nearest point inside */
        b0 = b0 < 0.0 ? 0.0 : b0, b1 = b1 < 0.0 ? 0.0 : b1, b2 = b2 < 0.0 ? 0.0 : b2;
        double s = b0 + b1 + b2;
        b0 /= s, b1 /= s, b2 /= s;
    }
    double pos[3], dist2 = 0.0, depth = 0.0;
    for (int i = 0; i < 3; ++i) {
        pos[i] = b0 * q[0][i] + b1 * q[1][i] + b2 * q[2][i];
        double r = pos[i] - o[i];
        dist2 += r * r;
        depth += (pos[i] - view->camera_to_world.m[12 + i]) * fw[i];
    }
    /* the front side as glTF defines it: counter-clockwise, clockwise under a mirroring transform */
    double det = (double)world[0] * ((double)world[5] * world[10] - (double)world[6] * world[9]) -
                 (double)world[4] * ((double)world[1] * world[10] - (double)world[2] * world[9]) +
                 (double)world[8] * ((double)world[1] * world[6] - (double)world[2] * world[5]);
    if (det < 0.0) nn = -nn;
    out->hit = true;
    out->barycentrics[0] = (float)b0;
    out->barycentrics[1] = (float)b1;
    out->barycentrics[2] = (float)b2;
    for (int i = 0; i < 3; ++i) {
        out->position[i] = (float)pos[i];
        out->normal[i] = (float)(n[i] / nn) + 0.0f; /* no -0 */
    }
    out->distance = (float)sqrt(dist2);
    out->depth = (float)depth;
    return true;
}

void sy_pick_name(sy_pick_result *out, const sy_mirror_instance_info *info, uint32_t triangle)
{
    out->node_id = info->node;
    out->placement = info->placement;
    out->mesh_id = info->mesh;
    out->primitive = info->primitive;
    out->triangle = triangle;
    out->material_id = info->material;
}
