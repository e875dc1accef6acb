/* sy_x3d.c — X3D (XML encoding) loader on libxml2: element tree -> sy_scene objects
 * (see sy_x3d.h for the supported nodes and the documented mappings). This file holds the public
 * entry points (options, the load's budget and limits, rollback of everything created on failure,
 * the log); the loader's modules, bottom-up (sy_x3d_internal.h): sy_x3d_fields.c (state, field
 * values, DEF / USE), sy_x3d_url.c, sy_x3d_appearance.c, sy_x3d_polygons.c, sy_x3d_geometry.c,
 * sy_x3d_lights.c, sy_x3d_nodes.c (the walk, files and Inline). */
#include "sy_x3d_internal.h"

#include "sy_log.h"

#include <libxml/parser.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>public ------------------------------------------------------------------------------------ */

void sy_x3d_info_free(sy_x3d_info *info)
{
    if (!info) return;
    sy_loader_warnings_free(x3d_warnings(info));
    free(info->camera_nodes);
    free(info->camera_fovs);
    memset(info, 0, sizeof *info);
}

/* What a successful load skipped or repaired is on the log (sy_log.h; module "x3d"): the stored
 * warnings (each names its file and line, so the item is NULL), then how many more there were
 * (sy_loader_warnings_log). They stay in info->warnings as well. */

static sy_result load_common(const char *path, const void *mem, size_t size, const char *base_dir, sy_scene *scene,
                             const sy_x3d_options *opts, sy_x3d_info *info_out, sy_error *err)
{
    sy_x3d_info local_info;
    sy_x3d_info *info = info_out ? info_out : &local_info;
    memset(info, 0, sizeof *info);
    if (!path || !scene) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_x3d_load: path and scene are required");
    loader L = {0};
    L.scene = scene;
    L.info = info;
    if (opts) L.opt = *opts;
    if (!L.opt.max_file_bytes) L.opt.max_file_bytes = (size_t)1 << 30;
    if (!L.opt.max_vertices) L.opt.max_vertices = (size_t)1 << 27;
    if (!L.opt.max_image_pixels) L.opt.max_image_pixels = (uint64_t)1 << 26;
    if (!L.opt.max_inline_depth) L.opt.max_inline_depth = 16;
    L.budget = sy_budget_make(path, L.opt.max_scene_bytes);
    L.max_values = L.opt.max_vertices > SIZE_MAX / 4 ? SIZE_MAX : L.opt.max_vertices * 4;
    L.bounds = sy_bounds_empty();
    xmlInitParser();
    L.cache = xmlHashCreate(256);
    L.inline_roots = xmlHashCreate(16);
    L.warned = xmlHashCreate(16);
    sy_result r = SY_OK;
    if (!L.cache || !L.inline_roots || !L.warned) r = sy_error_set(&L.err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    sy_node root = {0};
    char *model_dir = NULL;
    if (mem) {
        model_dir = strdup(base_dir ? base_dir : "");
    } else {
        const char *slash = strrchr(path, '/');
        size_t n = slash ? (size_t)(slash - path) + 1 : 0;
        if ((model_dir = malloc(n + 1))) {
            memcpy(model_dir, path, n);
            model_dir[n] = '\0';
        }
    }
    L.model_dir = model_dir;
    if (!model_dir && !r) r = sy_error_set(&L.err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    if (!r) r = x3d_load_file(&L, path, mem, size, base_dir, NULL, &root, NULL, NULL);
    free(model_dir);
    L.model_dir = NULL;
    if (!r && L.limit_r) {
        r = L.limit_r;
        L.err = L.limit_err;
    }
    /* USE and Inline fan-out: what the mirror and the back-ends will hold, once per path */
    if (!r) r = sy_budget_charge_placements(&L.budget, scene, root, &L.err);
    /* a message without a place (out of memory) names the file at least */
    if (r && strncmp(L.err.message, path, strlen(path)) != 0) sy_error_prefix(&L.err, "%s", path);
    if (!r) {
        x3d_finish_lights(&L);
        r = x3d_fix_light_animations(&L);
        info->root = root;
    }
    if (L.cache) xmlHashFree(L.cache, x3d_free_created);
    if (L.inline_roots) xmlHashFree(L.inline_roots, x3d_free_created);
    if (L.warned) xmlHashFree(L.warned, x3d_free_none);
    free(L.lights);
    free(L.mat_links);
    free(L.ifix);
    x3d_free_morphs(&L);
    if (r) {
        for (size_t k = L.obj_count; k-- > 0;) sy_object_destroy(scene, L.objs[k].type, L.objs[k].id, NULL);
        free(L.objs);
        if (err) *err = L.err;
        sy_x3d_info_free(info);
        return r;
    }
    free(L.objs);
    sy_loader_warnings_log(x3d_warnings(info), "x3d", NULL, path);
    if (info == &local_info) sy_x3d_info_free(info);
    return SY_OK;
}

sy_result sy_x3d_load(const char *path, sy_scene *scene, const sy_x3d_options *opts, sy_x3d_info *info_out,
                      sy_error *err)
{
    return load_common(path, NULL, 0, NULL, scene, opts, info_out, err);
}

sy_result sy_x3d_load_memory(const void *data, size_t size, const char *name, const char *base_dir,
                             sy_scene *scene, const sy_x3d_options *opts, sy_x3d_info *info_out, sy_error *err)
{
    if (!data && size) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_x3d_load_memory: no data");
    static const char empty[1] = "";
    return load_common(name ? name : "(memory)", data ? data : empty, size, base_dir, scene, opts, info_out, err);
}
