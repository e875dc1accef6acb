/* sy_assimp_anim.c — what moves in an Assimp scene, as the glTF loader makes it (sy_objects.h
 * "Skins and morph targets", "animation"; played by sy_anim.h, deformed by mediators/sy_deform.h):
 *   - bones: per vertex the joint indices (the bone's index in its mesh) and weights, at most
 *     SY_SKIN_MAX_INFLUENCES (the largest kept, a warning once), renormalised; every node that draws
 *     the mesh gets a skin whose joints are the nodes named by the bones, with their mOffsetMatrix as
 *     the inverse bind matrix;
 *   - anim meshes: morph targets (Assimp stores absolute positions and normals: the mesh's are
 *     subtracted), their mWeight as the mesh's default weights;
 *   - animations: one clip per aiAnimation (its name), key times in seconds (ticks / mTicksPerSecond,
 *     Assimp's default 25 ticks per second when the file gives none); each aiNodeAnim's position,
 *     rotation and scaling keys become LINEAR translation / rotation / scale channels on the node of
 *     that name (its transform turned from a matrix into the TRS it decomposes to); each
 *     aiMeshMorphAnim becomes a LINEAR weights channel on the nodes that draw the meshes of the node
 *     (else the meshes) of that name. Outside its keys a channel holds its first / last key (the
 *     clock's clamping): Assimp's DEFAULT and CONSTANT states; LINEAR and REPEAT are clamped too,
 *     with one warning per file.
 * Keys are checked as the glTF loader checks samplers (counts, finite values, strictly increasing
 * times, no zero quaternion); a bad channel is dropped with a warning naming the file, the
 * animation and the channel; the rest of the clip stays. Everything is charged to the file's budget
 * before it is made. */
#include "sy_assimp_internal.h"

#include <assimp/cimport.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ASP_TICKS_DEFAULT 25.0 /* Assimp's own default when mTicksPerSecond is 0 */

static sy_mat4 offset_of(const struct aiMatrix4x4 *a)
{
    sy_mat4 m = {{a->a1, a->b1, a->c1, a->d1, a->a2, a->b2, a->c2, a->d2, a->a3, a->b3, a->c3, a->d3, a->a4, a->b4, a->c4, a->d4}};
    return m;
}

static sy_result take_blob(asp_loader *L, void *data, size_t bytes, sy_blob **out)
{
    sy_result r = sy_blob_create_take(data, bytes, out, &L->err);
    if (r) free(data);
    return r;
}

/* >>skin attributes --------------------------------------------------------------------------- */

static sy_result mesh_bones(asp_loader *L, const char *where, const struct aiMesh *m, sy_primitive *p)
{
    size_t nv = m->mNumVertices;
    if (m->mNumBones > SY_SKIN_MAX_JOINTS || !m->mBones) {
        asp_warn(L, "%s: %u bones (at most %u); not skinned", where, m->mNumBones, SY_SKIN_MAX_JOINTS);
        return SY_OK;
    }
    sy_result r;
    if ((r = sy_budget_charge(&L->budget, nv, 2u * SY_SKIN_MAX_INFLUENCES * 4u, &L->err, "%s: skin of %zu vertices", where, nv)))
        return r;
    const uint32_t K = SY_SKIN_MAX_INFLUENCES;
    uint32_t *jt = calloc(nv * K + 1, sizeof *jt);
    float *wt = calloc(nv * K + 1, sizeof *wt);
    uint8_t *cnt = calloc(nv + 1, 1);
    if (!jt || !wt || !cnt) {
        free(jt), free(wt), free(cnt);
        return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "%s: out of memory for the skin of %zu vertices", where, nv);
    }
    size_t bad_id = 0, bad_w = 0, over = 0;
    for (unsigned b = 0; b < m->mNumBones; ++b) {
        const struct aiBone *bone = m->mBones[b];
        if (!bone || (bone->mNumWeights && !bone->mWeights)) continue;
        for (unsigned k = 0; k < bone->mNumWeights; ++k) {
            unsigned v = bone->mWeights[k].mVertexId;
            float w = bone->mWeights[k].mWeight;
            if (v >= nv) {
                bad_id++;
                continue;
            }
            if (!isfinite(w) || w < 0.0f) {
                bad_w++;
                continue;
            }
            if (w == 0.0f) continue;
            uint32_t *J = jt + (size_t)v * K;
            float *W = wt + (size_t)v * K;
            if (cnt[v] < K) {
                J[cnt[v]] = b, W[cnt[v]] = w, cnt[v]++;
                continue;
            }
            over++; /* keep the K largest: replace the smallest when this one is larger */
            uint32_t s = 0;
            for (uint32_t q = 1; q < K; ++q)
                if (W[q] < W[s]) s = q;
            if (w > W[s]) J[s] = b, W[s] = w;
        }
    }
    uint32_t most = 0;
    for (size_t v = 0; v < nv; ++v) most = cnt[v] > most ? cnt[v] : most;
    if (bad_id) asp_warn(L, "%s: %zu bone weights name a vertex past the %zu vertices; ignored", where, bad_id, nv);
    if (bad_w) asp_warn(L, "%s: %zu bone weights not finite and >= 0; ignored", where, bad_w);
    if (over)
        asp_warn(L, "%s: vertices with more than %u bone weights (%zu weights dropped); the %u largest kept, renormalised", where, K, over, K);
    uint32_t inf = most <= 4 ? 4 : K;
    if (most == 0) {
        asp_warn(L, "%s: %u bones but no usable weight; not skinned", where, m->mNumBones);
        free(jt), free(wt), free(cnt);
        return SY_OK;
    }
    /* packed to `inf` per vertex, renormalised (a vertex without weights keeps its bind pose) */
    for (size_t v = 0; v < nv; ++v) {
        float sum = 0;
        for (uint32_t q = 0; q < cnt[v]; ++q) sum += wt[v * K + q];
        for (uint32_t q = 0; q < inf; ++q) {
            bool in = q < cnt[v];
            jt[v * inf + q] = in ? jt[v * K + q] : 0;
            wt[v * inf + q] = in && sum > 0 ? wt[v * K + q] / sum : 0.0f;
        }
    }
    free(cnt);
    if ((r = take_blob(L, jt, nv * inf * sizeof *jt, &p->joints))) {
        free(wt);
        return r;
    }
    return take_blob(L, wt, nv * inf * sizeof *wt, &p->weights);
}

/* the nodes by name: L->named, sorted by asp_create_nodes (name, then breadth-first order) */
asp_named *asp_find_named(asp_loader *L, const char *name)
{
    size_t lo = 0, hi = L->named_count;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (strcmp(asp_str(&L->named[mid].ai->mName), name) < 0) lo = mid + 1;
        else hi = mid;
    }
    return lo < L->named_count && !strcmp(asp_str(&L->named[lo].ai->mName), name) ? &L->named[lo] : NULL;
}

/* >>morph targets ----------------------------------------------------------------------------- */

static sy_result mesh_targets(asp_loader *L, const char *where, const struct aiMesh *m, sy_primitive *p)
{
    size_t nv = m->mNumVertices, nt = m->mNumAnimMeshes;
    const char *why = NULL;
    bool normals = m->mNormals != NULL;
    if (nt > SY_MORPH_MAX_TARGETS) why = "more than SY_MORPH_MAX_TARGETS";
    else if (!m->mAnimMeshes) why = "no anim mesh array";
    for (size_t t = 0; t < nt && !why; ++t) {
        const struct aiAnimMesh *am = m->mAnimMeshes[t];
        if (!am || am->mNumVertices != nv || !am->mVertices) why = "an anim mesh without positions, or not of the mesh's vertex count";
        else normals = normals && am->mNormals;
    }
    if (why) {
        asp_warn(L, "%s: %zu anim meshes (morph targets) dropped (%s); drawn without them", where, nt, why);
        return SY_OK;
    }
    sy_result r;
    if ((r = sy_budget_charge(&L->budget, (uint64_t)nv * nt, normals ? 24u : 12u, &L->err, "%s: %zu morph targets", where, nt)))
        return r;
    for (int at = 0; at < (normals ? 2 : 1); ++at) {
        const struct aiVector3D *base = at ? m->mNormals : m->mVertices;
        float *d = malloc(nv * nt * 3 * sizeof(float) + 1);
        if (!d) return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "%s: out of memory for %zu morph targets", where, nt);
        for (size_t t = 0; t < nt && !why; ++t) {
            const struct aiVector3D *a = at ? m->mAnimMeshes[t]->mNormals : m->mAnimMeshes[t]->mVertices;
            for (size_t v = 0; v < nv && !why; ++v) {
                float x[3] = {a[v].x - base[v].x, a[v].y - base[v].y, a[v].z - base[v].z};
                if (!sy_coords_in_range(x, 3) || !isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2]))
                    why = "a delta is not finite or beyond the coordinate range";
                memcpy(d + (t * nv + v) * 3, x, sizeof x);
            }
        }
        if (why) {
            free(d);
            asp_warn(L, "%s: morph targets dropped (%s: %s)", where, at ? "normals" : "positions", why);
            sy_blob_release(p->target_positions);
            p->target_positions = NULL;
            return SY_OK;
        }
        if ((r = take_blob(L, d, nv * nt * 3 * sizeof(float), at ? &p->target_normals : &p->target_positions))) return r;
    }
    return SY_OK;
}

sy_result asp_mesh_deform(asp_loader *L, unsigned i, const struct aiMesh *m, sy_primitive *p)
{
    char where[64];
    snprintf(where, sizeof where, "meshes[%u] '%.32s'", i, asp_str(&m->mName));
    sy_result r = SY_OK;
    if (m->mNumBones && (r = mesh_bones(L, where, m, p))) return r;
    if (m->mNumAnimMeshes && p->topology == SY_TOPOLOGY_TRIANGLES) r = mesh_targets(L, where, m, p);
    return r;
}

sy_result asp_mesh_weights(asp_loader *L, unsigned i)
{
    const struct aiMesh *m = L->ai->mMeshes[i];
    float w[SY_MORPH_MAX_TARGETS];
    uint32_t n = L->mesh_targets[i];
    bool any = false;
    for (uint32_t t = 0; t < n; ++t) {
        float x = m->mAnimMeshes[t]->mWeight;
        w[t] = isfinite(x) && fabsf(x) < 1e6f ? x : 0.0f;
        any = any || w[t] != 0.0f;
    }
    if (!any) return SY_OK;
    sy_result r = sy_mesh_set_weights(L->scene, L->meshes[i], w, n, &L->err);
    if (r) sy_error_prefix(&L->err, "%s: meshes[%u]", L->path, i);
    return r;
}

/* >>skins ------------------------------------------------------------------------------------- */

sy_result asp_create_skins(asp_loader *L)
{
    sy_result r = SY_OK;
    for (size_t k = 0; k < L->placement_count && r == SY_OK; ++k) {
        const asp_placement *pl = &L->placements[k];
        if (!L->mesh_skinned[pl->mesh]) continue;
        const struct aiMesh *m = L->ai->mMeshes[pl->mesh];
        sy_node *joints = calloc(m->mNumBones + 1, sizeof *joints);
        sy_mat4 *ibm = calloc(m->mNumBones + 1, sizeof *ibm);
        if (!joints || !ibm) {
            free(joints), free(ibm);
            return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "meshes[%u]: out of memory for %u bones", pl->mesh, m->mNumBones);
        }
        const char *why = NULL;
        unsigned b = 0;
        for (; b < m->mNumBones && !why; ++b) {
            const struct aiBone *bone = m->mBones[b];
            asp_named *nd = bone ? asp_find_named(L, asp_str(&bone->mName)) : NULL;
            if (!nd) {
                why = "names no node";
                break;
            }
            joints[b] = nd->node;
            ibm[b] = offset_of(&bone->mOffsetMatrix);
            if (!sy_mat4_is_finite(&ibm[b]) || !sy_coords_in_range(ibm[b].m, 16)) why = "has an offset matrix not finite or beyond the coordinate range";
        }
        if (why) {
            asp_warn(L, "meshes[%u] '%s': bones[%u] '%s' %s; skin dropped (drawn in the bind pose)", pl->mesh, asp_str(&m->mName), b,
                     m->mBones[b] ? asp_str(&m->mBones[b]->mName) : "", why);
        } else if ((r = sy_node_set_skin(L->scene, pl->node, joints, ibm, m->mNumBones, (sy_node){0}, &L->err))) {
            sy_error_prefix(&L->err, "%s: meshes[%u] (skin)", L->path, pl->mesh);
        }
        free(joints);
        free(ibm);
    }
    return r;
}

/* >>animations -------------------------------------------------------------------------------- */

/* The samplers and channels of one clip being built. */
typedef struct clip_build {
    sy_anim_sampler_desc *descs;
    float **owned; /* per sampler: its times and values (one allocation each) */
    size_t nd, cap_d;
    sy_anim_channel *chans;
    size_t nc, cap_c;
} clip_build;

static void clip_free(clip_build *c)
{
    for (size_t k = 0; k < c->nd; ++k) free(c->owned[2 * k]), free(c->owned[2 * k + 1]);
    free(c->owned);
    free(c->descs);
    free(c->chans);
    memset(c, 0, sizeof *c);
}

/* Adds a LINEAR sampler (takes times and values). */
static sy_result add_sampler(asp_loader *L, clip_build *c, float *times, float *values, uint32_t keys, uint32_t comps,
                             uint32_t *index)
{
    size_t cap = c->cap_d;
    if (c->nd >= SY_ANIM_MAX_SAMPLERS || !sy_array_reserve(&c->descs, c->nd, &c->cap_d, sizeof *c->descs, 16)) {
        free(times), free(values);
        return asp_fail(L, SY_ERR_LIMIT, "animations: too many samplers, or out of memory");
    }
    if (c->cap_d != cap || !c->owned) {
        float **o = realloc(c->owned, c->cap_d * 2 * sizeof *o);
        if (!o) {
            free(times), free(values);
            return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "animations: out of memory");
        }
        c->owned = o;
    }
    c->owned[2 * c->nd] = times, c->owned[2 * c->nd + 1] = values;
    c->descs[c->nd] = (sy_anim_sampler_desc){SY_INTERP_LINEAR, comps, keys, times, values};
    *index = (uint32_t)c->nd++;
    return SY_OK;
}

static sy_result add_channel(asp_loader *L, clip_build *c, sy_node node, uint32_t path, uint32_t sampler)
{
    if (c->nc >= SY_ANIM_MAX_CHANNELS || !sy_array_reserve(&c->chans, c->nc, &c->cap_c, sizeof *c->chans, 16))
        return asp_fail(L, SY_ERR_LIMIT, "animations: too many channels, or out of memory");
    c->chans[c->nc++] = (sy_anim_channel){node.id, path, sampler};
    return SY_OK;
}

/* A key time in seconds, or NaN where it is not finite. */
static float key_time(double ticks, double tps) { return (float)(ticks / tps); }

/* Checks the times of n keys (each `stride` bytes apart from `first`, a double) into t[]; the reason
 * when one is bad. */
static const char *read_times(const void *first, size_t stride, size_t n, double tps, float *t, size_t *bad)
{
    for (size_t k = 0; k < n; ++k) {
        double d = *(const double *)((const char *)first + k * stride);
        t[k] = key_time(d, tps);
        *bad = k;
        if (!isfinite(t[k])) return "is not finite";
        if (k && !(t[k] > t[k - 1])) return "is not after the one before (times must increase strictly)";
    }
    return NULL;
}

/* The node's transform as TRS, once (a channel drives part of it; the rest keeps its static value). */
static sy_result make_trs(asp_loader *L, asp_named *nd)
{
    if (nd->trs) return SY_OK;
    struct aiVector3D sc, pos;
    struct aiQuaternion q;
    aiDecomposeMatrix(&nd->ai->mTransformation, &sc, &q, &pos);
    float t[3] = {pos.x, pos.y, pos.z}, r4[4] = {q.x, q.y, q.z, q.w}, s[3] = {sc.x, sc.y, sc.z};
    float len = sqrtf(r4[0] * r4[0] + r4[1] * r4[1] + r4[2] * r4[2] + r4[3] * r4[3]);
    bool ok = isfinite(len) && len > 1e-6f && sy_coords_in_range(t, 3) && sy_coords_in_range(s, 3) && isfinite(t[0] + t[1] + t[2] + s[0] + s[1] + s[2]);
    if (ok) {
        for (int k = 0; k < 4; ++k) r4[k] /= len;
        /* a shear (or a mirror) TRS cannot hold: the channel still drives the node, its static part approximated */
        sy_mat4 back = sy_mat4_from_trs(t, r4, s);
        const struct aiMatrix4x4 *a = &nd->ai->mTransformation;
        const float orig[16] = {a->a1, a->b1, a->c1, a->d1, a->a2, a->b2, a->c2, a->d2, a->a3, a->b3, a->c3, a->d3, a->a4, a->b4, a->c4, a->d4};
        float err = 0, mag = 1e-6f;
        for (int k = 0; k < 16; ++k) err = fmaxf(err, fabsf(back.m[k] - orig[k])), mag = fmaxf(mag, fabsf(orig[k]));
        if (err > 1e-3f * mag)
            asp_warn(L, "nodes '%s': animated, but its matrix is not a translation, rotation and scale (a shear or mirror); "
                        "taken as the nearest one", asp_str(&nd->ai->mName));
    } else {
        asp_warn(L, "nodes '%s': animated, but its matrix does not decompose; taken as identity", asp_str(&nd->ai->mName));
        t[0] = t[1] = t[2] = 0, r4[0] = r4[1] = r4[2] = 0, r4[3] = 1, s[0] = s[1] = s[2] = 1;
    }
    sy_result r = sy_node_set_trs(L->scene, nd->node, t, r4, s, &L->err);
    if (r) sy_error_prefix(&L->err, "%s: nodes '%s'", L->path, asp_str(&nd->ai->mName));
    nd->trs = true;
    return r;
}

/* One of a node channel's three key lists (path 0 position, 1 rotation, 2 scaling) into a sampler
 * and a channel; a warning naming the list when it cannot be used. */
static sy_result node_keys(asp_loader *L, clip_build *c, unsigned ai, unsigned ci, const struct aiNodeAnim *na, asp_named *nd,
                           uint32_t path, double tps)
{
    static const char *const names[3] = {"position", "rotation", "scaling"};
    unsigned n = path == 0 ? na->mNumPositionKeys : path == 1 ? na->mNumRotationKeys : na->mNumScalingKeys;
    const void *keys = path == 0 ? (const void *)na->mPositionKeys : path == 1 ? (const void *)na->mRotationKeys : (const void *)na->mScalingKeys;
    if (n == 0) return SY_OK;
    if (!keys || n > SY_ANIM_MAX_KEYS) {
        asp_warn(L, "animations[%u].channels[%u] '%s': %u %s keys (1 to %u, with data); dropped", ai, ci, asp_str(&na->mNodeName), n,
                 names[path], SY_ANIM_MAX_KEYS);
        return SY_OK;
    }
    uint32_t comps = path == 1 ? 4 : 3;
    sy_result r;
    if ((r = sy_budget_charge(&L->budget, (uint64_t)n * (1 + comps), sizeof(float), &L->err, "animations[%u].channels[%u]: %u keys",
                              ai, ci, n)))
        return r;
    float *t = malloc((size_t)n * sizeof *t + 1), *v = malloc((size_t)n * comps * sizeof *v + 1);
    if (!t || !v) {
        free(t), free(v);
        return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "animations[%u].channels[%u]: out of memory for %u keys", ai, ci, n);
    }
    size_t stride = path == 1 ? sizeof(struct aiQuatKey) : sizeof(struct aiVectorKey), bad = 0;
    const char *why = read_times(keys, stride, n, tps, t, &bad);
    if (why) {
        asp_warn(L, "animations[%u].channels[%u] '%s': %s key %zu time (%g s) %s; dropped", ai, ci, asp_str(&na->mNodeName),
                 names[path], bad, (double)t[bad], why);
        free(t), free(v);
        return SY_OK;
    }
    for (size_t k = 0; k < n && !why; ++k) {
        float *o = v + k * comps;
        if (path == 1) {
            const struct aiQuaternion *q = &na->mRotationKeys[k].mValue;
            o[0] = q->x, o[1] = q->y, o[2] = q->z, o[3] = q->w; /* Assimp: w x y z; the scene: x y z w */
            if (!isfinite(o[0] + o[1] + o[2] + o[3])) why = "is not finite";
            else if (!(o[0] * o[0] + o[1] * o[1] + o[2] * o[2] + o[3] * o[3] > 1e-12f)) why = "is the zero quaternion";
        } else {
            const struct aiVector3D *x = path == 0 ? &na->mPositionKeys[k].mValue : &na->mScalingKeys[k].mValue;
            o[0] = x->x, o[1] = x->y, o[2] = x->z;
            if (!isfinite(o[0]) || !isfinite(o[1]) || !isfinite(o[2]) || !sy_coords_in_range(o, 3))
                why = "is not finite or beyond the coordinate range";
        }
        bad = k;
    }
    if (why) {
        asp_warn(L, "animations[%u].channels[%u] '%s': %s key %zu value %s; dropped", ai, ci, asp_str(&na->mNodeName), names[path],
                 bad, why);
        free(t), free(v);
        return SY_OK;
    }
    if ((r = make_trs(L, nd))) {
        free(t), free(v);
        return r;
    }
    uint32_t si;
    if ((r = add_sampler(L, c, t, v, n, comps, &si))) return r;
    return add_channel(L, c, nd->node, path == 0 ? SY_ANIM_TRANSLATION : path == 1 ? SY_ANIM_ROTATION : SY_ANIM_SCALE, si);
}

/* A morph channel: the nodes that draw the morphed meshes of the node named mName (else the meshes
 * of that name); one sampler of dense weights (one per target of the first such mesh). */
static sy_result morph_keys(asp_loader *L, clip_build *c, unsigned ai, unsigned ci, const struct aiMeshMorphAnim *ma, double tps)
{
    const char *name = asp_str(&ma->mName);
    asp_named *nd = asp_find_named(L, name);
    uint32_t targets = 0;
    size_t hits = 0;
    for (size_t k = 0; k < L->placement_count; ++k) {
        const asp_placement *pl = &L->placements[k];
        bool mine = nd ? pl->walk == nd->walk : !strcmp(asp_str(&L->ai->mMeshes[pl->mesh]->mName), name);
        if (mine && L->mesh_targets[pl->mesh]) {
            if (!targets) targets = L->mesh_targets[pl->mesh];
            hits++;
        }
    }
    if (!hits) {
        asp_warn(L, "animations[%u].morph_channels[%u] '%s': names no node or mesh with morph targets; dropped", ai, ci, name);
        return SY_OK;
    }
    unsigned n = ma->mNumKeys;
    if (!ma->mKeys || n == 0 || n > SY_ANIM_MAX_KEYS) {
        asp_warn(L, "animations[%u].morph_channels[%u] '%s': %u keys (1 to %u); dropped", ai, ci, name, n, SY_ANIM_MAX_KEYS);
        return SY_OK;
    }
    sy_result r;
    if ((r = sy_budget_charge(&L->budget, (uint64_t)n * (1 + targets), sizeof(float), &L->err,
                              "animations[%u].morph_channels[%u]: %u keys x %u targets", ai, ci, n, targets)))
        return r;
    float *t = malloc((size_t)n * sizeof *t + 1), *v = calloc((size_t)n * targets + 1, sizeof *v);
    if (!t || !v) {
        free(t), free(v);
        return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "animations[%u].morph_channels[%u]: out of memory for %u keys", ai, ci, n);
    }
    size_t bad = 0;
    const char *why = read_times(&ma->mKeys[0].mTime, sizeof(struct aiMeshMorphKey), n, tps, t, &bad);
    if (why) {
        asp_warn(L, "animations[%u].morph_channels[%u] '%s': key %zu time (%g s) %s; dropped", ai, ci, name, bad, (double)t[bad], why);
        free(t), free(v);
        return SY_OK;
    }
    for (size_t k = 0; k < n && !why; ++k) {
        const struct aiMeshMorphKey *key = &ma->mKeys[k];
        if (key->mNumValuesAndWeights && (!key->mValues || !key->mWeights)) why = "has no values";
        for (unsigned q = 0; q < key->mNumValuesAndWeights && !why; ++q) {
            double w = key->mWeights[q];
            if (key->mValues[q] >= targets) why = "names a target the mesh does not have";
            else if (!isfinite(w) || fabs(w) > 1e6) why = "has a weight that is not finite (or beyond 10^6)";
            else v[k * targets + key->mValues[q]] = (float)w;
        }
        bad = k;
    }
    if (why) {
        asp_warn(L, "animations[%u].morph_channels[%u] '%s': key %zu %s; dropped", ai, ci, name, bad, why);
        free(t), free(v);
        return SY_OK;
    }
    uint32_t si;
    if ((r = add_sampler(L, c, t, v, n, targets, &si))) return r;
    for (size_t k = 0; k < L->placement_count && r == SY_OK; ++k) {
        const asp_placement *pl = &L->placements[k];
        bool mine = nd ? pl->walk == nd->walk : !strcmp(asp_str(&L->ai->mMeshes[pl->mesh]->mName), name);
        if (mine && L->mesh_targets[pl->mesh]) r = add_channel(L, c, pl->node, SY_ANIM_WEIGHTS, si);
    }
    return r;
}

static sy_result create_animation(asp_loader *L, unsigned ai)
{
    const struct aiAnimation *an = L->ai->mAnimations[ai];
    char where[48];
    snprintf(where, sizeof where, "animations[%u]", ai);
    uint32_t id;
    sy_result r = asp_new(L, SY_TYPE_ANIMATION, an ? asp_str(&an->mName) : NULL, where, &id);
    if (r || !an) return r;
    double tps = an->mTicksPerSecond;
    if (!(isfinite(tps) && tps > 0)) {
        if (tps != 0) asp_warn(L, "%s '%s': %g ticks per second; Assimp's default 25 used", where, asp_str(&an->mName), tps);
        tps = ASP_TICKS_DEFAULT;
    }
    clip_build c = {0};
    for (unsigned k = 0; k < an->mNumChannels && r == SY_OK; ++k) {
        const struct aiNodeAnim *na = an->mChannels ? an->mChannels[k] : NULL;
        if (!na) continue;
        asp_named *nd = asp_find_named(L, asp_str(&na->mNodeName));
        if (!nd) {
            asp_warn(L, "%s.channels[%u]: node '%s' is not in the tree; dropped", where, k, asp_str(&na->mNodeName));
            continue;
        }
        bool clamped = na->mPreState == aiAnimBehaviour_LINEAR || na->mPreState == aiAnimBehaviour_REPEAT ||
                       na->mPostState == aiAnimBehaviour_LINEAR || na->mPostState == aiAnimBehaviour_REPEAT;
        if (clamped && !L->anim_states_warned) {
            L->anim_states_warned = true;
            asp_warn(L, "%s.channels[%u] '%s': pre / post state linear or repeat; held at the first / last key (the scene clock "
                        "clamps; further such channels not named)", where, k, asp_str(&na->mNodeName));
        }
        for (uint32_t path = 0; path < 3 && r == SY_OK; ++path) r = node_keys(L, &c, ai, k, na, nd, path, tps);
    }
    for (unsigned k = 0; k < an->mNumMorphMeshChannels && r == SY_OK; ++k)
        if (an->mMorphMeshChannels && an->mMorphMeshChannels[k]) r = morph_keys(L, &c, ai, k, an->mMorphMeshChannels[k], tps);
    if (r == SY_OK && an->mNumMeshChannels)
        asp_warn(L, "%s '%s': %u mesh channels (vertex animation by whole anim meshes) not played", where, asp_str(&an->mName),
                 an->mNumMeshChannels);
    if (r == SY_OK && c.nc) {
        sy_error e = {0};
        if (sy_animation_set_clip(L->scene, (sy_animation){id}, c.descs, (uint32_t)c.nd, c.chans, (uint32_t)c.nc, &e) != SY_OK)
            asp_warn(L, "%s: refused (%s); the clip stays empty", where, e.message); /* checked above: not expected */
    }
    clip_free(&c);
    return r;
}

sy_result asp_create_animations(asp_loader *L)
{
    sy_result r = SY_OK;
    if (L->ai->mNumAnimations && !L->ai->mAnimations) return SY_OK;
    for (unsigned i = 0; i < L->ai->mNumAnimations && r == SY_OK; ++i) r = create_animation(L, i);
    return r;
}
