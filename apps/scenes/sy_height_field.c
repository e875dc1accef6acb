/* sy_height_field.c — a generated height field of a given triangle count (see sy_height_field.h):
 * one grid mesh (positions, normals, one UV set, uint32 indices) with its material, under one node. */
#include "sy_height_field.h"

#include <math.h>
#include <stdlib.h>

/* A (g+1)^2-vertex grid of 2 g^2 triangles (g = ceil(sqrt(tris / 2))), 1 x 1 m in XZ, heights
 * from a few sines; positions, normals, one UV set, uint32 indices, one blob each. */
sy_result sy_height_field_generate(sy_scene *s, uint32_t tris, sy_node *node_out, uint32_t *tris_out, sy_error *err)
{
    uint32_t g = (uint32_t)ceil(sqrt((double)tris / 2.0));
    if (g < 1) g = 1;
    if ((uint64_t)(g + 1) * (g + 1) > UINT32_MAX / 3u || (uint64_t)g * g * 6u > UINT32_MAX)
        return sy_error_set(err, SY_ERR_LIMIT, "height field: %u triangles exceed the index range", tris);
    size_t nv = (size_t)(g + 1) * (g + 1), nt = (size_t)g * g * 2;
    float *pos = malloc(nv * 3 * sizeof(float)), *nrm = malloc(nv * 3 * sizeof(float)), *uv = malloc(nv * 2 * sizeof(float));
    uint32_t *idx = malloc(nt * 3 * sizeof(uint32_t));
    sy_blob *bp = NULL, *bn = NULL, *bu = NULL, *bi = NULL;
    sy_result r = SY_OK;
    if (!pos || !nrm || !uv || !idx) {
        r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "height field: out of memory for %u triangles", 2 * g * g);
        goto done;
    }
    const float a = 0.04f, kx = 23.0f, kz = 17.0f;
    for (uint32_t z = 0; z <= g; ++z)
        for (uint32_t x = 0; x <= g; ++x) {
            size_t v = (size_t)z * (g + 1) + x;
            float fx = (float)x / (float)g, fz = (float)z / (float)g;
            float sx = sinf(kx * fx), cx = cosf(kx * fx), sz = sinf(kz * fz), cz = cosf(kz * fz);
            float h = a * sx * cz + 0.5f * a * sinf(3.1f * kx * fx + 2.3f * kz * fz);
            float dx = a * kx * cx * cz + 0.5f * a * 3.1f * kx * cosf(3.1f * kx * fx + 2.3f * kz * fz);
            float dz = -a * kz * sx * sz + 0.5f * a * 2.3f * kz * cosf(3.1f * kx * fx + 2.3f * kz * fz);
            float il = 1.0f / sqrtf(dx * dx + 1.0f + dz * dz);
            pos[3 * v] = fx - 0.5f, pos[3 * v + 1] = h, pos[3 * v + 2] = fz - 0.5f;
            nrm[3 * v] = -dx * il, nrm[3 * v + 1] = il, nrm[3 * v + 2] = -dz * il;
            uv[2 * v] = fx, uv[2 * v + 1] = fz;
        }
    size_t k = 0;
    for (uint32_t z = 0; z < g; ++z)
        for (uint32_t x = 0; x < g; ++x) {
            uint32_t v0 = z * (g + 1) + x, v1 = v0 + g + 1;
            idx[k++] = v0, idx[k++] = v1, idx[k++] = v0 + 1;
            idx[k++] = v0 + 1, idx[k++] = v1, idx[k++] = v1 + 1;
        }
    if ((r = sy_blob_create_take(pos, nv * 3 * sizeof(float), &bp, err)) != SY_OK) goto done;
    pos = NULL;
    if ((r = sy_blob_create_take(nrm, nv * 3 * sizeof(float), &bn, err)) != SY_OK) goto done;
    nrm = NULL;
    if ((r = sy_blob_create_take(uv, nv * 2 * sizeof(float), &bu, err)) != SY_OK) goto done;
    uv = NULL;
    if ((r = sy_blob_create_take(idx, nt * 3 * sizeof(uint32_t), &bi, err)) != SY_OK) goto done;
    idx = NULL;
    sy_material_data md = *(const sy_material_data *)sy_object_defaults(SY_TYPE_MATERIAL);
    md.base_color[0] = 0.7f, md.base_color[1] = 0.6f, md.base_color[2] = 0.5f;
    md.roughness = 0.8f, md.metallic = 0.0f;
    sy_material mat;
    sy_mesh mesh;
    if ((r = sy_material_create(s, "ground", &mat, err)) || (r = sy_material_set(s, mat, &md, err))) goto done;
    sy_primitive p = {.positions = bp, .normals = bn, .texcoords0 = bu, .indices = bi, .material = mat};
    if ((r = sy_mesh_create(s, "height field", &mesh, err)) || (r = sy_mesh_set_primitives(s, mesh, &p, 1, err)) ||
        (r = sy_node_create(s, "height field", node_out, err)) || (r = sy_node_set_mesh(s, *node_out, mesh, err)))
        goto done;
    *tris_out = (uint32_t)nt;
done:
    free(pos), free(nrm), free(uv), free(idx);
    sy_blob_release(bp), sy_blob_release(bn), sy_blob_release(bu), sy_blob_release(bi);
    return r;
}
