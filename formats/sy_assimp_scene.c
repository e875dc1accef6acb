/* sy_assimp_scene.c — Assimp's meshes, node tree, cameras and lights into the scene: the budget
 * charged for every mesh and placement first; one sy_mesh per aiMesh (triangles, lines or points,
 * as SortByPType left it); one sy_node per aiNode under a new root that carries the file's unit
 * scale and up axis; cameras and lights on child nodes of the nodes named after them, with the
 * conversions of sy_assimp.h (sy_classic.h for light intensities). */
#include "sy_assimp_internal.h"

#include "sy_classic.h"
#include "sy_mesh_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>budget ------------------------------------------------------------------------------------ */

static uint32_t per_element(unsigned types)
{
    types &= ~(unsigned)aiPrimitiveType_NGONEncodingFlag; /* Triangulate marks triangles made from polygons */
    return types == aiPrimitiveType_TRIANGLE ? 3 : types == aiPrimitiveType_LINE ? 2 : types == aiPrimitiveType_POINT ? 1 : 0;
}

/* Nodes of the tree (walked without recursion: a file may nest deeply); 0 with *ok false when the
 * tree is larger than `cap`. */
static size_t count_nodes(const struct aiNode *root, uint64_t *mesh_refs, size_t cap, bool *ok)
{
    *ok = true;
    *mesh_refs = 0;
    if (!root) return 0;
    const struct aiNode **stack = malloc(sizeof *stack * 64);
    size_t depth = 0, cap_stack = 64, n = 0;
    if (!stack) return *ok = false, 0;
    stack[depth++] = root;
    while (depth) {
        const struct aiNode *nd = stack[--depth];
        if (++n > cap) {
            *ok = false;
            break;
        }
        *mesh_refs += nd->mNumMeshes;
        for (unsigned c = 0; c < nd->mNumChildren; ++c) {
            if (depth == cap_stack) {
                const struct aiNode **s2 = realloc(stack, sizeof *stack * cap_stack * 2);
                if (!s2) {
                    *ok = false;
                    free(stack);
                    return 0;
                }
                stack = s2;
                cap_stack *= 2;
            }
            stack[depth++] = nd->mChildren[c];
        }
    }
    free(stack);
    return n;
}

sy_result asp_charge(asp_loader *L)
{
    const struct aiScene *s = L->ai;
    sy_result r;
    for (unsigned i = 0; i < s->mNumMeshes; ++i) {
        const struct aiMesh *m = s->mMeshes[i];
        uint32_t per = per_element(m->mPrimitiveTypes);
        if (m->mNumVertices > L->opt.max_vertices)
            return asp_fail(L, SY_ERR_LIMIT, "meshes[%u] '%s': %u vertices exceed the limit of %zu", i, asp_str(&m->mName),
                            m->mNumVertices, L->opt.max_vertices);
        uint64_t pv = 12u + (m->mNormals ? 12u : 0u) + (m->mTextureCoords[0] ? 8u : 0u) +
                      (m->mTextureCoords[1] ? 8u : 0u) + (m->mColors[0] ? 16u : 0u) +
                      (per == 3 && L->normal_mapped[m->mMaterialIndex < s->mNumMaterials ? m->mMaterialIndex : 0] ? 16u : 0u);
        if ((r = sy_budget_charge(&L->budget, m->mNumVertices, pv, &L->err, "meshes[%u]: %u vertices", i, m->mNumVertices)) ||
            (r = sy_budget_charge(&L->budget, (uint64_t)m->mNumFaces * (per ? per : 3), 4u, &L->err, "meshes[%u]: %u faces", i,
                                  m->mNumFaces)))
            return r;
    }
    uint64_t refs = 0;
    bool ok;
    uint64_t cap = L->budget.limit / SY_BUDGET_PLACEMENT_BYTES + 1;
    size_t n = count_nodes(s->mRootNode, &refs, cap > SIZE_MAX ? SIZE_MAX : (size_t)cap, &ok);
    uint64_t places = (uint64_t)n + refs + s->mNumCameras + s->mNumLights + 1u;
    if (!ok) places = cap;
    L->info->counts.nodes = (uint32_t)(n > UINT32_MAX ? UINT32_MAX : n);
    return sy_budget_charge(&L->budget, places, SY_BUDGET_PLACEMENT_BYTES, &L->err, "%s%llu placements (nodes)",
                            ok ? "" : "at least ", (unsigned long long)places);
}

/* >>meshes ------------------------------------------------------------------------------------ */

/* Copies count x comps floats into a new blob; non-finite values become 0 (*fixed set). */
static sy_result float_blob(asp_loader *L, const float *src, size_t stride, size_t count, size_t comps, sy_blob **out,
                            bool *fixed)
{
    float *f = malloc(count * comps * sizeof(float) + 1);
    if (!f) return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "out of memory for %zu vertices", count);
    for (size_t v = 0; v < count; ++v)
        for (size_t k = 0; k < comps; ++k) {
            float x = src[v * stride + k];
            if (!isfinite(x)) x = 0.0f, *fixed = true;
            f[v * comps + k] = x;
        }
    sy_result r = sy_blob_create_take(f, count * comps * sizeof(float), out, &L->err);
    if (r) free(f);
    return r;
}

static sy_result make_primitive(asp_loader *L, unsigned i, const struct aiMesh *m, uint32_t per, sy_primitive *p,
                                uint32_t *elements)
{
    char where[64];
    snprintf(where, sizeof where, "meshes[%u] '%.32s'", i, asp_str(&m->mName));
    size_t nv = m->mNumVertices;
    for (size_t v = 0; v < nv; ++v) {
        const struct aiVector3D *q = &m->mVertices[v];
        if (!isfinite(q->x) || !isfinite(q->y) || !isfinite(q->z))
            return asp_fail(L, SY_ERR_PARSE, "%s: non-finite position in vertex %zu", where, v);
    }
    uint32_t *idx = malloc((size_t)m->mNumFaces * per * sizeof(uint32_t) + 1);
    if (!idx) return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "%s: out of memory for %u faces", where, m->mNumFaces);
    size_t n = 0, bad = 0;
    for (unsigned f = 0; f < m->mNumFaces; ++f) {
        const struct aiFace *fc = &m->mFaces[f];
        bool ok = fc->mNumIndices == per && fc->mIndices;
        for (unsigned k = 0; ok && k < per; ++k) ok = fc->mIndices[k] < nv;
        if (!ok) {
            bad++;
            continue;
        }
        for (unsigned k = 0; k < per; ++k) idx[n++] = fc->mIndices[k];
    }
    if (bad) asp_warn(L, "%s: %zu faces of another size or with indices past the %zu vertices skipped", where, bad, nv);
    *elements = (uint32_t)(n / per);
    if (n == 0) {
        free(idx);
        return SY_OK;
    }
    sy_result r = sy_blob_create_take(idx, n * sizeof(uint32_t), &p->indices, &L->err);
    if (r) {
        free(idx);
        return r;
    }
    bool fixed = false;
    if ((r = float_blob(L, &m->mVertices[0].x, 3, nv, 3, &p->positions, &fixed)) ||
        (m->mNormals && (r = float_blob(L, &m->mNormals[0].x, 3, nv, 3, &p->normals, &fixed))))
        return r;
    for (unsigned t = 0; t < 2; ++t)
        if (m->mTextureCoords[t] && m->mNumUVComponents[t] >= 2 &&
            (r = float_blob(L, &m->mTextureCoords[t][0].x, 3, nv, 2, t ? &p->texcoords1 : &p->texcoords0, &fixed)))
            return r;
    if (m->mColors[0] && (r = float_blob(L, &m->mColors[0][0].r, 4, nv, 4, &p->colors, &fixed))) return r;
    if (fixed) asp_warn(L, "%s: non-finite normals, texture coordinates or colours replaced by 0", where);
    unsigned extra = 0;
    for (unsigned t = 2; t < AI_MAX_NUMBER_OF_TEXTURECOORDS; ++t) extra += m->mTextureCoords[t] != NULL;
    for (unsigned c = 1; c < AI_MAX_NUMBER_OF_COLOR_SETS; ++c) extra += m->mColors[c] != NULL;
    if (extra) asp_warn(L, "%s: %u more texture coordinate or colour sets not kept (two and one are)", where, extra);
    p->topology = per == 3 ? SY_TOPOLOGY_TRIANGLES : per == 2 ? SY_TOPOLOGY_LINES : SY_TOPOLOGY_POINTS;
    if ((r = asp_mesh_deform(L, i, m, p))) return r;
    unsigned mi = m->mMaterialIndex < L->ai->mNumMaterials ? m->mMaterialIndex : 0;
    p->material = L->ai->mNumMaterials ? L->materials[mi] : (sy_material){0};
    if (per == 3 && L->ai->mNumMaterials && L->normal_mapped[mi] && p->normals) {
        if (!p->texcoords0) asp_warn(L, "%s: normal map without texture coordinates; tangents not generated", where);
        else if ((r = sy_prim_generate_tangents(p, 0, &L->err))) return r;
    }
    return SY_OK;
}

sy_result asp_create_mesh(asp_loader *L, unsigned i)
{
    const struct aiMesh *m = L->ai->mMeshes[i];
    sy_assimp_counts *c = &L->info->counts;
    L->mesh_bounds[i] = sy_bounds_empty();
    if (m->mNumBones) {
        c->skinned_meshes++;
        c->bones += m->mNumBones;
    }
    c->morph_targets += m->mNumAnimMeshes;
    uint32_t per = per_element(m->mPrimitiveTypes);
    if (!per || !m->mVertices || !m->mNumVertices) {
        asp_warn(L, "meshes[%u] '%s': %s; skipped", i, asp_str(&m->mName),
                 per ? "no vertices" : "mixed or polygon primitives (not triangulated)");
        c->skipped++;
        return SY_OK;
    }
    sy_primitive p = {0};
    uint32_t elements = 0;
    sy_result r = make_primitive(L, i, m, per, &p, &elements);
    if (r == SY_OK && elements == 0) {
        sy_primitive_release(&p);
        asp_warn(L, "meshes[%u] '%s': no complete face; skipped", i, asp_str(&m->mName));
        c->skipped++;
        return SY_OK;
    }
    uint32_t id = 0;
    char where[48];
    snprintf(where, sizeof where, "meshes[%u]", i);
    if (r == SY_OK && (r = asp_new(L, SY_TYPE_MESH, asp_str(&m->mName), where, &id)) == SY_OK &&
        (r = sy_mesh_set_primitives(L->scene, (sy_mesh){id}, &p, 1, &L->err)) != SY_OK)
        sy_error_prefix(&L->err, "%s: %s", L->path, where);
    if (r == SY_OK) {
        L->meshes[i] = (sy_mesh){id};
        L->mesh_bounds[i] = sy_primitive_position_bounds(&p);
        L->mesh_skinned[i] = p.joints != NULL;
        L->mesh_targets[i] = sy_primitive_target_count(&p);
        c->meshes++;
        if (per == 3) c->triangles += elements;
        else if (per == 2) c->line_segments += elements;
        else c->points += elements;
    }
    sy_primitive_release(&p);
    if (r == SY_OK && L->mesh_targets[i]) r = asp_mesh_weights(L, i);
    return r;
}

/* >>nodes ------------------------------------------------------------------------------------- */

static sy_mat4 mat_of(const struct aiMatrix4x4 *a)
{
    sy_mat4 m = {{a->a1, a->b1, a->c1, a->d1, a->a2, a->b2, a->c2, a->d2, a->a3, a->b3, a->c3, a->d3, a->a4, a->b4, a->c4, a->d4}};
    return m;
}

static bool meta_number(const struct aiMetadata *md, const char *key, double *out)
{
    if (!md) return false;
    for (unsigned k = 0; k < md->mNumProperties; ++k) {
        if (strcmp(asp_str(&md->mKeys[k]), key) != 0 || !md->mValues[k].mData) continue;
        const void *d = md->mValues[k].mData;
        switch (md->mValues[k].mType) {
        case AI_INT32: *out = *(const int32_t *)d; return true;
        case AI_UINT64: *out = (double)*(const uint64_t *)d; return true;
        case AI_FLOAT: *out = *(const float *)d; return true;
        case AI_DOUBLE: *out = *(const double *)d; return true;
        default: return false;
        }
    }
    return false;
}

/* The root's matrix: metres per unit and the file's axes turned to the scene's (sy_assimp.h). */
static sy_mat4 root_matrix(asp_loader *L)
{
    const struct aiMetadata *md = L->ai->mMetaData;
    sy_mat4 m = sy_mat4_identity();
    double unit = 0, up = -1, ups = 1, front = -1, fs = 1, coord = -1, cs = 1;
    L->info->unit_scale = 1.0f;
    L->info->up_axis = -1;
    if (meta_number(md, "UnitScaleFactor", &unit) && isfinite(unit) && unit > 0 && unit < 1e6) {
        L->info->unit_scale = (float)(unit / 100.0); /* FBX: centimetres per unit */
    } else if (meta_number(md, "UnitScaleFactor", &unit)) {
        asp_warn(L, "UnitScaleFactor %g out of range; units taken as metres", unit);
    }
    if (meta_number(md, "UpAxis", &up) && meta_number(md, "FrontAxis", &front) && meta_number(md, "CoordAxis", &coord)) {
        meta_number(md, "UpAxisSign", &ups);
        meta_number(md, "FrontAxisSign", &fs);
        meta_number(md, "CoordAxisSign", &cs);
        int u = (int)up, f = (int)front, c = (int)coord;
        if (u >= 0 && u < 3 && f >= 0 && f < 3 && c >= 0 && c < 3 && u != f && f != c && u != c) {
            /* rows: right (coord), up, front: file coordinates -> the scene's x, y, z */
            float rows[3][3] = {{0}};
            rows[0][c] = cs < 0 ? -1.0f : 1.0f;
            rows[1][u] = ups < 0 ? -1.0f : 1.0f;
            rows[2][f] = fs < 0 ? -1.0f : 1.0f;
            for (int r = 0; r < 3; ++r)
                for (int k = 0; k < 3; ++k) m.m[k * 4 + r] = rows[r][k];
            L->info->up_axis = u;
        } else {
            asp_warn(L, "axes UpAxis %d, FrontAxis %d, CoordAxis %d are not a basis; taken as they are", u, f, c);
        }
    }
    for (int k = 0; k < 12; ++k) m.m[k] *= L->info->unit_scale;
    return m;
}

typedef struct walk_node {
    const struct aiNode *ai;
    sy_node node;
    sy_mat4 world;
    uint32_t first_child; /* index of its first child in the breadth-first order */
} walk_node;

static int by_name(const void *a, const void *b)
{
    const walk_node *x = *(walk_node *const *)a, *y = *(walk_node *const *)b;
    return strcmp(asp_str(&x->ai->mName), asp_str(&y->ai->mName));
}

static int named_order(const void *a, const void *b)
{
    const asp_named *x = a, *y = b;
    int c = strcmp(asp_str(&x->ai->mName), asp_str(&y->ai->mName));
    return c ? c : x->walk < y->walk ? -1 : x->walk > y->walk;
}

/* The node named `name` (the first in breadth-first order), NULL when none. */
static walk_node *find_named(walk_node **sorted, size_t n, const char *name)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        int c = strcmp(asp_str(&sorted[mid]->ai->mName), name);
        if (c < 0) lo = mid + 1;
        else hi = mid;
    }
    walk_node *best = NULL;
    for (size_t k = lo; k < n && !strcmp(asp_str(&sorted[k]->ai->mName), name); ++k)
        if (!best || sorted[k] < best) best = sorted[k];
    return best;
}

static void quat_from_basis(const float x[3], const float y[3], const float z[3], float q[4])
{
    float t = x[0] + y[1] + z[2];
    if (t > 0) {
        float s = sqrtf(t + 1.0f) * 2;
        q[3] = 0.25f * s, q[0] = (y[2] - z[1]) / s, q[1] = (z[0] - x[2]) / s, q[2] = (x[1] - y[0]) / s;
    } else if (x[0] > y[1] && x[0] > z[2]) {
        float s = sqrtf(1.0f + x[0] - y[1] - z[2]) * 2;
        q[3] = (y[2] - z[1]) / s, q[0] = 0.25f * s, q[1] = (y[0] + x[1]) / s, q[2] = (z[0] + x[2]) / s;
    } else if (y[1] > z[2]) {
        float s = sqrtf(1.0f + y[1] - x[0] - z[2]) * 2;
        q[3] = (z[0] - x[2]) / s, q[0] = (y[0] + x[1]) / s, q[1] = 0.25f * s, q[2] = (z[1] + y[2]) / s;
    } else {
        float s = sqrtf(1.0f + z[2] - x[0] - y[1]) * 2;
        q[3] = (x[1] - y[0]) / s, q[0] = (z[0] + x[2]) / s, q[1] = (z[1] + y[2]) / s, q[2] = 0.25f * s;
    }
}

static void normalize3(float v[3], const float fallback[3])
{
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(l > 1e-12f) || !isfinite(l)) {
        memcpy(v, fallback, 3 * sizeof(float));
        return;
    }
    v[0] /= l, v[1] /= l, v[2] /= l;
}

static void cross3(const float a[3], const float b[3], float o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
}

/* A child of parent at pos whose -Z looks along dir with +Y towards up (cameras, lights). */
static sy_result oriented_child(asp_loader *L, const char *name, const char *what, const struct aiVector3D *pos,
                                const struct aiVector3D *dir, const struct aiVector3D *upv, sy_node *out)
{
    static const float nz[3] = {0, 0, -1}, py[3] = {0, 1, 0}, px[3] = {1, 0, 0};
    float d[3] = {dir->x, dir->y, dir->z}, u[3] = {upv->x, upv->y, upv->z}, z[3], x[3], y[3];
    normalize3(d, nz);
    normalize3(u, py);
    z[0] = -d[0], z[1] = -d[1], z[2] = -d[2];
    cross3(u, z, x);
    normalize3(x, px);
    if (fabsf(x[0] * z[0] + x[1] * z[1] + x[2] * z[2]) > 1e-3f) { /* up along the direction: any perpendicular */
        float alt[3] = {fabsf(z[1]) < 0.9f ? 0.0f : 1.0f, fabsf(z[1]) < 0.9f ? 1.0f : 0.0f, 0};
        cross3(alt, z, x);
        normalize3(x, px);
    }
    cross3(z, x, y);
    float q[4], t[3] = {pos->x, pos->y, pos->z}, one[3] = {1, 1, 1};
    quat_from_basis(x, y, z, q);
    uint32_t id;
    sy_result r = asp_new(L, SY_TYPE_NODE, name, what, &id);
    if (!r) r = sy_node_set_trs(L->scene, (sy_node){id}, t, q, one, &L->err);
    if (!r) r = sy_node_set_flags(L->scene, (sy_node){id}, SY_NODE_VISIBLE, &L->err);
    if (r) sy_error_prefix(&L->err, "%s: %s", L->path, what);
    *out = (sy_node){id};
    return r;
}

/* children lists: extra nodes (mesh, camera, light) per walk node */
typedef struct extra_child {
    uint32_t parent; /* walk index */
    sy_node node;
} extra_child;

/* The uniform scale of a world matrix (cube root of its 3x3 determinant; 1 when degenerate): what
 * turns the file's lengths (clip planes, attenuation distances) into the scene's. */
static float world_scale(const sy_mat4 *m)
{
    const float *a = m->m;
    float det = a[0] * (a[5] * a[10] - a[9] * a[6]) - a[4] * (a[1] * a[10] - a[9] * a[2]) + a[8] * (a[1] * a[6] - a[5] * a[2]);
    float s = cbrtf(fabsf(det));
    return isfinite(s) && s > 0 ? s : 1.0f;
}

static sy_result add_camera(asp_loader *L, unsigned i, sy_node *out)
{
    const struct aiCamera *c = L->ai->mCameras[i];
    char what[48];
    snprintf(what, sizeof what, "cameras[%u]", i);
    sy_camera_data cd = *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
    float aspect = c->mAspect > 0 && isfinite(c->mAspect) ? c->mAspect : 4.0f / 3.0f;
    if (c->mOrthographicWidth > 0 && isfinite(c->mOrthographicWidth)) {
        cd.projection = SY_PROJECTION_ORTHOGRAPHIC;
        cd.xmag = c->mOrthographicWidth; /* camera-local units: the node's scale applies */
        cd.ymag = cd.xmag / aspect;
    } else {
        /* Assimp 5.2's importers (COLLADA, FBX, 3DS, glTF 1) store the FULL horizontal angle here,
         * although the header calls it the half angle: COLLADA xfov 49.13 arrives as 49.13 degrees */
        float h = c->mHorizontalFOV;
        if (!(h > 0.001f && h < 3.13f)) {
            asp_warn(L, "%s '%s': horizontal field of view %g out of range; 60 degrees used", what, asp_str(&c->mName), (double)h);
            h = 1.0472f;
        }
        cd.yfov = 2.0f * atanf(tanf(0.5f * h) / aspect);
    }
    cd.aspect = c->mAspect > 0 && isfinite(c->mAspect) ? c->mAspect : 0.0f;
    if (c->mClipPlaneNear > 0 && isfinite(c->mClipPlaneNear)) cd.znear = c->mClipPlaneNear;
    cd.zfar = c->mClipPlaneFar > cd.znear && isfinite(c->mClipPlaneFar) ? c->mClipPlaneFar : 0.0f;
    uint32_t id;
    sy_result r = asp_new(L, SY_TYPE_CAMERA, asp_str(&c->mName), what, &id);
    if (!r && (r = sy_camera_set(L->scene, (sy_camera){id}, &cd, &L->err))) sy_error_prefix(&L->err, "%s: %s", L->path, what);
    if (!r) r = oriented_child(L, asp_str(&c->mName), what, &c->mPosition, &c->mLookAt, &c->mUp, out);
    if (!r && (r = sy_node_set_camera(L->scene, *out, (sy_camera){id}, &L->err))) sy_error_prefix(&L->err, "%s: %s", L->path, what);
    if (!r) L->info->counts.cameras++;
    return r;
}

/* A light at its node; intensity (point, spot) set once the scene's bounds are known. */
static sy_result add_light(asp_loader *L, unsigned i, walk_node *host, sy_node *out, sy_light *light, float *classic, float *quadratic,
                           float world_pos[3])
{
    const struct aiLight *l = L->ai->mLights[i];
    char what[48];
    snprintf(what, sizeof what, "lights[%u]", i);
    *out = (sy_node){0};
    *light = (sy_light){0};
    if (l->mType != aiLightSource_DIRECTIONAL && l->mType != aiLightSource_POINT && l->mType != aiLightSource_SPOT) {
        asp_warn(L, "%s '%s': %s light not supported; skipped", what, asp_str(&l->mName),
                 l->mType == aiLightSource_AMBIENT ? "ambient" : l->mType == aiLightSource_AREA ? "area" : "undefined");
        L->info->counts.skipped++;
        return SY_OK;
    }
    sy_light_data ld = *(const sy_light_data *)sy_object_defaults(SY_TYPE_LIGHT);
    float col[3] = {l->mColorDiffuse.r, l->mColorDiffuse.g, l->mColorDiffuse.b};
    float in = 0;
    for (int k = 0; k < 3; ++k) in = fmaxf(in, isfinite(col[k]) ? col[k] : 0.0f);
    for (int k = 0; k < 3; ++k) ld.color[k] = in > 0 && isfinite(col[k]) ? fmaxf(0.0f, col[k] / in) : 1.0f;
    ld.type = l->mType == aiLightSource_DIRECTIONAL ? SY_LIGHT_DIRECTIONAL : l->mType == aiLightSource_SPOT ? SY_LIGHT_SPOT : SY_LIGHT_POINT;
    if (ld.type == SY_LIGHT_DIRECTIONAL) ld.intensity = sy_classic_directional_intensity(in);
    if (ld.type == SY_LIGHT_SPOT) {
        float outer = isfinite(l->mAngleOuterCone) && l->mAngleOuterCone > 0 ? l->mAngleOuterCone : 0.7854f;
        float inner = isfinite(l->mAngleInnerCone) && l->mAngleInnerCone >= 0 ? l->mAngleInnerCone : 0.0f;
        /* Assimp gives the full cone angles; KHR_lights_punctual the half angles */
        ld.outer_cone = fminf(1.5707f, 0.5f * outer);
        ld.inner_cone = fminf(ld.outer_cone, 0.5f * inner);
    }
    *classic = in;
    uint32_t id;
    sy_result r = asp_new(L, SY_TYPE_LIGHT, asp_str(&l->mName), what, &id);
    if (!r && (r = sy_light_set(L->scene, (sy_light){id}, &ld, &L->err))) sy_error_prefix(&L->err, "%s: %s", L->path, what);
    if (!r) r = oriented_child(L, asp_str(&l->mName), what, &l->mPosition, &l->mDirection, &l->mUp, out);
    if (!r && (r = sy_node_set_light(L->scene, *out, (sy_light){id}, &L->err))) sy_error_prefix(&L->err, "%s: %s", L->path, what);
    /* attenuation is per file unit squared: in the scene's units q / s^2 */
    float s2 = world_scale(&host->world) * world_scale(&host->world);
    *quadratic = isfinite(l->mAttenuationQuadratic) && l->mAttenuationQuadratic > 0 ? l->mAttenuationQuadratic / s2 : 0.0f;
    float p[3] = {l->mPosition.x, l->mPosition.y, l->mPosition.z};
    sy_mat4_transform_point(&host->world, p, world_pos);
    if (!r) L->info->counts.lights++;
    *light = (sy_light){id};
    return r;
}

typedef struct pending_light {
    sy_light light;
    float classic, quadratic, pos[3];
} pending_light;

static int by_parent(const void *a, const void *b)
{
    const extra_child *x = a, *y = b;
    return x->parent < y->parent ? -1 : x->parent > y->parent;
}

/* Point and spot intensities by sy_classic.h, from the centre of the scene's bounds. */
static void finish_lights(asp_loader *L, const pending_light *pl, size_t n, const sy_bounds *b)
{
    float centre[3] = {0, 0, 0}, diag = 1.0f;
    if (!sy_bounds_is_empty(b)) {
        float d[3];
        for (int k = 0; k < 3; k++) centre[k] = 0.5f * (b->min[k] + b->max[k]), d[k] = b->max[k] - b->min[k];
        diag = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(diag > 0) || !isfinite(diag)) diag = 1.0f;
    }
    for (size_t k = 0; k < n; k++) {
        const sy_light_data *cur = sy_light_get(L->scene, pl[k].light);
        if (!cur || cur->type == SY_LIGHT_DIRECTIONAL) continue;
        sy_light_data ld = *cur;
        float d[3] = {pl[k].pos[0] - centre[0], pl[k].pos[1] - centre[1], pl[k].pos[2] - centre[2]};
        float dist = fmaxf(sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), 0.05f * diag);
        ld.intensity = sy_classic_point_intensity(pl[k].classic, pl[k].quadratic, dist);
        if (!isfinite(ld.intensity)) ld.intensity = 0.0f;
        sy_light_set(L->scene, pl[k].light, &ld, NULL);
    }
}

static sy_result push_extra(asp_loader *L, extra_child **ex, size_t *n, size_t *cap, uint32_t parent, sy_node node)
{
    if (!sy_array_reserve(ex, *n, cap, sizeof **ex, 16)) return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "out of memory for nodes");
    (*ex)[(*n)++] = (extra_child){parent, node};
    return SY_OK;
}

/* The tree, breadth first (children of one node are neighbours), under a new root. */
sy_result asp_create_nodes(asp_loader *L)
{
    const struct aiScene *s = L->ai;
    size_t n = L->info->counts.nodes;
    sy_result r = SY_OK;
    walk_node *w = calloc(n + 1, sizeof *w);
    uint32_t *parent = calloc(n + 1, sizeof *parent);
    walk_node **sorted = calloc(n + 1, sizeof *sorted);
    pending_light *pl = calloc((size_t)s->mNumLights + 1, sizeof *pl);
    sy_node *kids = NULL;
    extra_child *ex = NULL;
    size_t nex = 0, cap_ex = 0, npl = 0;
    L->info->camera_nodes = calloc((size_t)s->mNumCameras + 1, sizeof(sy_node));
    if (!w || !parent || !sorted || !pl || !L->info->camera_nodes) {
        r = asp_fail(L, SY_ERR_OUT_OF_MEMORY, "out of memory for %zu nodes", n);
        goto done;
    }
    size_t head = 0, tail = 0;
    if (s->mRootNode && n) w[tail++].ai = s->mRootNode;
    while (head < tail) {
        walk_node *x = &w[head];
        x->first_child = (uint32_t)tail;
        for (unsigned c = 0; c < x->ai->mNumChildren && tail < n; ++c) {
            parent[tail] = (uint32_t)head;
            w[tail++].ai = x->ai->mChildren[c];
        }
        head++;
    }
    /* the root: the file's name, units and axes */
    const char *slash = strrchr(L->path, '/');
    uint32_t root_id;
    sy_mat4 rm = root_matrix(L);
    if ((r = asp_new(L, SY_TYPE_NODE, slash ? slash + 1 : L->path, "root node", &root_id)) ||
        (r = sy_node_set_matrix(L->scene, (sy_node){root_id}, &rm, &L->err)) ||
        (r = sy_node_set_flags(L->scene, (sy_node){root_id}, SY_NODE_VISIBLE, &L->err)))
        goto done;
    L->info->root = (sy_node){root_id};
    sy_bounds bounds = sy_bounds_empty();
    for (size_t k = 0; k < tail && r == SY_OK; ++k) {
        walk_node *x = &w[k];
        char what[48];
        snprintf(what, sizeof what, "nodes '%.32s'", asp_str(&x->ai->mName));
        sy_mat4 local = mat_of(&x->ai->mTransformation);
        const sy_mat4 *pw = k == 0 ? &rm : &w[parent[k]].world;
        x->world = sy_mat4_mul(pw, &local);
        uint32_t id;
        if ((r = asp_new(L, SY_TYPE_NODE, asp_str(&x->ai->mName), what, &id))) break;
        x->node = (sy_node){id};
        if ((r = sy_node_set_matrix(L->scene, x->node, &local, &L->err)) ||
            (r = sy_node_set_flags(L->scene, x->node, SY_NODE_VISIBLE, &L->err))) {
            sy_error_prefix(&L->err, "%s: %s", L->path, what);
            break;
        }
        for (unsigned j = 0; j < x->ai->mNumMeshes && r == SY_OK; ++j) {
            unsigned mi = x->ai->mMeshes[j];
            if (mi >= s->mNumMeshes || !L->meshes[mi].id) continue;
            sy_bounds b = sy_bounds_transform(&L->mesh_bounds[mi], &x->world);
            sy_bounds_add_bounds(&bounds, &b);
            if (!sy_array_reserve(&L->placements, L->placement_count, &L->placement_cap, sizeof *L->placements, 16)) {
                r = asp_fail(L, SY_ERR_OUT_OF_MEMORY, "out of memory for nodes");
                break;
            }
            if (x->ai->mNumMeshes == 1) {
                if ((r = sy_node_set_mesh(L->scene, x->node, L->meshes[mi], &L->err))) sy_error_prefix(&L->err, "%s: %s", L->path, what);
                else L->placements[L->placement_count++] = (asp_placement){(uint32_t)k, mi, x->node};
                continue;
            }
            uint32_t cid;
            if ((r = asp_new(L, SY_TYPE_NODE, asp_str(&s->mMeshes[mi]->mName), what, &cid)) ||
                (r = sy_node_set_mesh(L->scene, (sy_node){cid}, L->meshes[mi], &L->err)) ||
                (r = sy_node_set_flags(L->scene, (sy_node){cid}, SY_NODE_VISIBLE, &L->err)) ||
                (r = push_extra(L, &ex, &nex, &cap_ex, (uint32_t)k, (sy_node){cid})))
                break;
            L->placements[L->placement_count++] = (asp_placement){(uint32_t)k, mi, (sy_node){cid}};
        }
        sorted[k] = x;
    }
    if (r) goto done;
    /* the tree by name, for bones and animation channels (sy_assimp_anim.c) */
    if (!(L->named = calloc(tail + 1, sizeof *L->named))) {
        r = asp_fail(L, SY_ERR_OUT_OF_MEMORY, "out of memory for %zu nodes", tail);
        goto done;
    }
    for (size_t k = 0; k < tail; ++k) L->named[k] = (asp_named){w[k].ai, w[k].node, (uint32_t)k, false};
    L->named_count = tail;
    qsort(L->named, tail, sizeof *L->named, named_order);
    qsort(sorted, tail, sizeof *sorted, by_name);
    for (unsigned i = 0; i < s->mNumCameras + s->mNumLights && r == SY_OK; ++i) {
        bool cam = i < s->mNumCameras;
        unsigned j = cam ? i : i - s->mNumCameras;
        const struct aiString *name = cam ? &s->mCameras[j]->mName : &s->mLights[j]->mName;
        walk_node *host = tail ? find_named(sorted, tail, asp_str(name)) : NULL;
        if (!host && tail) {
            asp_warn(L, "%s[%u] '%s': no node of that name; placed at the root", cam ? "cameras" : "lights", j, asp_str(name));
            host = &w[0];
        }
        if (!host) break;
        sy_node node;
        if (cam) {
            if ((r = add_camera(L, j, &node))) break;
            L->info->camera_nodes[L->info->camera_node_count++] = node;
        } else {
            pending_light *p = &pl[npl];
            if ((r = add_light(L, j, host, &node, &p->light, &p->classic, &p->quadratic, p->pos))) break;
            if (!node.id) continue;
            npl++;
        }
        r = push_extra(L, &ex, &nex, &cap_ex, (uint32_t)(host - w), node);
    }
    if (r) goto done;
    /* children lists, each set once */
    if (nex) qsort(ex, nex, sizeof *ex, by_parent);
    size_t e = 0;
    kids = malloc((tail + nex + 1) * sizeof *kids);
    if (!kids) {
        r = asp_fail(L, SY_ERR_OUT_OF_MEMORY, "out of memory for nodes");
        goto done;
    }
    for (size_t k = 0; k < tail && r == SY_OK; ++k) {
        uint32_t nk = 0;
        for (unsigned c = 0; c < w[k].ai->mNumChildren && w[k].first_child + c < tail; ++c)
            kids[nk++] = w[w[k].first_child + c].node;
        while (e < nex && ex[e].parent == k) kids[nk++] = ex[e++].node;
        if (nk && (r = sy_node_set_children(L->scene, w[k].node, kids, nk, &L->err)))
            sy_error_prefix(&L->err, "%s: nodes '%.32s'", L->path, asp_str(&w[k].ai->mName));
    }
    if (r == SY_OK && tail && (r = sy_node_set_children(L->scene, L->info->root, &w[0].node, 1, &L->err)))
        sy_error_prefix(&L->err, "%s: root node", L->path);
    if (r == SY_OK) finish_lights(L, pl, npl, &bounds);
done:
    free(w);
    free(parent);
    free(sorted);
    free(pl);
    free(kids);
    free(ex);
    return r;
}
