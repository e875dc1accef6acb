/* sy_gltf_errors.c — the glTF loader's bookkeeping: errors (named after the file and the place; the
 * failure and warning macros gltf_fail / gltf_warn of sy_gltf_internal.h are sy_loader_log.h's
 * forms, warnings stored in sy_gltf_info), the objects it creates (tracked, so that a failed load destroys
 * them again: rollback) and overflow-checked allocation. Every other module of the loader builds on
 * this file (sy_gltf_internal.h). */
#include "sy_gltf_internal.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>errors ------------------------------------------------------------------------------------ */

/* Adds context to an error that a core call left in L->err. */
sy_result gltf_context(loader *L, sy_result r, const char *what)
{
    sy_error_prefix(&L->err, "%s: %s", L->path, what);
    return r;
}

sy_result gltf_create(loader *L, sy_object_type type, const char *name, const char *where, uint32_t *id)
{
    sy_result r = sy_object_create(L->scene, type, name, id, &L->err);
    if (r != SY_OK) return gltf_context(L, r, where);
    if (!sy_array_reserve(&L->objs, L->obj_count, &L->obj_cap, sizeof *L->objs, 64)) {
        sy_object_destroy(L->scene, type, *id, NULL);
        return gltf_fail(L, SY_ERR_OUT_OF_MEMORY, "out of memory");
    }
    L->objs[L->obj_count++] = (created_obj){(uint32_t)type, *id};
    return SY_OK;
}

void gltf_rollback(loader *L)
{
    for (size_t i = L->obj_count; i-- > 0;)
        sy_object_destroy(L->scene, (sy_object_type)L->objs[i].type, L->objs[i].id, NULL);
    L->obj_count = 0;
}

void *gltf_xcalloc(loader *L, size_t n, size_t size, sy_result *r)
{
    size_t bytes;
    if (!sy_size_mul(n, size, &bytes)) {
        *r = gltf_fail(L, SY_ERR_LIMIT, "allocation of %zu x %zu bytes overflows", n, size);
        return NULL;
    }
    void *p = calloc(bytes ? bytes : 1, 1);
    if (!p) *r = gltf_fail(L, SY_ERR_OUT_OF_MEMORY, "cannot allocate %zu bytes", bytes);
    return p;
}
