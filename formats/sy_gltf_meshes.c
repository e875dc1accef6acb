/* sy_gltf_meshes.c — glTF meshes into sy_meshes: the file's budget for every primitive charged
 * before any is decoded, vertex attributes, indices (range-checked; strips and fans converted),
 * points and lines, tangents where the file has none (a primitive without normals stays indexed
 * and without them: flat shading, sy_primitive), skin attributes and morph targets. */
#include "sy_gltf_internal.h"

#include "sy_mesh_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>meshes ------------------------------------------------------------------------------------ */

/* Takes ownership of data (freed on failure too). */
static sy_result make_blob(loader *L, void *data, size_t bytes, sy_blob **out)
{
    sy_result r = sy_blob_create_take(data, bytes, out, &L->err);
    if (r) {
        free(data);
        return gltf_context(L, r, "blob");
    }
    return SY_OK;
}

static const char *mode_name(int32_t mode)
{
    static const char *const names[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
    return (mode >= 0 && mode <= GLTF_LINE_STRIP) ? names[mode] : "?";
}

/* Reads an attribute into a blob. comps: output components. */
static sy_result read_attribute(loader *L, int32_t ai, size_t vcount, size_t comps, size_t m, size_t p,
                                const char *name, sy_blob **out)
{
    *out = NULL;
    if (ai < 0) return SY_OK;
    const sy_gltf_shim_accessor *a = &L->doc->accessors[ai];
    bool type_ok = !a->is_matrix && ((size_t)a->components == comps ||
                                     (!strcmp(name, "COLOR_0") && a->components == 3));
    if (!type_ok)
        return gltf_fail(L, SY_ERR_PARSE, "meshes[%zu].primitives[%zu]: %s accessor %d has %d components, expected %zu", m, p, name,
                         (int)ai, (int)a->components, comps);
    if (a->count != vcount)
        return gltf_fail(L, SY_ERR_PARSE, "meshes[%zu].primitives[%zu]: %s accessor %d count %zu differs from POSITION count %zu", m,
                         p, name, (int)ai, a->count, vcount);
    float *f;
    sy_result r = gltf_read_floats(L, (size_t)ai, comps, &f);
    if (r) return r;
    size_t n = vcount * comps; /* read_floats checked the product */
    bool is_pos = !strcmp(name, "POSITION");
    bool fixed = false;
    for (size_t k = 0; k < n; k++) {
        if (isfinite(f[k])) continue;
        if (is_pos) {
            free(f);
            return gltf_fail(L, SY_ERR_PARSE, "accessors[%d] (POSITION of meshes[%zu].primitives[%zu]): non-finite value in vertex %zu",
                             (int)ai, m, p, k / comps);
        }
        f[k] = 0.0f;
        fixed = true;
    }
    if (fixed) gltf_warn(L, "accessors[%d] (%s of meshes[%zu].primitives[%zu]): non-finite values replaced by 0", (int)ai, name, m, p);
    return make_blob(L, f, n * sizeof(float), out);
}

static uint32_t add_sat(uint32_t a, uint32_t b) { return a > UINT32_MAX - b ? UINT32_MAX : a + b; }

static sy_result read_all_attributes(loader *L, const sy_gltf_shim_primitive *pr, size_t vcount, size_t m, size_t p,
                                     sy_primitive *out)
{
    sy_result r;
    if ((r = read_attribute(L, pr->position, vcount, 3, m, p, "POSITION", &out->positions)) ||
        (r = read_attribute(L, pr->normal, vcount, 3, m, p, "NORMAL", &out->normals)) ||
        (r = read_attribute(L, pr->tangent, vcount, 4, m, p, "TANGENT", &out->tangents)) ||
        (r = read_attribute(L, pr->texcoord0, vcount, 2, m, p, "TEXCOORD_0", &out->texcoords0)) ||
        (r = read_attribute(L, pr->texcoord1, vcount, 2, m, p, "TEXCOORD_1", &out->texcoords1)) ||
        (r = read_attribute(L, pr->color0, vcount, 4, m, p, "COLOR_0", &out->colors)))
        sy_primitive_release(out);
    return r;
}

/* Skin attributes (JOINTS_0/WEIGHTS_0, then JOINTS_1/WEIGHTS_1: up to 8 influences per vertex,
 * interleaved per vertex as sy_primitive wants them) and morph targets (POSITION / NORMAL / TANGENT
 * deltas; an attribute some targets lack is 0 in those). What cannot be used is dropped with a
 * warning naming the primitive (the rest of it loads): joints without weights, counts that differ
 * from POSITION's, a non-finite or negative weight, a non-finite delta. L->mesh_joints[m] learns
 * the largest joint index, which the nodes check against their skin (sy_gltf_nodes.c). */
static sy_result read_deform(loader *L, const sy_gltf_shim_primitive *pr, size_t vcount, size_t m, size_t p,
                             sy_primitive *out)
{
    const sy_gltf_doc *d = L->doc;
    sy_result r = SY_OK;
    int32_t ja[2] = {pr->joints0, pr->joints1}, wa[2] = {pr->weights0, pr->weights1};
    size_t sets = ja[0] >= 0 && wa[0] >= 0 ? (ja[1] >= 0 && wa[1] >= 0 ? 2u : 1u) : 0u;
    if ((ja[0] >= 0) != (wa[0] >= 0))
        gltf_warn(L, "meshes[%zu].primitives[%zu]: JOINTS_0 without WEIGHTS_0 (or the reverse); not skinned", m, p);
    const char *why = NULL;
    for (size_t k = 0; k < sets && !why; k++) {
        if ((size_t)ja[k] >= d->accessor_count || (size_t)wa[k] >= d->accessor_count) {
            why = "an accessor index is out of range";
            break;
        }
        const sy_gltf_shim_accessor *a = &d->accessors[ja[k]], *b = &d->accessors[wa[k]];
        if (a->components != 4 || a->is_matrix || b->components != 4 || b->is_matrix) why = "JOINTS_n / WEIGHTS_n are not VEC4";
        else if (a->count != vcount || b->count != vcount) why = "JOINTS_n / WEIGHTS_n count differs from POSITION's";
        else if (a->component_type != CT_UBYTE && a->component_type != CT_USHORT) why = "JOINTS_n is not unsigned byte or short";
        else if ((a->buffer_view < 0 && !a->sparse) || (b->buffer_view < 0 && !b->sparse))
            why = "JOINTS_n / WEIGHTS_n hold no data";
    }
    if (sets && !why) {
        size_t inf = 4 * sets, n;
        if (!sy_size_mul(vcount, inf, &n)) return gltf_fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: joints", m, p);
        uint32_t *joints = gltf_xcalloc(L, n ? n : 1, sizeof(uint32_t), &r);
        float *weights = joints ? gltf_xcalloc(L, n ? n : 1, sizeof(float), &r) : NULL;
        uint32_t jmax = 0;
        for (size_t k = 0; k < sets && weights && !why; k++) {
            float *jf = NULL, *wf = NULL;
            if ((r = gltf_read_floats(L, (size_t)ja[k], 4, &jf)) || (r = gltf_read_floats(L, (size_t)wa[k], 4, &wf))) {
                free(jf);
                break;
            }
            for (size_t v = 0; v < vcount && !why; v++)
                for (size_t c = 0; c < 4; c++) {
                    float w = wf[4 * v + c];
                    if (!isfinite(w) || w < 0.0f) {
                        why = "a weight is not finite and >= 0";
                        break;
                    }
                    uint32_t j = (uint32_t)jf[4 * v + c];
                    joints[inf * v + 4 * k + c] = j;
                    weights[inf * v + 4 * k + c] = w;
                    if (w > 0.0f && j + 1 > jmax) jmax = j + 1;
                }
            free(jf);
            free(wf);
        }
        if (r == SY_OK && !why && weights) {
            sy_result r1 = make_blob(L, joints, n * sizeof(uint32_t), &out->joints); /* both take their array */
            sy_result r2 = make_blob(L, weights, n * sizeof(float), &out->weights);
            joints = NULL;
            weights = NULL;
            r = r1 ? r1 : r2;
            if (r == SY_OK && jmax > L->mesh_joints[m]) L->mesh_joints[m] = jmax;
        }
        free(joints);
        free(weights);
        if (r) return r;
    }
    if (why) gltf_warn(L, "meshes[%zu].primitives[%zu]: skin attributes dropped (%s); drawn in the bind pose", m, p, why);

    if (!pr->target_count) return SY_OK;
    if (pr->target_count > SY_MORPH_MAX_TARGETS) {
        gltf_warn(L, "meshes[%zu].primitives[%zu]: %zu morph targets (at most %u); targets dropped", m, p, pr->target_count,
                  SY_MORPH_MAX_TARGETS);
        return SY_OK;
    }
    sy_blob **dst[3] = {&out->target_positions, &out->target_normals, &out->target_tangents};
    static const char *const names[3] = {"POSITION", "NORMAL", "TANGENT"};
    why = NULL;
    for (int at = 0; at < 3 && !why && r == SY_OK; at++) {
        bool any = false;
        for (size_t t = 0; t < pr->target_count; t++) any = any || pr->targets[3 * t + at] >= 0;
        if (!any) continue;
        size_t per = vcount * 3, n;
        if (!sy_size_mul(per, pr->target_count, &n)) return gltf_fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: targets", m, p);
        float *all = gltf_xcalloc(L, n ? n : 1, sizeof(float), &r);
        if (!all) break;
        for (size_t t = 0; t < pr->target_count && !why; t++) {
            int32_t ai = pr->targets[3 * t + at];
            if (ai < 0) continue;
            if ((size_t)ai >= d->accessor_count) {
                why = "a target accessor index is out of range";
                break;
            }
            const sy_gltf_shim_accessor *a = &d->accessors[ai];
            if (a->components != 3 || a->is_matrix || a->count != vcount) {
                why = "a target accessor is not VEC3 with POSITION's count";
                break;
            }
            float *f;
            if ((r = gltf_read_floats(L, (size_t)ai, 3, &f))) break;
            for (size_t k = 0; k < per; k++) {
                if (!(fabsf(f[k]) <= SY_COORD_MAX)) {
                    why = "a delta is not finite or beyond the coordinate range";
                    break;
                }
                all[t * per + k] = f[k];
            }
            free(f);
        }
        if (r == SY_OK && !why) {
            r = make_blob(L, all, n * sizeof(float), dst[at]);
            all = NULL;
        }
        free(all);
        if (why) gltf_warn(L, "meshes[%zu].primitives[%zu]: morph targets dropped (%s: %s)", m, p, names[at], why);
    }
    if (why || r) {
        for (int at = 0; at < 3; at++) {
            sy_blob_release(*dst[at]);
            *dst[at] = NULL;
        }
    }
    return r;
}

/* POINTS, LINES, LINE_LOOP, LINE_STRIP: point and line primitives (loops and strips expanded to
 * index pairs). Takes ownership of idx (icount indices, or NULL: the vertices in order). Strokes
 * are drawn as tubes and balls with their own normals (sy_scene.h), so no flat normals are made. */
static sy_result convert_stroke(loader *L, size_t m, size_t p, sy_primitive *out, bool *used, uint32_t *idx,
                                size_t icount, size_t vcount)
{
    const sy_gltf_shim_primitive *pr = &L->doc->meshes[m].primitives[p];
    sy_result r = SY_OK;
    uint32_t *pairs = NULL;
    size_t elements = 0;
    if (pr->mode == GLTF_POINTS) {
        elements = icount;
        pairs = idx; /* NULL: non-indexed points */
        idx = NULL;
    } else if (pr->mode == GLTF_LINES) {
        elements = icount / 2;
        if (icount % 2)
            gltf_warn(L, "meshes[%zu].primitives[%zu]: LINES with %zu %s (odd); the last one ignored", m, p, icount,
                      idx ? "indices" : "vertices");
        if (idx) {
            pairs = idx;
            idx = NULL;
        } else if (icount % 2 && elements) {
            if (!(pairs = gltf_xcalloc(L, elements * 2, sizeof(uint32_t), &r))) return r;
            for (size_t k = 0; k < elements * 2; k++) pairs[k] = (uint32_t)k;
        }
    } else { /* LINE_LOOP closes back to the first vertex; LINE_STRIP does not */
        bool loop = pr->mode == GLTF_LINE_LOOP;
        elements = icount >= 2 ? icount - 1 + (loop && icount >= 3) : 0;
        if (elements > L->opt.max_indices / 2) {
            free(idx);
            return gltf_fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: %zu line segments exceed the index limit of %zu", m,
                             p, elements, L->opt.max_indices);
        }
        if (elements && !(pairs = gltf_xcalloc(L, elements * 2, sizeof(uint32_t), &r))) {
            free(idx);
            return r;
        }
        for (size_t k = 0; k < elements; k++) {
            size_t a = k, b = (k + 1) % icount;
            pairs[2 * k] = idx ? idx[a] : (uint32_t)a;
            pairs[2 * k + 1] = idx ? idx[b] : (uint32_t)b;
        }
        free(idx);
        idx = NULL;
    }
    free(idx);
    if (elements == 0) {
        free(pairs);
        gltf_warn(L, "meshes[%zu].primitives[%zu]: %s without a complete %s; skipped", m, p, mode_name(pr->mode),
                  pr->mode == GLTF_POINTS ? "point" : "segment");
        L->info->counts.skipped_primitives++;
        return SY_OK;
    }
    if (elements > UINT32_MAX / 2) {
        free(pairs);
        return gltf_fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: too many elements", m, p);
    }
    size_t per = pr->mode == GLTF_POINTS ? 1 : 2;
    if (pairs && (r = make_blob(L, pairs, elements * per * sizeof(uint32_t), &out->indices))) return r;
    if ((r = read_all_attributes(L, pr, vcount, m, p, out))) return r;
    if ((r = read_deform(L, pr, vcount, m, p, out))) {
        sy_primitive_release(out);
        return r;
    }
    out->topology = per == 1 ? SY_TOPOLOGY_POINTS : SY_TOPOLOGY_LINES;
    out->material = pr->material >= 0 ? L->materials[pr->material] : (sy_material){0};
    if (per == 1) L->info->counts.points = add_sat(L->info->counts.points, (uint32_t)elements);
    else L->info->counts.line_segments = add_sat(L->info->counts.line_segments, (uint32_t)elements);
    *used = true;
    return SY_OK;
}

/* The file's budget for every primitive of every mesh, before any is decoded: the vertex attributes
 * as the scene stores them and the indices (one per vertex without an index accessor), for each
 * primitive even where primitives share accessors (the back-ends copy per primitive). Accessor
 * indices were validated (validate_doc). */
sy_result gltf_charge_meshes(loader *L)
{
    const sy_gltf_doc *d = L->doc;
    sy_result r = SY_OK;
    for (size_t m = 0; m < d->mesh_count && r == SY_OK; m++)
        for (size_t p = 0; p < d->meshes[m].primitive_count && r == SY_OK; p++) {
            const sy_gltf_shim_primitive *pr = &d->meshes[m].primitives[p];
            if (pr->position < 0) continue;
            size_t vcount = d->accessors[pr->position].count;
            size_t ic = pr->indices >= 0 ? d->accessors[pr->indices].count : vcount;
            uint64_t per_vertex = 12u + (pr->normal >= 0 ? 12u : 0u) + (pr->tangent >= 0 ? 16u : 0u) +
                                  (pr->texcoord0 >= 0 ? 8u : 0u) + (pr->texcoord1 >= 0 ? 8u : 0u) +
                                  (pr->color0 >= 0 ? 16u : 0u) + (pr->joints0 >= 0 ? 32u : 0u) +
                                  (pr->joints1 >= 0 ? 32u : 0u) +
                                  36u * (uint64_t)(pr->target_count < 1024 ? pr->target_count : 1024);
            if ((r = sy_budget_charge(&L->budget, vcount, per_vertex, &L->err, "meshes[%zu].primitives[%zu]: %zu vertices", m, p, vcount)) == SY_OK)
                r = sy_budget_charge(&L->budget, ic, 4u, &L->err, "meshes[%zu].primitives[%zu]: %zu indices", m, p, ic);
        }
    return r;
}

static sy_result convert_primitive(loader *L, size_t m, size_t p, sy_primitive *out, bool *used, uint32_t *tris)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_primitive *pr = &d->meshes[m].primitives[p];
    sy_result r;
    *used = false;
    *tris = 0;
    memset(out, 0, sizeof *out);
    if (pr->position < 0) {
        gltf_warn(L, "meshes[%zu].primitives[%zu]: no POSITION attribute; skipped", m, p);
        L->info->counts.skipped_primitives++;
        return SY_OK;
    }
    size_t vcount = d->accessors[pr->position].count;
    if (vcount > L->opt.max_vertices || vcount > UINT32_MAX)
        return gltf_fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: %zu vertices exceed the limit of %zu", m, p, vcount,
                         L->opt.max_vertices);

    /* index list (before conversion) */
    uint32_t *idx = NULL;
    size_t icount = vcount;
    if (pr->indices >= 0) {
        const sy_gltf_shim_accessor *ia = &d->accessors[pr->indices];
        if (ia->components != 1 || ia->is_matrix ||
            (ia->component_type != CT_UBYTE && ia->component_type != CT_USHORT && ia->component_type != CT_UINT))
            return gltf_fail(L, SY_ERR_PARSE, "meshes[%zu].primitives[%zu]: indices accessor %d must be SCALAR of unsigned byte, short or int",
                             m, p, (int)pr->indices);
        icount = ia->count;
        if (icount > L->opt.max_indices)
            return gltf_fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: %zu indices exceed the limit of %zu", m, p, icount,
                             L->opt.max_indices);
        if ((r = gltf_read_uints(L, (size_t)pr->indices, &idx))) return r;
        for (size_t k = 0; k < icount; k++) {
            if (idx[k] >= vcount) {
                unsigned bad = (unsigned)idx[k];
                free(idx);
                return gltf_fail(L, SY_ERR_PARSE, "meshes[%zu].primitives[%zu]: index %u at position %zu (accessor %d) >= vertex count %zu",
                                 m, p, bad, k, (int)pr->indices, vcount);
            }
        }
    }

    if (pr->mode < GLTF_TRIANGLES) return convert_stroke(L, m, p, out, used, idx, icount, vcount);

    /* triangle list */
    uint32_t *tri = NULL;
    size_t tcount = 0; /* triangles */
    if (pr->mode == GLTF_TRIANGLES) {
        tcount = icount / 3;
        if (icount % 3)
            gltf_warn(L, "meshes[%zu].primitives[%zu]: %zu %s is not a multiple of 3; the last %zu ignored", m, p, icount,
                      idx ? "indices" : "vertices", icount % 3);
        if (idx) {
            tri = idx;
            idx = NULL;
        } else if (icount % 3) {
            tri = gltf_xcalloc(L, tcount * 3, sizeof(uint32_t), &r);
            if (!tri) return r;
            for (size_t k = 0; k < tcount * 3; k++) tri[k] = (uint32_t)k;
        }
    } else {
        tcount = icount >= 3 ? icount - 2 : 0;
        size_t n;
        if (!sy_size_mul(tcount, 3, &n) || n > L->opt.max_indices) {
            free(idx);
            return gltf_fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: %zu triangles after strip/fan conversion exceed the index limit of %zu",
                             m, p, tcount, L->opt.max_indices);
        }
        if (tcount) {
            tri = gltf_xcalloc(L, n, sizeof(uint32_t), &r);
            if (!tri) {
                free(idx);
                return r;
            }
        }
        for (size_t k = 0; k < tcount; k++) {
            size_t a, b, c;
            if (pr->mode == GLTF_TRIANGLE_STRIP) { /* keeps the winding of every other triangle */
                a = k;
                b = k + 1 + (k % 2);
                c = k + 2 - (k % 2);
            } else { /* fan */
                a = k + 1;
                b = k + 2;
                c = 0;
            }
            tri[3 * k] = idx ? idx[a] : (uint32_t)a;
            tri[3 * k + 1] = idx ? idx[b] : (uint32_t)b;
            tri[3 * k + 2] = idx ? idx[c] : (uint32_t)c;
        }
        free(idx);
        idx = NULL;
    }
    if (tcount == 0) {
        free(tri);
        gltf_warn(L, "meshes[%zu].primitives[%zu]: no complete triangle; skipped", m, p);
        L->info->counts.skipped_primitives++;
        return SY_OK;
    }
    if (tcount > UINT32_MAX / 3) {
        free(tri);
        return gltf_fail(L, SY_ERR_LIMIT, "meshes[%zu].primitives[%zu]: too many triangles", m, p);
    }
    if (tri && (r = make_blob(L, tri, tcount * 3 * sizeof(uint32_t), &out->indices))) return r;

    if ((r = read_all_attributes(L, pr, vcount, m, p, out))) return r;
    if ((r = read_deform(L, pr, vcount, m, p, out))) {
        sy_primitive_release(out);
        return r;
    }
    /* glTF 2.0: without NORMAL the client computes flat normals, and the file's tangents are
     * ignored. The primitive stays as it is, indexed and without normals: every back-end shades a
     * primitive without normals flat (sy_primitive), from the geometric normal of each triangle.
     * A normal map without TANGENT on a primitive with normals gets generated tangents (sy_mesh_util:
     * MikkTSpace-style angle-weighted accumulation); a flat one needs none (the back-ends build the
     * tangent frame of a normal map from the uv derivatives across the triangle). */
    if (!out->normals) {
        sy_blob_release(out->tangents);
        out->tangents = NULL;
    } else if (!out->tangents && pr->material >= 0 && d->materials[pr->material].normal_texture.index >= 0) {
        const sy_gltf_shim_texinfo *nt = &d->materials[pr->material].normal_texture;
        int32_t tc = nt->transform_texcoord >= 0 ? nt->transform_texcoord : nt->texcoord;
        if (tc != 1) tc = 0;
        if (!(tc ? out->texcoords1 : out->texcoords0)) {
            gltf_warn(L, "meshes[%zu].primitives[%zu]: normal map without TEXCOORD_%d; tangents not generated", m, p, (int)tc);
        } else if ((r = sy_prim_generate_tangents(out, (uint32_t)tc, &L->err))) {
            sy_primitive_release(out);
            return gltf_fail(L, r, "meshes[%zu].primitives[%zu]: tangents: %s", m, p, L->err.message);
        }
    }
    out->material = pr->material >= 0 ? L->materials[pr->material] : (sy_material){0};
    *used = true;
    *tris = (uint32_t)tcount;
    return SY_OK;
}

sy_result gltf_set_weights(loader *L, const double *w, size_t count, uint32_t id, sy_object_type type, const char *where)
{
    if (count > SY_MORPH_MAX_TARGETS) {
        gltf_warn(L, "%s: %zu morph weights (at most %u); ignored", where, count, SY_MORPH_MAX_TARGETS);
        return SY_OK;
    }
    float f[SY_MORPH_MAX_TARGETS];
    for (size_t k = 0; k < count; k++) {
        f[k] = (float)w[k];
        if (!isfinite(f[k])) {
            gltf_warn(L, "%s: a morph weight is not finite; weights ignored", where);
            return SY_OK;
        }
    }
    sy_result r = type == SY_TYPE_MESH ? sy_mesh_set_weights(L->scene, (sy_mesh){id}, f, (uint32_t)count, &L->err)
                                       : sy_node_set_weights(L->scene, (sy_node){id}, f, (uint32_t)count, &L->err);
    return r ? gltf_context(L, r, where) : SY_OK;
}

sy_result gltf_create_mesh(loader *L, size_t m)
{
    const sy_gltf_shim_mesh *mesh = &L->doc->meshes[m];
    sy_result r = SY_OK;
    sy_primitive *prims = gltf_xcalloc(L, mesh->primitive_count, sizeof(sy_primitive), &r);
    if (!prims) return r;
    uint32_t used_count = 0, triangles = 0;
    const sy_gltf_doc *d = L->doc;
    size_t vu = L->variant_cursor; /* the uses are in mesh then primitive order */
    for (size_t p = 0; p < mesh->primitive_count; p++) {
        bool used;
        uint32_t t;
        if ((r = convert_primitive(L, m, p, &prims[used_count], &used, &t))) goto done;
        for (; vu < d->variant_use_count && d->variant_uses[vu].mesh == (int32_t)m &&
               d->variant_uses[vu].primitive == (int32_t)p;
             vu++) {
            const sy_gltf_shim_variant_use *u = &d->variant_uses[vu];
            if (!used) continue; /* a skipped primitive (no positions) has no material to switch */
            L->info->variant_uses[L->info->variant_use_count++] = (sy_gltf_variant_use){
                .primitive = used_count, .variant = (uint32_t)u->variant, .material = L->materials[u->material],
                .default_material = prims[used_count].material};
        }
        if (used) {
            used_count++;
            if (triangles > UINT32_MAX - t) {
                r = gltf_fail(L, SY_ERR_LIMIT, "meshes[%zu]: too many triangles", m);
                goto done;
            }
            triangles += t;
        }
    }
    char where[48];
    snprintf(where, sizeof where, "meshes[%zu]", m);
    sy_mesh h;
    if ((r = gltf_create(L, SY_TYPE_MESH, gltf_nonempty(mesh->name), where, &h.id))) goto done;
    if (used_count && (r = sy_mesh_set_primitives(L->scene, h, prims, used_count, &L->err))) {
        r = gltf_context(L, r, where);
        goto done;
    }
    if (mesh->weight_count && (r = gltf_set_weights(L, mesh->weights, mesh->weight_count, h.id, SY_TYPE_MESH, where)))
        goto done;
    L->meshes[m] = h;
    L->mesh_triangles[m] = triangles;
    for (size_t k = L->variant_uses_done; k < L->info->variant_use_count; k++) L->info->variant_uses[k].mesh = h;
    L->variant_uses_done = L->info->variant_use_count;
    L->variant_cursor = vu;
done:
    for (uint32_t k = 0; k < used_count; k++) sy_primitive_release(&prims[k]);
    /* a primitive that failed half-way (released itself; harmless) - none when every one was made
     * and sy_mesh_set_primitives refused them (a position beyond SY_COORD_MAX, say) */
    if (r && used_count < mesh->primitive_count) sy_primitive_release(&prims[used_count]);
    free(prims);
    return r;
}
