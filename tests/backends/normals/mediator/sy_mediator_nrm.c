/* sy_mediator_nrm.c — the normals mediator (see sy_mediator_nrm.h). */
#include "sy_mediator_nrm.h"

#include "sy_backend_status.h"
#include "sy_mirror.h"
#include "sy_nrm.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct nrm_state {
    sy_nrm_device *dev;
    sy_mirror *mirror;
    sy_nrm_result code;             /* the device's last failure (nrm_error), on the thread of the call */
    char msg[SY_ERROR_MESSAGE_MAX]; /* its message */
} nrm_state;

SY_BACKEND_SAME_CODE(SY_NRM_ERROR_INVALID_ARGUMENT, SY_ERR_INVALID_ARGUMENT);
SY_BACKEND_SAME_CODE(SY_NRM_ERROR_OUT_OF_MEMORY, SY_ERR_OUT_OF_MEMORY);
SY_BACKEND_SAME_CODE(SY_NRM_ERROR_EMBREE, SY_ERR_BACKEND);

/* the device's error callback */
static void nrm_error(void *user, sy_nrm_result code, const char *message)
{
    nrm_state *st = user;
    st->code = code;
    snprintf(st->msg, sizeof st->msg, "%s", message);
}

static sy_result nrm_fail(const nrm_state *st, sy_error *err) { return sy_backend_fail(err, (int)st->code, NULL, NULL, st->msg); }

static sy_result cb_primitive(void *user, const sy_mirror_primitive_args *a, sy_error *err)
{
    nrm_state *st = user;
    uint32_t nv = a->flat->vertex_count, nt = a->flat->triangle_count;
    const uint32_t *idx = a->flat->indices;
    uint32_t *seq = NULL;
    if (!idx && nt) { /* non-indexed: vertices in order */
        seq = malloc((size_t)nt * 3 * sizeof *seq);
        if (!seq) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "normals: out of memory");
        for (uint32_t i = 0; i < nt * 3; ++i) seq[i] = i;
        idx = seq;
    }
    *a->handle = sy_nrm_mesh_create(st->dev, a->flat->positions, nv, idx, nt);
    free(seq);
    return *a->handle ? SY_OK : nrm_fail(st, err);
}

static sy_result cb_instance(void *user, const sy_mirror_instance_args *a, sy_error *err)
{
    nrm_state *st = user;
    uint32_t h = sy_nrm_instance_set(st->dev, *a->handle, a->mesh, a->world->m, a->visible);
    if (!h) return nrm_fail(st, err);
    *a->handle = h;
    return SY_OK;
}

static void cb_release(void *user, const sy_mirror_release_args *a)
{
    nrm_state *st = user;
    if (a->kind == SY_MIRROR_PRIMITIVE) sy_nrm_mesh_release(st->dev, a->handle);
    else if (a->kind == SY_MIRROR_INSTANCE) sy_nrm_instance_release(st->dev, a->handle);
}

static const sy_mirror_callbacks nrm_callbacks = { /* normals: no texture, material or light */
    .primitive_set = cb_primitive,
    .instance_set = cb_instance,
    .release = cb_release,
};

static void nrm_destroy(void *state)
{
    nrm_state *st = state;
    if (!st) return;
    sy_mirror_destroy(st->mirror); /* releases instances and meshes through the device */
    sy_nrm_device_destroy(st->dev);
    free(st);
}

static sy_result nrm_create(const sy_mediator_create_args *args, void **state_out, sy_error *err)
{
    *state_out = NULL; /* args->params: always empty (the class declares none, core refuses any) */
    nrm_state *st = calloc(1, sizeof *st);
    if (!st) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "normals: out of memory");
    sy_nrm_device_desc dd = {nrm_error, st};
    sy_result r = sy_nrm_device_create(&dd, &st->dev) ? nrm_fail(st, err) : SY_OK;
    sy_mirror_desc md = {.name = "normals mediator", .root_node_id = args->root_node_id, .callbacks = &nrm_callbacks,
                         .user = st};
    if (r == SY_OK) r = sy_mirror_create(&md, &st->mirror, err);
    if (r) {
        nrm_destroy(st);
        return r;
    }
    *state_out = st;
    return SY_OK;
}

static sy_result nrm_sync(void *state, const sy_changes *changes, sy_error *err)
{
    return sy_mirror_sync(((nrm_state *)state)->mirror, changes, NULL, err);
}

static sy_result nrm_render(void *state, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    nrm_state *st = state;
    sy_nrm_view v = {.orthographic = req->camera.projection == SY_PROJECTION_ORTHOGRAPHIC,
                     .full_width = req->full_width, .full_height = req->full_height,
                     .rect_x = req->rect_x, .rect_y = req->rect_y, .rect_w = req->rect_w, .rect_h = req->rect_h};
    memcpy(v.camera_to_world, req->camera.camera_to_world.m, sizeof v.camera_to_world);
    memcpy(v.window, req->camera.window, sizeof v.window);
    return sy_nrm_render(st->dev, &v, layer->rgba, layer->depth) ? nrm_fail(st, err) : SY_OK;
}

static const sy_mediator_class nrm_class = {
    .name = "normals",
    .caps = SY_CAP_DEPTH | SY_CAP_TILES | SY_CAP_ANALYSIS,
    .create = nrm_create,
    .destroy = nrm_destroy,
    .sync = nrm_sync,
    .render = nrm_render,
    /* its parameters: none. A back-end with some declares them here, e.g.
     *   static const sy_param_decl nrm_params[] = {{"flip", SY_PARAM_BOOL, 0, 0, "0", NULL, "negate normals", 0}};
     *   .param_table = SY_PARAM_TABLE(nrm_params),
     * and reads them in create with sy_param_bool(&table, args->params, "flip", &flip, err). */
    .param_table = {NULL, 0},
};

sy_result sy_mediator_nrm_register(sy_error *err) { return sy_mediator_register(&nrm_class, err); }
