/* sy_gltf_nodes.c — glTF cameras, KHR_lights_punctual lights and the node graph of one glTF scene:
 * the nodes reachable from its roots (placements charged to the budget), their transforms (the
 * first frame of animations[0] where one targets them), meshes, cameras, lights,
 * EXT_mesh_gpu_instancing instances, children and the new root node. */
#include "sy_gltf_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>cameras+lights ---------------------------------------------------------------------------- */

typedef sy_result (*object_setter)(sy_scene *s, uint32_t id, const void *data, sy_error *err);

static sy_result set_camera(sy_scene *s, uint32_t id, const void *d, sy_error *err) { return sy_camera_set(s, (sy_camera){id}, d, err); }
static sy_result set_light(sy_scene *s, uint32_t id, const void *d, sy_error *err) { return sy_light_set(s, (sy_light){id}, d, err); }

/* Creates the object of type `type` that the file's what[i] describes, named name, and sets its data
 * through set: its id in *id (left alone on failure); errors name what[i]. */
static sy_result create_set(loader *L, sy_object_type type, const char *what, size_t i, const char *name, const void *data,
                            object_setter set, uint32_t *id)
{
    char where[64];
    snprintf(where, sizeof where, "%s[%zu]", what, i);
    uint32_t h;
    sy_result r = gltf_create(L, type, name, where, &h);
    if (r != SY_OK) return r;
    if ((r = set(L->scene, h, data, &L->err))) return gltf_context(L, r, where);
    *id = h;
    return SY_OK;
}

sy_result gltf_create_camera(loader *L, size_t i)
{
    const sy_gltf_shim_camera *c = &L->doc->cameras[i];
    sy_camera_data cd = *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
    cd.name = (char *)gltf_nonempty(c->name);
    bool ok;
    if (!strcmp(c->type, "perspective")) {
        cd.projection = SY_PROJECTION_PERSPECTIVE;
        ok = gltf_to_float(c->yfov, &cd.yfov) && gltf_to_float(c->aspect, &cd.aspect) && gltf_to_float(c->znear, &cd.znear) &&
             gltf_to_float(c->zfar, &cd.zfar);
    } else {
        cd.projection = SY_PROJECTION_ORTHOGRAPHIC;
        ok = gltf_to_float(c->xmag, &cd.xmag) && gltf_to_float(c->ymag, &cd.ymag) && gltf_to_float(c->oznear, &cd.znear) &&
             gltf_to_float(c->ozfar, &cd.zfar);
    }
    if (!ok) return gltf_fail(L, SY_ERR_PARSE, "cameras[%zu]: value out of float range", i);
    return create_set(L, SY_TYPE_CAMERA, "cameras", i, cd.name, &cd, set_camera, &L->cameras[i].id);
}

sy_result gltf_create_light(loader *L, size_t i)
{
    const sy_gltf_shim_light *l = &L->doc->lights[i];
    sy_light_data ld = *(const sy_light_data *)sy_object_defaults(SY_TYPE_LIGHT);
    ld.name = (char *)gltf_nonempty(l->name);
    ld.type = !strcmp(l->type, "spot") ? SY_LIGHT_SPOT : !strcmp(l->type, "directional") ? SY_LIGHT_DIRECTIONAL : SY_LIGHT_POINT;
    bool ok = gltf_to_float(l->color[0], &ld.color[0]) && gltf_to_float(l->color[1], &ld.color[1]) &&
              gltf_to_float(l->color[2], &ld.color[2]) && gltf_to_float(l->intensity, &ld.intensity) &&
              gltf_to_float(l->range, &ld.range);
    if (ld.type == SY_LIGHT_SPOT) ok = ok && gltf_to_float(l->inner_cone, &ld.inner_cone) && gltf_to_float(l->outer_cone, &ld.outer_cone);
    if (!ok) return gltf_fail(L, SY_ERR_PARSE, "KHR_lights_punctual.lights[%zu]: value out of float range", i);
    return create_set(L, SY_TYPE_LIGHT, "KHR_lights_punctual.lights", i, ld.name, &ld, set_light, &L->lights[i].id);
}

/* >>nodes ------------------------------------------------------------------------------------- */

static sy_result new_node(loader *L, const char *name, sy_node *out, const char *where)
{
    sy_result r;
    if ((r = gltf_create(L, SY_TYPE_NODE, name, where, &out->id))) return r;
    if ((r = sy_node_set_flags(L->scene, *out, SY_NODE_VISIBLE, &L->err))) return gltf_context(L, r, where);
    return SY_OK;
}

static sy_result set_trs(loader *L, sy_node h, const float t[3], const float q_in[4], const float s[3], const char *where)
{
    float q[4] = {q_in[0], q_in[1], q_in[2], q_in[3]};
    double len = sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] + (double)q[3] * q[3]);
    if (!(len > 1e-12) || !isfinite(len)) return gltf_fail(L, SY_ERR_PARSE, "%s: rotation quaternion has zero length", where);
    for (int k = 0; k < 4; k++) q[k] = (float)(q[k] / len);
    sy_result r = sy_node_set_trs(L->scene, h, t, q, s, &L->err);
    return r ? gltf_context(L, r, where) : SY_OK;
}

/* Instance nodes of EXT_mesh_gpu_instancing, created as children of the glTF node. */
static sy_result create_instances(loader *L, size_t ni, sy_node **out, size_t *count_out)
{
    const sy_gltf_shim_node *n = &L->doc->nodes[ni];
    const int32_t acc[3] = {n->inst_translation, n->inst_rotation, n->inst_scale};
    float *data[3] = {NULL, NULL, NULL};
    const size_t comps[3] = {3, 4, 3};
    size_t count = 0;
    sy_result r = SY_OK;
    *out = NULL;
    *count_out = 0;
    for (int k = 0; k < 3; k++) {
        if (acc[k] < 0) continue;
        count = L->doc->accessors[acc[k]].count;
        if ((r = gltf_read_floats(L, (size_t)acc[k], comps[k], &data[k]))) goto done;
    }
    sy_node *nodes = gltf_xcalloc(L, count, sizeof(sy_node), &r);
    if (!nodes) goto done;
    char where[80];
    snprintf(where, sizeof where, "nodes[%zu].EXT_mesh_gpu_instancing", ni);
    for (size_t i = 0; i < count; i++) {
        float t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
        if (data[0]) memcpy(t, data[0] + 3 * i, sizeof t);
        if (data[1]) memcpy(q, data[1] + 4 * i, sizeof q);
        if (data[2]) memcpy(s, data[2] + 3 * i, sizeof s);
        for (int k = 0; k < 3; k++)
            if (!isfinite(t[k]) || !isfinite(s[k])) {
                r = gltf_fail(L, SY_ERR_PARSE, "%s: non-finite value in instance %zu", where, i);
                goto fail_nodes;
            }
        if ((r = new_node(L, NULL, &nodes[i], where)) || (r = set_trs(L, nodes[i], t, q, s, where)))
            goto fail_nodes;
        if ((r = sy_node_set_mesh(L->scene, nodes[i], L->meshes[n->mesh], &L->err))) {
            r = gltf_context(L, r, where);
            goto fail_nodes;
        }
    }
    *out = nodes;
    *count_out = count;
    goto done;
fail_nodes:
    free(nodes);
done:
    for (int k = 0; k < 3; k++) free(data[k]);
    return r;
}

/* The first frame of animations[0]: for every channel targeting node ni's translation, rotation
 * or scale, the sampler's first output value (the value at its first keyframe; for CUBICSPLINE the
 * middle element of the first triple) replaces the node's static value. Bad channels are warned
 * and skipped (local). */
/* first_frame's channels of node ni: head[ni], then next[c] (-1 ends), in channel order. Built once
 * per load (looking through every channel for each node made loading n animated nodes O(n^2):
 * 39 s for 3 x 10^4 nodes with two channels each). */
static sy_result first_frame(loader *L, size_t ni, const int32_t *head, const int32_t *next, float t[3], float q[4],
                             float s[3], bool *animated)
{
    const sy_gltf_doc *d = L->doc;
    for (int32_t ci = head[ni]; ci >= 0; ci = next[ci]) {
        size_t c = (size_t)ci;
        const sy_gltf_shim_channel *ch = &d->channels[c];
        if (ch->node != (int32_t)ni || ch->path < 0) continue;
        size_t comps = ch->path == 1 ? 4 : 3;
        if (ch->output < 0 || (size_t)ch->output >= d->accessor_count) {
            gltf_warn(L, "animations[0].channels[%zu]: invalid sampler output; ignored", c);
            continue;
        }
        const sy_gltf_shim_accessor *a = &d->accessors[ch->output];
        size_t at = ch->cubic ? 1 : 0;
        if ((size_t)a->components != comps || a->is_matrix || a->count <= at) {
            gltf_warn(L, "animations[0].channels[%zu]: output accessor %d is not %zu-component with a first value; ignored",
                      c, (int)ch->output, comps);
            continue;
        }
        float x[4];
        sy_result r = gltf_read_element(L, (size_t)ch->output, at, comps, x); /* not the whole accessor: its count is unbounded */
        if (r) return r;
        bool finite = true;
        for (size_t k = 0; k < comps; k++) finite = finite && isfinite(x[k]);
        if (finite && comps == 4 && !(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3] > 1e-12f)) finite = false;
        if (!finite) {
            gltf_warn(L, "animations[0].channels[%zu]: non-finite first value (or zero quaternion); ignored", c);
        } else {
            float *dst = ch->path == 0 ? t : ch->path == 1 ? q : s;
            memcpy(dst, x, comps * sizeof(float));
            *animated = true;
        }
    }
    return SY_OK;
}

/* Skin d->nodes[i].skin onto node i (a node with a mesh): the joints (reached nodes), the inverse
 * bind matrices (a MAT4 float accessor with at least one per joint; identity without one) and the
 * skeleton. A skin that cannot be used is dropped with a warning naming skins[k] (and the mesh
 * primitive whose joint index it cannot serve): the mesh is drawn in its bind pose, never read past
 * the skin. */
static sy_result set_skin(loader *L, size_t i)
{
    const sy_gltf_doc *d = L->doc;
    const sy_gltf_shim_node *n = &d->nodes[i];
    size_t k = (size_t)n->skin;
    const sy_gltf_shim_skin *sk = &d->skins[k];
    const char *why = NULL;
    if (sk->joint_count == 0 || sk->joint_count > SY_SKIN_MAX_JOINTS) why = "no joints, or more than SY_SKIN_MAX_JOINTS";
    for (size_t j = 0; j < sk->joint_count && !why; j++)
        if (sk->joints[j] < 0 || (size_t)sk->joints[j] >= d->node_count || !L->reached[sk->joints[j]])
            why = "a joint is not a node of the loaded scene";
    if (!why && sk->skeleton >= 0 && (size_t)sk->skeleton >= d->node_count) why = "skeleton is not a node";
    if (!why && L->mesh_joints[n->mesh] > sk->joint_count) {
        gltf_warn(L, "skins[%zu]: meshes[%d] uses joint index %u, past the skin's %zu joints; skin dropped (nodes[%zu] drawn in "
                     "its bind pose)",
                  k, (int)n->mesh, L->mesh_joints[n->mesh] - 1, sk->joint_count, i);
        return SY_OK;
    }
    if (!why && sk->inverse_bind_matrices >= 0) {
        const sy_gltf_shim_accessor *a = (size_t)sk->inverse_bind_matrices < d->accessor_count ? &d->accessors[sk->inverse_bind_matrices] : NULL;
        if (!a || a->components != 16 || a->count < sk->joint_count || a->component_type != CT_FLOAT)
            why = "inverseBindMatrices is not a float MAT4 accessor with one matrix per joint";
    }
    if (why) {
        gltf_warn(L, "skins[%zu] (of nodes[%zu]): %s; skin dropped (drawn in the bind pose)", k, i, why);
        return SY_OK;
    }
    sy_result r = SY_OK;
    sy_node *joints = gltf_xcalloc(L, sk->joint_count, sizeof *joints, &r);
    sy_mat4 *ibm = joints ? gltf_xcalloc(L, sk->joint_count, sizeof *ibm, &r) : NULL;
    if (!ibm) {
        free(joints);
        return r;
    }
    for (size_t j = 0; j < sk->joint_count; j++) {
        joints[j] = L->nodes[sk->joints[j]];
        ibm[j] = sy_mat4_identity();
        if (sk->inverse_bind_matrices >= 0 &&
            (r = gltf_read_element(L, (size_t)sk->inverse_bind_matrices, j, 16, ibm[j].m)))
            break;
        if (!sy_mat4_is_finite(&ibm[j]) || !sy_coords_in_range(ibm[j].m, 16)) {
            why = "an inverse bind matrix is not finite or beyond the coordinate range";
            break;
        }
    }
    if (r == SY_OK && why) gltf_warn(L, "skins[%zu] (of nodes[%zu]): %s; skin dropped (drawn in the bind pose)", k, i, why);
    if (r == SY_OK && !why) {
        sy_node skeleton = sk->skeleton >= 0 ? L->nodes[sk->skeleton] : (sy_node){0};
        if ((r = sy_node_set_skin(L->scene, L->nodes[i], joints, ibm, (uint32_t)sk->joint_count, skeleton, &L->err))) {
            char where[48];
            snprintf(where, sizeof where, "skins[%zu]", k);
            r = gltf_context(L, r, where);
        }
    }
    free(joints);
    free(ibm);
    return r;
}

sy_result gltf_create_nodes(loader *L, const int32_t *roots, size_t root_count, const char *root_name)
{
    const sy_gltf_doc *d = L->doc;
    sy_result r = SY_OK;
    /* reachability from the roots (iterative; the graph is a validated forest) */
    int32_t *stack = gltf_xcalloc(L, d->node_count + 1, sizeof(int32_t), &r);
    if (!stack) return r;
    size_t top = 0;
    for (size_t k = 0; k < root_count; k++) {
        if (L->reached[roots[k]]) continue;
        L->reached[roots[k]] = 1;
        stack[top++] = roots[k];
        while (top) {
            const sy_gltf_shim_node *n = &d->nodes[stack[--top]];
            for (size_t c = 0; c < n->child_count; c++)
                if (!L->reached[n->children[c]]) {
                    L->reached[n->children[c]] = 1;
                    stack[top++] = n->children[c];
                }
        }
    }
    free(stack);
    /* the budget's placements (a glTF graph is a forest: one per node, plus the instances) */
    size_t reached = 0, instances = 0;
    for (size_t i = 0; i < d->node_count; i++)
        if (L->reached[i]) {
            reached++;
            if (d->nodes[i].instancing) {
                const int32_t acc[3] = {d->nodes[i].inst_translation, d->nodes[i].inst_rotation, d->nodes[i].inst_scale};
                for (int k = 0; k < 3; k++)
                    if (acc[k] >= 0) {
                        instances += d->accessors[acc[k]].count;
                        break;
                    }
            }
        }
    if ((r = sy_budget_charge(&L->budget, (uint64_t)reached + instances, SY_BUDGET_PLACEMENT_BYTES, &L->err,
                              "%zu nodes and %zu EXT_mesh_gpu_instancing instances", reached, instances)))
        return r;

    sy_node **inst = gltf_xcalloc(L, d->node_count + 1, sizeof(sy_node *), &r);
    size_t *inst_count = inst ? gltf_xcalloc(L, d->node_count + 1, sizeof(size_t), &r) : NULL;
    sy_node *kids = NULL;
    /* each node's channels (first_frame), in channel order */
    int32_t *chan_head = inst_count ? gltf_xcalloc(L, d->node_count + 1, sizeof(int32_t), &r) : NULL;
    int32_t *chan_next = chan_head ? gltf_xcalloc(L, d->channel_count + 1, sizeof(int32_t), &r) : NULL;
    if (!inst || !inst_count || !chan_head || !chan_next) goto done;
    if (d->channel_count > INT32_MAX) {
        r = gltf_fail(L, SY_ERR_LIMIT, "animations[0]: too many channels (%zu)", d->channel_count);
        goto done;
    }
    for (size_t i = 0; i < d->node_count; i++) chan_head[i] = -1;
    for (size_t c = d->channel_count; c-- > 0;) {
        int32_t nd = d->channels[c].node;
        chan_next[c] = -1;
        if (nd < 0 || (size_t)nd >= d->node_count) continue;
        chan_next[c] = chan_head[nd];
        chan_head[nd] = (int32_t)c;
    }
    for (size_t i = 0; i < d->node_count; i++) {
        if (!L->reached[i]) continue;
        const sy_gltf_shim_node *n = &d->nodes[i];
        char where[48];
        snprintf(where, sizeof where, "nodes[%zu]", i);
        sy_node h;
        if ((r = new_node(L, gltf_nonempty(n->name), &h, where))) goto done;
        L->nodes[i] = h;
        if (n->matrix_count == 16) {
            sy_mat4 mat;
            for (int k = 0; k < 16; k++) mat.m[k] = (float)n->matrix[k]; /* finite and in range: validated */
            if ((r = sy_node_set_matrix(L->scene, h, &mat, &L->err))) {
                r = gltf_context(L, r, where);
                goto done;
            }
        } else {
            float t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
            for (size_t k = 0; k < n->translation_count; k++) t[k] = (float)n->translation[k];
            for (size_t k = 0; k < n->rotation_count; k++) q[k] = (float)n->rotation[k];
            for (size_t k = 0; k < n->scale_count; k++) s[k] = (float)n->scale[k];
            bool animated = false;
            if ((r = first_frame(L, i, chan_head, chan_next, t, q, s, &animated))) goto done;
            if ((n->translation_count || n->rotation_count || n->scale_count || animated) &&
                (r = set_trs(L, h, t, q, s, where)))
                goto done;
        }
        if (n->mesh >= 0 && !n->instancing && (r = sy_node_set_mesh(L->scene, h, L->meshes[n->mesh], &L->err))) {
            r = gltf_context(L, r, where);
            goto done;
        }
        if (n->camera >= 0 && (r = sy_node_set_camera(L->scene, h, L->cameras[n->camera], &L->err))) {
            r = gltf_context(L, r, where);
            goto done;
        }
        if (n->light >= 0 && (r = sy_node_set_light(L->scene, h, L->lights[n->light], &L->err))) {
            r = gltf_context(L, r, where);
            goto done;
        }
        if (n->weight_count && (r = gltf_set_weights(L, n->weights, n->weight_count, h.id, SY_TYPE_NODE, where))) goto done;
        if (n->instancing && (r = create_instances(L, i, &inst[i], &inst_count[i]))) goto done;
    }
    /* children (all reached, hence created) */
    for (size_t i = 0; i < d->node_count; i++) {
        if (!L->reached[i]) continue;
        const sy_gltf_shim_node *n = &d->nodes[i];
        size_t total = n->child_count + inst_count[i];
        if (total == 0) continue;
        if (total > UINT32_MAX) {
            r = gltf_fail(L, SY_ERR_LIMIT, "nodes[%zu]: too many children", i);
            goto done;
        }
        kids = gltf_xcalloc(L, total, sizeof(sy_node), &r);
        if (!kids) goto done;
        for (size_t k = 0; k < inst_count[i]; k++) kids[k] = inst[i][k];
        for (size_t c = 0; c < n->child_count; c++) kids[inst_count[i] + c] = L->nodes[n->children[c]];
        if ((r = sy_node_set_children(L->scene, L->nodes[i], kids, (uint32_t)total, &L->err))) {
            char where[48];
            snprintf(where, sizeof where, "nodes[%zu]", i);
            r = gltf_context(L, r, where);
            goto done;
        }
        free(kids);
        kids = NULL;
    }
    /* skins, once every joint node exists */
    for (size_t i = 0; i < d->node_count; i++)
        if (L->reached[i] && d->nodes[i].skin >= 0 && d->nodes[i].mesh >= 0 && !d->nodes[i].instancing &&
            (r = set_skin(L, i)))
            goto done;
    /* the new root */
    sy_node root;
    if ((r = new_node(L, root_name, &root, "scene root"))) goto done;
    if (root_count > UINT32_MAX) {
        r = gltf_fail(L, SY_ERR_LIMIT, "too many root nodes");
        goto done;
    }
    kids = gltf_xcalloc(L, root_count, sizeof(sy_node), &r);
    if (!kids) goto done;
    for (size_t k = 0; k < root_count; k++) kids[k] = L->nodes[roots[k]];
    if (root_count && (r = sy_node_set_children(L->scene, root, kids, (uint32_t)root_count, &L->err))) {
        r = gltf_context(L, r, "scene root");
        goto done;
    }
    L->info->root = root;
    /* camera nodes in glTF node order */
    uint32_t ncam = 0;
    for (size_t i = 0; i < d->node_count; i++) ncam += (L->reached[i] && d->nodes[i].camera >= 0);
    if (ncam) {
        L->info->camera_nodes = gltf_xcalloc(L, ncam, sizeof(sy_node), &r);
        if (!L->info->camera_nodes) goto done;
        for (size_t i = 0; i < d->node_count; i++)
            if (L->reached[i] && d->nodes[i].camera >= 0) L->info->camera_nodes[L->info->camera_node_count++] = L->nodes[i];
    }
done:
    free(kids);
    free(chan_head);
    free(chan_next);
    if (inst)
        for (size_t i = 0; i < d->node_count; i++) free(inst[i]);
    free(inst);
    free(inst_count);
    return r;
}
