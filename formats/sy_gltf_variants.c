/* sy_gltf_variants.c — KHR_materials_variants after a load: switching a loaded file's primitives to
 * the materials of one named variant (sy_gltf_select_variant, sy_gltf.h). The loader records the
 * mappings in sy_gltf_info; switching is plain scene editing, so every back-end, cluster replica and
 * web view follows through the change lists. */
#include "sy_gltf.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The variant a selector names: a name first, then a decimal index; -1 for none. */
static long find_variant(const sy_gltf_info *info, const char *sel)
{
    for (uint32_t i = 0; i < info->variant_count; i++)
        if (!strcmp(info->variant_names[i], sel)) return (long)i;
    char *end;
    long v = strtol(sel, &end, 10);
    return (*end == '\0' && end != sel && v >= 0 && v < (long)info->variant_count) ? v : -1;
}

static sy_result not_found(const sy_gltf_info *info, const char *sel, sy_error *err)
{
    if (!info->variant_count)
        return sy_error_set(err, SY_ERR_NOT_FOUND, "material variant '%s': the file has no KHR_materials_variants", sel);
    char list[512];
    size_t used = 0;
    list[0] = '\0';
    for (uint32_t i = 0; i < info->variant_count && used < sizeof list; i++) {
        int n = snprintf(list + used, sizeof list - used, "%s%u \"%s\"", i ? ", " : "", i, info->variant_names[i]);
        if (n < 0) break;
        used += (size_t)n;
    }
    return sy_error_set(err, SY_ERR_NOT_FOUND, "material variant '%s' not found (available: %s)", sel, list);
}

sy_result sy_gltf_select_variant(sy_scene *scene, const sy_gltf_info *info, const char *selector, sy_error *err)
{
    long v = -1; /* -1: the defaults */
    if (selector && selector[0] && (v = find_variant(info, selector)) < 0) return not_found(info, selector, err);
    /* the uses come grouped by mesh: one sy_mesh_set_primitives per mesh */
    for (uint32_t i = 0; i < info->variant_use_count;) {
        sy_mesh mesh = info->variant_uses[i].mesh;
        uint32_t end = i;
        while (end < info->variant_use_count && info->variant_uses[end].mesh.id == mesh.id) end++;
        const sy_mesh_data *md = sy_mesh_get(scene, mesh);
        if (!md)
            return sy_error_set(err, SY_ERR_INVALID_HANDLE, "material variant: mesh %#x of the file is gone", mesh.id);
        sy_primitive *prims = malloc((md->primitives.count ? md->primitives.count : 1) * sizeof *prims);
        if (!prims) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "material variant: out of memory");
        memcpy(prims, md->primitives.items, md->primitives.count * sizeof *prims);
        for (uint32_t k = i; k < end; k++) { /* first the defaults of every mapped primitive */
            const sy_gltf_variant_use *u = &info->variant_uses[k];
            if (u->primitive < md->primitives.count) prims[u->primitive].material = u->default_material;
        }
        for (uint32_t k = i; k < end; k++) { /* then the variant's materials */
            const sy_gltf_variant_use *u = &info->variant_uses[k];
            if (u->primitive < md->primitives.count && (long)u->variant == v) prims[u->primitive].material = u->material;
        }
        sy_result r = sy_mesh_set_primitives(scene, mesh, prims, md->primitives.count, err);
        free(prims);
        if (r != SY_OK) return r;
        i = end;
    }
    return SY_OK;
}
