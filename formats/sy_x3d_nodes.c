/* sy_x3d_nodes.c — the walk over an X3D document: one file (the main file or an Inline, parsed with
 * libxml2, with the cycle, depth and sharing rules of Inline), its Scene's element tree in
 * document order (DEF before USE), grouping nodes and Transforms into sy_nodes (a USEd node is one
 * sy_node under several parents), Shapes (geometry + appearance -> one sy_mesh), and the leaves
 * that sy_x3d_lights.c turns into lights, cameras and the background. */
#define _DEFAULT_SOURCE /* realpath */
#include "sy_x3d_internal.h"

#include "sy_file.h"
#include "sy_mesh_util.h"

#include <libxml/parser.h>
#include <libxml/xmlerror.h>

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>nodes ------------------------------------------------------------------------------------- */

static sy_result visit(loader *L, xfile *F, const xmlNode *el, const sy_mat4 *world, sy_node *out);

static bool warn_type_once(loader *L, const char *type)
{
    if (xmlHashLookup(L->warned, (const xmlChar *)type)) return false;
    xmlHashAddEntry(L->warned, (const xmlChar *)type, (void *)1);
    return true;
}

static bool silent_node(const char *n)
{
    return x3d_name_in(n, "WorldInfo|NavigationInfo|ROUTE|EXPORT|IMPORT|meta|head|component|unit|MetadataString|"
                      "MetadataFloat|MetadataDouble|MetadataInteger|MetadataBoolean|MetadataSet|IS|connect|field|"
                      "fieldValue|ProtoDeclare|ExternProtoDeclare|Script");
}

static sy_result children_of(loader *L, xfile *F, const xmlNode *el, const sy_mat4 *world, sy_node node,
                             const char *only_nth)
{
    sy_result r = SY_OK;
    sy_node *kids = NULL;
    size_t nk = 0, cap = 0;
    long which = only_nth ? strtol(only_nth, NULL, 10) : -2, idx = 0;
    for (const xmlNode *c = el->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE) continue;
        if (only_nth) {
            if (idx++ != which) continue;
        }
        sy_node k = {0};
        if ((r = visit(L, F, c, world, &k))) break;
        if (!k.id) continue;
        bool dup = false;
        for (size_t q = 0; q < nk; q++) dup |= kids[q].id == k.id;
        if (dup) continue; /* the same USEd node twice under one parent adds nothing */
        if (nk == cap) {
            cap = cap ? cap * 2 : 8;
            sy_node *p = realloc(kids, cap * sizeof *p);
            if (!p) {
                r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
                break;
            }
            kids = p;
        }
        kids[nk++] = k;
    }
    if (!r && nk) {
        r = sy_node_set_children(L->scene, node, kids, (uint32_t)nk, &L->err);
        if (r) sy_error_prefix(&L->err, "%s:%d: %s", F->path, x3d_line_of(el), x3d_ename(el));
    }
    free(kids);
    return r;
}

static void bounds_add_prim(loader *L, const sy_primitive *p, const sy_mat4 *world)
{
    if (!p->positions) return;
    const float *v = sy_blob_data(p->positions);
    size_t n = sy_blob_size(p->positions) / 12;
    sy_bounds b = sy_bounds_empty();
    for (size_t k = 0; k < n; k++) sy_bounds_add_point(&b, v + 3 * k);
    sy_bounds w = sy_bounds_transform(&b, world);
    sy_bounds_add_bounds(&L->bounds, &w);
}


static sy_result set_transform(loader *L, xfile *F, const xmlNode *el, sy_node h, sy_mat4 *local)
{
    x3d_transform x;
    x3d_read_transform(L, F, el, &x);
    sy_result r;
    if (!x3d_transform_pivoted(&x)) {
        *local = sy_mat4_from_trs(x.t, x.r, x.s);
        r = sy_node_set_trs(L->scene, h, x.t, x.r, x.s, &L->err);
    } else { /* T C R (SR S -SR -C) */
        float one[3] = {1, 1, 1}, tc[3] = {x.t[0] + x.c[0], x.t[1] + x.c[1], x.t[2] + x.c[2]};
        sy_mat4 head = sy_mat4_from_trs(tc, x.r, one), tail = x3d_transform_tail(&x, true);
        *local = sy_mat4_mul(&head, &tail);
        r = sy_node_set_matrix(L->scene, h, local, &L->err);
    }
    if (r) sy_error_prefix(&L->err, "%s:%d: Transform", F->path, x3d_line_of(el));
    return r;
}

/* Creates the node for an element (DEF name as node name) and marks it in progress. */
static sy_result begin_node(loader *L, xfile *F, const xmlNode *el, created *c, sy_node *h)
{
    char *def = x3d_attr(el, "DEF");
    char *desc = def ? NULL : x3d_attr(el, "description");
    sy_result r = x3d_new_object(L, SY_TYPE_NODE, def ? def : desc, &h->id);
    xmlFree(def);
    xmlFree(desc);
    if (r) {
        sy_error_prefix(&L->err, "%s:%d: %s", F->path, x3d_line_of(el), x3d_ename(el));
        return r;
    }
    L->info->counts.nodes++;
    c->node = h->id;
    c->in_progress = true;
    return SY_OK;
}

static sy_result visit_shape(loader *L, xfile *F, const xmlNode *el, const sy_mat4 *world, sy_node h)
{
    created *c = x3d_cache_get(L, F, el, "mesh", true);
    if (!c) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    sy_result r;
    if (!c->done) {
        c->done = true;
        const xmlNode *app = x3d_field_child(L, F, el, "Appearance", "appearance");
        const xmlNode *geo = NULL;
        for (const xmlNode *k = el->children; k; k = k->next) {
            if (k->type != XML_ELEMENT_NODE || !strcmp(x3d_ename(k), "Appearance") || silent_node(x3d_ename(k))) continue;
            char *cf = x3d_attr(k, "containerField");
            bool other = cf && strcmp(cf, "geometry") != 0;
            xmlFree(cf);
            if (other) continue;
            x3d_define(L, F, k);
            geo = x3d_resolve(L, F, k);
            break;
        }
        if (!geo) return SY_OK;
        if (!x3d_name_in(x3d_ename(geo), "IndexedFaceSet|IndexedTriangleSet|TriangleSet|IndexedTriangleStripSet|IndexedTriangleFanSet|"
                           "TriangleStripSet|TriangleFanSet|IndexedQuadSet|QuadSet|Extrusion|Box|Sphere|Cone|Cylinder|"
                           "PointSet|LineSet|IndexedLineSet|Text")) {
            L->info->counts.skipped_geometry++;
            if (warn_type_once(L, x3d_ename(geo)))
                x3d_warn(L, "%s:%d: geometry %s not supported; skipped (reported once per type)", F->path, x3d_line_of(geo),
                         x3d_ename(geo));
            return SY_OK;
        }
        const xmlNode *tt = app ? x3d_field_child(L, F, app, "TextureTransform", "textureTransform") : NULL;
        sy_primitive prim;
        bool ok, colors, solid;
        L->morph_pending = 0;
        if ((r = x3d_build_geometry(L, F, geo, tt, &prim, &ok, &colors, &solid))) return r;
        size_t morph = L->morph_pending; /* built on an animated Coordinate (sy_x3d_anim.c) */
        L->morph_pending = 0;
        if (!ok) {
            L->info->counts.skipped_geometry++;
            return SY_OK;
        }
        uint32_t mat = 0;
        bool normal_map = false;
        r = x3d_get_material(L, F, app, solid, colors, prim.topology != SY_TOPOLOGY_TRIANGLES, &mat, &normal_map);
        if (!r && normal_map && prim.texcoords0 && prim.normals) r = sy_prim_generate_tangents(&prim, 0, &L->err);
        prim.material.id = mat;
        char *def = x3d_attr(el, "DEF");
        if (!def) def = x3d_attr(geo, "DEF");
        uint32_t mid = 0;
        if (!r) r = x3d_new_object(L, SY_TYPE_MESH, def, &mid);
        xmlFree(def);
        if (!r) r = sy_mesh_set_primitives(L->scene, (sy_mesh){mid}, &prim, 1, &L->err);
        if (!r) {
            L->info->counts.meshes++;
            L->info->counts.primitives++;
            L->info->counts.triangles += sy_primitive_triangle_count(&prim);
            if (prim.topology == SY_TOPOLOGY_LINES) L->info->counts.line_segments += sy_primitive_element_count(&prim);
            if (prim.topology == SY_TOPOLOGY_POINTS) L->info->counts.points += sy_primitive_element_count(&prim);
            if (!strcmp(x3d_ename(geo), "Text")) L->info->counts.texts++;
            c->mesh = mid;
            bounds_add_prim(L, &prim, world);
            morph_src *m = morph ? &L->morphs[morph - 1] : NULL;
            if (m && !sy_array_reserve(&m->meshes, m->mesh_count, &m->mesh_cap, sizeof *m->meshes, 4))
                r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
            if (m && !r) m->meshes[m->mesh_count++] = mid;
        } else {
            sy_error_prefix(&L->err, "%s:%d: Shape", F->path, x3d_line_of(el));
        }
        sy_primitive_release(&prim);
        if (r) return r;
    }
    if (c->mesh && (r = sy_node_set_mesh(L->scene, h, (sy_mesh){c->mesh}, &L->err))) return r;
    return SY_OK;
}

static sy_result visit_inline(loader *L, xfile *F, const xmlNode *el, sy_node h)
{
    if (!x3d_get_bool(el, "load", true)) return SY_OK;
    char *urls = x3d_attr(el, "url");
    if (!urls) {
        x3d_warn(L, "%s:%d: Inline without url; ignored", F->path, x3d_line_of(el));
        return SY_OK;
    }
    const char *p = urls;
    char u[2048], path[4096];
    sy_result r = SY_OK;
    bool loaded = false;
    while (!loaded && x3d_next_mfstring(&p, u, sizeof u)) {
        if (!u[0] || x3d_is_remote(u)) continue;
        char *hash = strchr(u, '#');
        if (hash) *hash = '\0';
        char joined[4096];
        if (!x3d_resolve_url(F, u, joined, sizeof joined)) continue;
        r = x3d_confine_url(L, F, el, u, joined, path, sizeof path);
        if (r == SY_ERR_NOT_FOUND) {
            r = SY_OK;
            x3d_warn(L, "%s:%d: Inline '%s': not found", F->path, x3d_line_of(el), joined);
            continue;
        }
        if (r) break;
        sy_node sub = {0};
        r = x3d_load_file(L, path, NULL, 0, NULL, F, &sub, el, F);
        if (r) break;
        if (sub.id) {
            loaded = true;
            r = sy_node_set_children(L->scene, h, &sub, 1, &L->err);
            if (r) sy_error_prefix(&L->err, "%s:%d: Inline", F->path, x3d_line_of(el));
        }
    }
    xmlFree(urls);
    return r;
}

static sy_result visit(loader *L, xfile *F, const xmlNode *el_in, const sy_mat4 *world, sy_node *out)
{
    out->id = 0;
    const char *n = x3d_ename(el_in);
    if (silent_node(n)) return SY_OK;
    x3d_define(L, F, el_in);
    const xmlNode *el = x3d_resolve(L, F, el_in);
    if (!el) return SY_OK;
    n = x3d_ename(el);
    size_t nlen = strlen(n);
    if (!strcmp(n, "TimeSensor") || (nlen > 12 && !strcmp(n + nlen - 12, "Interpolator")) ||
        (nlen > 14 && !strcmp(n + nlen - 14, "Interpolator2D")))
        return SY_OK; /* the scene clock's (sy_x3d_anim.c: what is routed and does not map is reported there) */
    if (!strcmp(n, "Background") || !strcmp(n, "TextureBackground")) return x3d_visit_background(L, F, el);
    bool group = x3d_name_in(n, "Transform|Group|StaticGroup|Collision|Anchor|Billboard|Switch|LOD|CADAssembly|CADLayer|CADPart|CADFace|HAnimHumanoid|HAnimJoint|HAnimSegment|HAnimSite|ScreenGroup|LayoutGroup");
    bool leaf = x3d_name_in(n, "Shape|DirectionalLight|PointLight|SpotLight|Viewpoint|OrthoViewpoint|Inline");
    if (!group && !leaf) {
        if (warn_type_once(L, n))
            x3d_warn(L, "%s:%d: node type %s not supported; skipped (reported once per type)", F->path, x3d_line_of(el), n);
        return SY_OK;
    }
    created *c = x3d_cache_get(L, F, el, "node", true);
    if (!c) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    if (c->in_progress) {
        x3d_warn(L, "%s:%d: USE of '%s' inside its own definition (line %d): cycle; skipped", F->path, x3d_line_of(el_in),
                 n, x3d_line_of(el));
        return SY_OK;
    }
    if (c->done) {
        out->id = c->node;
        return SY_OK;
    }
    sy_node h;
    sy_result r;
    if ((r = begin_node(L, F, el, c, &h))) return r;
    sy_mat4 local = sy_mat4_identity();
    if (!strcmp(n, "Transform") || !strcmp(n, "HAnimJoint") || !strcmp(n, "HAnimHumanoid") || !strcmp(n, "CADPart"))
        r = set_transform(L, F, el, h, &local);
    sy_mat4 w = sy_mat4_mul(world, &local);
    if (!r) {
        if (!strcmp(n, "Shape")) r = visit_shape(L, F, el, &w, h);
        else if (x3d_name_in(n, "DirectionalLight|PointLight|SpotLight")) r = x3d_visit_light(L, F, el, &w, h);
        else if (!strcmp(n, "Viewpoint") || !strcmp(n, "OrthoViewpoint")) r = x3d_visit_viewpoint(L, F, el, h);
        else if (!strcmp(n, "Inline")) r = visit_inline(L, F, el, h);
        else if (!strcmp(n, "Switch")) {
            char *wc = x3d_attr(el, "whichChoice");
            r = children_of(L, F, el, &w, h, wc ? wc : "-1");
            xmlFree(wc);
        } else if (!strcmp(n, "LOD")) r = children_of(L, F, el, &w, h, "0");
        else r = children_of(L, F, el, &w, h, NULL);
    }
    if (!r && (r = sy_node_set_flags(L->scene, h, SY_NODE_VISIBLE, &L->err)))
        sy_error_prefix(&L->err, "%s:%d: %s", F->path, x3d_line_of(el), n);
    c->in_progress = false;
    c->done = true;
    if (!r) *out = h;
    return r;
}

/* >>files ------------------------------------------------------------------------------------- */

static char *dir_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    size_t n = slash ? (size_t)(slash - path) + 1 : 0;
    char *d = malloc(n + 1);
    if (!d) return NULL;
    memcpy(d, path, n);
    d[n] = '\0';
    return d;
}

/* Loads one X3D document (the main file or an Inline) and returns the node for its Scene. For an
 * Inline (at != NULL) problems are warnings (the Inline stays empty); for the main file errors. */
sy_result x3d_load_file(loader *L, const char *path, const void *mem, size_t mem_size, const char *base_dir,
                        xfile *parent, sy_node *root_out, const xmlNode *at, xfile *atF)
{
    root_out->id = 0;
    xfile F = {0};
    sy_result r = SY_OK;
    void *bytes = NULL;
    size_t size = 0;
    xmlDocPtr doc = NULL;
    created *ic = NULL;
    if (parent) {
        if (parent->depth + 1 > L->opt.max_inline_depth) {
            x3d_warn(L, "%s:%d: Inline nesting deeper than %u; ignored", atF->path, x3d_line_of(at), L->opt.max_inline_depth);
            return SY_OK;
        }
        char why[SY_ERROR_MESSAGE_MAX];
        if (!x3d_regular_file(path, why, sizeof why)) {
            x3d_warn(L, "%s:%d: Inline: %s; ignored", atF->path, x3d_line_of(at), why);
            return SY_OK;
        }
        char *real = realpath(path, NULL);
        if (!real) {
            x3d_warn(L, "%s:%d: Inline '%s': %s; ignored", atF->path, x3d_line_of(at), path, strerror(errno));
            return SY_OK;
        }
        for (xfile *p = parent; p; p = p->parent)
            if (p->real && !strcmp(p->real, real)) {
                x3d_warn(L, "%s:%d: Inline '%s' includes itself (cycle); ignored", atF->path, x3d_line_of(at), path);
                free(real);
                return SY_OK;
            }
        ic = xmlHashLookup(L->inline_roots, (const xmlChar *)real);
        if (ic) { /* loaded before: share its node */
            free(real);
            root_out->id = ic->node;
            return SY_OK;
        }
        F.real = real;
        F.depth = parent->depth + 1;
    } else if (!mem) {
        F.real = realpath(path, NULL);
    }
    F.parent = parent;
    F.serial = ++L->file_serial;
    F.path = strdup(path);
    F.dir = mem ? strdup(base_dir ? base_dir : "") : dir_of(path);
    F.defs = xmlHashCreate(64);
    if (!F.path || !F.dir || !F.defs) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    if (F.dir[0] && F.dir[strlen(F.dir) - 1] != '/' && mem) {
        char *d = malloc(strlen(F.dir) + 2);
        if (!d) {
            r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
            goto done;
        }
        sprintf(d, "%s/", F.dir);
        free(F.dir);
        F.dir = d;
    }
    if (!mem) {
        sy_error ferr = {0};
        if ((r = sy_file_read_all(path, L->opt.max_file_bytes, &bytes, &size, &ferr))) {
            if (parent) {
                x3d_warn(L, "%s:%d: Inline: %s; ignored", atF->path, x3d_line_of(at), ferr.message);
                r = SY_OK;
            } else {
                L->err = ferr;
            }
            goto done;
        }
        mem = bytes;
        mem_size = size;
    }
    if (mem_size > INT_MAX) {
        r = sy_error_set(&L->err, SY_ERR_LIMIT, "%s: too large for the XML parser", path);
        goto done;
    }
    xmlParserCtxtPtr ctxt = xmlNewParserCtxt();
    if (!ctxt) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
        goto done;
    }
    doc = xmlCtxtReadMemory(ctxt, mem, (int)mem_size, path, NULL,
                            XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING | XML_PARSE_NOCDATA);
    if (!doc) {
        const xmlError *e = xmlCtxtGetLastError(ctxt);
        char msg[256] = "not well-formed XML";
        if (e && e->message) {
            snprintf(msg, sizeof msg, "%s", e->message);
            size_t k = strlen(msg);
            while (k && (msg[k - 1] == '\n' || msg[k - 1] == ' ')) msg[--k] = '\0';
        }
        int line = e ? e->line : 0;
        xmlFreeParserCtxt(ctxt);
        if (parent) {
            x3d_warn(L, "%s:%d: Inline '%s': line %d: %s; ignored", atF->path, x3d_line_of(at), path, line, msg);
        } else {
            r = sy_error_set(&L->err, SY_ERR_PARSE, "%s:%d: malformed XML: %s", path, line, msg);
        }
        goto done;
    }
    xmlFreeParserCtxt(ctxt);
    const xmlNode *x3d = xmlDocGetRootElement(doc), *scene = NULL;
    if (x3d && !strcmp(x3d_ename(x3d), "X3D")) {
        for (const xmlNode *c = x3d->children; c; c = c->next)
            if (c->type == XML_ELEMENT_NODE && !strcmp(x3d_ename(c), "Scene")) scene = c;
    } else if (x3d && !strcmp(x3d_ename(x3d), "Scene")) {
        scene = x3d;
    }
    if (!scene) {
        if (parent) x3d_warn(L, "%s:%d: Inline '%s': no X3D Scene element; ignored", atF->path, x3d_line_of(at), path);
        else r = sy_error_set(&L->err, SY_ERR_PARSE, "%s:%d: not an X3D file (root element <%s>, expected <X3D> with a <Scene>)",
                              path, x3d ? x3d_line_of(x3d) : 1, x3d ? x3d_ename(x3d) : "none");
        goto done;
    }
    sy_node h;
    if ((r = x3d_new_object(L, SY_TYPE_NODE, parent ? path : "Scene", &h.id))) goto done;
    L->info->counts.nodes++;
    if (parent) {
        L->info->counts.inlines++;
        ic = calloc(1, sizeof *ic);
        if (!ic || xmlHashAddEntry(L->inline_roots, (const xmlChar *)F.real, ic) != 0) {
            free(ic);
            r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
            goto done;
        }
        ic->node = h.id;
    }
    sy_mat4 id = sy_mat4_identity();
    if ((r = x3d_scan_morphs(L, &F, scene))) goto done;
    if ((r = children_of(L, &F, scene, &id, h, NULL))) goto done;
    if ((r = sy_node_set_flags(L->scene, h, SY_NODE_VISIBLE, &L->err))) goto done;
    if ((r = x3d_load_animations(L, &F, scene))) goto done;
    *root_out = h;
done:
    if (doc) xmlFreeDoc(doc);
    free(bytes);
    if (F.defs) xmlHashFree(F.defs, x3d_free_none);
    free(F.path);
    free(F.dir);
    free(F.real);
    return r;
}
