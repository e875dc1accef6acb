/* sy_rt_placement.c — what instances (sy_rt_instance.c) and moved instances (sy_rt_moved.c) share
 * about placing a mesh: the checks of a transform (finite, invertible, within SY_RT_COORD_MAX) with
 * its normal matrix, a baked instance's world-space vertices and the geometry id -> instance maps.
 * Calls only sy_rt_base, so both modules call it one way. */
#include "sy_rt_scene.h"

#include <stdlib.h>
#include <string.h>

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

/* Checks that xf is finite and invertible and computes the normal matrix (inverse transpose of
 * the upper 3x3, row-major) and *gain, the row-sum norm of the inverse (how much the inverse
 * magnifies a ray's coordinates). */
static sy_rt_result normal_matrix(const sy_rt_device *dev, const float *xf, float nrm[9], double *gain)
{
    for (int i = 0; i < 16; ++i)
        if (!isfinite(xf[i])) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance: transform[%d] = %g is not finite", i, (double)xf[i]);
    double a[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) a[r][c] = xf[c * 4 + r];
    double C[3][3] = {
        {a[1][1] * a[2][2] - a[1][2] * a[2][1], -(a[1][0] * a[2][2] - a[1][2] * a[2][0]), a[1][0] * a[2][1] - a[1][1] * a[2][0]},
        {-(a[0][1] * a[2][2] - a[0][2] * a[2][1]), a[0][0] * a[2][2] - a[0][2] * a[2][0], -(a[0][0] * a[2][1] - a[0][1] * a[2][0])},
        {a[0][1] * a[1][2] - a[0][2] * a[1][1], -(a[0][0] * a[1][2] - a[0][2] * a[1][0]), a[0][0] * a[1][1] - a[0][1] * a[1][0]},
    };
    double det = a[0][0] * C[0][0] + a[0][1] * C[0][1] + a[0][2] * C[0][2];
    double scale = 0.0;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) scale = fmax(scale, fabs(a[r][c]));
    if (!(fabs(det) > 1e-30 * scale * scale * scale) || scale == 0.0)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance: transform is singular (det %g)", det);
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) nrm[r * 3 + c] = (float)(C[r][c] / det);
    *gain = 0.0; /* the inverse is C^T / det: its rows are C's columns */
    for (int c = 0; c < 3; ++c) *gain = fmax(*gain, (fabs(C[0][c]) + fabs(C[1][c]) + fabs(C[2][c])) / fabs(det));
    return SY_RT_OK;
}

/* SY_RT_COORD_MAX for an instance of mesh m placed by xf: its translation and its world extent. */
static sy_rt_result instance_in_range(const sy_rt_device *dev, const sy_rt_mesh_data *m, const float *xf)
{
    double lin = 0.0, t = fmax(fabs(xf[12]), fmax(fabs(xf[13]), fabs(xf[14])));
    for (int r = 0; r < 3; ++r)
        lin = fmax(lin, fabs(xf[r]) + fabs(xf[4 + r]) + fabs(xf[8 + r]));
    double reach = lin * m->extent + t;
    if (!(reach <= SY_RT_COORD_MAX))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT,
                    "instance: placed beyond SY_RT_COORD_MAX (translation (%g %g %g), world extent up to %g; at most %g)",
                    (double)xf[12], (double)xf[13], (double)xf[14], reach, (double)SY_RT_COORD_MAX);
    return SY_RT_OK;
}

sy_rt_result sy_rt_placement_check(const sy_rt_device *dev, const sy_rt_mesh_data *m, const float *xf, float nrm[9],
                                   double *gain)
{
    sy_rt_result r = normal_matrix(dev, xf, nrm, gain);
    return r != SY_RT_OK ? r : instance_in_range(dev, m, xf);
}

sy_rt_result sy_rt_placement_recheck(const sy_rt_device *dev, const sy_rt_instance_data *in, const float *xf,
                                     float nrm[9], const char *what, const char *tail)
{
    double gain;
    sy_rt_result r = sy_rt_placement_check(dev, in->mesh, xf, nrm, &gain);
    if (r != SY_RT_OK) return r;
    if (gain > SY_RT_INSTANCE_GAIN_MAX && !(in->flags & SY_RT_INSTANCE_BAKED))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT,
                    "%s shrinks by %g (more than SY_RT_INSTANCE_GAIN_MAX %g allows for an instance created unbaked)%s",
                    what, 1.0 / gain, (double)SY_RT_INSTANCE_GAIN_MAX, tail);
    return SY_RT_OK;
}

/* Writes the world-space positions of a baked instance. */
void sy_rt_bake_positions(sy_rt_instance_data *in)
{
    const sy_rt_mesh_data *m = in->mesh;
    for (uint32_t i = 0; i < m->vertex_count; ++i) {
        sy_rt_v3 p = m4_point(in->xf, v3_load(m->positions + 3u * i));
        in->baked_positions[3u * i + 0] = p.x;
        in->baked_positions[3u * i + 1] = p.y;
        in->baked_positions[3u * i + 2] = p.z;
    }
}

/* Geometry id -> instance maps (dev->top_map, dev->dyn_map): grows *map to hold id. */
bool sy_rt_id_map_set(sy_rt_instance_data ***map_io, uint32_t *cap_io, unsigned id, sy_rt_instance_data *in)
{
    if (id >= *cap_io) {
        uint32_t ncap = *cap_io ? *cap_io : 64u;
        while (ncap <= id) {
            if (ncap > UINT32_MAX / 2u) return false;
            ncap *= 2u;
        }
        sy_rt_instance_data **map = realloc(*map_io, (size_t)ncap * sizeof *map);
        if (!map) return false;
        memset(map + *cap_io, 0, (size_t)(ncap - *cap_io) * sizeof *map);
        *map_io = map;
        *cap_io = ncap;
    }
    (*map_io)[id] = in;
    return true;
}
