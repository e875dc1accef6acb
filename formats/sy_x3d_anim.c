/* sy_x3d_anim.c — X3D's event model for time, as far as it maps onto the scene clock (sy_anim.h):
 * a TimeSensor becomes one animation (clip) named by its DEF, with its cycleInterval as the period
 * and its loop field; every interpolator it drives (ROUTE fraction_changed -> set_fraction) becomes
 * LINEAR samplers whose key times are key x cycleInterval, and every ROUTE of that interpolator's
 * value_changed to a field the scene maps becomes a channel:
 *   PositionInterpolator     -> Transform translation / scale, Viewpoint position, Point- and
 *                               SpotLight location (node translation), Directional- and SpotLight
 *                               direction (node rotation: X3D's linearly interpolated direction,
 *                               sampled at X3D_HSV_STEPS points per key interval as the rotation of
 *                               -Z onto it, slerped between them);
 *   OrientationInterpolator  -> Transform rotation, Viewpoint orientation (quaternions, the shorter
 *                               arc as X3D asks);
 *   ColorInterpolator        -> Material diffuseColor / emissiveColor, PhysicalMaterial baseColor /
 *                               emissiveColor, UnlitMaterial emissiveColor (the material of every
 *                               Shape that uses the Material, where the colour shows), light color;
 *                               X3D interpolates colours in HSV: each key interval is sampled at
 *                               X3D_HSV_STEPS points along the HSV path (hue the shorter way round),
 *                               linear in RGB between them (interpolators of more than
 *                               X3D_RESAMPLE_KEYS keys: RGB between the keys);
 *   ScalarInterpolator       -> Material / PhysicalMaterial / UnlitMaterial transparency (base
 *                               colour alpha = 1 - value), PhysicalMaterial metallic / roughness,
 *                               light intensity (scaled as the loader scales the light's, sy_x3d.h),
 *                               Viewpoint fieldOfView (camera yfov);
 *   CoordinateInterpolator   -> Coordinate.point: x3d_scan_morphs (sy_x3d_morphs.c) finds such
 *                               Coordinates before the walk, x3d_emit gives every primitive built on one a morph target per
 *                               key (its points; normals generated again per key where the geometry
 *                               generates them), and each node showing such a mesh gets a weights
 *                               channel whose key k is the k-th unit vector (LINEAR weights blend
 *                               consecutive keys exactly as X3D interpolates the points; at most
 *                               SY_MORPH_MAX_TARGETS keys); the mirror deforms it for every back-end;
 *   NormalInterpolator       -> Normal.vector: the same, as normal deltas (geometry whose every corner
 *                               has an explicit normal; with a CoordinateInterpolator on the same
 *                               geometry only when both have the same keys, one channel for both);
 *   CoordinateInterpolator2D -> TextureCoordinate.point, and PositionInterpolator2D ->
 *                               TextureTransform translation / scale / center: the same, as texture
 *                               coordinate deltas (target_texcoords0, sy_objects.h): each key's
 *                               coordinates through the TextureTransform (X3D's transform is affine in
 *                               each of those fields, so LINEAR weights of consecutive keys give exactly
 *                               the interpolated field's coordinates); ScalarInterpolator ->
 *                               TextureTransform.rotation the same way, its keys made dense first
 *                               (at most X3D_TEX_ROTATION_STEP apart: the blend of two keys'
 *                               coordinates is a chord of the rotation); polygon geometry and (the
 *                               TextureTransform's fields) the primitives Box, Sphere, Cone, Cylinder
 *                               (Text keeps its), not with moving points on the same geometry; one
 *                               interpolator per TextureCoordinate / TextureTransform.
 * ROUTEs are read per file, so DEF names resolve in the file's own namespace (an Inline's routes
 * see the Inline's DEFs).
 *
 * A TimeSensor runs from scene time 0 (startTime, stopTime, pauseTime and the sensors that start
 * one at a user's touch are not modelled: `sy render --at T` shows where the motion is T seconds
 * after it starts). Routes are checked before anything plays, each problem a warning naming the
 * file and the ROUTE's line: a route from or to a name this file does not DEFine; a route whose
 * fields' types differ (SFVec3f into SFColor: X3D forbids it); a route that closes a loop of routes
 * (X3D passes one event per route per timestamp, so a loop never runs away; the clock has no event
 * cascade at all, and the route is dropped). What has no target here is reported once per kind:
 * mapped-but-not-animated fields (Material.shininess, Transform.center, ...), scale routes to a Transform with a scaleOrientation (routes to a Transform with a center
 * play: x3d_pivot). Bad interpolators (key and keyValue counts that differ, keys that decrease,
 * values that are not finite) are dropped with a warning naming them (file, line, type and DEF);
 * equal keys (an X3D jump) become a step one float step later. Several routes into one
 * field at one time: the channels apply in clip order (the last sensor's in the file wins), as the
 * one-event-per-route rule leaves it to the order events arrive. */
#include "sy_x3d_internal.h"

#include "sy_anim.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* X3D field types of what interpolators send and what they are routed to. */
enum { T_NONE, T_SFFLOAT, T_SFVEC2F, T_SFVEC3F, T_SFCOLOR, T_SFROTATION, T_MFVEC3F, T_MFVEC2F };
static const char *const type_names[] = {"?", "SFFloat", "SFVec2f", "SFVec3f", "SFColor", "SFRotation", "MFVec3f", "MFVec2f"};

/* What a routed value becomes on the way into its sampler. */
enum { CONV_NONE, CONV_AXIS_ANGLE, CONV_DIRECTION, CONV_HSV, CONV_ONE_MINUS, CONV_SCALE, CONV_ONE_HOT, CONV_OFFSET };

/* Key intervals of a ColorInterpolator (and of directions) are sampled at this many steps along
 * X3D's path: HSV for colours, the normalised straight line for directions. */
#define X3D_HSV_STEPS 16u
#define X3D_RESAMPLE_KEYS 1024u

/* What a target field does: a node path, a material path (through the Material's links), a light
 * or camera field, or nothing (reported). */
enum { W_NONE, W_TRANSLATION, W_ROTATION, W_SCALE, W_DIRECTION, W_FOV, W_LIGHT_COLOR, W_LIGHT_INTENSITY, W_DIFFUSE,
       W_EMISSIVE, W_TRANSPARENCY, W_METALLIC, W_ROUGHNESS, W_MORPH };

typedef struct field_map {
    const char *nodes, *fields; /* '|'-separated */
    uint8_t type, what;
} field_map;

static const field_map field_maps[] = {
    {"Transform", "translation", T_SFVEC3F, W_TRANSLATION},
    {"Transform", "rotation", T_SFROTATION, W_ROTATION},
    {"Transform", "scale", T_SFVEC3F, W_SCALE},
    {"Transform", "center", T_SFVEC3F, W_NONE},
    {"Transform", "scaleOrientation", T_SFROTATION, W_NONE},
    {"Viewpoint|OrthoViewpoint", "position", T_SFVEC3F, W_TRANSLATION},
    {"Viewpoint|OrthoViewpoint", "centerOfRotation", T_SFVEC3F, W_NONE},
    {"Viewpoint|OrthoViewpoint", "orientation", T_SFROTATION, W_ROTATION},
    {"Viewpoint", "fieldOfView", T_SFFLOAT, W_FOV},
    {"DirectionalLight|PointLight|SpotLight", "color", T_SFCOLOR, W_LIGHT_COLOR},
    {"DirectionalLight|PointLight|SpotLight", "intensity", T_SFFLOAT, W_LIGHT_INTENSITY},
    {"DirectionalLight|PointLight|SpotLight", "ambientIntensity", T_SFFLOAT, W_NONE},
    {"PointLight|SpotLight", "location", T_SFVEC3F, W_TRANSLATION},
    {"PointLight|SpotLight", "attenuation", T_SFVEC3F, W_NONE},
    {"PointLight|SpotLight", "radius", T_SFFLOAT, W_NONE},
    {"SpotLight", "beamWidth|cutOffAngle", T_SFFLOAT, W_NONE},
    {"DirectionalLight|SpotLight", "direction", T_SFVEC3F, W_DIRECTION},
    {"Material", "diffuseColor", T_SFCOLOR, W_DIFFUSE},
    {"PhysicalMaterial", "baseColor", T_SFCOLOR, W_DIFFUSE},
    {"Material|PhysicalMaterial|UnlitMaterial", "emissiveColor", T_SFCOLOR, W_EMISSIVE},
    {"Material|PhysicalMaterial|UnlitMaterial", "transparency", T_SFFLOAT, W_TRANSPARENCY},
    {"PhysicalMaterial", "metallic", T_SFFLOAT, W_METALLIC},
    {"PhysicalMaterial", "roughness", T_SFFLOAT, W_ROUGHNESS},
    {"Material", "specularColor", T_SFCOLOR, W_NONE},
    {"Material", "shininess|ambientIntensity|occlusionStrength|normalScale", T_SFFLOAT, W_NONE},
    {"Coordinate|CoordinateDouble", "point", T_MFVEC3F, W_MORPH},
    {"Normal", "vector", T_MFVEC3F, W_MORPH},
    {"TextureCoordinate", "point", T_MFVEC2F, W_MORPH},
    {"TextureTransform", "translation|scale|center", T_SFVEC2F, W_MORPH},
    {"TextureTransform", "rotation", T_SFFLOAT, W_MORPH},
};

/* The interpolators: value type, key value group, and whether the clock plays them. */
typedef struct interp_kind {
    const char *name;
    uint8_t type, group;
    bool played;
} interp_kind;

static const interp_kind interp_kinds[] = {
    {"PositionInterpolator", T_SFVEC3F, 3, true},    {"OrientationInterpolator", T_SFROTATION, 4, true},
    {"ColorInterpolator", T_SFCOLOR, 3, true},       {"ScalarInterpolator", T_SFFLOAT, 1, true},
    {"PositionInterpolator2D", T_SFVEC2F, 2, true},  {"CoordinateInterpolator", T_MFVEC3F, 3, true},
    {"NormalInterpolator", T_MFVEC3F, 3, true},     {"CoordinateInterpolator2D", T_MFVEC2F, 2, true},
};

static const interp_kind *kind_of(const xmlNode *el)
{
    for (size_t i = 0; i < sizeof interp_kinds / sizeof interp_kinds[0]; ++i)
        if (!strcmp(x3d_ename(el), interp_kinds[i].name)) return &interp_kinds[i];
    return NULL;
}

/* One channel a sensor drives: interpolator, what its values become, the target object and path. */
typedef struct drive {
    const xmlNode *sensor, *interp, *route;
    uint32_t path, target; /* sy_anim_path, the object's id */
    uint8_t conv;          /* CONV_* */
    float scale;           /* CONV_SCALE */
    float offset[3];       /* CONV_OFFSET: added to each value (a Transform's center, x3d_pivot) */
    uint32_t fix_light;    /* a point / spot light whose intensity x3d_fix_light_animations scales, else 0 */
    size_t scale_index;    /* CONV_ONE_HOT: the L->morphs entry */
    size_t seq;            /* order found (ties in the sorts below) */
} drive;

/* Drives a file may make (each is a channel): beyond it the rest is reported and not played. */
#define X3D_MAX_DRIVES 65536u

/* A node showing a mesh (x3d_load_animations sorts them by mesh when the file has morphs). */
typedef struct mesh_node {
    uint32_t mesh, node;
} mesh_node;

typedef struct drives {
    drive *items;
    size_t count, cap;
    bool capped;
    mesh_node *shown; /* the loader's nodes that show a mesh, by mesh (NULL: no morphs) */
    size_t shown_count;
} drives;

static int cmp_mesh_node(const void *a, const void *b)
{
    const mesh_node *x = a, *y = b;
    if (x->mesh != y->mesh) return x->mesh < y->mesh ? -1 : 1;
    return x->node < y->node ? -1 : x->node > y->node;
}

/* A ROUTE with its ends resolved: from / to elements (NULL: not DEFined), fields, dropped. */
typedef struct route {
    const xmlNode *el, *from, *to;
    char *ff, *tf;
    bool dropped;
} route;

static int cmp_ptr(const void *a, const void *b)
{
    uintptr_t x = (uintptr_t)a, y = (uintptr_t)b;
    return x < y ? -1 : x > y;
}

int x3d_cmp_ptr_el(const void *a, const void *b) { return cmp_ptr(*(const void *const *)a, *(const void *const *)b); }

/* by element line, element, then the order found: a deterministic order that follows the file */
static int cmp_elem_seq(const xmlNode *ea, const xmlNode *eb, size_t sa, size_t sb)
{
    int la = x3d_line_of(ea), lb = x3d_line_of(eb);
    if (la != lb) return la < lb ? -1 : 1;
    int c = cmp_ptr(ea, eb);
    return c ? c : (sa < sb ? -1 : sa > sb);
}

static int cmp_by_sensor(const void *a, const void *b)
{
    const drive *x = a, *y = b;
    return cmp_elem_seq(x->sensor, y->sensor, x->seq, y->seq);
}

/* an interpolator's drives together, those with the same conversion next to each other (one sampler) */
static int cmp_by_sampler(const void *a, const void *b)
{
    const drive *x = a, *y = b;
    int c = cmp_elem_seq(x->interp, y->interp, 0, 0);
    if (c) return c;
    if (x->conv != y->conv) return x->conv < y->conv ? -1 : 1;
    if (x->scale != y->scale) return x->scale < y->scale ? -1 : 1;
    if (x->fix_light != y->fix_light) return x->fix_light < y->fix_light ? -1 : 1;
    if (x->scale_index != y->scale_index) return x->scale_index < y->scale_index ? -1 : 1;
    int o = memcmp(x->offset, y->offset, sizeof x->offset);
    if (o) return o;
    return x->seq < y->seq ? -1 : x->seq > y->seq;
}

static bool same_sampler(const drive *a, const drive *b)
{
    return a->interp == b->interp && a->conv == b->conv && a->scale == b->scale && a->fix_light == b->fix_light &&
           a->scale_index == b->scale_index && !memcmp(a->offset, b->offset, sizeof a->offset);
}

typedef x3d_elems elems;

bool x3d_elems_push(x3d_elems *rs, const xmlNode *c)
{
    if (!sy_array_reserve(&rs->items, rs->count, &rs->cap, sizeof *rs->items, 16)) return false;
    rs->items[rs->count++] = c;
    return true;
}

static bool collect(elems *rs, const xmlNode *el, unsigned depth)
{
    for (const xmlNode *c = el->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE) continue;
        if (!strcmp(x3d_ename(c), "ROUTE")) {
            if (!x3d_elems_push(rs, c)) return false;
        } else if (depth < 256 && !x3d_name_in(x3d_ename(c), "ProtoDeclare|ExternProtoDeclare|Script")) {
            if (!collect(rs, c, depth + 1)) return false;
        }
    }
    return true;
}

/* The element a DEF name stands for in this file, or NULL. */
static const xmlNode *def_of(xfile *F, const char *name)
{
    return name ? xmlHashLookup(F->defs, (const xmlChar *)name) : NULL;
}

bool x3d_field_is(const char *f, const char *name)
{
    if (!f) return false;
    if (!strncmp(f, "set_", 4)) f += 4;
    size_t n = strlen(name);
    return !strncmp(f, name, n) && (!f[n] || !strcmp(f + n, "_changed"));
}

static bool field_in(const char *f, const char *list)
{
    char one[64];
    for (const char *p = list; *p;) {
        const char *bar = strchr(p, '|');
        size_t n = bar ? (size_t)(bar - p) : strlen(p);
        if (n < sizeof one) {
            memcpy(one, p, n);
            one[n] = '\0';
            if (x3d_field_is(f, one)) return true;
        }
        p += n + (bar ? 1 : 0);
    }
    return false;
}

/* Warns once per key (the loader's once-per-type table). */
static bool once(loader *L, const char *key)
{
    if (xmlHashLookup(L->warned, (const xmlChar *)key)) return false;
    xmlHashAddEntry(L->warned, (const xmlChar *)key, (void *)1);
    return true;
}

/* >>loops: routes that close a cycle of routes (a back edge of a depth-first walk) are dropped */

typedef struct edge {
    const xmlNode *from;
    size_t route;
} edge;

static int cmp_edge(const void *a, const void *b)
{
    const edge *x = a, *y = b;
    int c = cmp_ptr(x->from, y->from);
    return c ? c : (x->route < y->route ? -1 : x->route > y->route);
}

/* The first edge from el in e[0 .. n-1] (sorted), n when none. */
static size_t first_edge(const edge *e, size_t n, const xmlNode *el)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (cmp_ptr(e[mid].from, el) < 0) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* Element states of the walk, by address in a sorted array of the route ends. */
typedef struct vstate {
    const xmlNode *el;
    uint8_t state; /* 0 new, 1 on the walk's stack, 2 done */
} vstate;

static int cmp_vstate(const void *a, const void *b) { return cmp_ptr(((const vstate *)a)->el, ((const vstate *)b)->el); }

static vstate *state_of(vstate *v, size_t n, const xmlNode *el)
{
    vstate key = {el, 0};
    return bsearch(&key, v, n, sizeof *v, cmp_vstate);
}

/* Drops (warned) the routes that close loops: O(R log R), iterative (no recursion on untrusted depth). */
static sy_result drop_loops(loader *L, xfile *F, route *rt, size_t nr)
{
    edge *e = malloc((nr + 1) * sizeof *e);
    vstate *v = malloc((2 * nr + 1) * sizeof *v);
    size_t *stack = malloc((nr + 1) * sizeof *stack); /* the walk: the edge index to try next, per element */
    const xmlNode **stack_el = malloc((nr + 1) * sizeof *stack_el);
    sy_result r = SY_OK;
    if (!e || !v || !stack || !stack_el) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
        goto done;
    }
    size_t ne = 0, nv = 0;
    for (size_t i = 0; i < nr; ++i) {
        if (rt[i].dropped) continue;
        e[ne++] = (edge){rt[i].from, i};
        v[nv++] = (vstate){rt[i].from, 0};
        v[nv++] = (vstate){rt[i].to, 0};
    }
    qsort(e, ne, sizeof *e, cmp_edge);
    qsort(v, nv, sizeof *v, cmp_vstate);
    size_t u = 0; /* unique */
    for (size_t i = 0; i < nv; ++i)
        if (!u || v[u - 1].el != v[i].el) v[u++] = v[i];
    nv = u;
    for (size_t s0 = 0; s0 < nv; ++s0) {
        if (v[s0].state) continue;
        size_t depth = 0;
        stack_el[0] = v[s0].el;
        stack[0] = first_edge(e, ne, v[s0].el);
        v[s0].state = 1;
        while (depth != (size_t)-1) {
            const xmlNode *at = stack_el[depth];
            size_t k = stack[depth];
            if (k < ne && e[k].from == at) {
                stack[depth]++;
                route *ro = &rt[e[k].route];
                vstate *w = state_of(v, nv, ro->to);
                if (w->state == 1) { /* back to an element on the walk: this route closes a loop */
                    ro->dropped = true;
                    x3d_warn(L, "%s:%d: ROUTE from %s.%s to %s.%s closes a loop of routes; dropped (X3D passes one event "
                             "per route per timestamp)", F->path, x3d_line_of(ro->el), x3d_ename(ro->from), ro->ff,
                             x3d_ename(ro->to), ro->tf);
                } else if (w->state == 0) {
                    w->state = 1;
                    ++depth;
                    stack_el[depth] = ro->to;
                    stack[depth] = first_edge(e, ne, ro->to);
                }
            } else {
                state_of(v, nv, at)->state = 2;
                --depth;
            }
        }
    }
done:
    free(e);
    free(v);
    free(stack);
    free(stack_el);
    return r;
}

/* >>samplers */

static void rgb_to_hsv(const float c[3], float hsv[3])
{
    float mx = fmaxf(c[0], fmaxf(c[1], c[2])), mn = fminf(c[0], fminf(c[1], c[2])), d = mx - mn, h = 0.0f;
    if (d > 0.0f) {
        if (mx == c[0]) h = fmodf((c[1] - c[2]) / d, 6.0f);
        else if (mx == c[1]) h = (c[2] - c[0]) / d + 2.0f;
        else h = (c[0] - c[1]) / d + 4.0f;
        if (h < 0.0f) h += 6.0f;
    }
    hsv[0] = h; /* sextants, [0, 6) */
    hsv[1] = mx > 0.0f ? d / mx : 0.0f;
    hsv[2] = mx;
}

static void hsv_to_rgb(const float hsv[3], float c[3])
{
    float h = fmodf(hsv[0], 6.0f), s = hsv[1], v = hsv[2];
    if (h < 0.0f) h += 6.0f;
    int i = (int)floorf(h);
    float f = h - (float)i, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    switch (i % 6) {
    case 0: c[0] = v, c[1] = t, c[2] = p; break;
    case 1: c[0] = q, c[1] = v, c[2] = p; break;
    case 2: c[0] = p, c[1] = v, c[2] = t; break;
    case 3: c[0] = p, c[1] = q, c[2] = v; break;
    case 4: c[0] = t, c[1] = p, c[2] = v; break;
    default: c[0] = v, c[1] = p, c[2] = q; break;
    }
}

/* X3D's HSV interpolation of colours a and b at u in [0, 1]: hue the shorter way round (a grey end
 * takes the other end's hue), saturation and value linear. */
static void hsv_lerp(const float a[3], const float b[3], float u, float out[3])
{
    float ha[3], hb[3], h[3];
    rgb_to_hsv(a, ha);
    rgb_to_hsv(b, hb);
    if (ha[1] == 0.0f) ha[0] = hb[0];
    if (hb[1] == 0.0f) hb[0] = ha[0];
    float dh = hb[0] - ha[0];
    if (dh > 3.0f) dh -= 6.0f;
    if (dh < -3.0f) dh += 6.0f;
    h[0] = ha[0] + u * dh;
    h[1] = ha[1] + u * (hb[1] - ha[1]);
    h[2] = ha[2] + u * (hb[2] - ha[2]);
    hsv_to_rgb(h, out);
}

/* The weights sampler of a CoordinateInterpolator's morph targets (x3d_scan_morphs read its keys,
 * m->key: a rotation's made dense there): one weight per key, key k's value the k-th unit vector,
 * so LINEAR blends consecutive keys as X3D interpolates their points. Equal keys jump one float
 * step later, as in read_sampler. */
static int read_one_hot(loader *L, xfile *F, const drive *d, float cycle, sy_anim_sampler_desc *sd, float **times_out,
                        float **values_out)
{
    const morph_src *m = &L->morphs[d->scale_index];
    size_t nk = m->keys;
    *times_out = *values_out = NULL;
    float *key = malloc(nk * sizeof *key);
    if (!key) {
        sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
        return -1;
    }
    memcpy(key, m->key, nk * sizeof *key);
    float prev = -INFINITY;
    for (size_t k = 0; k < nk; ++k) {
        float raw = key[k], t = raw * cycle;
        if (!isfinite(t) || raw < prev) {
            x3d_warn(L, "%s:%d: %s: key %zu (%g) %s; not played", F->path, x3d_line_of(m->interp), x3d_ename(m->interp), k,
                     (double)raw, isfinite(t) ? "is less than the key before it" : "is not finite");
            free(key);
            return 0;
        }
        prev = raw;
        key[k] = k && !(t > key[k - 1]) ? nextafterf(key[k - 1], INFINITY) : t;
    }
    float *ov = calloc(nk * nk, sizeof *ov);
    if (!ov) {
        free(key);
        sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
        return -1;
    }
    for (size_t k = 0; k < nk; ++k) ov[k * nk + k] = 1.0f;
    *sd = (sy_anim_sampler_desc){SY_INTERP_LINEAR, (uint32_t)nk, (uint32_t)nk, key, ov};
    *times_out = key, *values_out = ov;
    return 1;
}

/* Between key values a and b at u, as X3D interpolates them, into the sampler's value o: colours
 * in HSV (CONV_HSV), directions linearly and then as the rotation of -Z onto the direction
 * (CONV_DIRECTION, 4 components). */
static void sample_at(uint8_t conv, const float a[3], const float b[3], float u, float *o)
{
    if (conv == CONV_HSV) {
        hsv_lerp(a, b, u, o);
        return;
    }
    float v[3] = {a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]), a[2] + u * (b[2] - a[2])};
    x3d_quat_from_neg_z(v, o);
}

/* The sampler of interpolator el for drive d, with times key x cycle: 1, or 0 (warned) when it
 * cannot be, -1 out of memory (in L->err). times / values are malloc()ed into *times_out, *values_out. */
static int read_sampler(loader *L, xfile *F, const drive *d, float cycle, sy_anim_sampler_desc *sd, float **times_out,
                         float **values_out)
{
    const xmlNode *el = d->interp;
    const interp_kind *ik = kind_of(el);
    float *key = NULL, *kv = NULL, *ot = NULL, *ov = NULL;
    if (d->conv == CONV_ONE_HOT) return read_one_hot(L, F, d, cycle, sd, times_out, values_out);
    size_t nk = 0, nv = 0;
    const size_t group = ik->group;
    *times_out = *values_out = NULL;
    bool ok = x3d_get_float_array(L, F, el, "key", 1, &key, &nk) && x3d_get_float_array(L, F, el, "keyValue", group, &kv, &nv);
    const char *what = x3d_ename(el);
    if (ok && (nk == 0 || nk != nv || nk > SY_ANIM_MAX_KEYS)) {
        x3d_warn(L, "%s:%d: %s: %zu keys and %zu key values (they must be equal, at least one and at most %u); not played",
                 F->path, x3d_line_of(el), what, nk, nv, SY_ANIM_MAX_KEYS);
        ok = false;
    }
    float prev = -INFINITY;
    for (size_t k = 0; ok && k < nk; ++k) {
        float raw = key[k], t = raw * cycle;
        if (!isfinite(t) || raw < prev) {
            x3d_warn(L, "%s:%d: %s: key %zu (%g) %s; not played", F->path, x3d_line_of(el), what, k, (double)raw,
                     isfinite(t) ? "is less than the key before it" : "is not finite");
            ok = false;
            break;
        }
        prev = raw;
        /* equal keys: X3D's jump, one float step later (the clock's times increase strictly) */
        key[k] = k && !(t > key[k - 1]) ? nextafterf(key[k - 1], INFINITY) : t;
    }
    for (size_t k = 0; ok && k < nk * group; ++k)
        if (!isfinite(kv[k])) {
            x3d_warn(L, "%s:%d: %s: key value %zu is not finite; not played", F->path, x3d_line_of(el), what, k / group);
            ok = false;
        }
    uint32_t comps = d->conv == CONV_AXIS_ANGLE || d->conv == CONV_DIRECTION ? 4u : (uint32_t)group;
    size_t nout = nk;
    bool resample = (d->conv == CONV_HSV || d->conv == CONV_DIRECTION) && nk > 1;
    /* up to X3D_RESAMPLE_KEYS keys, X3D_HSV_STEPS samples per interval; beyond, the keys alone (the
     * output stays within a small multiple of the input's size) */
    uint32_t steps = nk <= X3D_RESAMPLE_KEYS ? X3D_HSV_STEPS : 1u;
    if (ok && resample) nout = (nk - 1) * steps + 1;
    bool oom = false;
    if (ok && (!(ot = malloc(nout * sizeof *ot)) || !(ov = malloc(nout * comps * sizeof *ov)))) {
        sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
        ok = false, oom = true;
    }
    if (ok && resample) {
        size_t n = 0;
        for (size_t k = 0; k + 1 < nk; ++k)
            for (uint32_t j = 0; j < steps; ++j) {
                float u = (float)j / (float)steps, t = key[k] + u * (key[k + 1] - key[k]);
                if (n && !(t > ot[n - 1])) continue; /* a jump's interval: too short to sample */
                ot[n] = t;
                sample_at(d->conv, kv + 3 * k, kv + 3 * (k + 1), u, ov + comps * n);
                ++n;
            }
        if (!(key[nk - 1] > ot[n - 1])) --n; /* the last key replaces a sample it does not follow */
        ot[n] = key[nk - 1];
        sample_at(d->conv, kv + 3 * (nk - 1), kv + 3 * (nk - 1), 0.0f, ov + comps * n);
        nout = n + 1;
    } else if (ok) {
        memcpy(ot, key, nk * sizeof *ot);
        for (size_t k = 0; k < nk; ++k) {
            const float *in = kv + group * k;
            float *o = ov + comps * k;
            switch (d->conv) {
            case CONV_AXIS_ANGLE: x3d_axis_angle_quat(in, o); break;
            case CONV_DIRECTION: x3d_quat_from_neg_z(in, o); break;
            case CONV_ONE_MINUS: o[0] = 1.0f - fmaxf(0.0f, fminf(1.0f, in[0])); break;
            case CONV_SCALE: o[0] = fmaxf(0.0f, in[0]) * d->scale; break;
            case CONV_OFFSET:
                for (int a = 0; a < 3; ++a) o[a] = in[a] + d->offset[a];
                break;
            default: memcpy(o, in, group * sizeof(float));
            }
        }
    }
    if (ok && ik->type == T_SFCOLOR) x3d_clamp01(ov, (int)(nout * 3));
    free(key);
    free(kv);
    if (!ok) {
        free(ot);
        free(ov);
        return oom ? -1 : 0;
    }
    *sd = (sy_anim_sampler_desc){SY_INTERP_LINEAR, comps, (uint32_t)nout, ot, ov};
    *times_out = ot, *values_out = ov;
    return 1;
}

/* Builds the clip of one sensor from the drives that name it (dv[0 .. n-1], same sensor). */
static sy_result build_clip(loader *L, xfile *F, drive *dv, size_t n)
{
    const xmlNode *sensor = dv[0].sensor;
    if (!x3d_get_bool(sensor, "enabled", true)) {
        x3d_warn(L, "%s:%d: TimeSensor disabled (enabled false); not played", F->path, x3d_line_of(sensor));
        return SY_OK;
    }
    float cycle = x3d_get_float(L, F, sensor, "cycleInterval", 1.0f);
    if (!(cycle > 0.0f && cycle <= SY_ANIM_MAX_CYCLE)) {
        x3d_warn(L, "%s:%d: TimeSensor cycleInterval %g (above 0, at most %g); not played", F->path, x3d_line_of(sensor),
                 (double)cycle, (double)SY_ANIM_MAX_CYCLE);
        return SY_OK;
    }
    sy_anim_sampler_desc *sd = calloc(n, sizeof *sd);
    sy_anim_channel *ch = calloc(n, sizeof *ch);
    const drive **owner = calloc(n, sizeof *owner);
    float **bufs = calloc(2 * n, sizeof *bufs);
    uint32_t *fix = calloc(n, sizeof *fix); /* per sampler: the light whose intensity it is, or 0 */
    sy_result r = SY_OK;
    if (!sd || !ch || !owner || !bufs || !fix) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s:%d: TimeSensor: out of memory", F->path, x3d_line_of(sensor));
        goto done;
    }
    uint32_t ns = 0, nc = 0;
    qsort(dv, n, sizeof *dv, cmp_by_sampler);
    for (size_t i = 0; i < n && !r; ++i) {
        uint32_t s = ns ? ns - 1 : 0;
        if (!ns || !same_sampler(owner[s], &dv[i])) {
            s = ns;
            owner[ns] = &dv[i];
            int got = read_sampler(L, F, &dv[i], cycle, &sd[ns], &bufs[2 * ns], &bufs[2 * ns + 1]);
            if (got <= 0) {
                if (got < 0) r = SY_ERR_OUT_OF_MEMORY;
                while (i + 1 < n && dv[i + 1].interp == dv[i].interp) ++i; /* dropped: its other drives too */
                continue;
            }
            fix[ns] = dv[i].fix_light;
            ns++;
        }
        ch[nc++] = (sy_anim_channel){dv[i].target, dv[i].path, s};
    }
    if (!nc || r) goto done;
    char *def = x3d_attr(sensor, "DEF");
    sy_animation a;
    sy_error e = {0};
    r = x3d_new_object(L, SY_TYPE_ANIMATION, def ? def : "TimeSensor", &a.id);
    xmlFree(def);
    if (!r && (r = sy_animation_set_clip(L->scene, a, sd, ns, ch, nc, &e)) == SY_OK)
        r = sy_animation_set_timing(L->scene, a, cycle, x3d_get_bool(sensor, "loop", false), &e);
    if (r && r != SY_ERR_OUT_OF_MEMORY) { /* a value the core refuses (out of range): this clip only */
        x3d_warn(L, "%s:%d: TimeSensor: %s; not played", F->path, x3d_line_of(sensor), e.message);
        sy_error de = {0};
        if (sy_object_destroy(L->scene, SY_TYPE_ANIMATION, a.id, &de) == SY_OK) {
            r = SY_OK;
            L->obj_count--; /* x3d_new_object tracked it last */
        }
    } else if (r) {
        L->err = e;
    } else {
        L->info->counts.animations++;
        for (uint32_t s = 0; s < ns && !r; ++s) {
            if (!fix[s]) continue;
            if (!sy_array_reserve(&L->ifix, L->ifix_count, &L->ifix_cap, sizeof *L->ifix, 8)) {
                r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
                break;
            }
            L->ifix[L->ifix_count++] = (intensity_fix){a.id, s, fix[s]};
        }
    }
done:
    for (size_t i = 0; bufs && i < 2 * n; ++i) free(bufs[i]);
    free(bufs);
    free(owner);
    free(ch);
    free(sd);
    free(fix);
    return r;
}

/* >>targets */

static bool push(loader *L, xfile *F, drives *ds, const drive *d)
{
    if (ds->capped) return true;
    if (ds->count == X3D_MAX_DRIVES) {
        x3d_warn(L, "%s:%d: more than %u interpolator routes; the rest is not played", F->path, x3d_line_of(d->route),
                 X3D_MAX_DRIVES);
        ds->capped = true;
        return true;
    }
    if (!sy_array_reserve(&ds->items, ds->count, &ds->cap, sizeof *ds->items, 16)) return false;
    ds->items[ds->count++] = *d;
    return true;
}

/* Reports once per kind that a route's target field does not animate here. */
static void not_played(loader *L, xfile *F, const route *ro, const char *why)
{
    char key[192];
    snprintf(key, sizeof key, "route %s -> %s.%s", x3d_ename(ro->from), x3d_ename(ro->to), ro->tf);
    if (once(L, key))
        x3d_warn(L, "%s:%d: ROUTE from a %s to %s.%s: not played (%s; reported once)", F->path, x3d_line_of(ro->el),
                 x3d_ename(ro->from), x3d_ename(ro->to), ro->tf, why);
}

/* A routed Transform with a center c or a scaleOrientation SR: its node held one matrix,
 * T C R SR S -SR -C, which the clock cannot drive. The first route to it splits it in two: the
 * Transform's node keeps translation T + c, rotation R and (without SR) scale S as fields the
 * clock drives, and a new pivot node under it holds the rest (-C, or SR S -SR -C) and the
 * Transform's children; the static pose is the same matrix product. *c_out gets the center (a
 * route to translation adds it to its values). Returns 0 (nothing to do), 1 (split: center only),
 * 2 (split with a scaleOrientation: scale routes are not played), -1 on failure (L->err set). */
static int x3d_pivot(loader *L, xfile *F, const xmlNode *t, uint32_t node, float c_out[3])
{
    x3d_transform x;
    x3d_read_transform(L, F, t, &x);
    if (!x3d_transform_pivoted(&x)) return 0; /* plain TRS (set_transform) */
    bool has_so = x.so[3] != 1.0f;
    memcpy(c_out, x.c, 3 * sizeof(float));
    created *pc = x3d_cache_get(L, F, t, "pivot", true);
    if (!pc) {
        sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
        return -1;
    }
    if (pc->done) return has_so ? 2 : 1;
    pc->done = true;
    const sy_node_data *nd = sy_node_get(L->scene, (sy_node){node});
    uint32_t nk = 0;
    const uint32_t *kids = nd ? sy_node_children(nd, &nk) : NULL;
    sy_node *moved = nk ? malloc(nk * sizeof *moved) : NULL;
    if (nk && !moved) {
        sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
        return -1;
    }
    for (uint32_t k = 0; k < nk; ++k) moved[k].id = kids[k];
    sy_node p = {0};
    float one[3] = {1, 1, 1}, tc[3] = {x.t[0] + x.c[0], x.t[1] + x.c[1], x.t[2] + x.c[2]};
    sy_mat4 tail = x3d_transform_tail(&x, has_so); /* -C, or SR S -SR -C */
    sy_result r = sy_node_create(L->scene, NULL, &p, &L->err);
    if (!r) r = sy_node_set_children(L->scene, p, moved, nk, &L->err);
    free(moved);
    if (!r) r = sy_node_set_children(L->scene, (sy_node){node}, &p, 1, &L->err);
    if (!r) r = sy_node_set_flags(L->scene, p, SY_NODE_VISIBLE, &L->err);
    if (!r) r = sy_node_set_trs(L->scene, (sy_node){node}, tc, x.r, has_so ? one : x.s, &L->err);
    if (!r) r = sy_node_set_matrix(L->scene, p, &tail, &L->err);
    if (r) {
        sy_error_prefix(&L->err, "%s:%d: Transform (its pivot for a ROUTE)", F->path, x3d_line_of(t));
        return -1;
    }
    L->info->counts.nodes++;
    return has_so ? 2 : 1;
}

/* The drives of route ro (from interpolator ro->from, of kind ik, driven by sensor): appended to ds;
 * false only when out of memory. */
static bool add_targets(loader *L, xfile *F, const route *ro, const xmlNode *sensor, const interp_kind *ik, drives *ds)
{
    const xmlNode *t = ro->to;
    const field_map *fm = NULL;
    for (size_t i = 0; i < sizeof field_maps / sizeof field_maps[0] && !fm; ++i)
        if (x3d_name_in(x3d_ename(t), field_maps[i].nodes) && field_in(ro->tf, field_maps[i].fields)) fm = &field_maps[i];
    if (!fm) {
        not_played(L, F, ro, "the scene clock maps no such field");
        return true;
    }
    if (fm->type != ik->type) {
        x3d_warn(L, "%s:%d: ROUTE from %s.%s (%s) to %s.%s (%s): the types differ; dropped", F->path, x3d_line_of(ro->el),
                 x3d_ename(ro->from), ro->ff, type_names[ik->type], x3d_ename(t), ro->tf, type_names[fm->type]);
        return true;
    }
    if (!ik->played || fm->what == W_NONE) {
        not_played(L, F, ro,
                   !strcmp(x3d_ename(t), "Coordinate") || !strcmp(x3d_ename(t), "Normal") ||
                           !strcmp(x3d_ename(t), "TextureCoordinate") || !strcmp(x3d_ename(t), "TextureTransform")
                       ? "the loader bakes it into the mesh's vertices"
                       : "the scene clock does not animate that field");
        return true;
    }
    drive d = {.sensor = sensor, .interp = ro->from, .route = ro->el, .conv = CONV_NONE, .scale = 1.0f, .seq = ds->count};
    if (fm->what == W_MORPH) { /* the weights of every node showing a mesh built on the Coordinate */
        const morph_src *m = NULL;
        bool other = false; /* another interpolator drives it (x3d_scan_morphs warned) */
        for (size_t i = 0; i < L->morph_count && !m; ++i)
            if (L->morphs[i].coord == t && L->morphs[i].serial == F->serial) {
                if (L->morphs[i].interp == ro->from) m = &L->morphs[i];
                else other = true;
            }
        if (!m && other) return true;
        if (m && m->merged && !m->mesh_count) return true; /* the CoordinateInterpolator's channel plays it */
        if (!m || !m->mesh_count) {
            x3d_warn(L, "%s:%d: ROUTE to %s.%s: no Shape shows that %s (line %d) with the interpolator's points; not played",
                     F->path, x3d_line_of(ro->el), x3d_ename(t), ro->tf, x3d_ename(t), x3d_line_of(t));
            return true;
        }
        d.path = SY_ANIM_WEIGHTS, d.conv = CONV_ONE_HOT, d.scale_index = (size_t)(m - L->morphs);
        for (size_t k = 0; k < m->mesh_count; ++k) { /* the nodes of each mesh: a binary search, then a run */
            size_t lo = 0, hi = ds->shown_count;
            while (lo < hi) {
                size_t mid = lo + (hi - lo) / 2;
                if (ds->shown[mid].mesh < m->meshes[k]) lo = mid + 1;
                else hi = mid;
            }
            for (; lo < ds->shown_count && ds->shown[lo].mesh == m->meshes[k]; ++lo) {
                d.target = ds->shown[lo].node;
                if (!push(L, F, ds, &d)) return false;
            }
        }
        return true;
    }
    if (fm->what == W_DIFFUSE || fm->what == W_EMISSIVE || fm->what == W_TRANSPARENCY || fm->what == W_METALLIC ||
        fm->what == W_ROUGHNESS) {
        bool any = false;
        for (size_t i = 0; i < L->mat_link_count; ++i) {
            const mat_link *ml = &L->mat_links[i];
            if (ml->mat != t || ml->serial != F->serial) continue;
            any = true;
            uint32_t path = fm->what == W_DIFFUSE ? ml->diffuse
                            : fm->what == W_EMISSIVE ? ml->emissive
                            : fm->what == W_TRANSPARENCY ? (uint32_t)SY_ANIM_OPACITY
                            : fm->what == W_METALLIC ? (uint32_t)SY_ANIM_METALLIC
                                                     : (uint32_t)SY_ANIM_ROUGHNESS;
            if (path == X3D_NO_PATH) continue; /* this shape's colour comes from a texture or vertex colours */
            d.path = path, d.target = ml->material;
            d.conv = fm->what == W_DIFFUSE || fm->what == W_EMISSIVE ? (ik->type == T_SFCOLOR ? CONV_HSV : CONV_NONE)
                     : fm->what == W_TRANSPARENCY                   ? CONV_ONE_MINUS
                                                                     : CONV_NONE;
            if (!push(L, F, ds, &d)) return false;
        }
        if (!any)
            x3d_warn(L, "%s:%d: ROUTE to %s.%s: no Shape uses that %s (line %d); not played", F->path, x3d_line_of(ro->el),
                     x3d_ename(t), ro->tf, x3d_ename(t), x3d_line_of(t));
        return true;
    }
    created *c = x3d_cache_get(L, F, t, "node", false);
    const sy_node_data *nd = c && c->done && c->node ? sy_node_get(L->scene, (sy_node){c->node}) : NULL;
    if (!nd) {
        x3d_warn(L, "%s:%d: ROUTE to %s.%s: the %s (line %d) is not in the loaded scene; not played", F->path,
                 x3d_line_of(ro->el), x3d_ename(t), ro->tf, x3d_ename(t), x3d_line_of(t));
        return true;
    }
    bool light = x3d_name_in(x3d_ename(t), "DirectionalLight|PointLight|SpotLight");
    if (light && !nd->light.id) {
        x3d_warn(L, "%s:%d: ROUTE to %s.%s: the light (line %d) is off; not played", F->path, x3d_line_of(ro->el),
                 x3d_ename(t), ro->tf, x3d_line_of(t));
        return true;
    }
    float pivot_c[3] = {0, 0, 0};
    if (!strcmp(x3d_ename(t), "Transform")) {
        int pv = x3d_pivot(L, F, t, c->node, pivot_c);
        if (pv < 0) return false;
        if (pv == 2 && fm->what == W_SCALE) {
            x3d_warn(L, "%s:%d: ROUTE to the %s of a Transform with a scaleOrientation (line %d): not played", F->path,
                     x3d_line_of(ro->el), ro->tf, x3d_line_of(t));
            return true;
        }
    }
    d.target = c->node;
    switch (fm->what) {
    case W_TRANSLATION:
        d.path = SY_ANIM_TRANSLATION;
        if (pivot_c[0] != 0.0f || pivot_c[1] != 0.0f || pivot_c[2] != 0.0f) {
            d.conv = CONV_OFFSET;
            memcpy(d.offset, pivot_c, sizeof d.offset);
        }
        break;
    case W_SCALE: d.path = SY_ANIM_SCALE; break;
    case W_ROTATION: d.path = SY_ANIM_ROTATION, d.conv = CONV_AXIS_ANGLE; break;
    case W_DIRECTION: d.path = SY_ANIM_ROTATION, d.conv = CONV_DIRECTION; break;
    case W_FOV:
        if (!nd->camera.id) return true;
        d.path = SY_ANIM_CAMERA_YFOV, d.target = nd->camera.id;
        break;
    case W_LIGHT_COLOR: d.path = SY_ANIM_LIGHT_COLOR, d.target = nd->light.id, d.conv = CONV_HSV; break;
    default: { /* W_LIGHT_INTENSITY: x pi (sy_x3d.h); point and spot lights also as x3d_finish_lights scales */
        const sy_light_data *ld = sy_light_get(L->scene, nd->light);
        d.path = SY_ANIM_LIGHT_INTENSITY, d.target = nd->light.id, d.conv = CONV_SCALE, d.scale = PI_F;
        if (ld && ld->type != SY_LIGHT_DIRECTIONAL) d.fix_light = nd->light.id;
    }
    }
    return push(L, F, ds, &d);
}

sy_result x3d_load_animations(loader *L, xfile *F, const xmlNode *scene)
{
    elems rs = {0};
    route *rt = NULL;
    edge *vr = NULL;
    drives ds = {0};
    size_t nv = 0;
    sy_result r = SY_OK;
    if (!collect(&rs, scene, 0)) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
        goto done;
    }
    if (!rs.count) goto done;
    if (!(rt = calloc(rs.count, sizeof *rt)) || !(vr = malloc(rs.count * sizeof *vr))) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
        goto done;
    }
    /* every route's ends: one this file does not DEFine drops the route */
    for (size_t i = 0; i < rs.count; ++i) {
        route *ro = &rt[i];
        char *fn = x3d_attr(rs.items[i], "fromNode"), *tn = x3d_attr(rs.items[i], "toNode");
        ro->el = rs.items[i];
        ro->ff = x3d_attr(rs.items[i], "fromField");
        ro->tf = x3d_attr(rs.items[i], "toField");
        ro->from = def_of(F, fn);
        ro->to = def_of(F, tn);
        if (!ro->from || !ro->to || !ro->ff || !ro->tf) {
            ro->dropped = true;
            const char *name = !ro->from ? fn : tn;
            if (!ro->ff || !ro->tf)
                x3d_warn(L, "%s:%d: ROUTE without a fromField or toField; ignored", F->path, x3d_line_of(ro->el));
            else
                x3d_warn(L, "%s:%d: ROUTE %s '%s', which is not DEFined in this file; ignored", F->path,
                         x3d_line_of(ro->el), !ro->from ? "from" : "to", name ? name : "");
        }
        xmlFree(fn), xmlFree(tn);
    }
    if ((r = drop_loops(L, F, rt, rs.count))) goto done;
    if (L->morph_count) { /* the nodes that show each mesh, for the morph weights channels: O(N log N) once */
        if (!(ds.shown = malloc((L->obj_count + 1) * sizeof *ds.shown))) {
            r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
            goto done;
        }
        for (size_t i = 0; i < L->obj_count; ++i) {
            if (L->objs[i].type != SY_TYPE_NODE) continue;
            const sy_node_data *nd = sy_node_get(L->scene, (sy_node){L->objs[i].id});
            if (nd && nd->mesh.id) ds.shown[ds.shown_count++] = (mesh_node){nd->mesh.id, L->objs[i].id};
        }
        if (ds.shown_count) qsort(ds.shown, ds.shown_count, sizeof *ds.shown, cmp_mesh_node);
    }
    /* the interpolators' value_changed routes, sorted by where they come from (O(R log R) joins) */
    for (size_t i = 0; i < rs.count; ++i)
        if (!rt[i].dropped && kind_of(rt[i].from) && !strcmp(rt[i].ff, "value_changed")) vr[nv++] = (edge){rt[i].from, i};
    qsort(vr, nv, sizeof *vr, cmp_edge);
    /* every sensor -> interpolator route, joined with that interpolator's routes to fields */
    for (size_t i = 0; i < rs.count && !r && !ds.capped; ++i) {
        const route *ra = &rt[i];
        if (ra->dropped || strcmp(x3d_ename(ra->from), "TimeSensor") != 0 || strcmp(ra->ff, "fraction_changed") != 0)
            continue;
        const xmlNode *interp = ra->to;
        const interp_kind *ik = kind_of(interp);
        if (!ik || !x3d_field_is(ra->tf, "fraction")) {
            not_played(L, F, ra, ik ? "an interpolator's fraction comes in through set_fraction" : "it is no interpolator");
            continue;
        }
        if (!ik->played) {
            char key[96];
            snprintf(key, sizeof key, "interpolator %s", x3d_ename(interp));
            if (once(L, key))
                x3d_warn(L, "%s:%d: %s: not played (its target is baked into the meshes when loading; reported once)",
                         F->path, x3d_line_of(interp), x3d_ename(interp));
            continue;
        }
        for (size_t j = first_edge(vr, nv, interp); j < nv && vr[j].from == interp && !r && !ds.capped; ++j)
            if (!add_targets(L, F, &rt[vr[j].route], ra->from, ik, &ds))
                r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
    }
    /* routes from interpolators no sensor drives, and other routes, do nothing here: an event
     * cascade needs a sensor to start it (the user's sensors are not modelled) */
    /* one clip per sensor, in the sensors' document order */
    if (!r && ds.count) qsort(ds.items, ds.count, sizeof *ds.items, cmp_by_sensor);
    for (size_t i = 0; i < ds.count && !r;) {
        size_t k = i + 1;
        while (k < ds.count && ds.items[k].sensor == ds.items[i].sensor) ++k;
        r = build_clip(L, F, ds.items + i, k - i);
        i = k;
    }
done:
    for (size_t i = 0; rt && i < rs.count; ++i) xmlFree(rt[i].ff), xmlFree(rt[i].tf);
    free(rt);
    free(vr);
    free(ds.items);
    free(ds.shown);
    free(rs.items);
    return r;
}

/* >>light intensities, once the loader has scaled the lights */

sy_result x3d_fix_light_animations(loader *L)
{
    /* build_clip appends a clip's fixes together: one copy and one set_clip per clip */
    for (size_t i = 0; i < L->ifix_count;) {
        size_t j = i;
        while (j < L->ifix_count && L->ifix[j].animation == L->ifix[i].animation) ++j;
        sy_animation a = {L->ifix[i].animation};
        const sy_animation_data *d = sy_animation_get(L->scene, a);
        uint32_t ns = 0, nc = 0;
        const sy_anim_sampler *sm = d ? sy_animation_samplers(d, &ns) : NULL;
        const sy_anim_channel *ch = d ? sy_animation_channels(d, &nc) : NULL;
        size_t nval = sm ? sy_blob_size(d->values) / sizeof(float) : 0;
        float *vals = sm ? malloc(nval * sizeof *vals) : NULL;
        sy_anim_sampler_desc *sd = sm ? malloc(ns * sizeof *sd) : NULL;
        sy_anim_channel *cc = sm ? malloc((nc + 1) * sizeof *cc) : NULL;
        if (sm && (!vals || !sd || !cc)) {
            free(vals), free(sd), free(cc);
            return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        }
        bool changed = false;
        if (sm) {
            memcpy(vals, sy_blob_data(d->values), nval * sizeof *vals);
            memcpy(cc, ch, nc * sizeof *cc);
        }
        for (size_t f = i; sm && f < j; ++f) { /* each fixed sampler x its light's factor (x3d_finish_lights) */
            float mult = 1.0f;
            for (size_t k = 0; k < L->light_count; ++k)
                if (L->lights[k].light == L->ifix[f].light) mult = L->lights[k].mult;
            if (mult == 1.0f || L->ifix[f].sampler >= ns) continue;
            const sy_anim_sampler *smp = &sm[L->ifix[f].sampler]; /* its own sampler (cmp_by_sampler) */
            for (uint32_t k = 0; k < smp->key_count * smp->components; ++k) vals[smp->values_offset + k] *= mult;
            changed = true;
        }
        if (changed) {
            const float *times = sy_blob_data(d->times);
            for (uint32_t k = 0; k < ns; ++k)
                sd[k] = (sy_anim_sampler_desc){sm[k].interpolation, sm[k].components, sm[k].key_count,
                                               times + sm[k].times_offset, vals + sm[k].values_offset};
            sy_error e = {0};
            if (sy_animation_set_clip(L->scene, a, sd, ns, cc, nc, &e) != SY_OK)
                x3d_warn(L, "light intensity animation: %s; left unscaled", e.message);
        }
        free(vals), free(sd), free(cc);
        i = j;
    }
    return SY_OK;
}
