/* sy_interactive.c — the interactive view of sy view and sy web: orbit input, display-filter keys,
 * the governor's frames with the view set on the viewports, the display filter, 8-bit images (see
 * sy_interactive.h). */
#include "sy_interactive.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct sy_interactive {
    sy_governor *gov;
    bool planned;                /* a frame was planned: the fields below describe it */
    sy_mat4 view;                /* the orbit's matrix at the last plan */
    const sy_mediator_class *backend;
    uint32_t width, height;
    uint64_t filter_version;
    const sy_context *filter_ctx; /* the context the filter was last set on (borrowed from the pool) */
    uint64_t filter_applied;
    uint32_t filter_index;
    float filter_threshold;
    bool filter_enabled;
    bool temporal;         /* temporal reuse on moving frames (sy_interactive_set_temporal) */
    bool temporal_applied; /* the value last set on filter_ctx */
};

/* The "filter" parameter of the registered class with SY_CAP_FILTERS (NULL: none). */
static const sy_param_decl *filter_decl(void)
{
    for (uint32_t i = 0; i < sy_mediator_count(); ++i) {
        const sy_mediator_class *c = sy_mediator_at(i);
        const sy_param_decl *d = c && (c->caps & SY_CAP_FILTERS) ? sy_param_find(&c->param_table, "filter") : NULL;
        if (d && d->type == SY_PARAM_ENUM && d->enum_values) return d;
    }
    return NULL;
}

uint32_t sy_interactive_filter_count(void)
{
    const sy_param_decl *d = filter_decl();
    uint32_t n = 1;
    for (const char *p = d ? d->enum_values : ""; *p; ++p) n += *p == '|';
    return n;
}

const char *sy_interactive_filter_name(uint32_t index, char out[32])
{
    const sy_param_decl *d = filter_decl();
    const char *p = d ? d->enum_values : "none";
    for (index %= sy_interactive_filter_count(); index > 0 && p; --index) {
        p = strchr(p, '|');
        if (p) ++p;
    }
    size_t n = p ? strcspn(p, "|") : 0;
    snprintf(out, 32, "%.*s", (int)(n < 31 ? n : 31), p ? p : "");
    return out;
}

sy_result sy_interactive_input_init(const sy_scene *scene, sy_node root, sy_node camera, float aspect,
                                    const char *filter, float threshold, sy_interactive_input *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    uint32_t n = sy_interactive_filter_count();
    char name[32];
    if (filter) { /* the initial display filter, by name */
        while (out->filter < n && strcmp(sy_interactive_filter_name(out->filter, name), filter) != 0) out->filter++;
        if (out->filter == n) {
            char list[256] = "";
            for (uint32_t i = 0; i < n; ++i) {
                size_t l = strlen(list);
                snprintf(list + l, sizeof list - l, "%s%s", i == 0 ? "" : i + 1 == n ? " or " : ", ",
                         sy_interactive_filter_name(i, name));
            }
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "unknown filter '%s' (expected %s)", filter, list);
        }
    }
    if (!(threshold >= 0.0f) || !isfinite(threshold))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "threshold %g must be a finite value >= 0", (double)threshold);
    out->threshold = threshold > 0.0f ? threshold : 0.01f; /* the pixel filter's default t */
    sy_bounds b;
    if (sy_node_world_bounds(scene, root, &b, NULL) != SY_OK) b = sy_scene_world_bounds(scene);
    sy_mat4 world = sy_mat4_identity();
    if (camera.id) sy_node_world_matrix(scene, camera, &world, NULL);
    else world = sy_camera_view_frame_bounds(&b, aspect > 0.0f ? aspect : 1.0f).camera_to_world;
    sy_orbit_from_matrix(&world, &b, &out->orbit);
    out->home = out->orbit;
    return SY_OK;
}

void sy_interactive_drag(sy_interactive_input *in, int button, float dx, float dy)
{
    if (button == 0) sy_orbit_rotate(&in->orbit, dx, dy);
    else sy_orbit_pan(&in->orbit, dx, dy);
}

void sy_interactive_wheel(sy_interactive_input *in, float steps) { sy_orbit_zoom(&in->orbit, steps); }

bool sy_interactive_fly(sy_interactive_input *in, const float move[3], float dt)
{
    if (move[0] == 0 && move[1] == 0 && move[2] == 0) return false;
    sy_mat4 m;
    sy_orbit_matrix(&in->orbit, &m);
    float speed = in->orbit.dist * 0.8f * dt;
    for (int i = 0; i < 3; ++i)
        in->orbit.target[i] += speed * (move[0] * m.m[i] + move[2] * m.m[8 + i]) + speed * move[1] * (i == 1 ? 1.0f : 0.0f);
    return true;
}

bool sy_interactive_key(sy_interactive_input *in, int key)
{
    switch (tolower(key)) {
    case 'f': in->filter = (in->filter + 1) % sy_interactive_filter_count(); break;
    case '[':
        if (in->threshold > 1e-6f) in->threshold *= 0.5f;
        break;
    case ']':
        if (in->threshold < 1e3f) in->threshold *= 2.0f;
        break;
    case 'r': in->orbit = in->home; return true;
    default: return false;
    }
    in->filter_version++;
    return true;
}

float sy_interactive_fov(const sy_scene *scene, sy_node camera)
{
    const sy_node_data *cn = camera.id ? sy_node_get(scene, camera) : NULL;
    const sy_camera_data *cd = cn && cn->camera.id ? sy_camera_get(scene, cn->camera) : NULL;
    return cd && cd->projection == SY_PROJECTION_PERSPECTIVE ? cd->yfov : 0.0f;
}

sy_result sy_interactive_set_fov(sy_scene *scene, sy_node camera, float fov, sy_error *err)
{
    const sy_node_data *cn = camera.id ? sy_node_get(scene, camera) : NULL;
    const sy_camera_data *cd = cn && cn->camera.id ? sy_camera_get(scene, cn->camera) : NULL;
    if (!cd) return sy_error_set(err, SY_ERR_NOT_FOUND, "field of view: node %u has no camera", camera.id);
    sy_camera_data nd = *cd;
    char *name = cd->name ? strdup(cd->name) : NULL; /* the scene's copy is replaced by the set */
    nd.yfov = fov, nd.name = name;
    sy_result r = sy_camera_set(scene, cn->camera, &nd, err);
    free(name);
    return r == SY_OK ? sy_scene_commit(scene, NULL, err) : r;
}

sy_result sy_interactive_backend_index(const char *name, uint32_t *index, sy_error *err)
{
    const sy_mediator_class *c = name ? sy_mediator_find(name) : sy_mediator_default();
    for (uint32_t i = 0; c && i < sy_mediator_count(); ++i)
        if (sy_mediator_at(i) == c) {
            *index = i;
            return SY_OK;
        }
    if (!name) return sy_error_set(err, SY_ERR_NOT_FOUND, "no back-end offers itself as the default; name one (sy backends)");
    return sy_error_set(err, SY_ERR_NOT_FOUND, "back-end '%s' is not registered (see sy backends)", name);
}

sy_result sy_interactive_create(const sy_governor_desc *gov, sy_interactive **out, sy_error *err)
{
    *out = NULL;
    sy_interactive *ia = calloc(1, sizeof *ia);
    if (!ia) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "interactive view: out of memory");
    sy_result r = sy_governor_create(gov, &ia->gov, err);
    if (r != SY_OK) {
        free(ia);
        return r;
    }
    ia->temporal = true;
    *out = ia;
    return SY_OK;
}

void sy_interactive_destroy(sy_interactive *ia)
{
    if (!ia) return;
    sy_governor_destroy(ia->gov);
    free(ia);
}

void sy_interactive_plan(sy_interactive *ia, const sy_interactive_view *v, double now_ms, sy_governor_frame *out,
                         sy_mat4 *camera_to_world)
{
    sy_mat4 m;
    sy_orbit_matrix(v->orbit, &m);
    for (uint32_t i = 0; i < v->viewport_count; ++i) sy_viewport_set_view(v->viewports[i], &m);
    if (camera_to_world) *camera_to_world = m;
    bool backend_changed = !ia->planned || v->backend != ia->backend;
    bool changed = backend_changed || v->changed || !sy_mat4_equal(&m, &ia->view) || v->width != ia->width ||
                   v->height != ia->height;
    if (backend_changed) sy_governor_reset(ia->gov); /* another back-end: another cost */
    if (ia->planned && v->filter_version != ia->filter_version) sy_governor_redraw(ia->gov); /* same samples */
    ia->planned = true;
    ia->view = m;
    ia->backend = v->backend;
    ia->width = v->width, ia->height = v->height;
    ia->filter_version = v->filter_version;
    sy_governor_plan(ia->gov, v->width, v->height, v->caps, changed, now_ms, out);
}

void sy_interactive_report(sy_interactive *ia, const sy_governor_frame *f, double ms, bool new_context)
{
    if (!new_context) sy_governor_report(ia->gov, f, ms);
}

void sy_interactive_set_temporal(sy_interactive *ia, bool on)
{
    ia->temporal = on;
}

void sy_interactive_set_min_scale(sy_interactive *ia, float min_scale)
{
    sy_governor_set_min_scale(ia->gov, min_scale);
}

bool sy_interactive_view_matrix(const sy_interactive *ia, sy_mat4 *camera_to_world)
{
    if (ia->planned) *camera_to_world = ia->view;
    return ia->planned;
}

sy_result sy_interactive_apply_filter(sy_interactive *ia, sy_context_pool *pool, sy_scene *scene, uint32_t root_id,
                                      const sy_mediator_class *cls, uint32_t filter, float threshold, uint64_t version,
                                      bool enabled, sy_filter_info *info, sy_error *err)
{
    if (info) memset(info, 0, sizeof *info);
    if (!(cls->caps & SY_CAP_FILTERS)) return SY_OK;
    sy_context *ctx = NULL;
    sy_result r = sy_context_pool_get(pool, scene, cls->name, NULL, root_id, &ctx, err);
    if (r != SY_OK) return r;
    if (ctx != ia->filter_ctx || version != ia->filter_applied || enabled != ia->filter_enabled ||
        filter != ia->filter_index || threshold != ia->filter_threshold || ia->temporal != ia->temporal_applied) {
        sy_params opts = {0};
        char t[32], name[32];
        snprintf(t, sizeof t, "%g", (double)threshold);
        r = sy_params_set(&opts, "threshold", t, err);
        /* temporal reuse where the class has it (a live boolean "temporal" parameter) */
        const sy_param_decl *td = sy_param_find(&cls->param_table, "temporal");
        if (r == SY_OK && td && td->type == SY_PARAM_BOOL && (td->flags & SY_PARAM_LIVE))
            r = sy_params_set(&opts, "temporal", ia->temporal ? "1" : "0", err);
        if (r == SY_OK)
            r = sy_context_set_filter(ctx, enabled ? sy_interactive_filter_name(filter, name) : "none", &opts, err);
        if (r != SY_OK) return r;
        ia->filter_ctx = ctx;
        ia->filter_applied = version;
        ia->filter_enabled = enabled;
        ia->filter_index = filter, ia->filter_threshold = threshold;
        ia->temporal_applied = ia->temporal;
    }
    if (info) sy_context_filter_info(ctx, info);
    return SY_OK;
}

uint8_t *sy_interactive_rgba8(const sy_layer *img, sy_rgba8_alpha alpha)
{
    size_t n = (size_t)img->width * img->height;
    uint8_t *px = malloc(n > 0 ? n * 4 : 1);
    if (!px) return NULL;
    for (size_t i = 0; i < n * 4; ++i) {
        float x = img->rgba[i];
        if (alpha == SY_RGBA8_OVER_BLACK) x = (i & 3) == 3 ? 1.0f : x;
        else if ((i & 3) != 3 && img->rgba[i | 3] > 0.0f) x /= img->rgba[i | 3]; /* straight for display */
        px[i] = sy_unorm8(x);
    }
    return px;
}
