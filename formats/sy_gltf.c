/* sy_gltf.c — glTF 2.0 loader: file reading, GLB container validation, one validation pass over the
 * parsed document (formats/sy_gltf_shim.h gives it as plain C structs), then conversion into core
 * scene objects through the public scene API, with rollback of everything created on failure.
 *
 * This file holds the public entry points (options, the order of the load, the log); the loader's
 * modules, bottom-up (sy_gltf_internal.h): sy_gltf_errors.c, sy_gltf_validate.c,
 * sy_gltf_accessors.c, sy_gltf_materials.c, sy_gltf_meshes.c, sy_gltf_nodes.c. */
#include "sy_gltf_internal.h"

#include "sy_file.h"
#include "sy_log.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>public ------------------------------------------------------------------------------------ */

const char *const *sy_gltf_supported_extensions(void) { return gltf_supported; }

void sy_gltf_info_free(sy_gltf_info *info)
{
    if (!info) return;
    free(info->camera_nodes);
    for (uint32_t i = 0; i < info->variant_count; i++) free(info->variant_names[i]);
    free(info->variant_names);
    for (uint32_t i = 0; i < info->extensions_used_count; i++) free(info->extensions_used[i]);
    free(info->extensions_used);
    free(info->variant_uses);
    free(info->animations);
    sy_loader_warnings_free(gltf_warnings(info));
    memset(info, 0, sizeof *info);
}

static sy_gltf_options resolve_options(const sy_gltf_options *o)
{
    sy_gltf_options r = o ? *o : (sy_gltf_options){0};
    if (!r.max_file_bytes) r.max_file_bytes = (size_t)2 << 30;
    if (r.max_file_bytes > UINT32_MAX - 1u) r.max_file_bytes = UINT32_MAX - 1u; /* tinygltf takes unsigned lengths */
    if (!r.max_vertices) r.max_vertices = (size_t)1 << 28;
    if (!r.max_indices) r.max_indices = (size_t)1 << 28;
    if (!r.max_image_pixels) r.max_image_pixels = (uint64_t)1 << 26;
    if (!r.max_instances) r.max_instances = (size_t)1 << 20;
    if (!r.max_json_depth) r.max_json_depth = 64;
    if (!r.max_scene_bytes) r.max_scene_bytes = sy_budget_default_bytes();
    return r;
}

static sy_result load_doc(loader *L)
{
    const sy_gltf_doc *d = L->doc;
    sy_gltf_counts *c = &L->info->counts;
    sy_result r = SY_OK;
    c->nodes = (uint32_t)d->node_count;
    c->meshes = (uint32_t)d->mesh_count;
    c->materials = (uint32_t)d->material_count;
    c->textures = (uint32_t)d->texture_count;
    c->images = (uint32_t)d->image_count;
    c->lights = (uint32_t)d->light_count;
    c->cameras = (uint32_t)d->camera_count;
    c->animations = (uint32_t)d->animation_count;
    for (size_t m = 0; m < d->mesh_count; m++) c->primitives += (uint32_t)d->meshes[m].primitive_count;

    if (!(L->parent = gltf_xcalloc(L, d->node_count + 1, sizeof(int32_t), &r))) return r;
    for (size_t i = 0; i < d->node_count; i++) L->parent[i] = -1;
    if ((r = gltf_validate_doc(L))) return r;

    if (!(L->reached = gltf_xcalloc(L, d->node_count + 1, 1, &r)) ||
        !(L->materials = gltf_xcalloc(L, d->material_count + 1, sizeof(sy_material), &r)) ||
        !(L->meshes = gltf_xcalloc(L, d->mesh_count + 1, sizeof(sy_mesh), &r)) ||
        !(L->mesh_triangles = gltf_xcalloc(L, d->mesh_count + 1, sizeof(uint32_t), &r)) ||
        !(L->mesh_joints = gltf_xcalloc(L, d->mesh_count + 1, sizeof(uint32_t), &r)) ||
        !(L->cameras = gltf_xcalloc(L, d->camera_count + 1, sizeof(sy_camera), &r)) ||
        !(L->lights = gltf_xcalloc(L, d->light_count + 1, sizeof(sy_light), &r)) ||
        !(L->nodes = gltf_xcalloc(L, d->node_count + 1, sizeof(sy_node), &r)) ||
        !(L->textures = gltf_xcalloc(L, d->texture_count * 2 + 2, sizeof(sy_texture), &r)) ||
        !(L->image_blobs = gltf_xcalloc(L, d->image_count + 1, sizeof(sy_blob *), &r)))
        return r;

    if ((r = gltf_charge_meshes(L))) return r;
    if (d->variant_count) {
        if (!(L->info->variant_names = gltf_xcalloc(L, d->variant_count, sizeof(char *), &r)) ||
            !(L->info->variant_uses = gltf_xcalloc(L, d->variant_use_count + 1, sizeof(sy_gltf_variant_use), &r)))
            return r;
        for (size_t i = 0; i < d->variant_count; i++) {
            if (!(L->info->variant_names[i] = strdup(d->variant_names[i])))
                return gltf_fail(L, SY_ERR_OUT_OF_MEMORY, "KHR_materials_variants: out of memory");
            L->info->variant_count = (uint32_t)i + 1;
        }
    }
    if (d->extensions_used_count) {
        if (!(L->info->extensions_used = gltf_xcalloc(L, d->extensions_used_count, sizeof(char *), &r))) return r;
        for (size_t i = 0; i < d->extensions_used_count; i++) {
            if (!(L->info->extensions_used[i] = strdup(d->extensions_used[i])))
                return gltf_fail(L, SY_ERR_OUT_OF_MEMORY, "extensionsUsed: out of memory");
            L->info->extensions_used_count = (uint32_t)i + 1;
        }
    }
    /* dependency order: textures (on demand) + materials, meshes, lights, cameras, nodes */
    for (size_t i = 0; i < d->material_count; i++)
        if ((r = gltf_create_material(L, i))) return r;
    for (size_t i = 0; i < d->mesh_count; i++) {
        if ((r = gltf_create_mesh(L, i))) return r;
        if (c->triangles > UINT32_MAX - L->mesh_triangles[i]) return gltf_fail(L, SY_ERR_LIMIT, "too many triangles");
        c->triangles += L->mesh_triangles[i];
    }
    for (size_t i = 0; i < d->light_count; i++)
        if ((r = gltf_create_light(L, i))) return r;
    for (size_t i = 0; i < d->camera_count; i++)
        if ((r = gltf_create_camera(L, i))) return r;

    /* which glTF scene */
    int32_t si = -1;
    if (L->opt.use_scene_index) {
        if (L->opt.scene_index < 0 || (size_t)L->opt.scene_index >= d->scene_count)
            return gltf_fail(L, SY_ERR_NOT_FOUND, "scene %d requested, the file has %zu scenes", (int)L->opt.scene_index, d->scene_count);
        si = L->opt.scene_index;
    } else if (d->default_scene >= 0) {
        si = d->default_scene;
    } else if (d->scene_count > 0) {
        si = 0;
    }
    L->info->scene_index = si;
    char name[64];
    if (si >= 0) {
        const sy_gltf_shim_scene *sc = &d->scenes[si];
        snprintf(name, sizeof name, "scene %d", (int)si);
        if ((r = gltf_create_nodes(L, sc->nodes, sc->node_count, gltf_nonempty(sc->name) ? sc->name : name))) return r;
        return gltf_create_animations(L);
    }
    int32_t *roots = gltf_xcalloc(L, d->node_count + 1, sizeof(int32_t), &r);
    if (!roots) return r;
    size_t nr = 0;
    for (size_t i = 0; i < d->node_count; i++)
        if (L->parent[i] == -1) roots[nr++] = (int32_t)i;
    r = gltf_create_nodes(L, roots, nr, "scene");
    free(roots);
    return r ? r : gltf_create_animations(L);
}

/* Shared by sy_gltf_load (mem NULL: reads path; external files relative to its directory) and
 * sy_gltf_load_memory (mem borrowed, path only names it in messages, base_dir given). */
/* What a successful load skipped or repaired is on the log (sy_log.h; module "gltf", item the file):
 * the stored warnings, then how many more there were (sy_loader_warnings_log). They stay in
 * info->warnings as well. */
static sy_result load_common(const char *path, const void *mem, size_t mem_size, const char *base_dir, sy_scene *scene,
                             const sy_gltf_options *opts, sy_gltf_info *info_out, sy_error *err)
{
    sy_gltf_info local_info;
    sy_gltf_info *info = info_out ? info_out : &local_info;
    memset(info, 0, sizeof *info);
    info->scene_index = -1;

    loader L;
    memset(&L, 0, sizeof L);
    L.path = path;
    L.scene = scene;
    L.opt = resolve_options(opts);
    L.info = info;
    L.budget = sy_budget_make(path, L.opt.max_scene_bytes);

    void *bytes = NULL;
    const void *input = NULL;
    size_t size = 0;
    sy_gltf_doc *doc = NULL;
    sy_result r = sy_loader_input(path, mem, mem_size, L.opt.max_file_bytes, &bytes, &input, &size, &L.err);
    if (r) goto out;

    const uint8_t *b = input, *json = b;
    size_t json_len = size;
    size_t plen = strlen(path);
    bool ext_glb = plen >= 4 && (!strcmp(path + plen - 4, ".glb") || !strcmp(path + plen - 4, ".GLB"));
    bool binary = size >= 4 && memcmp(b, "glTF", 4) == 0;
    if (binary || ext_glb) {
        json = NULL;
        if ((r = gltf_check_glb(&L, b, size, &json, &json_len))) goto out;
        binary = true;
    }
    if (json_len == 0) {
        r = gltf_fail(&L, SY_ERR_PARSE, "empty file");
        goto out;
    }
    if ((r = gltf_check_json_depth(&L, json, json_len))) goto out;

    /* external files are relative to the file's directory */
    const char *slash = strrchr(path, '/');
    size_t dlen = mem ? strlen(base_dir) : slash ? (size_t)(slash - path) + 1 : 0;
    char *base = malloc(dlen + 1);
    if (!base) {
        r = gltf_fail(&L, SY_ERR_OUT_OF_MEMORY, "out of memory");
        goto out;
    }
    memcpy(base, mem ? base_dir : path, dlen);
    base[dlen] = '\0';
    sy_gltf_shim_limits lim = {L.opt.max_file_bytes, L.opt.max_image_pixels, L.opt.allowed_roots,
                               L.opt.allowed_root_count, gltf_supported, L.budget.limit, L.budget.limit};
    r = sy_gltf_shim_parse(b, size, binary, base, &lim, &doc, &L.err);
    free(base);
    /* the document holds its own copy of every buffer: the file's bytes go before the scene's blobs
     * are made (a 10^7-triangle .glb peaks at one copy of it less) */
    free(bytes);
    bytes = NULL;
    if (r) {
        sy_error_prefix(&L.err, "%s: %s", path, r == SY_ERR_PARSE ? "invalid glTF" : "cannot load");
        goto out;
    }
    if (doc->warnings[0]) gltf_warn(&L, "tinygltf: %s", doc->warnings);
    L.doc = doc;
    for (size_t i = 0; i < doc->image_count && r == SY_OK; i++) /* within the budget: the shim checked it */
        if (doc->images[i].pixels)
            r = sy_budget_charge(&L.budget, (uint64_t)doc->images[i].width * doc->images[i].height,
                                 doc->images[i].channels, &L.err, "images[%zu]", i);
    if (r) goto out;
    r = load_doc(&L);
    if (r) gltf_rollback(&L);

out:
    if (L.image_blobs)
        for (size_t i = 0; i < doc->image_count; i++) sy_blob_release(L.image_blobs[i]);
    free(L.image_blobs);
    free(L.materials);
    free(L.meshes);
    free(L.mesh_triangles);
    free(L.mesh_joints);
    free(L.cameras);
    free(L.lights);
    free(L.nodes);
    free(L.textures);
    free(L.parent);
    free(L.reached);
    free(L.objs);
    sy_gltf_shim_free(doc);
    free(bytes);
    if (r) {
        sy_gltf_info_free(info);
        info->scene_index = -1;
        if (err) *err = L.err;
        return r;
    }
    sy_loader_warnings_log(gltf_warnings(info), "gltf", path, path);
    if (!info_out) sy_gltf_info_free(&local_info);
    return SY_OK;
}

sy_result sy_gltf_load(const char *path, sy_scene *scene, const sy_gltf_options *opts, sy_gltf_info *info_out,
                       sy_error *err)
{
    if (!path || !scene) {
        if (info_out) {
            memset(info_out, 0, sizeof *info_out);
            info_out->scene_index = -1;
        }
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_gltf_load: path and scene are required");
    }
    return load_common(path, NULL, 0, NULL, scene, opts, info_out, err);
}

sy_result sy_gltf_load_memory(const void *data, size_t size, const char *name, const char *base_dir, sy_scene *scene,
                              const sy_gltf_options *opts, sy_gltf_info *info_out, sy_error *err)
{
    if (!data || !name || !base_dir || !scene) {
        if (info_out) {
            memset(info_out, 0, sizeof *info_out);
            info_out->scene_index = -1;
        }
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_gltf_load_memory: data, name, base_dir and scene are required");
    }
    return load_common(name, data, size, base_dir, scene, opts, info_out, err);
}

sy_result sy_gltf_find_camera(const sy_scene *scene, const sy_gltf_info *info, const char *selector, sy_node *out,
                              sy_error *err)
{
    if (!info || !selector || !out) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_gltf_find_camera: missing argument");
    char *end = NULL;
    errno = 0;
    unsigned long idx = strtoul(selector, &end, 10);
    if (selector[0] >= '0' && selector[0] <= '9' && end && *end == '\0' && errno == 0) {
        if (idx < info->camera_node_count) {
            *out = info->camera_nodes[idx];
            return SY_OK;
        }
        return sy_error_set(err, SY_ERR_NOT_FOUND, "camera index %lu out of range (%u cameras)", idx,
                            (unsigned)info->camera_node_count);
    }
    char list[256] = "";
    for (uint32_t i = 0; i < info->camera_node_count; i++) {
        const sy_node_data *nd = sy_node_get(scene, info->camera_nodes[i]);
        const sy_camera_data *cd = nd ? sy_camera_get(scene, nd->camera) : NULL;
        if ((nd && nd->name && !strcmp(nd->name, selector)) || (cd && cd->name && !strcmp(cd->name, selector))) {
            *out = info->camera_nodes[i];
            return SY_OK;
        }
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s%u:%s", i ? ", " : "", (unsigned)i,
                 nd && nd->name ? nd->name : (cd && cd->name ? cd->name : "(unnamed)"));
    }
    return sy_error_set(err, SY_ERR_NOT_FOUND, "no camera named '%s' (available: %s)", selector,
                        info->camera_node_count ? list : "none");
}
