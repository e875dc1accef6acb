/* sy_x3d_geometry.c — one X3D geometry node into one sy_primitive: the dispatch by node type, the
 * tessellated primitives (Box, Sphere, Cone, Cylinder), points and lines (PointSet, LineSet,
 * IndexedLineSet), Text (sy_text.h) and the TextureTransform; coordinate-based polygon geometry is
 * built in sy_x3d_polygons.c. */
#include "sy_x3d_internal.h"

#include "sy_mesh_util.h"
#include "sy_text.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void texture_transform(loader *L, xfile *F, const xmlNode *tt, float m[6])
{
    x3d_texture_transform(L, F, tt, X3D_TEX_NONE, NULL, m);
}

/* A primitive's (Box, Sphere, Cone, Cylinder) texture coordinates under an animated TextureTransform
 * field (sy_x3d_anim.c: a PositionInterpolator2D into translation / scale / center, a
 * ScalarInterpolator into rotation): one morph target per key, the nv vertices' coordinates
 * (src: the tessellator's, before the transform) through the transform with the key's value, minus
 * uv (the static ones); L->morph_pending names the source. Charged to the load's budget. */
static sy_result primitive_tex_targets(loader *L, xfile *F, const xmlNode *el, const xmlNode *tt, const float *src,
                                       const float *uv, size_t nv, sy_primitive *prim)
{
    morph_src *m = NULL;
    for (size_t i = 0; i < L->morph_count && !m; i++)
        if (L->morphs[i].tex && L->morphs[i].tex != X3D_TEX_POINT && L->morphs[i].coord == tt && L->morphs[i].serial == F->serial)
            m = &L->morphs[i];
    if (!m) return SY_OK;
    float *d;
    sy_result r = x3d_tex_targets_alloc(L, F, el, m, nv, &d);
    if (r) return r;
    for (size_t k = 0; k < m->keys; k++) {
        float mk[6];
        x3d_texture_transform(L, F, tt, m->tex, m->values + 2 * k, mk);
        for (size_t i = 0; i < nv; i++) {
            float s = src[2 * i], t = 1.0f - src[2 * i + 1];
            d[(k * nv + i) * 2] = mk[0] * s + mk[1] * t + mk[2] - uv[2 * i];
            d[(k * nv + i) * 2 + 1] = 1.0f - (mk[3] * s + mk[4] * t + mk[5]) - uv[2 * i + 1];
        }
    }
    return x3d_tex_targets_finish(L, m, d, nv, prim);
}

/* Output of a stroke geometry node: vertices (positions, optional RGBA colours) and, for lines,
 * index pairs. */
typedef struct stroke_out {
    float *pos, *col;
    uint32_t *pairs;
    size_t nv, npairs, cap_v;
} stroke_out;

static void stroke_out_free(stroke_out *o)
{
    free(o->pos); free(o->col); free(o->pairs);
    memset(o, 0, sizeof *o);
}

/* Colour k of a Color / ColorRGBA source as RGBA. */
static void src_color(const geom_src *g, size_t k, float *out)
{
    const float *c = g->col + (size_t)g->col_comps * k;
    out[0] = c[0]; out[1] = c[1]; out[2] = c[2];
    out[3] = g->col_comps == 4 ? c[3] : 1.0f;
}

/* PointSet, LineSet, IndexedLineSet: SY_TOPOLOGY_POINTS / SY_TOPOLOGY_LINES primitives (width 0:
 * core's rule; every back-end draws them as tubes and balls). Polylines become index pairs;
 * IndexedLineSet vertices are repeated per polyline so per-polyline colours stay exact. Colours: per
 * vertex (PointSet, LineSet; IndexedLineSet with colorPerVertex, through colorIndex or coordIndex)
 * or per polyline (IndexedLineSet colorPerVertex false, through colorIndex or the polyline number).
 * Bad indices or counts are warned (file:line) and skip the geometry. */
static sy_result build_strokes(loader *L, xfile *F, const xmlNode *el, const geom_src *g, stroke_out *o, bool *ok)
{
    *ok = false;
    const char *n = x3d_ename(el);
    sy_result r = SY_OK;
    int32_t *ci = NULL, *coi = NULL, *vc = NULL;
    size_t nci = 0, ncoi = 0, nvc = 0;
    if (!strcmp(n, "PointSet")) {
        o->nv = g->npts;
        if (o->nv == 0) {
            x3d_warn(L, "%s:%d: PointSet without points; skipped", F->path, x3d_line_of(el));
            return SY_OK;
        }
    } else if (!strcmp(n, "LineSet")) {
        if (!x3d_get_int_array(L, F, el, "vertexCount", &vc, &nvc)) return SY_OK;
        size_t used = 0;
        for (size_t k = 0; k < nvc; k++) {
            if (vc[k] < 2) {
                x3d_warn(L, "%s:%d: LineSet.vertexCount[%zu] = %d is less than 2; geometry skipped", F->path, x3d_line_of(el), k,
                         (int)vc[k]);
                goto done;
            }
            if ((size_t)vc[k] > g->npts - used) {
                x3d_warn(L, "%s:%d: LineSet.vertexCount needs more than the %zu points of its Coordinate; geometry skipped",
                         F->path, x3d_line_of(el), g->npts);
                goto done;
            }
            used += (size_t)vc[k];
            o->npairs += (size_t)vc[k] - 1;
        }
        o->nv = used;
    } else { /* IndexedLineSet */
        if (!x3d_get_int_array(L, F, el, "coordIndex", &ci, &nci) || !x3d_get_int_array(L, F, el, "colorIndex", &coi, &ncoi))
            goto done;
        for (size_t k = 0, k0 = 0; k <= nci; k++) {
            if (k < nci && ci[k] != -1) {
                if (ci[k] < 0 || (size_t)ci[k] >= g->npts) {
                    x3d_warn(L, "%s:%d: IndexedLineSet: coordIndex[%zu] = %d is outside the %zu points of its Coordinate; "
                             "geometry skipped", F->path, x3d_line_of(el), k, (int)ci[k], g->npts);
                    goto done;
                }
                continue;
            }
            if (k - k0 >= 2) {
                o->nv += k - k0;
                o->npairs += k - k0 - 1;
            }
            k0 = k + 1;
        }
    }
    if (o->nv > L->opt.max_vertices) {
        r = sy_error_set(&L->err, SY_ERR_LIMIT, "%s:%d: %s: %zu vertices exceed the limit of %zu", F->path, x3d_line_of(el),
                         n, o->nv, L->opt.max_vertices);
        goto done;
    }
    if ((r = x3d_budget_vertices(L, F->path, el, o->nv, true))) goto done; /* strokes do not go through emit */
    if (o->nv == 0 || (strcmp(n, "PointSet") && o->npairs == 0)) {
        x3d_warn(L, "%s:%d: %s has no polyline with 2 or more vertices; skipped", F->path, x3d_line_of(el), n);
        goto done;
    }
    o->pos = malloc(o->nv * 12);
    o->col = g->col ? malloc(o->nv * 16) : NULL;
    o->pairs = o->npairs ? malloc(o->npairs * 2 * sizeof(uint32_t)) : NULL;
    if (!o->pos || (g->col && !o->col) || (o->npairs && !o->pairs)) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    size_t v = 0, pr = 0;
    if (strcmp(n, "IndexedLineSet")) { /* PointSet, LineSet: the first nv points, in order */
        if (g->col && g->ncol < o->nv) {
            x3d_warn(L, "%s:%d: %s: %zu colours for %zu vertices; geometry skipped", F->path, x3d_line_of(el), n, g->ncol, o->nv);
            goto done;
        }
        memcpy(o->pos, g->pts, o->nv * 12);
        for (size_t k = 0; o->col && k < o->nv; k++) src_color(g, k, o->col + 4 * k);
        for (size_t k = 0, start = 0; k < nvc; start += (size_t)vc[k], k++)
            for (size_t j = 0; j + 1 < (size_t)vc[k]; j++, pr++) {
                o->pairs[2 * pr] = (uint32_t)(start + j);
                o->pairs[2 * pr + 1] = (uint32_t)(start + j + 1);
            }
    } else {
        bool cpv = x3d_get_bool(el, "colorPerVertex", true);
        size_t line = 0;
        for (size_t k = 0, k0 = 0; k <= nci; k++) {
            if (k < nci && ci[k] != -1) continue;
            size_t cnt = k - k0;
            if (cnt >= 2) {
                for (size_t j = 0; j < cnt; j++) {
                    memcpy(o->pos + 3 * (v + j), g->pts + 3 * (size_t)ci[k0 + j], 12);
                    if (o->col) {
                        size_t at = cpv ? k0 + j : line;
                        int64_t c = ncoi ? (at < ncoi ? coi[at] : -2) : cpv ? ci[at] : (int64_t)at;
                        if (c < 0 || (size_t)c >= g->ncol) {
                            x3d_warn(L, "%s:%d: IndexedLineSet: colour %lld of %s %zu is outside the %zu colours; geometry "
                                     "skipped", F->path, x3d_line_of(el), (long long)c, cpv ? "vertex" : "polyline",
                                     cpv ? k0 + j : line, g->ncol);
                            goto done;
                        }
                        src_color(g, (size_t)c, o->col + 4 * (v + j));
                    }
                    if (j + 1 < cnt) {
                        o->pairs[2 * pr] = (uint32_t)(v + j);
                        o->pairs[2 * pr + 1] = (uint32_t)(v + j + 1);
                        pr++;
                    }
                }
                v += cnt;
            }
            if (k < nci || cnt > 0) line++;
            k0 = k + 1;
        }
    }
    *ok = true;
done:
    free(ci); free(coi); free(vc);
    return r;
}

/* Text: the strings as flat geometry (sy_text.h) with the FontStyle's font (family SANS / SERIF
 * (the default) / TYPEWRITER -> DejaVu Sans / Serif / Sans Mono under SY_X3D_FONT_DIR, style PLAIN /
 * BOLD / ITALIC / BOLDITALIC), size, spacing and justify (major, minor). A missing font is a
 * warning and the text is skipped; length, maxExtent and vertical / right-to-left layouts are not
 * supported (warned). */
#ifndef SY_X3D_FONT_DIR
#define SY_X3D_FONT_DIR "/usr/share/fonts/truetype/dejavu/"
#endif
static uint32_t justify_of(const char *s, bool major)
{
    if (!strcmp(s, "BEGIN")) return SY_TEXT_BEGIN;
    if (!strcmp(s, "MIDDLE")) return SY_TEXT_MIDDLE;
    if (!strcmp(s, "END")) return SY_TEXT_END;
    return major ? SY_TEXT_BEGIN : SY_TEXT_FIRST; /* FIRST (and anything else) */
}

static sy_result build_text(loader *L, xfile *F, const xmlNode *el, sy_primitive *prim, bool *ok)
{
    *ok = false;
    sy_result r = SY_OK;
    char *strs = x3d_attr(el, "string");
    if (!strs) return SY_OK; /* no string: nothing to draw */
    size_t cap = strlen(strs) + 1, nl = 0, lcap = 0;
    char **lines = NULL, *buf = NULL;
    for (const char *p = strs;;) {
        if (!buf && !(buf = malloc(cap))) goto oom;
        if (!x3d_next_mfstring(&p, buf, cap)) break;
        if (nl == lcap) {
            lcap = lcap ? lcap * 2 : 4;
            char **q = realloc(lines, lcap * sizeof *q);
            if (!q) goto oom;
            lines = q;
        }
        lines[nl++] = buf;
        buf = NULL;
    }
    const xmlNode *fs = x3d_field_child(L, F, el, "FontStyle|ScreenFontStyle", "fontStyle");
    const char *family = "DejaVuSerif", *style_sfx = "";
    float size = 1.0f, spacing = 1.0f;
    uint32_t major = SY_TEXT_BEGIN, minor = SY_TEXT_FIRST;
    if (fs) {
        char *fam = x3d_attr(fs, "family"), tok[64];
        const char *p = fam;
        while (p && x3d_next_mfstring(&p, tok, sizeof tok)) {
            if (!strcmp(tok, "SANS")) { family = "DejaVuSans"; break; }
            if (!strcmp(tok, "SERIF")) { family = "DejaVuSerif"; break; }
            if (!strcmp(tok, "TYPEWRITER")) { family = "DejaVuSansMono"; break; }
        }
        xmlFree(fam);
        char *st = x3d_attr(fs, "style");
        bool bold = st && strstr(st, "BOLD"), italic = st && strstr(st, "ITALIC");
        xmlFree(st);
        bool serif = !strcmp(family, "DejaVuSerif");
        style_sfx = bold && italic ? (serif ? "-BoldItalic" : "-BoldOblique") : bold ? "-Bold"
                    : italic ? (serif ? "-Italic" : "-Oblique") : "";
        size = x3d_get_float(L, F, fs, "size", 1.0f);
        spacing = x3d_get_float(L, F, fs, "spacing", 1.0f);
        char *j = x3d_attr(fs, "justify");
        p = j;
        if (p && x3d_next_mfstring(&p, tok, sizeof tok)) {
            major = justify_of(tok, true);
            if (x3d_next_mfstring(&p, tok, sizeof tok)) minor = justify_of(tok, false);
        }
        xmlFree(j);
        if (!x3d_get_bool(fs, "horizontal", true) || !x3d_get_bool(fs, "leftToRight", true) || !x3d_get_bool(fs, "topToBottom", true))
            x3d_warn(L, "%s:%d: FontStyle: only horizontal, left-to-right, top-to-bottom text is supported", F->path,
                     x3d_line_of(fs));
    }
    if (!(size > 0) || !(spacing >= 0)) {
        x3d_warn(L, "%s:%d: Text: FontStyle size %g / spacing %g out of range; skipped", F->path, x3d_line_of(el), (double)size,
                 (double)spacing);
        goto done;
    }
    if (x3d_attr_present(el, "length") || x3d_attr_present(el, "maxExtent"))
        x3d_warn(L, "%s:%d: Text: length and maxExtent are not supported; ignored", F->path, x3d_line_of(el));
    char font[512];
    snprintf(font, sizeof font, "%s%s%s.ttf", SY_X3D_FONT_DIR, family, style_sfx);
    if (!x3d_regular_file(font, NULL, 0)) {
        x3d_warn(L, "%s:%d: Text: font '%s' not found (install fonts-dejavu-core); text skipped", F->path, x3d_line_of(el), font);
        goto done;
    }
    sy_text_desc td = {.lines = (const char *const *)lines, .line_count = nl, .font_path = font, .size = size,
                       .spacing = spacing, .major = major, .minor = minor, .max_triangles = L->opt.max_vertices / 3};
    sy_text_stats ts;
    r = sy_text_build(&td, prim, &ts, &L->err);
    if (r == SY_ERR_NOT_FOUND) {
        x3d_warn(L, "%s:%d: Text: %s; text skipped", F->path, x3d_line_of(el), L->err.message);
        r = SY_OK;
    } else if (r) {
        sy_error_prefix(&L->err, "%s:%d: Text", F->path, x3d_line_of(el));
    } else if (!prim->positions) {
        x3d_warn(L, "%s:%d: Text has no visible glyph; skipped", F->path, x3d_line_of(el));
    } else {
        *ok = true;
    }
    goto done;
oom:
    r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
done:
    for (size_t k = 0; k < nl; k++) free(lines[k]);
    free(lines);
    free(buf);
    xmlFree(strs);
    return r;
}

/* Builds the primitive of a geometry node (cached per geometry element and texture transform). */
sy_result x3d_build_geometry(loader *L, xfile *F, const xmlNode *el, const xmlNode *ttel, sy_primitive *prim,
                             bool *ok, bool *has_colors, bool *solid)
{
    *ok = false;
    memset(prim, 0, sizeof *prim);
    const char *n = x3d_ename(el);
    sy_result r = SY_OK;
    *solid = x3d_get_bool(el, "solid", true);
    *has_colors = false;
    if (!strcmp(n, "Box")) {
        float size[3] = {2, 2, 2};
        x3d_get_floats(L, F, el, "size", size, 3);
        if (!(size[0] > 0 && size[1] > 0 && size[2] > 0)) goto bad_size;
        r = sy_tess_box(size, prim, &L->err);
    } else if (!strcmp(n, "Sphere")) {
        float rad = x3d_get_float(L, F, el, "radius", 1.0f);
        if (!(rad > 0)) goto bad_size;
        r = sy_tess_sphere(rad, NULL, prim, &L->err);
    } else if (!strcmp(n, "Cone")) {
        float rad = x3d_get_float(L, F, el, "bottomRadius", 1.0f), h = x3d_get_float(L, F, el, "height", 2.0f);
        if (!(rad > 0 && h > 0)) goto bad_size;
        bool side = x3d_get_bool(el, "side", true), bottom = x3d_get_bool(el, "bottom", true);
        if (!side && !bottom) goto empty;
        r = sy_tess_cone(rad, h, side, bottom, NULL, prim, &L->err);
    } else if (!strcmp(n, "Text")) {
        *solid = x3d_get_bool(el, "solid", false); /* X3D: Text is not solid by default */
        bool built = false;
        r = build_text(L, F, el, prim, &built);
        if (r || !built) return r;
    } else if (!strcmp(n, "Cylinder")) {
        float rad = x3d_get_float(L, F, el, "radius", 1.0f), h = x3d_get_float(L, F, el, "height", 2.0f);
        if (!(rad > 0 && h > 0)) goto bad_size;
        bool side = x3d_get_bool(el, "side", true), top = x3d_get_bool(el, "top", true), bottom = x3d_get_bool(el, "bottom", true);
        if (!side && !top && !bottom) goto empty;
        r = sy_tess_cylinder(rad, h, side, top, bottom, NULL, prim, &L->err);
    } else {
        geom_src g = {0};
        corners c = {0};
        bool built = false;
        texture_transform(L, F, ttel, g.tt);
        g.tt_el = ttel;
        if (!x3d_read_sources(L, F, el, &g)) {
            x3d_geom_src_free(&g);
            if (L->limit_r) L->err = L->limit_err;
            return L->limit_r;
        }
        if (!strcmp(n, "Extrusion")) {
            x3d_geom_src_free(&g); /* an Extrusion has no Coordinate etc.: its fields build the sources */
            memset(&g, 0, sizeof g);
            texture_transform(L, F, ttel, g.tt);
            g.tt_el = ttel;
            g.ccw = x3d_get_bool(el, "ccw", true);
            g.crease = x3d_get_float(L, F, el, "creaseAngle", 0.0f);
            r = x3d_build_extrusion(L, F, el, &g, &c, &built);
        } else if (!g.pts) {
            x3d_warn(L, "%s:%d: %s without Coordinate points; skipped", F->path, x3d_line_of(el), n);
        } else if (x3d_name_in(n, "PointSet|LineSet|IndexedLineSet")) {
            stroke_out so = {0};
            r = build_strokes(L, F, el, &g, &so, &built);
            if (!r && L->limit_r) {
                r = L->limit_r;
                L->err = L->limit_err;
            }
            if (!r && built) {
                r = x3d_make_blob(L, so.pos, so.nv * 12, &prim->positions);
                so.pos = NULL;
                if (!r && so.col) r = x3d_make_blob(L, so.col, so.nv * 16, &prim->colors);
                so.col = NULL;
                if (!r && so.pairs) r = x3d_make_blob(L, so.pairs, so.npairs * 8, &prim->indices);
                so.pairs = NULL;
                if (r) sy_primitive_release(prim);
                else prim->topology = so.npairs ? SY_TOPOLOGY_LINES : SY_TOPOLOGY_POINTS;
                *ok = !r;
                *has_colors = !r && prim->colors != NULL;
                *solid = false;
            }
            stroke_out_free(&so);
            x3d_geom_src_free(&g);
            return r;
        } else if (!strcmp(n, "IndexedFaceSet")) {
            r = x3d_build_faceset(L, F, el, &g, &c, &built);
        } else if (!strcmp(n, "IndexedTriangleSet")) {
            r = x3d_build_triset(L, F, el, &g, &c, true, &built);
        } else if (strstr(n, "Strip") || strstr(n, "Fan") || strstr(n, "Quad")) {
            r = x3d_build_strip_fan_quad(L, F, el, &g, &c, &built);

        } else {
            r = x3d_build_triset(L, F, el, &g, &c, false, &built);
        }
        if (!r && L->limit_r) { /* an attribute over the value limit: the load fails */
            r = L->limit_r;
            L->err = L->limit_err;
        }
        if (!r && built) {
            r = x3d_emit(L, F, el, &g, &c, prim);
            if (!r) {
                *ok = true;
                *has_colors = prim->colors != NULL;
            }
        }
        x3d_corners_free(&c);
        x3d_geom_src_free(&g);
        return r;
    }
    if (r) {
        sy_error_prefix(&L->err, "%s:%d: %s", F->path, x3d_line_of(el), n);
        return r;
    }
    if (ttel && prim->texcoords0) { /* apply the texture transform to the tessellated coordinates */
        float m[6];
        texture_transform(L, F, ttel, m);
        size_t nv = sy_blob_size(prim->texcoords0) / 8;
        float *uv = malloc(nv * 8);
        if (!uv) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        const float *src = sy_blob_data(prim->texcoords0);
        for (size_t k = 0; k < nv; k++) {
            float s = src[2 * k], t = 1.0f - src[2 * k + 1];
            uv[2 * k] = m[0] * s + m[1] * t + m[2];
            uv[2 * k + 1] = 1.0f - (m[3] * s + m[4] * t + m[5]);
        }
        if ((r = primitive_tex_targets(L, F, el, ttel, src, uv, nv, prim))) {
            free(uv);
            return r;
        }
        sy_blob *b;
        if ((r = x3d_make_blob(L, uv, nv * 8, &b))) return r;
        sy_blob_release(prim->texcoords0);
        prim->texcoords0 = b;
    }
    *ok = true;
    return SY_OK;
bad_size:
    x3d_warn(L, "%s:%d: %s with a non-positive size; skipped", F->path, x3d_line_of(el), n);
    return SY_OK;
empty:
    return SY_OK;
}
