/* sy_web_cull.c — remote culling over sy_web: the route handlers of POST /api/cull, GET
 * /api/object/ID, GET /api/view, GET /api/environment and GET /client/... (see sy_web_cull.h). */
#define _XOPEN_SOURCE 700 /* realpath */
#include "sy_web_cull.h"

#include "sy_blob.h"
#include "sy_cull.h"
#include "sy_look.h"
#include "sy_orbit.h"

#include <cjson/cJSON.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifndef SY_WEB_CLIENT_DIR
#define SY_WEB_CLIENT_DIR ""
#endif

/* The client page's files are small (three.js is the largest, about 1.3 MB). */
#define CLIENT_FILE_MAX (32u << 20)

struct sy_web_cull {
    sy_scene *scene;
    sy_node root;
    sy_context_pool *pool;
    sy_culler *culler;
    const sy_web *server;
    char client_dir[PATH_MAX]; /* realpath, "" = no /client/ route */
};

const char *sy_web_cull_client_dir_default(void) { return SY_WEB_CLIENT_DIR; }

static sy_result take_text(char *text, const char *type, sy_web_response *resp, sy_error *err)
{
    if (!text) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    resp->status = 200;
    snprintf(resp->content_type, sizeof resp->content_type, "%s", type);
    resp->body = (uint8_t *)text;
    resp->body_len = strlen(text);
    return SY_OK;
}

/* POST /api/cull */
static sy_result on_cull(void *user, sy_scene *scene, const sy_web_request *req, sy_web_response *resp, sy_error *err)
{
    (void)scene;
    sy_web_cull *c = user;
    char *json = NULL;
    sy_result r = sy_culler_query_json(c->culler, (const char *)req->body, req->body_len, &json, err);
    return r == SY_OK ? take_text(json, "application/json", resp, err) : r;
}

/* GET /api/pose: the moved objects' matrices (sy_culler_poses_json), after the scene clock's time
 * (the render thread applies it before it runs a route) */
static sy_result on_pose(void *user, sy_scene *scene, const sy_web_request *req, sy_web_response *resp, sy_error *err)
{
    (void)scene, (void)req;
    sy_web_cull *c = user;
    char *json = NULL;
    sy_result r = sy_culler_poses_json(c->culler, &json, err);
    return r == SY_OK ? take_text(json, "application/json", resp, err) : r;
}

/* GET /api/object/ID */
static sy_result on_object(void *user, sy_scene *scene, const sy_web_request *req, sy_web_response *resp, sy_error *err)
{
    (void)scene;
    sy_web_cull *c = user;
    const char *id_text = req->path + strlen("/api/object/");
    uint32_t id = 0;
    uint8_t *glb = NULL;
    size_t len = 0;
    sy_result r = sy_cull_parse_id(id_text, strlen(id_text), &id, err);
    if (r == SY_OK) r = sy_culler_object_glb(c->culler, id, &glb, &len, err);
    if (r != SY_OK) return r;
    resp->status = 200;
    snprintf(resp->content_type, sizeof resp->content_type, "model/gltf-binary");
    resp->body = glb;
    resp->body_len = len;
    return SY_OK;
}

/* The look the server's view has now (sy_look_resolve on the scene as the mirrors count it: a
 * light placed on a visible node, a material whose emission exceeds 1) and its exposure. */
static void view_look(const sy_web_cull *c, sy_scene *scene, sy_look *look, float *exposure)
{
    sy_background world = {0};
    sy_web_look(c->server, &world, exposure);
    const sy_background_data *bd = world.id ? sy_background_get(scene, world) : NULL;
    const sy_texture_data *env = bd && bd->environment.id ? sy_texture_get(scene, bd->environment) : NULL;
    sy_look_inputs in = {.world = bd, .world_env_ready = env && env->pixels};
    for (uint32_t id = sy_scene_next(scene, SY_TYPE_NODE, 0); id; id = sy_scene_next(scene, SY_TYPE_NODE, id)) {
        const sy_node_data *nd = sy_node_get(scene, (sy_node){id});
        if (nd && nd->light.id && (nd->flags & SY_NODE_VISIBLE)) in.light_count++;
    }
    for (uint32_t id = sy_scene_next(scene, SY_TYPE_MATERIAL, 0); id; id = sy_scene_next(scene, SY_TYPE_MATERIAL, id)) {
        const sy_material_data *md = sy_material_get(scene, (sy_material){id});
        for (int k = 0; md && k < 3; ++k)
            if (md->emissive[k] * md->emissive_strength > 1.0f) {
                in.emitter_count++;
                break;
            }
    }
    sy_look_resolve(&in, look);
}

/* GET /api/environment: the environment light of the view now, as /api/view's "look" describes it:
 * a lat-long image of little-endian float32 linear RGB, row 0 up (sy_look.h's convention), before
 * the look's intensity: the library's studio (sy_look_studio_pixels), or the world's texture when it
 * is float RGB or RGBA; 404 when the view has no environment or one not served. */
static sy_result environment_answer(const sy_web_cull *c, sy_scene *scene, sy_web_response *resp, sy_error *err)
{
    sy_look look;
    float exposure;
    view_look(c, scene, &look, &exposure);
    const sy_texture_data *t = look.env == SY_LOOK_ENV_TEXTURE ? sy_texture_get(scene, (sy_texture){look.env_texture}) : NULL;
    if (look.env == SY_LOOK_ENV_TEXTURE &&
        (!t || !t->pixels || t->info.format != SY_PIXEL_F32 || t->info.channels < 3 || !t->info.width || !t->info.height ||
         sy_blob_size(t->pixels) < (size_t)t->info.width * t->info.height * t->info.channels * sizeof(float)))
        return sy_error_set(err, SY_ERR_NOT_FOUND, "/api/environment: the world's environment texture is not float RGB(A): not served");
    if (look.env != SY_LOOK_ENV_STUDIO && look.env != SY_LOOK_ENV_TEXTURE)
        return sy_error_set(err, SY_ERR_NOT_FOUND, "/api/environment: the view has no environment light");
    uint32_t w = t ? t->info.width : SY_LOOK_STUDIO_WIDTH, h = t ? t->info.height : SY_LOOK_STUDIO_HEIGHT;
    float *rgb = malloc((size_t)w * h * 3 * sizeof *rgb);
    if (!rgb) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "/api/environment: out of memory");
    if (t) {
        const float *src = sy_blob_data(t->pixels);
        for (size_t i = 0; i < (size_t)w * h; ++i)
            for (int k = 0; k < 3; ++k) rgb[3 * i + k] = src[t->info.channels * i + k];
    } else {
        sy_look_studio_pixels(w, h, rgb);
    }
    resp->status = 200;
    snprintf(resp->content_type, sizeof resp->content_type, "application/octet-stream");
    resp->body = (uint8_t *)rgb; /* x86 and ARM: little-endian */
    resp->body_len = (size_t)w * h * 3 * sizeof *rgb;
    return SY_OK;
}

/* /api/view's "look": what lights the view and how it is shown, for a client that draws it itself:
 * {"environment": "studio" | "texture" | "none", "width", "height" (GET /api/environment's image),
 * "intensity", "exposure" (stops), "tonemap": "aces" (sy_post.c's curve), "srgb": true}. */
static bool add_look(const sy_web_cull *c, sy_scene *scene, cJSON *o)
{
    sy_look look;
    float exposure;
    view_look(c, scene, &look, &exposure);
    const sy_texture_data *t = look.env == SY_LOOK_ENV_TEXTURE ? sy_texture_get(scene, (sy_texture){look.env_texture}) : NULL;
    cJSON *l = cJSON_AddObjectToObject(o, "look");
    if (!l) return false;
    const char *env = look.env == SY_LOOK_ENV_STUDIO ? "studio" : look.env == SY_LOOK_ENV_TEXTURE ? "texture" : "none";
    cJSON_AddStringToObject(l, "environment", env);
    cJSON_AddNumberToObject(l, "width", t ? t->info.width : look.env == SY_LOOK_ENV_STUDIO ? SY_LOOK_STUDIO_WIDTH : 0);
    cJSON_AddNumberToObject(l, "height", t ? t->info.height : look.env == SY_LOOK_ENV_STUDIO ? SY_LOOK_STUDIO_HEIGHT : 0);
    cJSON_AddNumberToObject(l, "intensity", look.env ? look.env_intensity : 0);
    cJSON_AddNumberToObject(l, "exposure", exposure);
    cJSON_AddStringToObject(l, "tonemap", "aces");
    return cJSON_AddBoolToObject(l, "srgb", true) != NULL;
}

/* GET /api/view: the server's camera as /api/cull takes it, plus the orbit target (sy_orbit's:
 * the root's bounds centre projected on the viewing axis) for a client's orbit controls. */
static sy_result view_answer(const sy_web_cull *c, sy_scene *scene, sy_web_response *resp, sy_error *err)
{
    sy_node cam;
    sy_mat4 m;
    sy_web_view(c->server, &m, &cam);
    const sy_node_data *nd = sy_node_get(scene, cam);
    const sy_camera_data *cd = nd ? sy_camera_get(scene, nd->camera) : NULL;
    double fov = cd && cd->yfov > 0.0f ? (double)cd->yfov * (180.0 / 3.14159265358979323846) : 45.0;
    /* rotation: the matrix's columns without their scale, to a quaternion (Shepperd) */
    double R[3][3];
    for (int col = 0; col < 3; ++col) {
        double l = sqrt((double)m.m[4 * col] * m.m[4 * col] + (double)m.m[4 * col + 1] * m.m[4 * col + 1] +
                        (double)m.m[4 * col + 2] * m.m[4 * col + 2]);
        if (!(l > 0.0)) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "/api/view: the camera matrix is singular");
        for (int row = 0; row < 3; ++row) R[row][col] = m.m[4 * col + row] / l;
    }
    double q[4], tr = R[0][0] + R[1][1] + R[2][2];
    if (tr > 0.0) {
        double s = 2.0 * sqrt(tr + 1.0);
        q[3] = 0.25 * s, q[0] = (R[2][1] - R[1][2]) / s, q[1] = (R[0][2] - R[2][0]) / s, q[2] = (R[1][0] - R[0][1]) / s;
    } else if (R[0][0] > R[1][1] && R[0][0] > R[2][2]) {
        double s = 2.0 * sqrt(1.0 + R[0][0] - R[1][1] - R[2][2]);
        q[3] = (R[2][1] - R[1][2]) / s, q[0] = 0.25 * s, q[1] = (R[0][1] + R[1][0]) / s, q[2] = (R[0][2] + R[2][0]) / s;
    } else if (R[1][1] > R[2][2]) {
        double s = 2.0 * sqrt(1.0 + R[1][1] - R[0][0] - R[2][2]);
        q[3] = (R[0][2] - R[2][0]) / s, q[0] = (R[0][1] + R[1][0]) / s, q[1] = 0.25 * s, q[2] = (R[1][2] + R[2][1]) / s;
    } else {
        double s = 2.0 * sqrt(1.0 + R[2][2] - R[0][0] - R[1][1]);
        q[3] = (R[1][0] - R[0][1]) / s, q[0] = (R[0][2] + R[2][0]) / s, q[1] = (R[1][2] + R[2][1]) / s, q[2] = 0.25 * s;
    }
    double pos[3] = {m.m[12], m.m[13], m.m[14]};
    sy_bounds b;
    if (c->root.id == 0 || sy_node_world_bounds(scene, c->root, &b, NULL) != SY_OK) b = sy_scene_world_bounds(scene);
    sy_orbit orbit; /* the target on the viewing axis, as sy web's own orbit places it */
    sy_orbit_from_matrix(&m, &b, &orbit);
    cJSON *o = cJSON_CreateObject();
    double target[3] = {orbit.target[0], orbit.target[1], orbit.target[2]};
    if (o && cJSON_AddItemToObject(o, "position", cJSON_CreateDoubleArray(pos, 3)) &&
        cJSON_AddItemToObject(o, "orientation", cJSON_CreateDoubleArray(q, 4)) && cJSON_AddNumberToObject(o, "fov", fov) &&
        cJSON_AddItemToObject(o, "target", cJSON_CreateDoubleArray(target, 3)) && add_look(c, scene, o)) {
        char *text = cJSON_PrintUnformatted(o);
        cJSON_Delete(o);
        return take_text(text, "application/json", resp, err);
    }
    cJSON_Delete(o);
    return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "/api/view: out of memory");
}

/* GET /api/view and GET /api/environment answer from the attached server's view; 404 without one. */
static sy_result on_view(void *user, sy_scene *scene, const sy_web_request *req, sy_web_response *resp, sy_error *err)
{
    const sy_web_cull *c = user;
    return c->server ? view_answer(c, scene, resp, err) : sy_error_set(err, SY_ERR_NOT_FOUND, "%s: no server attached", req->path);
}

static sy_result on_environment(void *user, sy_scene *scene, const sy_web_request *req, sy_web_response *resp, sy_error *err)
{
    const sy_web_cull *c = user;
    return c->server ? environment_answer(c, scene, resp, err)
                     : sy_error_set(err, SY_ERR_NOT_FOUND, "%s: no server attached", req->path);
}

static const char *content_type_of(const char *name)
{
    const char *dot = strrchr(name, '.');
    if (!dot) return "text/plain; charset=utf-8";
    if (!strcmp(dot, ".html")) return "text/html; charset=utf-8";
    if (!strcmp(dot, ".js") || !strcmp(dot, ".mjs")) return "text/javascript; charset=utf-8";
    if (!strcmp(dot, ".json")) return "application/json";
    if (!strcmp(dot, ".css")) return "text/css; charset=utf-8";
    if (!strcmp(dot, ".wasm")) return "application/wasm";
    return "application/octet-stream";
}

/* GET /client/PATH: a file of the page: client.html, client.js or vendor/...; PATH is plain names (letters, digits, '.', '_',
 * '-') separated by '/', no name starting with '.'; the file must resolve inside the folder
 * (symbolic links out of it are refused) and be a regular file under CLIENT_FILE_MAX. */
static sy_result on_client(void *user, sy_scene *scene, const sy_web_request *req, sy_web_response *resp, sy_error *err)
{
    (void)scene;
    sy_web_cull *c = user;
    const char *rel = req->path + strlen("/client/");
    if (!*rel) rel = "client.html";
    size_t n = strlen(rel);
    bool ok = n < 256;
    for (size_t i = 0; ok && i < n; ++i) {
        char ch = rel[i];
        bool start = i == 0 || rel[i - 1] == '/';
        ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_' || ch == '-' ||
             (ch == '.' && !start) || (ch == '/' && !start);
    }
    /* only the page's own files: client.html, client.js and what the build vendored under vendor/
     * (the npm folder the build installs beside them is not served) */
    ok = ok && (!strcmp(rel, "client.html") || !strcmp(rel, "client.js") || !strncmp(rel, "vendor/", 7));
    if (!ok || rel[n - 1] == '/') return sy_error_set(err, SY_ERR_NOT_FOUND, "/client/%.64s: no such file", rel);
    char path[PATH_MAX], real[PATH_MAX];
    if (snprintf(path, sizeof path, "%s/%s", c->client_dir, rel) >= (int)sizeof path || !realpath(path, real) ||
        strncmp(real, c->client_dir, strlen(c->client_dir)) != 0 || real[strlen(c->client_dir)] != '/')
        return sy_error_set(err, SY_ERR_NOT_FOUND, "/client/%s: no such file", rel);
    struct stat st;
    if (stat(real, &st) != 0 || !S_ISREG(st.st_mode)) return sy_error_set(err, SY_ERR_NOT_FOUND, "/client/%s: no such file", rel);
    if (st.st_size > (off_t)CLIENT_FILE_MAX) return sy_error_set(err, SY_ERR_LIMIT, "/client/%s: too large", rel);
    FILE *f = fopen(real, "rb");
    if (!f) return sy_error_set(err, SY_ERR_NOT_FOUND, "/client/%s: cannot be read", rel);
    uint8_t *buf = malloc((size_t)st.st_size + 1u);
    size_t got = buf ? fread(buf, 1, (size_t)st.st_size, f) : 0;
    fclose(f);
    if (!buf || got != (size_t)st.st_size) {
        free(buf);
        return sy_error_set(err, buf ? SY_ERR_IO : SY_ERR_OUT_OF_MEMORY, "/client/%s: read failed", rel);
    }
    resp->status = 200;
    snprintf(resp->content_type, sizeof resp->content_type, "%s", content_type_of(rel));
    resp->body = buf;
    resp->body_len = got;
    return SY_OK;
}

sy_result sy_web_cull_create(sy_scene *scene, sy_node root, const char *client_dir, sy_web_cull **out,
                             sy_web_route routes[SY_WEB_CULL_MAX_ROUTES], uint32_t *count, sy_error *err)
{
    *out = NULL;
    *count = 0;
    sy_web_cull *c = calloc(1, sizeof *c);
    if (!c) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web cull: out of memory");
    c->scene = scene;
    c->root = root;
    sy_result r = SY_OK;
    if (client_dir) {
        char page[PATH_MAX];
        struct stat st;
        if (!*client_dir)
            r = sy_error_set(err, SY_ERR_NOT_FOUND, "the client-render page was not built (npm was not found at "
                             "configure time; apps/cull/client needs npm to vendor three.js)");
        else if (!realpath(client_dir, c->client_dir) ||
                 snprintf(page, sizeof page, "%s/client.html", c->client_dir) >= (int)sizeof page ||
                 stat(page, &st) != 0)
            r = sy_error_set(err, SY_ERR_NOT_FOUND, "the client-render page is not in %s (npm ci failed at build time? "
                             "delete cull_client/.stamp in the build folder and build again)", client_dir);
    }
    if (r == SY_OK) r = sy_context_pool_create(&c->pool, err);
    if (r == SY_OK) r = sy_culler_create(scene, c->pool, root, NULL, &c->culler, err);
    if (r != SY_OK) {
        sy_web_cull_destroy(c);
        return r;
    }
    uint32_t n = 0;
    routes[n++] = (sy_web_route){"POST", "/api/cull", on_cull, c};
    routes[n++] = (sy_web_route){"GET", "/api/object/", on_object, c};
    routes[n++] = (sy_web_route){"GET", "/api/view", on_view, c};
    routes[n++] = (sy_web_route){"GET", "/api/pose", on_pose, c};
    routes[n++] = (sy_web_route){"GET", "/api/environment", on_environment, c};
    if (client_dir) routes[n++] = (sy_web_route){"GET", "/client/", on_client, c};
    *count = n;
    *out = c;
    return SY_OK;
}

void sy_web_cull_attach(sy_web_cull *c, const sy_web *server)
{
    if (c) c->server = server;
}

void sy_web_cull_destroy(sy_web_cull *c)
{
    if (!c) return;
    sy_culler_destroy(c->culler);
    sy_context_pool_destroy(c->pool);
    free(c);
}
