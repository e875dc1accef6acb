/* sy_gltf_write.c — scene placements to GLB (see sy_gltf_write.h): collects placements from the
 * node graph, maps meshes and materials to glTF indices, points the shim at the blobs' arrays
 * (no copies here) and lets tinygltf serialise the document. */
#include "sy_gltf_write.h"

#include "sy_file.h"
#include "sy_gltf_shim.h"

#include <stdlib.h>
#include <string.h>

/* >>placements */
typedef struct collector {
    sy_gltf_placement *items;
    uint32_t count, cap;
} collector;

/* One node of the walk (sy_scene_walk, visible nodes only): its mesh at its world matrix. */
static sy_result collect(void *user, const sy_walk_step *st, sy_error *err)
{
    collector *c = user;
    if (!st->data) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "placements: node %u is stale", st->node.id);
    if (st->depth >= SY_GLTF_MAX_DEPTH)
        return sy_error_set(err, SY_ERR_LIMIT, "placements: node %u lies deeper than %u levels", st->node.id,
                            SY_GLTF_MAX_DEPTH);
    if (!st->data->mesh.id) return SY_OK;
    if (c->count == SY_GLTF_MAX_PLACEMENTS)
        return sy_error_set(err, SY_ERR_LIMIT, "placements: more than %u mesh placements", SY_GLTF_MAX_PLACEMENTS);
    if (c->count == c->cap) {
        uint32_t nc = c->cap ? c->cap * 2 : 64;
        sy_gltf_placement *ni = realloc(c->items, sizeof *ni * nc);
        if (!ni) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "placements: out of memory");
        c->items = ni, c->cap = nc;
    }
    c->items[c->count++] =
        (sy_gltf_placement){.node_id = st->node.id, .mesh = st->data->mesh, .world = st->place.world, .id = st->node.id};
    return SY_OK;
}

sy_result sy_gltf_placements_collect(const sy_scene *s, sy_node root, sy_gltf_placement **placements_out,
                                     uint32_t *count_out, sy_error *err)
{
    *placements_out = NULL;
    *count_out = 0;
    collector c = {0};
    /* under an identity (as before the walk existed: the root's world is identity x its matrix) */
    sy_placement top = {.world = sy_mat4_identity(), .visible = true};
    sy_result r = sy_scene_walk(s, root, &top, SY_WALK_VISIBLE_ONLY, collect, &c, err);
    if (r != SY_OK) {
        free(c.items);
        return r;
    }
    *placements_out = c.items;
    *count_out = c.count;
    return SY_OK;
}

/* >>writing */
/* A small id -> index map (linear probing); ids are nonzero except the default material's 0, which
 * is stored as UINT32_MAX. */
typedef struct idmap {
    uint32_t *keys, *vals, cap, count;
} idmap;

static bool idmap_find(const idmap *m, uint32_t key, uint32_t *val)
{
    if (!m->cap) return false;
    for (uint32_t h = (key * 2654435761u) & (m->cap - 1);; h = (h + 1) & (m->cap - 1)) {
        if (m->keys[h] == 0) return false;
        if (m->keys[h] == key) {
            *val = m->vals[h];
            return true;
        }
    }
}

static bool idmap_put(idmap *m, uint32_t key, uint32_t val)
{
    if ((m->count + 1) * 2 > m->cap) {
        uint32_t nc = m->cap ? m->cap * 2 : 64;
        uint32_t *nk = calloc(nc, sizeof *nk), *nv = calloc(nc, sizeof *nv);
        if (!nk || !nv) {
            free(nk), free(nv);
            return false;
        }
        for (uint32_t i = 0; i < m->cap; ++i)
            if (m->keys[i]) {
                uint32_t h = (m->keys[i] * 2654435761u) & (nc - 1);
                while (nk[h]) h = (h + 1) & (nc - 1);
                nk[h] = m->keys[i], nv[h] = m->vals[i];
            }
        free(m->keys), free(m->vals);
        m->keys = nk, m->vals = nv, m->cap = nc;
    }
    uint32_t h = (key * 2654435761u) & (m->cap - 1);
    while (m->keys[h]) h = (h + 1) & (m->cap - 1);
    m->keys[h] = key, m->vals[h] = val, m->count++;
    return true;
}

static void idmap_free(idmap *m)
{
    free(m->keys), free(m->vals);
}

typedef struct writer {
    const sy_scene *s;
    idmap meshes, materials;
    sy_gltf_shim_wmesh *wmeshes;
    sy_gltf_shim_wmaterial *wmats;
    uint32_t mesh_count, mat_count;
    sy_gltf_shim_wprimitive **prims; /* per mesh, freed at the end */
    sy_error *err;
} writer;

static const char *const alpha_modes[] = {"OPAQUE", "MASK", "BLEND"};

static sy_result material_index(writer *w, sy_material m, int32_t *out)
{
    uint32_t key = m.id ? m.id : UINT32_MAX, v;
    if (idmap_find(&w->materials, key, &v)) {
        *out = (int32_t)v;
        return SY_OK;
    }
    const sy_material_data *d = sy_material_get(w->s, m);
    if (!d) return sy_error_set(w->err, SY_ERR_INVALID_HANDLE, "write GLB: material %u is stale", m.id);
    sy_gltf_shim_wmaterial *nm = realloc(w->wmats, sizeof *nm * (w->mat_count + 1));
    if (!nm) return sy_error_set(w->err, SY_ERR_OUT_OF_MEMORY, "write GLB: out of memory");
    w->wmats = nm;
    sy_gltf_shim_wmaterial *o = &nm[w->mat_count];
    memset(o, 0, sizeof *o);
    o->name = d->name;
    for (int i = 0; i < 4; ++i) o->base_color[i] = d->base_color[i];
    for (int i = 0; i < 3; ++i) o->emissive[i] = d->emissive[i];
    o->metallic = d->metallic, o->roughness = d->roughness, o->emissive_strength = d->emissive_strength;
    o->alpha_mode = alpha_modes[d->alpha_mode < 3 ? d->alpha_mode : 0];
    o->alpha_cutoff = d->alpha_cutoff, o->double_sided = d->double_sided != 0, o->unlit = d->unlit != 0;
    if (!idmap_put(&w->materials, key, w->mat_count)) return sy_error_set(w->err, SY_ERR_OUT_OF_MEMORY, "write GLB: out of memory");
    *out = (int32_t)w->mat_count++;
    return SY_OK;
}

/* The blob's array when it holds exactly `count` elements of `elem` bytes, else NULL. */
static const void *array_of(const sy_blob *b, size_t count, size_t elem)
{
    return b && sy_blob_size(b) == count * elem ? sy_blob_data(b) : NULL;
}

static sy_result mesh_index(writer *w, sy_mesh m, int32_t *out)
{
    uint32_t v;
    if (idmap_find(&w->meshes, m.id, &v)) {
        *out = (int32_t)v;
        return SY_OK;
    }
    const sy_mesh_data *d = sy_mesh_get(w->s, m);
    if (!d) return sy_error_set(w->err, SY_ERR_INVALID_HANDLE, "write GLB: mesh %u is stale", m.id);
    sy_gltf_shim_wmesh *nm = realloc(w->wmeshes, sizeof *nm * (w->mesh_count + 1));
    sy_gltf_shim_wprimitive **np = nm ? realloc(w->prims, sizeof *np * (w->mesh_count + 1)) : NULL;
    if (nm) w->wmeshes = nm;
    if (np) w->prims = np;
    if (!nm || !np) return sy_error_set(w->err, SY_ERR_OUT_OF_MEMORY, "write GLB: out of memory");
    sy_gltf_shim_wprimitive *ps = calloc(d->primitives.count ? d->primitives.count : 1, sizeof *ps);
    w->prims[w->mesh_count] = ps;
    w->wmeshes[w->mesh_count] = (sy_gltf_shim_wmesh){.name = d->name, .primitives = ps, .primitive_count = 0};
    w->mesh_count++;
    if (!ps) return sy_error_set(w->err, SY_ERR_OUT_OF_MEMORY, "write GLB: out of memory");
    static const int32_t modes[SY_TOPOLOGY_COUNT] = {4, 1, 0};
    uint32_t k = 0;
    for (uint32_t i = 0; i < d->primitives.count; ++i) {
        const sy_primitive *p = &d->primitives.items[i];
        size_t nv = sy_blob_size(p->positions) / 12, ni = p->indices ? sy_blob_size(p->indices) / 4 : 0;
        if (nv == 0 || p->topology >= SY_TOPOLOGY_COUNT) continue; /* nothing to draw */
        if (nv > UINT32_MAX || ni > UINT32_MAX)
            return sy_error_set(w->err, SY_ERR_LIMIT, "write GLB: mesh %u primitive %u: %zu vertices / %zu indices exceed 2^32",
                                m.id, i, nv, ni);
        const uint32_t *idx = p->indices ? sy_blob_data(p->indices) : NULL;
        for (size_t j = 0; j < ni; ++j) /* the writer narrows indices to 16 bits: each must name a vertex */
            if (idx[j] >= nv)
                return sy_error_set(w->err, SY_ERR_INVALID_ARGUMENT, "write GLB: mesh %u primitive %u: index %zu is %u, past its %zu vertices",
                                    m.id, i, j, idx[j], nv);
        sy_gltf_shim_wprimitive *o = &ps[k++];
        o->mode = modes[p->topology];
        o->vertex_count = (uint32_t)nv;
        o->positions = sy_blob_data(p->positions);
        o->normals = array_of(p->normals, nv, 12);
        o->texcoords0 = array_of(p->texcoords0, nv, 8);
        o->colors = array_of(p->colors, nv, 16);
        o->indices = p->indices ? sy_blob_data(p->indices) : NULL;
        o->index_count = (uint32_t)ni;
        sy_result r = material_index(w, p->material, &o->material);
        if (r != SY_OK) return r;
    }
    w->wmeshes[w->mesh_count - 1].primitive_count = k;
    if (!idmap_put(&w->meshes, m.id, w->mesh_count - 1)) return sy_error_set(w->err, SY_ERR_OUT_OF_MEMORY, "write GLB: out of memory");
    *out = (int32_t)(w->mesh_count - 1);
    return SY_OK;
}

sy_result sy_gltf_write_placements(const sy_scene *s, const sy_gltf_placement *placements, uint32_t count,
                                   const sy_gltf_write_options *opts, uint8_t **glb_out, size_t *len_out, sy_error *err)
{
    *glb_out = NULL;
    *len_out = 0;
    writer w = {.s = s, .err = err};
    sy_gltf_shim_wnode *nodes = calloc(count ? count : 1, sizeof *nodes);
    sy_result r = nodes ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "write GLB: out of memory for %u nodes", count);
    for (uint32_t i = 0; r == SY_OK && i < count; ++i) {
        const sy_gltf_placement *p = &placements[i];
        sy_gltf_shim_wnode *n = &nodes[i];
        const sy_node_data *nd = p->node_id ? sy_node_get(s, (sy_node){p->node_id}) : NULL;
        n->name = nd ? nd->name : NULL;
        n->id = p->id;
        for (int k = 0; k < 16; ++k) n->matrix[k] = p->world.m[k];
        n->mesh = -1;
        if (p->mesh.id) r = mesh_index(&w, p->mesh, &n->mesh);
    }
    if (r == SY_OK) {
        sy_gltf_shim_wdoc doc = {.generator = opts && opts->generator ? opts->generator : "Switchyard",
                                 .materials = w.wmats, .material_count = w.mat_count,
                                 .meshes = w.wmeshes, .mesh_count = w.mesh_count,
                                 .nodes = nodes, .node_count = count};
        r = sy_gltf_shim_write_glb(&doc, glb_out, len_out, err);
    }
    for (uint32_t i = 0; i < w.mesh_count; ++i) free(w.prims[i]);
    free(w.prims), free(w.wmeshes), free(w.wmats), free(nodes);
    idmap_free(&w.meshes), idmap_free(&w.materials);
    return r;
}

sy_result sy_gltf_write_subtree(const sy_scene *s, sy_node root, const sy_gltf_write_options *opts, uint8_t **glb_out,
                                size_t *len_out, sy_error *err)
{
    *glb_out = NULL;
    *len_out = 0;
    sy_gltf_placement *p = NULL;
    uint32_t n = 0;
    sy_result r = sy_gltf_placements_collect(s, root, &p, &n, err);
    if (r == SY_OK) r = sy_gltf_write_placements(s, p, n, opts, glb_out, len_out, err);
    free(p);
    return r;
}

sy_result sy_gltf_write_subtree_file(const sy_scene *s, sy_node root, const sy_gltf_write_options *opts,
                                     const char *path, sy_error *err)
{
    uint8_t *glb = NULL;
    size_t len = 0;
    sy_result r = sy_gltf_write_subtree(s, root, opts, &glb, &len, err);
    if (r != SY_OK) return r;
    sy_atomic_file af = {0};
    r = sy_atomic_file_begin(path, &af, err);
    if (r == SY_OK) {
        if (fwrite(glb, 1, len, af.fp) != len) {
            sy_atomic_file_abort(&af);
            r = sy_error_set(err, SY_ERR_IO, "%s: write failed", path);
        } else {
            r = sy_atomic_file_commit(&af, err);
        }
    }
    free(glb);
    return r;
}
