/* sy_x3d_morphs.c — before the walk of an X3D file, the Coordinates (and texture coordinates,
 * normals, TextureTransforms) that interpolators animate: x3d_scan_morphs finds them through the
 * file's ROUTEs and TimeSensors and keeps their keys in L->morphs, so that x3d_emit gives every
 * primitive built on one a morph target per key (sy_x3d_anim.c turns the routes into the weights
 * channels). Part of the X3D loader (sy_x3d_internal.h). */
#include "sy_x3d_internal.h"

#include "sy_anim.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>morphs: Coordinates that CoordinateInterpolators animate, found before the walk */

typedef struct scan {
    x3d_elems routes;
    xmlHashTablePtr defs; /* DEF -> element (first wins), of the kinds that matter here */
} scan;

static bool scan_collect(scan *sc, const xmlNode *el, unsigned depth)
{
    for (const xmlNode *c = el->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE) continue;
        const char *n = x3d_ename(c);
        if (!strcmp(n, "ROUTE")) {
            if (!x3d_elems_push(&sc->routes, c)) return false;
            continue;
        }
        if (x3d_name_in(n, "ProtoDeclare|ExternProtoDeclare|Script")) continue;
        if (x3d_name_in(n, "Coordinate|CoordinateDouble|CoordinateInterpolator|Normal|NormalInterpolator|TimeSensor|"
                           "TextureCoordinate|TextureTransform|CoordinateInterpolator2D|PositionInterpolator2D|"
                           "ScalarInterpolator")) {
            char *def = x3d_attr(c, "DEF");
            if (def && !xmlHashLookup(sc->defs, (const xmlChar *)def)) xmlHashAddEntry(sc->defs, (const xmlChar *)def, (void *)c);
            xmlFree(def);
        }
        if (depth < 256 && !scan_collect(sc, c, depth + 1)) return false;
    }
    return true;
}

static const xmlNode *scan_def(const scan *sc, const xmlNode *route, const char *attr, const char *kinds)
{
    char *name = x3d_attr(route, attr);
    const xmlNode *el = name ? xmlHashLookup(sc->defs, (const xmlChar *)name) : NULL;
    xmlFree(name);
    return el && x3d_name_in(x3d_ename(el), kinds) ? el : NULL;
}

static bool route_fields(const xmlNode *route, const char *from, const char *to)
{
    char *ff = x3d_attr(route, "fromField"), *tf = x3d_attr(route, "toField");
    bool ok = ff && tf && !strcmp(ff, from) && x3d_field_is(tf, to);
    xmlFree(ff), xmlFree(tf);
    return ok;
}

/* A ScalarInterpolator's keys into a TextureTransform's rotation (*key, *kv: nk raw keys and
 * angles, malloc()ed) made dense: keys added between the file's, linearly in the key and the angle
 * as X3D interpolates them, so that no two are more than X3D_TEX_ROTATION_STEP apart (with at most
 * SY_MORPH_MAX_TARGETS keys in all: a larger step beyond); the angles stored as (angle, 0), the
 * morph sources' texture stride. Keys that decrease are refused later (read_one_hot, naming the
 * file's key): such keys are left as they are. Returns SY_OK with *kv NULL (warned) when the keys
 * are too many, an error when out of memory (in L->err). */
static sy_result dense_rotation(loader *L, xfile *F, const xmlNode *in, const char *def, float **key, float **kv, size_t *nk)
{
    const float *k0 = *key, *v0 = *kv;
    size_t n = *nk;
    bool sorted = true;
    for (size_t k = 0; k + 1 < n && sorted; ++k) sorted = !(k0[k + 1] < k0[k]);
    double total = 0;
    for (size_t k = 0; k + 1 < n; ++k) total += k0[k + 1] > k0[k] ? fabs((double)v0[k + 1] - v0[k]) : 0;
    double step = X3D_TEX_ROTATION_STEP;
    if (n > 1 && total / step + (double)n > SY_MORPH_MAX_TARGETS) step = total / (double)(SY_MORPH_MAX_TARGETS - n);
    if (!sorted) total = 0; /* nothing added: read_one_hot refuses the keys */
    if (n >= SY_MORPH_MAX_TARGETS && total > 0) {
        x3d_warn(L, "%s:%d: ScalarInterpolator '%s': %zu keys into a TextureTransform's rotation leave no room for the keys "
                 "between them (at most %u); not played", F->path, x3d_line_of(in), def ? def : "", n, SY_MORPH_MAX_TARGETS - 1);
        free(*kv);
        *kv = NULL;
        return SY_OK;
    }
    size_t out = n;
    for (size_t k = 0; k + 1 < n && total > 0; ++k)
        if (k0[k + 1] > k0[k]) out += (size_t)ceil(fabs((double)v0[k + 1] - v0[k]) / step - 1e-6) - (v0[k + 1] != v0[k]);
    if (out > SY_MORPH_MAX_TARGETS) out = SY_MORPH_MAX_TARGETS; /* rounding: never reached, a guard */
    float *nkey = malloc(out * sizeof *nkey), *nkv = calloc(out * 2, sizeof *nkv);
    if (!nkey || !nkv) {
        free(nkey), free(nkv);
        return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
    }
    size_t o = 0;
    for (size_t k = 0; k < n && o < out; ++k) {
        nkey[o] = k0[k], nkv[2 * o] = v0[k], ++o;
        if (k + 1 == n || !(k0[k + 1] > k0[k]) || !(total > 0)) continue;
        size_t parts = (size_t)ceil(fabs((double)v0[k + 1] - v0[k]) / step - 1e-6);
        for (size_t j = 1; j < parts && o + (n - k - 1) < out; ++j) {
            double u = (double)j / (double)parts;
            nkey[o] = (float)(k0[k] + u * (k0[k + 1] - k0[k]));
            nkv[2 * o] = (float)(v0[k] + u * (v0[k + 1] - v0[k]));
            if (nkey[o] > nkey[o - 1] && nkey[o] < k0[k + 1]) ++o; /* keys too close for floats: fewer */
        }
    }
    free(*key), free(*kv);
    *key = nkey, *kv = nkv, *nk = o;
    return SY_OK;
}

sy_result x3d_scan_morphs(loader *L, xfile *F, const xmlNode *scene)
{
    scan sc = {{0}, xmlHashCreate(16)};
    const xmlNode **driven = NULL;
    sy_result r = SY_OK;
    if (!sc.defs || !scan_collect(&sc, scene, 0)) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
        goto done;
    }
    size_t nd = 0;
    if (sc.routes.count && !(driven = malloc(sc.routes.count * sizeof *driven))) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
        goto done;
    }
    /* the interpolators a TimeSensor drives */
    for (size_t i = 0; i < sc.routes.count; ++i) {
        const xmlNode *ro = sc.routes.items[i],
                      *in = scan_def(&sc, ro, "toNode", "CoordinateInterpolator|NormalInterpolator|CoordinateInterpolator2D|"
                                                         "PositionInterpolator2D|ScalarInterpolator");
        if (in && scan_def(&sc, ro, "fromNode", "TimeSensor") && route_fields(ro, "fraction_changed", "fraction"))
            driven[nd++] = in;
    }
    if (nd) qsort(driven, nd, sizeof *driven, x3d_cmp_ptr_el);
    for (size_t i = 0; i < sc.routes.count && !r; ++i) {
        const xmlNode *ro = sc.routes.items[i];
        const xmlNode *in = scan_def(&sc, ro, "fromNode", "CoordinateInterpolator|NormalInterpolator|CoordinateInterpolator2D|"
                                                           "PositionInterpolator2D|ScalarInterpolator");
        bool normals = in && !strcmp(x3d_ename(in), "NormalInterpolator");
        bool tc2 = in && !strcmp(x3d_ename(in), "CoordinateInterpolator2D"), pos2 = in && !strcmp(x3d_ename(in), "PositionInterpolator2D");
        bool rot = in && !strcmp(x3d_ename(in), "ScalarInterpolator"); /* into a TextureTransform's rotation */
        const xmlNode *co = scan_def(&sc, ro, "toNode", normals ? "Normal" : tc2 ? "TextureCoordinate" : pos2 || rot ? "TextureTransform"
                                                                          : "Coordinate|CoordinateDouble");
        uint8_t tex = tc2 ? X3D_TEX_POINT : X3D_TEX_NONE;
        if (pos2)
            tex = route_fields(ro, "value_changed", "translation") ? X3D_TEX_TRANSLATION
                  : route_fields(ro, "value_changed", "scale")     ? X3D_TEX_SCALE
                  : route_fields(ro, "value_changed", "center")    ? X3D_TEX_CENTER
                                                                   : X3D_TEX_NONE;
        if (rot) tex = route_fields(ro, "value_changed", "rotation") ? X3D_TEX_ROTATION : X3D_TEX_NONE;
        if (!in || !co || (pos2 || rot ? !tex : !route_fields(ro, "value_changed", normals ? "vector" : "point")) || !nd ||
            !bsearch(&in, driven, nd, sizeof *driven, x3d_cmp_ptr_el))
            continue;
        bool seen = false; /* one interpolator per Coordinate: the first route in the file */
        for (size_t k = 0; k < L->morph_count && !seen; ++k) seen = L->morphs[k].coord == co && L->morphs[k].serial == F->serial;
        if (seen) {
            x3d_warn(L, "%s:%d: ROUTE: a second %s into the %s of line %d; not played", F->path, x3d_line_of(ro),
                     x3d_ename(in), x3d_ename(co), x3d_line_of(co));
            continue;
        }
        float *key = NULL, *kv = NULL;
        size_t nk = 0, nv = 0, group = rot ? 1 : tex ? 2 : 3;
        char *def = x3d_attr(in, "DEF");
        if (!x3d_get_float_array(L, F, in, "key", 1, &key, &nk) || !x3d_get_float_array(L, F, in, "keyValue", group, &kv, &nv) ||
            nk == 0 || nk > SY_MORPH_MAX_TARGETS || nv % nk != 0 || nv / nk == 0 || ((pos2 || rot) && nv != nk)) {
            if (L->limit_r) r = L->limit_r, L->err = L->limit_err;
            else
                x3d_warn(L, "%s:%d: %s '%s': %zu keys and %zu key values (1 to %u keys, %s); not played", F->path,
                         x3d_line_of(in), x3d_ename(in), def ? def : "", nk, nv, SY_MORPH_MAX_TARGETS,
                         pos2 || rot ? "one value per key" : "the same number of values for each");
            free(key), free(kv), xmlFree(def);
            continue;
        }
        size_t bad = (size_t)-1; /* a key or key value that is not finite (NaN, inf): not played */
        for (size_t k = 0; k < nk && bad == (size_t)-1; ++k)
            if (!isfinite(key[k])) bad = k;
        if (bad != (size_t)-1) {
            x3d_warn(L, "%s:%d: %s '%s': key %zu is not finite; not played", F->path, x3d_line_of(in), x3d_ename(in),
                     def ? def : "", bad);
            free(key), free(kv), xmlFree(def);
            continue;
        }
        for (size_t k = 0; k < nv * group && bad == (size_t)-1; ++k)
            if (!isfinite(kv[k])) bad = k / group;
        if (bad != (size_t)-1) {
            x3d_warn(L, "%s:%d: %s '%s': key value %zu is not finite; not played", F->path, x3d_line_of(in), x3d_ename(in),
                     def ? def : "", bad);
            free(key), free(kv), xmlFree(def);
            continue;
        }
        if (rot && !(r = dense_rotation(L, F, in, def, &key, &kv, &nk)) && !kv) { /* warned: not played */
            free(key), xmlFree(def);
            continue;
        }
        xmlFree(def);
        if (r) {
            free(key), free(kv);
            break;
        }
        if (!sy_array_reserve(&L->morphs, L->morph_count, &L->morph_cap, sizeof *L->morphs, 4)) {
            free(kv), free(key);
            r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", F->path);
            break;
        }
        L->morphs[L->morph_count++] = (morph_src){.coord = co, .interp = in, .serial = F->serial, .values = kv, .key = key,
                                                  .keys = nk, .points = nv / nk, .normals = normals, .tex = tex};
    }
done:
    free(driven);
    free(sc.routes.items);
    if (sc.defs) xmlHashFree(sc.defs, NULL);
    return r;
}

void x3d_free_morphs(loader *L)
{
    for (size_t i = 0; i < L->morph_count; ++i) free(L->morphs[i].values), free(L->morphs[i].key), free(L->morphs[i].meshes);
    free(L->morphs);
    L->morphs = NULL;
    L->morph_count = L->morph_cap = 0;
}
