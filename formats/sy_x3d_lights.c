/* sy_x3d_lights.c — the X3D nodes that set up the view rather than the geometry: DirectionalLight,
 * PointLight and SpotLight (intensities fixed to the scene's size once it is loaded, as sy_x3d.h
 * documents), Viewpoint and OrthoViewpoint (the cameras, and sy_x3d_yfov / sy_x3d_fit_cameras /
 * sy_x3d_find_camera over them) and Background / TextureBackground (the world's gradient). */
#include "sy_x3d_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>lights ------------------------------------------------------------------------------------ */

void x3d_quat_from_neg_z(const float d_in[3], float q[4])
{
    float d[3] = {d_in[0], d_in[1], d_in[2]};
    float l = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(l > 0)) { d[0] = 0; d[1] = 0; d[2] = -1; }
    else { d[0] /= l; d[1] /= l; d[2] /= l; }
    float a[3] = {0, 0, -1};
    float cx = a[1] * d[2] - a[2] * d[1], cy = a[2] * d[0] - a[0] * d[2], cz = a[0] * d[1] - a[1] * d[0];
    float dot = -d[2];
    if (dot < -0.999999f) { q[0] = 0; q[1] = 1; q[2] = 0; q[3] = 0; return; }
    q[0] = cx; q[1] = cy; q[2] = cz; q[3] = 1.0f + dot;
    float n = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int k = 0; k < 4; k++) q[k] /= n;
}

sy_result x3d_visit_light(loader *L, xfile *F, const xmlNode *el, const sy_mat4 *world, sy_node h)
{
    if (!x3d_get_bool(el, "on", true)) return SY_OK;
    sy_light_data ld = *(const sy_light_data *)sy_object_defaults(SY_TYPE_LIGHT);
    float color[3] = {1, 1, 1}, dir[3] = {0, 0, -1}, loc[3] = {0, 0, 0}, att[3] = {1, 0, 0};
    x3d_get_floats(L, F, el, "color", color, 3);
    x3d_clamp01(color, 3);
    memcpy(ld.color, color, sizeof color);
    float inten = fmaxf(0.0f, x3d_get_float(L, F, el, "intensity", 1.0f));
    x3d_get_floats(L, F, el, "direction", dir, 3);
    x3d_get_floats(L, F, el, "location", loc, 3);
    x3d_get_floats(L, F, el, "attenuation", att, 3);
    const char *n = x3d_ename(el);
    float q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
    if (!strcmp(n, "DirectionalLight")) {
        ld.type = SY_LIGHT_DIRECTIONAL;
        ld.intensity = inten * PI_F;
        x3d_quat_from_neg_z(dir, q);
        loc[0] = loc[1] = loc[2] = 0;
    } else if (!strcmp(n, "PointLight")) {
        ld.type = SY_LIGHT_POINT;
        ld.range = fmaxf(0.0f, x3d_get_float(L, F, el, "radius", 100.0f));
    } else {
        ld.type = SY_LIGHT_SPOT;
        ld.range = fmaxf(0.0f, x3d_get_float(L, F, el, "radius", 100.0f));
        float cut = x3d_get_float(L, F, el, "cutOffAngle", PI_F / 4), beam = x3d_get_float(L, F, el, "beamWidth", PI_F / 4);
        cut = fmaxf(1e-4f, fminf(PI_F / 2, cut));
        ld.outer_cone = cut;
        ld.inner_cone = fmaxf(0.0f, fminf(beam, cut * 0.999f));
        x3d_quat_from_neg_z(dir, q);
    }
    sy_result r;
    char *def = x3d_attr(el, "DEF");
    uint32_t lid;
    r = x3d_new_object(L, SY_TYPE_LIGHT, def, &lid);
    xmlFree(def);
    if (!r) r = sy_light_set(L->scene, (sy_light){lid}, &ld, &L->err);
    if (!r) r = sy_node_set_trs(L->scene, h, loc, q, one, &L->err);
    if (!r) r = sy_node_set_light(L->scene, h, (sy_light){lid}, &L->err);
    if (r) {
        sy_error_prefix(&L->err, "%s:%d: %s", F->path, x3d_line_of(el), n);
        return r;
    }
    L->info->counts.lights++;
    if (ld.type != SY_LIGHT_DIRECTIONAL) {
        if (!sy_array_reserve(&L->lights, L->light_count, &L->light_cap, sizeof *L->lights, 8))
            return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        pending_light *pl = &L->lights[L->light_count++];
        pl->light = lid;
        sy_mat4_transform_point(world, loc, pl->pos);
        pl->intensity = inten * PI_F;
        pl->a2 = att[2] > 0 && isfinite(att[2]) ? att[2] : 0.0f;
        pl->mult = 1.0f;
    }
    return SY_OK;
}

void x3d_finish_lights(loader *L)
{
    float centre[3] = {0, 0, 0}, diag = 1.0f;
    if (!sy_bounds_is_empty(&L->bounds)) {
        for (int k = 0; k < 3; k++) centre[k] = 0.5f * (L->bounds.min[k] + L->bounds.max[k]);
        float d[3] = {L->bounds.max[0] - L->bounds.min[0], L->bounds.max[1] - L->bounds.min[1], L->bounds.max[2] - L->bounds.min[2]};
        diag = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(diag > 0)) diag = 1.0f;
    }
    for (size_t k = 0; k < L->light_count; k++) {
        pending_light *pl = &L->lights[k];
        const sy_light_data *cur = sy_light_get(L->scene, (sy_light){pl->light});
        if (!cur) continue;
        sy_light_data ld = *cur;
        if (pl->a2 > 0) {
            pl->mult = 1.0f / pl->a2;
        } else {
            float d[3] = {pl->pos[0] - centre[0], pl->pos[1] - centre[1], pl->pos[2] - centre[2]};
            float dist = fmaxf(sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), 0.05f * diag);
            pl->mult = dist * dist;
        }
        ld.intensity = pl->intensity * pl->mult;
        sy_light_set(L->scene, (sy_light){pl->light}, &ld, NULL);
    }
}

/* >>viewpoints -------------------------------------------------------------------------------- */

sy_result x3d_visit_viewpoint(loader *L, xfile *F, const xmlNode *el, sy_node h)
{
    float pos[3] = {0, 0, 10}, ori[4] = {0, 0, 1, 0}, q[4], one[3] = {1, 1, 1};
    x3d_get_floats(L, F, el, "position", pos, 3);
    x3d_get_floats(L, F, el, "orientation", ori, 4);
    x3d_axis_angle_quat(ori, q);
    sy_camera_data cd = *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
    float fov = PI_F / 4;
    if (!strcmp(x3d_ename(el), "OrthoViewpoint")) {
        float fw[4] = {-1, -1, 1, 1};
        x3d_get_floats(L, F, el, "fieldOfView", fw, 4);
        cd.projection = SY_PROJECTION_ORTHOGRAPHIC;
        cd.xmag = fmaxf(1e-6f, 0.5f * fabsf(fw[2] - fw[0]));
        cd.ymag = fmaxf(1e-6f, 0.5f * fabsf(fw[3] - fw[1]));
        fov = 0;
    } else {
        fov = x3d_get_float(L, F, el, "fieldOfView", PI_F / 4);
        if (!(fov > 0 && fov < PI_F)) {
            x3d_warn(L, "%s:%d: Viewpoint fieldOfView %g outside (0, pi); using pi/4", F->path, x3d_line_of(el), (double)fov);
            fov = PI_F / 4;
        }
        cd.projection = SY_PROJECTION_PERSPECTIVE;
        cd.yfov = fov;
    }
    char *desc = x3d_attr(el, "description");
    char *def = x3d_attr(el, "DEF");
    uint32_t cid;
    sy_result r = x3d_new_object(L, SY_TYPE_CAMERA, desc ? desc : def, &cid);
    xmlFree(desc);
    xmlFree(def);
    if (!r) {
        cd.name = (char *)sy_camera_get(L->scene, (sy_camera){cid})->name;
        r = sy_camera_set(L->scene, (sy_camera){cid}, &cd, &L->err);
    }
    if (!r) r = sy_node_set_trs(L->scene, h, pos, q, one, &L->err);
    if (!r) r = sy_node_set_camera(L->scene, h, (sy_camera){cid}, &L->err);
    if (r) {
        sy_error_prefix(&L->err, "%s:%d: %s", F->path, x3d_line_of(el), x3d_ename(el));
        return r;
    }
    sy_x3d_info *I = L->info;
    void *a = realloc(I->camera_nodes, (I->camera_node_count + 1) * sizeof(sy_node));
    if (!a) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    I->camera_nodes = a;
    void *b = realloc(I->camera_fovs, (I->camera_node_count + 1) * sizeof(float));
    if (!b) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    I->camera_fovs = b;
    I->camera_nodes[I->camera_node_count] = h;
    I->camera_fovs[I->camera_node_count++] = fov;
    I->counts.cameras++;
    return SY_OK;
}

float sy_x3d_yfov(float fov, float aspect)
{
    if (!(aspect > 0) || aspect >= 1.0f) return fov;
    return 2.0f * atanf(tanf(0.5f * fov) / aspect);
}

/* Whether an animation of the scene drives camera c's yfov (a routed Viewpoint.fieldOfView). */
static bool yfov_animated(const sy_scene *scene, sy_camera c)
{
    for (uint32_t id = sy_scene_next(scene, SY_TYPE_ANIMATION, 0); id; id = sy_scene_next(scene, SY_TYPE_ANIMATION, id)) {
        uint32_t nc;
        const sy_anim_channel *ch = sy_animation_channels(sy_object_get(scene, SY_TYPE_ANIMATION, id), &nc);
        for (uint32_t i = 0; i < nc; i++)
            if (ch[i].path == SY_ANIM_CAMERA_YFOV && ch[i].node == c.id) return true;
    }
    return false;
}

sy_result sy_x3d_fit_cameras(sy_scene *scene, const sy_x3d_info *info, float aspect, sy_error *err)
{
    for (uint32_t k = 0; k < info->camera_node_count; k++) {
        if (!(info->camera_fovs[k] > 0)) continue;
        const sy_node_data *nd = sy_node_get(scene, info->camera_nodes[k]);
        if (!nd) continue;
        const sy_camera_data *cd = sy_camera_get(scene, nd->camera);
        if (!cd || yfov_animated(scene, nd->camera)) continue; /* the clock sets it: the routed angle as yfov */
        sy_camera_data c = *cd;
        c.yfov = fminf(sy_x3d_yfov(info->camera_fovs[k], aspect), 3.1f);
        sy_result r = sy_camera_set(scene, nd->camera, &c, err);
        if (r) return r;
    }
    return SY_OK;
}

sy_result sy_x3d_find_camera(const sy_scene *scene, const sy_x3d_info *info, const char *selector, sy_node *out,
                             sy_error *err)
{
    char *end;
    unsigned long idx = strtoul(selector, &end, 10);
    if (*selector && !*end) {
        if (idx < info->camera_node_count) {
            *out = info->camera_nodes[idx];
            return SY_OK;
        }
    } else {
        for (uint32_t k = 0; k < info->camera_node_count; k++) {
            const sy_node_data *nd = sy_node_get(scene, info->camera_nodes[k]);
            const sy_camera_data *cd = nd ? sy_camera_get(scene, nd->camera) : NULL;
            if ((nd && nd->name && !strcmp(nd->name, selector)) || (cd && cd->name && !strcmp(cd->name, selector))) {
                *out = info->camera_nodes[k];
                return SY_OK;
            }
        }
    }
    char list[256] = "";
    size_t used = 0;
    for (uint32_t k = 0; k < info->camera_node_count && used + 1 < sizeof list; k++) {
        const sy_node_data *nd = sy_node_get(scene, info->camera_nodes[k]);
        int w = snprintf(list + used, sizeof list - used, "%s%u \"%s\"", k ? ", " : "", (unsigned)k,
                         nd && nd->name ? nd->name : "");
        if (w < 0) break;
        used += (size_t)w;
        if (used >= sizeof list) used = sizeof list - 1;
    }
    return sy_error_set(err, SY_ERR_NOT_FOUND, "no viewpoint '%s' (available: %s)", selector,
                        info->camera_node_count ? list : "none");
}

/* >>background -------------------------------------------------------------------------------- */

/* One part of an X3D Background gradient (sky or ground) into colours[]/angles[]: at most
 * SY_GRADIENT_MAX colours (more are cut, warned), one angle fewer than colours (a mismatch is
 * warned and the shorter list wins), angles increasing within (0, limit] as core's check_gradient
 * requires (angles up to 1e-3 past the limit are taken as the limit; otherwise warned and only the
 * first colour is used). Returns the colour count (0: none). */
static uint32_t gradient_part(loader *L, xfile *F, const xmlNode *el, const char *cname, const char *aname,
                              float limit, float (*colours)[3], float *angles)
{
    float *c = NULL, *a = NULL;
    size_t nc = 0, na = 0;
    if (!x3d_get_float_array(L, F, el, cname, 3, &c, &nc) || !x3d_get_float_array(L, F, el, aname, 1, &a, &na)) {
        free(c);
        free(a);
        return 0;
    }
    size_t given = nc;
    if (nc > SY_GRADIENT_MAX) {
        x3d_warn(L, "%s:%d: %s.%s: %zu colours, only the first %u are used", F->path, x3d_line_of(el), x3d_ename(el), cname, nc,
                 (unsigned)SY_GRADIENT_MAX);
        nc = SY_GRADIENT_MAX;
    }
    if (nc && na != nc - 1) {
        size_t keep = na < nc - 1 ? na + 1 : nc;
        if (na != given - 1)
            x3d_warn(L, "%s:%d: %s: %zu %s for %zu %s (expected one fewer angle than colours); %zu colour(s) used", F->path,
                     x3d_line_of(el), x3d_ename(el), na, aname, nc, cname, keep);
        nc = keep;
    }
    float prev = 0.0f;
    for (size_t k = 0; k + 1 < nc; k++) {
        if (a[k] > limit && a[k] <= limit + 1e-3f) a[k] = limit; /* "1.5708", "3.1416" */
        if (!(a[k] > prev && a[k] <= limit)) {
            x3d_warn(L, "%s:%d: %s.%s[%zu] = %g must increase within (0, %g]; only the first %s used", F->path,
                     x3d_line_of(el), x3d_ename(el), aname, k, (double)a[k], (double)limit, cname);
            nc = 1; /* one colour needs no angle */
            break;
        }
        prev = a[k];
    }
    for (size_t k = 0; k < nc; k++) {
        for (int j = 0; j < 3; j++) colours[k][j] = fmaxf(0.0f, fminf(1.0f, c[3 * k + j]));
        if (k + 1 < nc) angles[k] = a[k];
    }
    free(c);
    free(a);
    return (uint32_t)nc;
}

/* Background / TextureBackground: skyColor / skyAngle / groundColor / groundAngle become the
 * world's gradient (SY_BACKGROUND_GRADIENT), shown where nothing is hit; the world's colour is
 * transparent (alpha 0) and nothing of it lights the scene. No skyColor: X3D's default black sky.
 * transparency is not supported with a gradient (warned). Textures of the panorama are ignored. */
sy_result x3d_visit_background(loader *L, xfile *F, const xmlNode *el)
{
    if (L->have_background) return SY_OK; /* the first one is bound */
    L->have_background = true;
    sy_background_data bd = *(const sy_background_data *)sy_object_defaults(SY_TYPE_BACKGROUND);
    memset(bd.color, 0, sizeof bd.color);
    sy_gradient *g = &bd.gradient;
    memset(g, 0, sizeof *g);
    char *sky = x3d_attr(el, "skyColor");
    bool has_sky = sky != NULL;
    xmlFree(sky);
    if (has_sky) g->sky_count = gradient_part(L, F, el, "skyColor", "skyAngle", 3.1415927f, g->sky_color, g->sky_angle);
    else g->sky_count = 1; /* X3D default: skyColor 0 0 0 */
    if (g->sky_count)
        g->ground_count = gradient_part(L, F, el, "groundColor", "groundAngle", 1.5707964f, g->ground_color, g->ground_angle);
    if (x3d_get_float(L, F, el, "transparency", 0.0f) > 0.0f)
        x3d_warn(L, "%s:%d: %s.transparency is not supported; the background is opaque", F->path, x3d_line_of(el), x3d_ename(el));
    char *def = x3d_attr(el, "DEF");
    uint32_t id;
    sy_result r = x3d_new_object(L, SY_TYPE_BACKGROUND, def ? def : "Background", &id);
    xmlFree(def);
    if (!r) {
        bd.name = (char *)sy_background_get(L->scene, (sy_background){id})->name;
        r = sy_background_set(L->scene, (sy_background){id}, &bd, &L->err);
    }
    if (r) {
        sy_error_prefix(&L->err, "%s:%d: Background", F->path, x3d_line_of(el));
        return r;
    }
    L->info->background.id = id;
    return SY_OK;
}
