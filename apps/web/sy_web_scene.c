/* sy_web_scene.c — what pages ask of the scene, on the render thread (it owns the scene): picks
 * (sy_viewport_pick, with the view and planes of the live frame), visibility, selection and
 * isolation (sy_node_set_visible / _selected, sy_scene_isolate, committed so every context sees
 * them), section planes and their caps (sy_viewport_set_clip_planes / _clip_cap on the server's
 * viewports) and the scene's
 * hierarchy, a page at a time (WEB_TREE_PAGE children of a node, opened below while the answer stays
 * within WEB_TREE_MAX nodes). Answers go back to the asking page as JSON text
 * through the mailbox (web_reply); unknown nodes and failures are logged and answered with a
 * "refused" message, never applied (sy_web_internal.h; docs/WEB.md, "The WebSocket protocol"). */
#include "sy_web_internal.h"

#include "sy_graph.h"
#include "sy_log.h"
#include "sy_look.h"
#include "sy_mediator.h"
#include "sy_viewport.h"

#include <cjson/cJSON.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Queues the JSON o (deleted here) for connection conn. At most WEB_REPLIES_PER_CONN wait for one
 * connection (a page that does not read its answers loses its newest, with a log line); when
 * WEB_REPLIES_MAX wait in all, the oldest gives way (mostly an answer for a page that left, which
 * the network thread drops when it next runs: 80 pages that asked and left while the render thread
 * was busy filled the queue before it ran, and the next page's answer was dropped, `web_scene`
 * under load). */
static void post_reply(sy_web *w, const web_action *a, cJSON *o)
{
    char *s = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    web_reply *y = s ? calloc(1, sizeof *y) : NULL;
    if (!y) {
        free(s);
        sy_log(SY_LOG_WARNING, "web", a->peer, "out of memory for an answer");
        return;
    }
    y->conn = a->conn, y->text = s;
    web_reply *oldest = NULL;
    pthread_mutex_lock(&w->mu);
    uint32_t mine = 0;
    for (const web_reply *r = w->replies; r; r = r->next) mine += r->conn == a->conn;
    bool over = mine >= WEB_REPLIES_PER_CONN;
    if (!over) {
        if (w->reply_count >= WEB_REPLIES_MAX) {
            oldest = w->replies;
            w->replies = oldest->next, w->reply_count--;
            if (!w->replies) w->replies_tail = &w->replies;
        }
        *w->replies_tail = y, w->replies_tail = &y->next, w->reply_count++;
    }
    pthread_mutex_unlock(&w->mu);
    if (oldest) {
        sy_log(SY_LOG_WARNING, "web", NULL, "%u answers wait already: the oldest dropped", WEB_REPLIES_MAX);
        free(oldest->text), free(oldest);
    }
    if (over) {
        free(s), free(y);
        sy_log(SY_LOG_WARNING, "web", a->peer, "%u answers wait for this viewer already: one dropped", WEB_REPLIES_PER_CONN);
        return;
    }
    sy_webi_wake_network(w);
}

/* A request that was not applied: logged, and the page is told why. */
static void refuse(sy_web *w, const web_action *a, const char *what, const char *why)
{
    sy_log(SY_LOG_WARNING, "web", a->peer, "ignored %s: %s", what, why);
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "t", "refused");
    cJSON_AddStringToObject(o, "what", what);
    cJSON_AddStringToObject(o, "reason", why);
    if (a->in.seq) cJSON_AddNumberToObject(o, "seq", a->in.seq);
    post_reply(w, a, o);
}

static void add_vec3(cJSON *o, const char *key, const float v[3])
{
    cJSON *arr = cJSON_AddArrayToObject(o, key);
    for (int i = 0; i < 3; ++i) cJSON_AddItemToArray(arr, cJSON_CreateNumber(v[i]));
}

static void add_name(cJSON *o, const char *key, const char *name)
{
    char n[128];
    snprintf(n, sizeof n, "%s", name ? name : "");
    cJSON_AddStringToObject(o, key, n);
}

/* Deselects every selected node (but keep, when keep.id != 0). */
static sy_result clear_selection(sy_scene *s, sy_node keep, sy_error *err)
{
    sy_result r = SY_OK;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id && r == SY_OK; id = sy_scene_next(s, SY_TYPE_NODE, id)) {
        const sy_node_data *d = sy_node_get(s, (sy_node){id});
        if (d && (d->flags & SY_NODE_SELECTED) && id != keep.id) r = sy_node_set_selected(s, (sy_node){id}, false, err);
    }
    return r;
}

/* The pick: through the live viewport when its back-end can pick (and cut, with planes), else a
 * window of its own with the first back-end that can, the same view and planes. (x, y) in the
 * live window's pixels (the size of the last frame). */
static sy_result pick(const sy_web_scene_ctx *sc, double fx, double fy, sy_pick_result *p, const char **by, sy_error *err)
{
    sy_web *w = sc->w;
    uint32_t cw = 0, ch = 0, need = SY_CAP_PICK;
    sy_window_size(sc->win, &cw, &ch);
    float planes[SY_CLIP_PLANES_MAX][4];
    uint32_t np = sy_viewport_clip_planes(sc->vp, planes);
    if (np) need |= SY_CAP_CLIP;
    double x = fx * cw, y = fy * ch;
    const sy_mediator_class *cls = sy_mediator_at(sc->backend);
    if (cls && (cls->caps & need) == need) {
        *by = cls->name;
        sy_viewport_set_view(sc->vp, &w->view); /* the pages' view: the last frame may be rendered ahead of it */
        return sy_viewport_pick(sc->vp, w->d.scene, sc->pool, x, y, p, err);
    }
    cls = sy_mediator_with_caps(need);
    if (!cls) return sy_error_set(err, SY_ERR_UNSUPPORTED, "no back-end can pick%s", np ? " with section planes" : "");
    *by = cls->name;
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_viewport_desc vd = {.root = w->d.root, .camera = w->d.camera, .backend = cls->name};
    sy_result r = sy_window_create(cw, ch, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, err);
    if (r == SY_OK) sy_viewport_set_view(vp, &w->view);
    if (r == SY_OK && np) r = sy_viewport_set_clip_planes(vp, (const float(*)[4])planes, np, err);
    float cap[3];
    if (r == SY_OK && sy_viewport_clip_cap(sc->vp, cap)) r = sy_viewport_set_clip_cap(vp, cap, err); /* a pick lands on a cap */
    if (r == SY_OK) r = sy_viewport_pick(vp, w->d.scene, sc->pool, x, y, p, err);
    sy_window_destroy(win);
    return r;
}

static bool do_pick(const sy_web_scene_ctx *sc, const web_action *a)
{
    sy_web *w = sc->w;
    sy_scene *s = w->d.scene;
    sy_pick_result p = {0};
    sy_error err = {0};
    const char *by = "";
    if (pick(sc, a->in.a, a->in.b, &p, &by, &err) != SY_OK) {
        refuse(w, a, "pick", err.message);
        return false;
    }
    bool changed = false;
    if (a->in.on) { /* select what is hit (only it); nothing hit clears the selection */
        sy_result r = clear_selection(s, p.hit ? (sy_node){p.node_id} : (sy_node){0}, &err);
        if (r == SY_OK && p.hit) r = sy_node_set_selected(s, (sy_node){p.node_id}, true, &err);
        if (r != SY_OK) sy_log(SY_LOG_WARNING, "web", a->peer, "pick: select: %s", err.message);
        changed = sy_scene_has_pending(s);
    }
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "t", "pick");
    cJSON_AddNumberToObject(o, "seq", a->in.seq);
    cJSON_AddBoolToObject(o, "hit", p.hit);
    cJSON_AddStringToObject(o, "backend", by);
    if (p.hit) {
        const sy_node_data *nd = sy_node_get(s, (sy_node){p.node_id});
        const sy_mesh_data *md = sy_mesh_get(s, (sy_mesh){p.mesh_id});
        const sy_material_data *mat = p.material_id ? sy_material_get(s, (sy_material){p.material_id}) : NULL;
        cJSON_AddNumberToObject(o, "node", p.node_id);
        add_name(o, "name", nd ? nd->name : NULL);
        cJSON_AddNumberToObject(o, "mesh", p.mesh_id);
        add_name(o, "mesh_name", md ? md->name : NULL);
        cJSON_AddNumberToObject(o, "primitive", p.primitive);
        cJSON_AddNumberToObject(o, "triangle", p.triangle);
        cJSON_AddNumberToObject(o, "material", p.material_id);
        add_name(o, "material_name", mat ? mat->name : p.material_id ? NULL : "default");
        add_vec3(o, "position", p.position);
        add_vec3(o, "normal", p.normal);
        cJSON_AddNumberToObject(o, "distance", p.distance);
        cJSON_AddBoolToObject(o, "selected", a->in.on);
    }
    post_reply(w, a, o);
    return changed;
}

/* visible, select, isolate: the node must exist (checked here: the scene may have changed since
 * the page's tree). */
static bool do_node(const sy_web_scene_ctx *sc, const web_action *a)
{
    sy_web *w = sc->w;
    sy_scene *s = w->d.scene;
    sy_node n = {a->in.node};
    sy_error err = {0};
    const char *what = a->in.type == SY_WEB_INPUT_VISIBLE ? "visible" : a->in.type == SY_WEB_INPUT_SELECT ? "select" : "isolate";
    if (n.id && !sy_node_get(s, n)) {
        char why[64];
        snprintf(why, sizeof why, "no node %u in the scene", n.id);
        refuse(w, a, what, why);
        return false;
    }
    sy_result r;
    if (a->in.type == SY_WEB_INPUT_VISIBLE) r = sy_node_set_visible(s, n, a->in.on, &err);
    else if (a->in.type == SY_WEB_INPUT_ISOLATE) r = sy_scene_isolate(s, &n, n.id ? 1 : 0, &err);
    else if (!n.id) r = clear_selection(s, (sy_node){0}, &err);
    else r = sy_node_set_selected(s, n, a->in.on, &err);
    if (r != SY_OK) {
        refuse(w, a, what, err.message);
        return sy_scene_has_pending(s);
    }
    return true;
}

static bool do_clip(const sy_web_scene_ctx *sc, const web_action *a)
{
    sy_error err = {0};
    const float(*planes)[4] = (const float(*)[4])a->in.planes;
    sy_result r = sy_viewport_set_clip_planes(sc->vp, planes, a->in.plane_count, &err);
    if (r == SY_OK) r = sy_viewport_set_clip_planes(sc->still_vp, planes, a->in.plane_count, &err);
    if (r == SY_OK && a->in.cap != SY_WEB_CAP_KEEP) { /* the caps' colour (checked by the parser) or off */
        const float *rgb = a->in.cap == SY_WEB_CAP_ON ? a->in.cap_rgb : NULL;
        r = sy_viewport_set_clip_cap(sc->vp, rgb, &err);
        if (r == SY_OK) r = sy_viewport_set_clip_cap(sc->still_vp, rgb, &err);
    }
    if (r != SY_OK) {
        refuse(sc->w, a, "clip", err.message);
        return false;
    }
    const sy_mediator_class *cls = sy_mediator_at(sc->backend);
    if (a->in.plane_count && cls && !(cls->caps & SY_CAP_CLIP))
        sy_log(SY_LOG_WARNING, "web", a->peer, "section planes set, but %s cannot cut: it will refuse to render", cls->name);
    return true;
}

const char *const sy_webi_environment_names[SY_WEB_ENVIRONMENTS] = {"scene", "studio", "none"};

/* The world of environment i, made the first time it is chosen (a scene change: committed by the
 * caller): "studio" keeps the start world's background and lights with the library's studio
 * (sy_look_studio_pixels, not seen by the camera); "none" keeps the background without any
 * environment or default light. */
static sy_result environment_world(sy_web *w, uint32_t i, sy_background *out, bool *made, sy_error *err)
{
    *made = false;
    if (i == 0) {
        *out = w->d.background;
        return SY_OK;
    }
    if (w->env_made[i].id) {
        *out = w->env_made[i];
        return SY_OK;
    }
    sy_scene *s = w->d.scene;
    const sy_background_data *start = w->d.background.id ? sy_background_get(s, w->d.background) : NULL;
    sy_background_data bd = *(const sy_background_data *)(start ? start : sy_object_defaults(SY_TYPE_BACKGROUND));
    bd.name = NULL;
    bd.environment = (sy_texture){0};
    bd.default_lighting = 0;
    bd.intensity = 1.0f;
    sy_result r = SY_OK;
    if (i == 1) {
        uint32_t tw = SY_LOOK_STUDIO_WIDTH, th = SY_LOOK_STUDIO_HEIGHT;
        float *px = malloc((size_t)tw * th * 3 * sizeof *px);
        sy_blob *blob = NULL;
        if (!px) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "environment studio: out of memory");
        sy_look_studio_pixels(tw, th, px);
        r = sy_blob_create_take(px, (size_t)tw * th * 3 * sizeof *px, &blob, err); /* px is the blob's now */
        if (r != SY_OK) free(px);
        sy_image_info info = {tw, th, 3, SY_PIXEL_F32};
        sy_sampler smp = {SY_WRAP_REPEAT, SY_WRAP_CLAMP, SY_FILTER_LINEAR, SY_FILTER_LINEAR};
        if (r == SY_OK) r = sy_texture_create(s, "sy web: studio", &bd.environment, err);
        if (r == SY_OK) r = sy_texture_set_image(s, bd.environment, &info, blob, err);
        if (r == SY_OK) r = sy_texture_set_sampler(s, bd.environment, &smp, err);
        sy_blob_release(blob);
        bd.environment_visible = 0; /* it lights; the camera sees the start world's background */
    }
    sy_background b = {0};
    if (r == SY_OK) r = sy_background_create(s, i == 1 ? "sy web: studio" : "sy web: no environment", &b, err);
    if (r == SY_OK) r = sy_background_set(s, b, &bd, err);
    if (r != SY_OK) return r;
    w->env_made[i] = *out = b;
    *made = true;
    return SY_OK;
}

/* environment: the world of the menu's choice on the live and the still viewport; true when the
 * scene changed (a world made now: committed by the caller). */
static bool do_environment(const sy_web_scene_ctx *sc, const web_action *a, bool *look)
{
    sy_web *w = sc->w;
    uint32_t i = 0;
    while (i < SY_WEB_ENVIRONMENTS && strcmp(sy_webi_environment_names[i], a->in.filter) != 0) i++;
    if (i == SY_WEB_ENVIRONMENTS) {
        refuse(w, a, "environment", "no such environment (scene, studio, none)");
        return false;
    }
    sy_background b;
    bool made = false;
    sy_error err = {0};
    if (environment_world(w, i, &b, &made, &err) != SY_OK) {
        refuse(w, a, "environment", err.message);
        return sy_scene_has_pending(w->d.scene);
    }
    sy_viewport_set_background(sc->vp, b);
    sy_viewport_set_background(sc->still_vp, b);
    pthread_mutex_lock(&w->mu);
    w->environment = i;
    pthread_mutex_unlock(&w->mu);
    *look = true;
    return true; /* every page is told (a "scene" message: its tree answer names the environment) */
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

static uint32_t index_of(const uint32_t *ids, uint32_t n, uint32_t id)
{
    const uint32_t *f = bsearch(&id, ids, n, sizeof *ids, cmp_u32);
    return f ? (uint32_t)(f - ids) : UINT32_MAX;
}

/* The hierarchy, one page of it: the "level" is the children of node a->in.node (0: the roots,
 * nodes nobody lists as a child; with w->d.root, that node), from a->in.offset, at most
 * WEB_TREE_PAGE of them (depth 0); below each, depth first, its children while the node has at
 * most WEB_TREE_PAGE of them and the answer's nodes (listed and reserved on the stack) stay within
 * WEB_TREE_MAX ("open": true), else it is sent closed with its child count. Each node once (a node
 * with several parents under the first). An unknown node is refused; an offset past the end gives
 * no nodes (the scene may have changed since the page's last answer). */
static void do_tree(const sy_web_scene_ctx *sc, const web_action *a)
{
    sy_web *w = sc->w;
    sy_scene *s = w->d.scene;
    uint32_t total = sy_scene_count(s, SY_TYPE_NODE), n = 0, parent = a->in.node;
    if (parent && !sy_node_get(s, (sy_node){parent})) {
        char why[64];
        snprintf(why, sizeof why, "no node %u in the scene", parent);
        refuse(w, a, "tree", why);
        return;
    }
    uint32_t *ids = malloc((total ? total : 1) * sizeof *ids);
    uint8_t *state = calloc(total ? total : 1, 1); /* 1: someone's child, 2: listed */
    uint32_t *level = malloc((total ? total : 1) * sizeof *level);
    uint32_t *stack = malloc((size_t)(WEB_TREE_MAX + WEB_TREE_PAGE) * 2 * sizeof *stack);
    cJSON *o = cJSON_CreateObject(), *arr = NULL;
    if (!ids || !state || !level || !stack || !o) {
        free(ids), free(state), free(level), free(stack), cJSON_Delete(o);
        sy_log(SY_LOG_WARNING, "web", a->peer, "tree: out of memory");
        return;
    }
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id && n < total; id = sy_scene_next(s, SY_TYPE_NODE, id)) ids[n++] = id;
    qsort(ids, n, sizeof *ids, cmp_u32);
    for (uint32_t i = 0; i < n; ++i) {
        uint32_t cn = 0;
        const sy_node_data *d = sy_node_get(s, (sy_node){ids[i]});
        const uint32_t *ch = d ? sy_node_children(d, &cn) : NULL;
        for (uint32_t k = 0; ch && k < cn; ++k) {
            uint32_t j = index_of(ids, n, ch[k]);
            if (j != UINT32_MAX) state[j] = 1;
        }
    }
    /* the level: indices into ids, in order */
    uint32_t count = 0;
    if (parent) {
        uint32_t cn = 0;
        const uint32_t *ch = sy_node_children(sy_node_get(s, (sy_node){parent}), &cn);
        for (uint32_t k = 0; ch && k < cn && count < n; ++k) {
            uint32_t j = index_of(ids, n, ch[k]);
            if (j != UINT32_MAX) level[count++] = j;
        }
    } else if (w->d.root.id) {
        uint32_t j = index_of(ids, n, w->d.root.id);
        if (j != UINT32_MAX) level[count++] = j;
    } else {
        for (uint32_t i = 0; i < n; ++i)
            if (state[i] == 0) level[count++] = i;
    }
    cJSON_AddStringToObject(o, "t", "tree");
    cJSON_AddNumberToObject(o, "seq", a->in.seq);
    cJSON_AddNumberToObject(o, "total", n);
    cJSON_AddNumberToObject(o, "node", parent);
    cJSON_AddNumberToObject(o, "offset", a->in.offset);
    cJSON_AddNumberToObject(o, "count", count);
    arr = cJSON_AddArrayToObject(o, "nodes");
    uint32_t listed = 0, first = a->in.offset < count ? a->in.offset : count;
    uint32_t last = count - first > WEB_TREE_PAGE ? first + WEB_TREE_PAGE : count;
    /* the level's page pushed in reverse so it comes out in order; the stack holds (index, depth),
     * and reserved counts the nodes listed or on it: never above WEB_TREE_MAX + WEB_TREE_PAGE */
    uint32_t sp = 0, reserved = last - first;
    for (uint32_t k = last; k-- > first;) stack[sp++] = level[k], stack[sp++] = 0;
    while (sp) {
        uint32_t depth = stack[--sp], i = stack[--sp];
        if (state[i] == 2) continue;
        state[i] = 2;
        const sy_node_data *d = sy_node_get(s, (sy_node){ids[i]});
        uint32_t cn = 0;
        const uint32_t *ch = d ? sy_node_children(d, &cn) : NULL;
        bool open = cn > 0 && cn <= WEB_TREE_PAGE && reserved + cn <= WEB_TREE_MAX;
        cJSON *e = cJSON_CreateObject();
        cJSON_AddNumberToObject(e, "id", ids[i]);
        cJSON_AddNumberToObject(e, "depth", depth);
        add_name(e, "name", d ? d->name : NULL);
        uint32_t kind = d && d->mesh.id ? 1 : d && d->light.id ? 2 : d && d->camera.id ? 3 : 0;
        cJSON_AddStringToObject(e, "kind", kind == 1 ? "mesh" : kind == 2 ? "light" : kind == 3 ? "camera" : "group");
        cJSON_AddBoolToObject(e, "visible", d && (d->flags & SY_NODE_VISIBLE));
        cJSON_AddBoolToObject(e, "selected", d && (d->flags & SY_NODE_SELECTED));
        cJSON_AddNumberToObject(e, "children", cn);
        cJSON_AddBoolToObject(e, "open", open);
        cJSON_AddItemToArray(arr, e);
        listed++;
        if (!open) continue;
        reserved += cn;
        /* children pushed in reverse: listed in their order */
        for (uint32_t k = cn; k-- > 0;) {
            uint32_t j = index_of(ids, n, ch[k]);
            if (j != UINT32_MAX && state[j] != 2) stack[sp++] = j, stack[sp++] = depth + 1;
        }
    }
    cJSON_AddBoolToObject(o, "truncated", listed < n);
    sy_bounds b = sy_scene_world_bounds(s);
    if (w->d.root.id) sy_node_world_bounds(s, w->d.root, &b, NULL);
    add_vec3(o, "min", b.min);
    add_vec3(o, "max", b.max);
    float planes[SY_CLIP_PLANES_MAX][4];
    uint32_t np = sy_viewport_clip_planes(sc->vp, planes);
    cJSON *pl = cJSON_AddArrayToObject(o, "planes");
    for (uint32_t i = 0; i < np; ++i) cJSON_AddItemToArray(pl, cJSON_CreateFloatArray(planes[i], 4));
    float cap[3];
    if (sy_viewport_clip_cap(sc->vp, cap)) add_vec3(o, "cap", cap);
    else cJSON_AddNullToObject(o, "cap");
    pthread_mutex_lock(&w->mu);
    cJSON_AddStringToObject(o, "environment", sy_webi_environment_names[w->environment < SY_WEB_ENVIRONMENTS ? w->environment : 0]);
    pthread_mutex_unlock(&w->mu);
    free(ids), free(state), free(level), free(stack);
    post_reply(w, a, o);
}

bool sy_webi_scene_actions(const sy_web_scene_ctx *sc, web_action *list)
{
    sy_web *w = sc->w;
    bool scene = false, look = false;
    while (list) {
        web_action *a = list;
        list = a->next;
        switch (a->in.type) {
        case SY_WEB_INPUT_PICK: scene |= do_pick(sc, a); break;
        case SY_WEB_INPUT_VISIBLE:
        case SY_WEB_INPUT_SELECT:
        case SY_WEB_INPUT_ISOLATE: scene |= do_node(sc, a); break;
        case SY_WEB_INPUT_CLIP: look |= do_clip(sc, a); break;
        case SY_WEB_INPUT_ENVIRONMENT: scene |= do_environment(sc, a, &look); break;
        case SY_WEB_INPUT_TREE: do_tree(sc, a); break;
        default: break;
        }
        free(a);
    }
    if (scene) { /* the flags are scene changes: committed, so every context (and cluster node) sees them */
        sy_error err = {0};
        if (sy_scene_commit(w->d.scene, NULL, &err) != SY_OK) sy_log(SY_LOG_WARNING, "web", NULL, "commit: %s", err.message);
    }
    if (scene) { /* every page is told, and asks for the tree again */
        pthread_mutex_lock(&w->mu);
        w->scene_version++;
        pthread_mutex_unlock(&w->mu);
        sy_webi_wake_network(w);
    }
    return scene || look;
}
