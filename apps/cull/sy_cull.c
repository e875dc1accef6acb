/* sy_cull.c — the remote culling service (see sy_cull.h): an index of the objects under the root
 * (rebuilt when the scene committed since), coverage on a context of the back-end that offers it
 * (SY_CAP_COVERAGE, sy_context_coverage), the ranking and budget cut, the JSON query / answer
 * (cJSON) and objects as GLB (sy_gltf_write). */
#include "sy_cull.h"

#include "sy_gltf_write.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>index */
typedef struct cull_obj {
    uint32_t id;
    uint32_t first, count; /* placements [first, first + count) of the sorted placement array */
    uint64_t triangles;
} cull_obj;

struct sy_culler {
    sy_scene *scene;
    sy_node root;
    sy_context *ctx; /* own reference */
    uint64_t max_coverage_pixels;
    uint64_t index_frame; /* scene frame the index was built for */
    bool indexed;
    sy_gltf_placement *placements; /* sorted by node id (stable: path order within a node) */
    uint32_t placement_count;
    cull_obj *objs; /* sorted by id */
    uint32_t obj_count;
    uint64_t total_triangles;
    sy_bounds bounds; /* of every placement */
    /* poses (sy_culler_poses_json): the placements as the culler was created (the loaded pose),
     * sorted as placements; the ids of the objects that have left it since (sorted) */
    sy_gltf_placement *base;
    uint32_t base_count;
    uint32_t *moved;
    uint32_t moved_count, moved_cap;
};

static uint64_t mesh_triangles(const sy_scene *s, sy_mesh m)
{
    const sy_mesh_data *d = sy_mesh_get(s, m);
    uint64_t t = 0;
    for (uint32_t i = 0; d && i < d->primitives.count; ++i) t += sy_primitive_triangle_count(&d->primitives.items[i]);
    return t;
}

static sy_result index_build(sy_culler *c, sy_error *err)
{
    uint64_t frame = sy_scene_frame(c->scene);
    if (c->indexed && frame == c->index_frame) return SY_OK;
    sy_gltf_placement *p = NULL, *sorted = NULL;
    uint32_t n = 0;
    sy_result r = sy_gltf_placements_collect(c->scene, c->root, &p, &n, err);
    if (r != SY_OK) {
        sy_error_prefix(err, "cull");
        return r;
    }
    sy_u32_pair *ord = malloc(sizeof *ord * (n ? n : 1));
    sorted = malloc(sizeof *sorted * (n ? n : 1));
    cull_obj *objs = malloc(sizeof *objs * (n ? n : 1));
    if (!ord || !sorted || !objs) {
        free(p), free(ord), free(sorted), free(objs);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cull: out of memory for %u placements", n);
    }
    for (uint32_t i = 0; i < n; ++i) ord[i] = (sy_u32_pair){p[i].node_id, i}; /* by node, then placement */
    qsort(ord, n, sizeof *ord, sy_u32_pair_cmp);
    uint32_t m = 0;
    uint64_t total = 0;
    sy_bounds all = sy_bounds_empty();
    for (uint32_t i = 0; i < n; ++i) {
        sorted[i] = p[ord[i].value];
        sy_bounds mb, wb;
        sy_error ignored = {0};
        if (sy_mesh_bounds(c->scene, sorted[i].mesh, &mb, &ignored) == SY_OK) {
            wb = sy_bounds_transform(&mb, &sorted[i].world);
            sy_bounds_add_bounds(&all, &wb);
        }
        uint64_t t = mesh_triangles(c->scene, sorted[i].mesh);
        if (m == 0 || objs[m - 1].id != sorted[i].node_id) objs[m++] = (cull_obj){sorted[i].node_id, i, 0, 0};
        objs[m - 1].count++;
        objs[m - 1].triangles += t;
        total += t;
    }
    free(p), free(ord);
    free(c->placements), free(c->objs);
    c->placements = sorted, c->placement_count = n, c->objs = objs, c->obj_count = m, c->total_triangles = total;
    c->bounds = all;
    c->index_frame = frame, c->indexed = true;
    return SY_OK;
}

static const cull_obj *obj_find(const sy_culler *c, uint32_t id)
{
    uint32_t lo = 0, hi = c->obj_count;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (c->objs[mid].id < id) lo = mid + 1;
        else hi = mid;
    }
    return lo < c->obj_count && c->objs[lo].id == id ? &c->objs[lo] : NULL;
}

/* >>life cycle */
sy_result sy_culler_create(sy_scene *scene, sy_context_pool *pool, sy_node root, const sy_culler_options *opts,
                           sy_culler **out, sy_error *err)
{
    *out = NULL;
    if (!scene || !sy_node_get(scene, root))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: the root node %u is not a node of the scene", root.id);
    sy_culler *c = calloc(1, sizeof *c);
    if (!c) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cull: out of memory");
    c->scene = scene, c->root = root;
    c->max_coverage_pixels = opts && opts->max_coverage_pixels ? opts->max_coverage_pixels : (1u << 20);
    /* the first registered class that counts per-node coverage (the Embree back-ends' "coverage") */
    const sy_mediator_class *cls = sy_mediator_with_caps(SY_CAP_COVERAGE);
    sy_result r;
    if (!cls) {
        r = sy_error_set(err, SY_ERR_UNSUPPORTED, "cull: no registered back-end counts per-node coverage (SY_CAP_COVERAGE)");
    } else if (pool) {
        r = sy_context_pool_get(pool, scene, cls->name, NULL, root.id, &c->ctx, err);
        if (r == SY_OK) sy_context_retain(c->ctx);
    } else {
        r = sy_context_create(scene, cls->name, NULL, root.id, &c->ctx, err);
    }
    if (r == SY_OK) r = index_build(c, err);
    if (r == SY_OK && !(c->base = malloc(sizeof *c->base * (c->placement_count ? c->placement_count : 1))))
        r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cull: out of memory for %u placements", c->placement_count);
    if (r != SY_OK) {
        sy_culler_destroy(c);
        return r;
    }
    memcpy(c->base, c->placements, sizeof *c->base * c->placement_count);
    c->base_count = c->placement_count;
    *out = c;
    return SY_OK;
}

void sy_culler_destroy(sy_culler *c)
{
    if (!c) return;
    if (c->ctx) sy_context_release(c->ctx);
    free(c->placements), free(c->objs), free(c->base), free(c->moved), free(c);
}

/* >>views */
sy_result sy_cull_view_check(const sy_cull_view *v, sy_error *err)
{
    static const char *const axes[] = {"x", "y", "z", "w"};
    /* the core's one bound on coordinates (core/sy_math.h): the back-ends' rays stay valid */
    for (int i = 0; i < 3; ++i)
        if (!(fabs(v->position[i]) <= (double)SY_COORD_MAX))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: position.%s must be a finite number at most %g in size (SY_COORD_MAX)",
                                axes[i], (double)SY_COORD_MAX);
    double q2 = 0;
    for (int i = 0; i < 4; ++i) {
        if (!isfinite(v->orientation[i]) || fabs(v->orientation[i]) > 1e6)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: orientation.%s must be a finite number", axes[i]);
        q2 += v->orientation[i] * v->orientation[i];
    }
    if (!(q2 > 1e-12)) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: orientation must be a nonzero quaternion [x,y,z,w]");
    if (!isfinite(v->fov_degrees) || !(v->fov_degrees >= 0.01 && v->fov_degrees <= 179))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: fov must be a vertical field of view in degrees, 0.01..179");
    if (v->width < 1 || v->width > SY_CULL_MAX_SIZE)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: width must be 1..%u pixels", SY_CULL_MAX_SIZE);
    if (v->height < 1 || v->height > SY_CULL_MAX_SIZE)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: height must be 1..%u pixels", SY_CULL_MAX_SIZE);
    return SY_OK;
}

sy_camera_view sy_cull_view_camera(const sy_cull_view *v)
{
    double l = sqrt(v->orientation[0] * v->orientation[0] + v->orientation[1] * v->orientation[1] +
                    v->orientation[2] * v->orientation[2] + v->orientation[3] * v->orientation[3]);
    float t[3] = {(float)v->position[0], (float)v->position[1], (float)v->position[2]};
    float q[4] = {(float)(v->orientation[0] / l), (float)(v->orientation[1] / l), (float)(v->orientation[2] / l),
                  (float)(v->orientation[3] / l)};
    float s[3] = {1, 1, 1};
    /* no near clip: the view carries none, and a fixed one would cut small scenes (a model in
     * millimetres seen from a centimetre); the rasterizer picks its near plane from the scene */
    sy_camera_view cv = {.camera_to_world = sy_mat4_from_trs(t, q, s), .projection = SY_PROJECTION_PERSPECTIVE,
                         .znear = 0.0f, .zfar = 0};
    double th = tan(0.5 * v->fov_degrees * 3.14159265358979323846 / 180.0), aspect = (double)v->width / v->height;
    cv.window[0] = (float)(-th * aspect), cv.window[1] = (float)(th * aspect);
    cv.window[2] = (float)-th, cv.window[3] = (float)th;
    return cv;
}

/* >>query */
void sy_cull_result_free(sy_cull_result *r)
{
    if (!r) return;
    free(r->objects);
    memset(r, 0, sizeof *r);
}

sy_result sy_culler_query(sy_culler *c, const sy_cull_view *v, uint64_t budget, sy_cull_result *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    sy_result r = sy_cull_view_check(v, err);
    if (r != SY_OK) return r;
    if (budget > SY_CULL_MAX_BUDGET)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: budget must be 0..%llu triangles", (unsigned long long)SY_CULL_MAX_BUDGET);
    if ((r = sy_context_sync(c->ctx, err)) != SY_OK) return r;
    if ((r = index_build(c, err)) != SY_OK) return r;
    uint32_t cw = v->width, ch = v->height;
    double px = (double)cw * ch;
    if (px > (double)c->max_coverage_pixels) {
        double f = sqrt((double)c->max_coverage_pixels / px);
        cw = (uint32_t)fmax(1.0, floor(cw * f)), ch = (uint32_t)fmax(1.0, floor(ch * f));
    }
    sy_camera_view cam = sy_cull_view_camera(v);
    sy_coverage_entry *e = NULL;
    uint32_t n = 0;
    if ((r = sy_context_coverage(c->ctx, &cam, cw, ch, &e, &n, err)) != SY_OK) {
        sy_error_prefix(err, "cull");
        return r;
    }
    out->objects = malloc(sizeof *out->objects * (n ? n : 1));
    if (!out->objects) {
        free(e);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cull: out of memory for %u objects", n);
    }
    /* entries come most pixels first, ties by node id: keep what fits */
    for (uint32_t i = 0; i < n; ++i) {
        const cull_obj *o = obj_find(c, e[i].node_id);
        if (!o) continue; /* not an object of the index (cannot happen after a sync; be safe) */
        out->visible_objects++;
        out->visible_triangles += o->triangles;
        if (o->triangles > budget - out->triangles) continue;
        out->objects[out->count++] = (sy_cull_object){o->id, e[i].pixels, o->triangles};
        out->triangles += o->triangles;
    }
    free(e);
    out->total_objects = c->obj_count, out->total_triangles = c->total_triangles;
    out->coverage_width = cw, out->coverage_height = ch;
    out->bounds = c->bounds;
    return SY_OK;
}

/* >>JSON */
static sy_result field_number(const cJSON *item, const char *name, double *out, sy_error *err)
{
    if (!cJSON_IsNumber(item)) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: %s must be a number", name);
    *out = item->valuedouble;
    if (!isfinite(*out)) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: %s must be finite", name);
    return SY_OK;
}

static sy_result field_array(const cJSON *item, const char *name, int count, double *out, sy_error *err)
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != count)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: %s must be an array of %d numbers", name, count);
    int i = 0;
    for (const cJSON *e = item->child; e; e = e->next, ++i) {
        char nm[32];
        snprintf(nm, sizeof nm, "%s[%d]", name, i);
        sy_result r = field_number(e, nm, &out[i], err);
        if (r != SY_OK) return r;
    }
    return SY_OK;
}

static sy_result field_uint(const cJSON *item, const char *name, double lo, double hi, double *out, sy_error *err)
{
    sy_result r = field_number(item, name, out, err);
    if (r != SY_OK) return r;
    if (*out != floor(*out) || *out < lo || *out > hi)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: %s must be an integer %.0f..%.0f", name, lo, hi);
    return SY_OK;
}

sy_result sy_cull_parse_query(const char *body, size_t len, sy_cull_view *view_out, uint64_t *budget_out, sy_error *err)
{
    memset(view_out, 0, sizeof *view_out);
    *budget_out = 0;
    if (!body && len) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: no body");
    if (len > SY_CULL_MAX_BODY)
        return sy_error_set(err, SY_ERR_LIMIT, "cull: the query body has %zu bytes, more than the limit %u", len, SY_CULL_MAX_BODY);
    if (len == 0) return sy_error_set(err, SY_ERR_PARSE, "cull: the query body is empty (a JSON object is expected)");
    const char *end = NULL;
    cJSON *doc = cJSON_ParseWithLengthOpts(body, len, &end, 0);
    if (!doc) {
        size_t at = end && end >= body && end <= body + len ? (size_t)(end - body) : 0;
        return sy_error_set(err, SY_ERR_PARSE, "cull: the query is not valid JSON (at byte %zu)", at);
    }
    for (const char *p = end; p && p < body + len; ++p)
        if (*p != ' ' && *p != '\t' && *p != '\r' && *p != '\n') {
            cJSON_Delete(doc);
            return sy_error_set(err, SY_ERR_PARSE, "cull: text after the JSON object (at byte %zu)", (size_t)(p - body));
        }
    sy_result r = SY_OK;
    if (!cJSON_IsObject(doc)) r = sy_error_set(err, SY_ERR_PARSE, "cull: the query must be a JSON object");
    static const char *const names[] = {"position", "orientation", "fov", "width", "height", "budget"};
    const cJSON *f[6] = {0};
    for (const cJSON *e = r == SY_OK ? doc->child : NULL; e && r == SY_OK; e = e->next) {
        int k = 0;
        while (k < 6 && (!e->string || strcmp(e->string, names[k]) != 0)) k++;
        if (k == 6) {
            char key[48];
            snprintf(key, sizeof key, "%.40s", e->string ? e->string : "");
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                             "cull: unknown field '%s' (fields: position, orientation, fov, width, height, budget)", key);
        } else if (f[k]) {
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: field '%s' given twice", names[k]);
        } else {
            f[k] = e;
        }
    }
    for (int k = 0; k < 6 && r == SY_OK; ++k)
        if (!f[k]) r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: field '%s' is missing", names[k]);
    double w = 0, h = 0, b = 0;
    if (r == SY_OK) r = field_array(f[0], "position", 3, view_out->position, err);
    if (r == SY_OK) r = field_array(f[1], "orientation", 4, view_out->orientation, err);
    if (r == SY_OK) r = field_number(f[2], "fov", &view_out->fov_degrees, err);
    if (r == SY_OK) r = field_uint(f[3], "width", 1, SY_CULL_MAX_SIZE, &w, err);
    if (r == SY_OK) r = field_uint(f[4], "height", 1, SY_CULL_MAX_SIZE, &h, err);
    if (r == SY_OK) r = field_uint(f[5], "budget", 0, (double)SY_CULL_MAX_BUDGET, &b, err);
    cJSON_Delete(doc);
    if (r != SY_OK) return r;
    view_out->width = (uint32_t)w, view_out->height = (uint32_t)h;
    *budget_out = (uint64_t)b;
    return sy_cull_view_check(view_out, err);
}

static cJSON *jadd(cJSON *parent, const char *key, cJSON *item)
{
    if (!item) return NULL;
    if (key) cJSON_AddItemToObject(parent, key, item);
    else cJSON_AddItemToArray(parent, item);
    return item;
}

sy_result sy_culler_query_json(sy_culler *c, const char *body, size_t len, char **json_out, sy_error *err)
{
    *json_out = NULL;
    sy_cull_view v;
    uint64_t budget;
    sy_result r = sy_cull_parse_query(body, len, &v, &budget, err);
    if (r != SY_OK) return r;
    sy_cull_result res;
    if ((r = sy_culler_query(c, &v, budget, &res, err)) != SY_OK) return r;
    cJSON *doc = cJSON_CreateObject(), *objs = doc ? jadd(doc, "objects", cJSON_CreateArray()) : NULL;
    bool ok = objs != NULL;
    for (uint32_t i = 0; ok && i < res.count; ++i) {
        cJSON *o = jadd(objs, NULL, cJSON_CreateObject());
        ok = o && jadd(o, "id", cJSON_CreateNumber(res.objects[i].id)) &&
             jadd(o, "pixels", cJSON_CreateNumber(res.objects[i].pixels)) &&
             jadd(o, "triangles", cJSON_CreateNumber((double)res.objects[i].triangles));
    }
    cJSON *cov = ok ? jadd(doc, "coverage", cJSON_CreateArray()) : NULL;
    ok = ok && cov && jadd(cov, NULL, cJSON_CreateNumber(res.coverage_width)) &&
         jadd(cov, NULL, cJSON_CreateNumber(res.coverage_height)) &&
         jadd(doc, "triangles", cJSON_CreateNumber((double)res.triangles)) &&
         jadd(doc, "budget", cJSON_CreateNumber((double)budget)) &&
         jadd(doc, "visible_objects", cJSON_CreateNumber(res.visible_objects)) &&
         jadd(doc, "visible_triangles", cJSON_CreateNumber((double)res.visible_triangles)) &&
         jadd(doc, "total_objects", cJSON_CreateNumber(res.total_objects)) &&
         jadd(doc, "total_triangles", cJSON_CreateNumber((double)res.total_triangles));
    if (ok && !sy_bounds_is_empty(&res.bounds)) {
        cJSON *bo = jadd(doc, "bounds", cJSON_CreateObject());
        const float *mm[2] = {res.bounds.min, res.bounds.max};
        static const char *const names[2] = {"min", "max"};
        for (int k = 0; ok && k < 2; ++k) {
            cJSON *a = bo ? jadd(bo, names[k], cJSON_CreateArray()) : NULL;
            for (int i = 0; a && i < 3; ++i) ok = jadd(a, NULL, cJSON_CreateNumber(mm[k][i])) != NULL;
            ok = ok && a;
        }
    }
    char *text = ok ? cJSON_PrintUnformatted(doc) : NULL;
    cJSON_Delete(doc);
    sy_cull_result_free(&res);
    if (!text) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cull: out of memory writing the answer");
    *json_out = text;
    return SY_OK;
}

/* >>poses */
/* Whether object o's placements are those of the loaded pose (c->base: the same count, the same
 * world matrices). */
static bool at_base(const sy_culler *c, const cull_obj *o)
{
    uint32_t lo = 0, hi = c->base_count;
    while (lo < hi) { /* the first base placement of o's node */
        uint32_t mid = lo + (hi - lo) / 2;
        if (c->base[mid].node_id < o->id) lo = mid + 1;
        else hi = mid;
    }
    uint32_t n = 0;
    while (lo + n < c->base_count && c->base[lo + n].node_id == o->id) ++n;
    if (n != o->count) return false;
    for (uint32_t k = 0; k < n; ++k)
        if (memcmp(c->base[lo + k].world.m, c->placements[o->first + k].world.m, sizeof c->base[0].world.m)) return false;
    return true;
}

/* Adds id to the sorted set c->moved (once); false when out of memory. */
static bool moved_add(sy_culler *c, uint32_t id)
{
    uint32_t lo = 0, hi = c->moved_count;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (c->moved[mid] < id) lo = mid + 1;
        else hi = mid;
    }
    if (lo < c->moved_count && c->moved[lo] == id) return true;
    if (c->moved_count == c->moved_cap) {
        uint32_t cap = c->moved_cap ? c->moved_cap * 2 : 16;
        uint32_t *m = realloc(c->moved, sizeof *m * cap);
        if (!m) return false;
        c->moved = m, c->moved_cap = cap;
    }
    memmove(c->moved + lo + 1, c->moved + lo, sizeof *c->moved * (c->moved_count - lo));
    c->moved[lo] = id;
    c->moved_count++;
    return true;
}

static bool moved_has(const sy_culler *c, uint32_t id)
{
    uint32_t lo = 0, hi = c->moved_count;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (c->moved[mid] < id) lo = mid + 1;
        else hi = mid;
    }
    return lo < c->moved_count && c->moved[lo] == id;
}

sy_result sy_culler_poses_json(sy_culler *c, char **json_out, sy_error *err)
{
    *json_out = NULL;
    sy_result r = index_build(c, err);
    if (r != SY_OK) return r;
    cJSON *doc = cJSON_CreateObject(), *objs = doc ? jadd(doc, "objects", cJSON_CreateArray()) : NULL;
    bool ok = objs && jadd(doc, "frame", cJSON_CreateNumber((double)c->index_frame));
    for (uint32_t i = 0; ok && i < c->obj_count; ++i) {
        const cull_obj *o = &c->objs[i];
        if (!moved_has(c, o->id)) {
            if (at_base(c, o)) continue;
            if (!moved_add(c, o->id)) ok = false;
        }
        cJSON *jo = ok ? jadd(objs, NULL, cJSON_CreateObject()) : NULL;
        cJSON *ms = jo && jadd(jo, "id", cJSON_CreateNumber(o->id)) ? jadd(jo, "matrices", cJSON_CreateArray()) : NULL;
        ok = ms != NULL;
        for (uint32_t k = 0; ok && k < o->count; ++k) {
            cJSON *m = jadd(ms, NULL, cJSON_CreateArray());
            for (int e = 0; m && e < 16; ++e) m = jadd(m, NULL, cJSON_CreateNumber(c->placements[o->first + k].world.m[e])) ? m : NULL;
            ok = m != NULL;
        }
    }
    char *text = ok ? cJSON_PrintUnformatted(doc) : NULL;
    cJSON_Delete(doc);
    if (!text) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cull: out of memory writing the poses");
    *json_out = text;
    return SY_OK;
}

/* >>objects */
sy_result sy_cull_parse_id(const char *text, size_t len, uint32_t *id_out, sy_error *err)
{
    *id_out = 0;
    uint64_t v = 0;
    if (!text || len == 0 || len > 10) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: an object id is 1 to 10 decimal digits");
    for (size_t i = 0; i < len; ++i) {
        if (text[i] < '0' || text[i] > '9')
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: an object id is decimal digits only");
        v = v * 10 + (uint64_t)(text[i] - '0');
    }
    if (v == 0 || v > UINT32_MAX) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cull: object id out of range 1..4294967295");
    *id_out = (uint32_t)v;
    return SY_OK;
}

sy_result sy_culler_object_triangles(sy_culler *c, uint32_t id, uint64_t *triangles_out, sy_error *err)
{
    *triangles_out = 0;
    sy_result r = index_build(c, err);
    if (r != SY_OK) return r;
    const cull_obj *o = obj_find(c, id);
    if (!o) return sy_error_set(err, SY_ERR_NOT_FOUND, "cull: no object %u (ids are those /api/cull lists)", id);
    *triangles_out = o->triangles;
    return SY_OK;
}

sy_result sy_culler_object_glb(sy_culler *c, uint32_t id, uint8_t **glb_out, size_t *len_out, sy_error *err)
{
    *glb_out = NULL;
    *len_out = 0;
    sy_result r = index_build(c, err);
    if (r != SY_OK) return r;
    const cull_obj *o = obj_find(c, id);
    if (!o) return sy_error_set(err, SY_ERR_NOT_FOUND, "cull: no object %u (ids are those /api/cull lists)", id);
    /* the materials in full with their textures, halved to SY_CULL_TEXTURE_MAX_SIDE at most: the
     * page draws a textured model as the rasterizer does */
    sy_gltf_write_options wo = {.generator = "Switchyard culling service", .textures = true,
                                .texture_max_side = SY_CULL_TEXTURE_MAX_SIDE};
    r = sy_gltf_write_placements(c->scene, c->placements + o->first, o->count, &wo, glb_out, len_out, err);
    if (r != SY_OK) sy_error_prefix(err, "cull: object %u", id);
    return r;
}
