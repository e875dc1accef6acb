/* sy_x3d_anim.c — X3D's event model for time, as far as it maps onto the scene clock (sy_anim.h):
 * a TimeSensor becomes one animation (clip) named by its DEF, with its cycleInterval as the period
 * and its loop field; every PositionInterpolator and OrientationInterpolator it drives (ROUTE
 * fraction_changed -> set_fraction) becomes a LINEAR sampler whose key times are key x
 * cycleInterval (orientations as quaternions, interpolated along the shorter arc as X3D asks);
 * every ROUTE of such an interpolator's value_changed to a Transform's translation or rotation
 * becomes a channel on that Transform's node. ROUTEs are read per file, so DEF names resolve in the
 * file's own namespace (an Inline's routes see the Inline's DEFs).
 *
 * A TimeSensor runs from scene time 0 (startTime, stopTime, pauseTime and the sensors that start
 * one at a user's touch are not modelled: `sy render --at T` shows where the motion is T seconds
 * after it starts). What does not map is reported once per kind, naming the file and the line:
 * other interpolators, routes to other fields, Transforms with a center or scaleOrientation (their
 * node holds a matrix, which the clock does not drive). Bad interpolators (key and keyValue counts
 * that differ, keys that decrease) are dropped with a warning naming them; equal keys (an X3D jump)
 * become a step one float step later. */
#include "sy_x3d_internal.h"

#include "sy_anim.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* One interpolator a sensor drives and the Transform field it goes to. */
typedef struct drive {
    const xmlNode *sensor, *interp, *target;
    uint32_t path; /* SY_ANIM_TRANSLATION or SY_ANIM_ROTATION */
    int line;      /* of the ROUTE to the target */
    size_t seq;    /* order found (ties in the sorts below) */
} drive;

/* Drives a file may make (each is a channel): beyond it the rest is reported and not played. */
#define X3D_MAX_DRIVES 65536u

/* A ROUTE from an interpolator's value_changed, by the element it comes from (sorted). */
typedef struct from_route {
    const xmlNode *from, *route;
} from_route;

static int cmp_ptr(const void *a, const void *b)
{
    uintptr_t x = (uintptr_t)a, y = (uintptr_t)b;
    return x < y ? -1 : x > y;
}

static int cmp_from(const void *a, const void *b)
{
    const from_route *x = a, *y = b;
    int c = cmp_ptr(x->from, y->from);
    return c ? c : cmp_ptr(x->route, y->route);
}

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

static int cmp_by_interp(const void *a, const void *b)
{
    const drive *x = a, *y = b;
    return cmp_elem_seq(x->interp, y->interp, x->seq, y->seq);
}

typedef struct routes {
    const xmlNode **items;
    size_t count, cap;
} routes;

static bool collect(routes *rs, const xmlNode *el, unsigned depth)
{
    for (const xmlNode *c = el->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE) continue;
        if (!strcmp(x3d_ename(c), "ROUTE")) {
            if (rs->count == rs->cap) {
                size_t cap = rs->cap ? 2 * rs->cap : 16;
                const xmlNode **n = realloc(rs->items, cap * sizeof *n);
                if (!n) return false;
                rs->items = n, rs->cap = cap;
            }
            rs->items[rs->count++] = c;
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

static bool field_is(const char *f, const char *name)
{
    if (!f) return false;
    if (!strncmp(f, "set_", 4)) f += 4;
    return !strcmp(f, name);
}

/* Warns once per key (the loader's once-per-type table). */
static bool once(loader *L, const char *key)
{
    if (xmlHashLookup(L->warned, (const xmlChar *)key)) return false;
    xmlHashAddEntry(L->warned, (const xmlChar *)key, (void *)1);
    return true;
}

/* The sampler of interpolator el, with times key x cycle; false (warned) when it cannot be. */
static bool read_sampler(loader *L, xfile *F, const xmlNode *el, float cycle, bool orientation, sy_anim_sampler_desc *sd,
                         float **times_out, float **values_out)
{
    float *key = NULL, *kv = NULL;
    size_t nk = 0, nv = 0;
    const size_t group = orientation ? 4 : 3;
    *times_out = *values_out = NULL;
    bool ok = x3d_get_float_array(L, F, el, "key", 1, &key, &nk) && x3d_get_float_array(L, F, el, "keyValue", group, &kv, &nv);
    const char *what = x3d_ename(el);
    if (ok && (nk == 0 || nk != nv || nk > SY_ANIM_MAX_KEYS)) {
        x3d_warn(L, "%s:%d: %s: %zu keys and %zu key values (they must be equal and at least one); not played", F->path,
                 x3d_line_of(el), what, nk, nv);
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
    if (ok && orientation) { /* axis-angle to quaternions, in place */
        for (size_t k = 0; k < nk; ++k) {
            float q[4];
            x3d_axis_angle_quat(kv + 4 * k, q);
            memcpy(kv + 4 * k, q, sizeof q);
        }
    }
    if (!ok) {
        free(key);
        free(kv);
        return false;
    }
    *sd = (sy_anim_sampler_desc){SY_INTERP_LINEAR, orientation ? 4u : 3u, (uint32_t)nk, key, kv};
    *times_out = key, *values_out = kv;
    return true;
}

/* Builds the clip of one sensor from the drives that name it (drives[0 .. n-1], same sensor). */
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
    const xmlNode **owner = calloc(n, sizeof *owner);
    float **bufs = calloc(2 * n, sizeof *bufs);
    sy_result r = SY_OK;
    if (!sd || !ch || !owner || !bufs) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s:%d: TimeSensor: out of memory", F->path, x3d_line_of(sensor));
        goto done;
    }
    uint32_t ns = 0, nc = 0;
    qsort((drive *)dv, n, sizeof *dv, cmp_by_interp); /* an interpolator's drives together: one sampler each */
    for (size_t i = 0; i < n; ++i) {
        uint32_t s = ns ? ns - 1 : 0;
        if (!ns || owner[s] != dv[i].interp) {
            s = ns;
            owner[ns] = dv[i].interp;
            if (!read_sampler(L, F, dv[i].interp, cycle, dv[i].path == SY_ANIM_ROTATION, &sd[ns], &bufs[2 * ns],
                              &bufs[2 * ns + 1])) {
                while (i + 1 < n && dv[i + 1].interp == dv[i].interp) ++i; /* dropped: its other drives too */
                continue;
            }
            ns++;
        }
        created *c = x3d_cache_get(L, F, dv[i].target, "node", false);
        if (!c || !c->done || !c->node) continue; /* a Transform outside the loaded scene graph */
        ch[nc++] = (sy_anim_channel){c->node, dv[i].path, s};
    }
    if (!nc) goto done;
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
    }
done:
    for (size_t i = 0; bufs && i < 2 * n; ++i) free(bufs[i]);
    free(bufs);
    free(owner);
    free(ch);
    free(sd);
    return r;
}

/* The interpolator and target of a ROUTE from an interpolator's value_changed, as a drive of its
 * sensor; false (reported once per kind) when it does not map. */
static bool target_of(loader *L, xfile *F, const xmlNode *route, const xmlNode *interp, const char *to_node,
                      const char *to_field, drive *out)
{
    const xmlNode *t = def_of(F, to_node);
    if (!t) {
        x3d_warn(L, "%s:%d: ROUTE to '%s', which is not DEFined in this file; ignored", F->path, x3d_line_of(route),
                 to_node ? to_node : "");
        return false;
    }
    bool position = !strcmp(x3d_ename(interp), "PositionInterpolator");
    const char *want = position ? "translation" : "rotation";
    if (strcmp(x3d_ename(t), "Transform") != 0 || !field_is(to_field, want)) {
        char key[160];
        snprintf(key, sizeof key, "route %s -> %s.%s", x3d_ename(interp), x3d_ename(t), to_field ? to_field : "");
        if (once(L, key))
            x3d_warn(L, "%s:%d: ROUTE from a %s to %s.%s: not played (the scene clock drives a Transform's %s; reported "
                     "once)",
                     F->path, x3d_line_of(route), x3d_ename(interp), x3d_ename(t), to_field ? to_field : "", want);
        return false;
    }
    float c[3] = {0, 0, 0}, so[4] = {0, 0, 1, 0};
    x3d_get_floats(L, F, t, "center", c, 3);
    x3d_get_floats(L, F, t, "scaleOrientation", so, 4);
    if (c[0] != 0.0f || c[1] != 0.0f || c[2] != 0.0f || (so[3] != 0.0f && fmodf(so[3], 2.0f * PI_F) != 0.0f)) {
        x3d_warn(L, "%s:%d: ROUTE to the %s of a Transform with a center or scaleOrientation (line %d): not played", F->path,
                 x3d_line_of(route), want, x3d_line_of(t));
        return false;
    }
    out->interp = interp;
    out->target = t;
    out->path = position ? SY_ANIM_TRANSLATION : SY_ANIM_ROTATION;
    out->line = x3d_line_of(route);
    return true;
}

sy_result x3d_load_animations(loader *L, xfile *F, const xmlNode *scene)
{
    routes rs = {0};
    drive *dv = NULL;
    from_route *vr = NULL;
    size_t nd = 0, cap = 0, nv = 0;
    sy_result r = SY_OK;
    if (!collect(&rs, scene, 0)) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
        goto done;
    }
    if (!rs.count) goto done;
    /* the interpolators' value_changed routes, sorted by where they come from (O(R log R) joins) */
    if (!(vr = malloc(rs.count * sizeof *vr))) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
        goto done;
    }
    for (size_t i = 0; i < rs.count; ++i) {
        char *fn = x3d_attr(rs.items[i], "fromNode"), *ff = x3d_attr(rs.items[i], "fromField");
        const xmlNode *from = def_of(F, fn);
        if (from && ff && !strcmp(ff, "value_changed")) vr[nv++] = (from_route){from, rs.items[i]};
        xmlFree(fn), xmlFree(ff);
    }
    qsort(vr, nv, sizeof *vr, cmp_from);
    /* every sensor -> interpolator route, joined with that interpolator's routes to Transforms */
    bool capped = false;
    for (size_t i = 0; i < rs.count && !r && !capped; ++i) {
        const xmlNode *ra = rs.items[i];
        char *fn = x3d_attr(ra, "fromNode"), *ff = x3d_attr(ra, "fromField"), *tn = x3d_attr(ra, "toNode"),
             *tf = x3d_attr(ra, "toField");
        const xmlNode *sensor = def_of(F, fn), *interp = def_of(F, tn);
        bool from_sensor = sensor && !strcmp(x3d_ename(sensor), "TimeSensor") && ff && !strcmp(ff, "fraction_changed");
        if (from_sensor && interp && field_is(tf, "fraction")) {
            if (!x3d_name_in(x3d_ename(interp), "PositionInterpolator|OrientationInterpolator")) {
                char key[96];
                snprintf(key, sizeof key, "interpolator %s", x3d_ename(interp));
                if (once(L, key))
                    x3d_warn(L, "%s:%d: %s: not played (the scene clock plays Position- and OrientationInterpolators; "
                             "reported once)", F->path, x3d_line_of(interp), x3d_ename(interp));
            } else {
                size_t lo = 0, hi = nv; /* the first value_changed route from interp */
                while (lo < hi) {
                    size_t mid = lo + (hi - lo) / 2;
                    if (cmp_ptr(vr[mid].from, interp) < 0) lo = mid + 1;
                    else hi = mid;
                }
                for (size_t j = lo; j < nv && vr[j].from == interp && !r; ++j) {
                    const xmlNode *rb = vr[j].route;
                    char *btn = x3d_attr(rb, "toNode"), *btf = x3d_attr(rb, "toField");
                    drive d = {.sensor = sensor, .seq = nd};
                    if (target_of(L, F, rb, interp, btn, btf, &d)) {
                        if (nd == X3D_MAX_DRIVES) {
                            x3d_warn(L, "%s:%d: more than %u interpolator routes to Transforms; the rest is not played",
                                     F->path, x3d_line_of(rb), X3D_MAX_DRIVES);
                            capped = true;
                        } else if (nd == cap) {
                            size_t nc = cap ? 2 * cap : 16;
                            drive *p = realloc(dv, nc * sizeof *p);
                            if (!p) r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
                            else dv = p, cap = nc;
                        }
                        if (!r && !capped) dv[nd++] = d;
                    }
                    xmlFree(btn), xmlFree(btf);
                    if (capped) break;
                }
            }
        }
        xmlFree(fn), xmlFree(ff), xmlFree(tn), xmlFree(tf);
    }
    /* one clip per sensor, in the sensors' document order */
    if (!r && nd) qsort(dv, nd, sizeof *dv, cmp_by_sensor);
    for (size_t i = 0; i < nd && !r;) {
        size_t k = i + 1;
        while (k < nd && dv[k].sensor == dv[i].sensor) ++k;
        r = build_clip(L, F, dv + i, k - i);
        i = k;
    }
done:
    free(vr);
    free(dv);
    free(rs.items);
    return r;
}
