/* sy_gltf_write.c — scene placements to GLB (see sy_gltf_write.h): collects placements from the
 * node graph, maps meshes and materials to glTF indices, points the shim at the blobs' arrays
 * (no copies here) and lets tinygltf serialise the document. */
#include "sy_gltf_write.h"

#include "sy_file.h"
#include "sy_gltf_shim.h"
#include "sy_log.h"

#include <png.h>

#include <stdlib.h>
#include <string.h>
#include <strings.h>

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

/* The index already given to key, in *val (left alone when there is none). */
static bool idmap_find(const idmap *m, uint32_t key, int32_t *val)
{
    if (!m->cap) return false;
    for (uint32_t h = (key * 2654435761u) & (m->cap - 1);; h = (h + 1) & (m->cap - 1)) {
        if (m->keys[h] == 0) return false;
        if (m->keys[h] == key) {
            *val = (int32_t)m->vals[h];
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
    bool full; /* sy_gltf_write_scene (and placements with opts->textures): textures, tangents, texcoord 1 and every material extension */
    uint32_t max_side; /* opts->texture_max_side: larger textures are halved until they fit (0: as they are) */
    idmap meshes, materials, textures;
    sy_gltf_shim_wtexture *wtex;
    uint32_t tex_count;
    sy_gltf_shim_wmesh *wmeshes;
    sy_gltf_shim_wmaterial *wmats;
    uint32_t mesh_count, mat_count;
    sy_gltf_shim_wprimitive **prims; /* per mesh, freed at the end */
    sy_error *err;
} writer;

static const char *const alpha_modes[] = {"OPAQUE", "MASK", "BLEND"};

static sy_result texture_index(writer *w, sy_texture t, int32_t *out);

/* A material's texture reference (texture + 1, 0: none or left out). */
static sy_result texref(writer *w, const sy_texture_ref *r, sy_gltf_shim_wtexref *o)
{
    *o = (sy_gltf_shim_wtexref){.scale = r->scale, .offset = {r->offset[0], r->offset[1]}, .rotation = r->rotation,
                                .uv_scale = {r->uv_scale[0], r->uv_scale[1]}, .texcoord = r->texcoord};
    return r->texture.id ? texture_index(w, r->texture, &o->texture) : SY_OK;
}

/* Every field of a material beyond the placements' ones (sy_gltf_write_scene). */
static sy_result material_full(writer *w, const sy_material_data *d, sy_gltf_shim_wmaterial *o)
{
    o->full = 1;
    o->transmission = d->transmission, o->ior = d->ior, o->specular = d->specular;
    o->clearcoat = d->clearcoat, o->clearcoat_roughness = d->clearcoat_roughness, o->sheen_roughness = d->sheen_roughness;
    o->thickness = d->thickness, o->attenuation_distance = d->attenuation_distance, o->iridescence = d->iridescence;
    o->iridescence_ior = d->iridescence_ior, o->anisotropy = d->anisotropy, o->anisotropy_rotation = d->anisotropy_rotation;
    for (int i = 0; i < 3; ++i) {
        o->specular_color[i] = d->specular_color[i], o->sheen_color[i] = d->sheen_color[i];
        o->attenuation_color[i] = d->attenuation_color[i];
    }
    o->iridescence_thickness[0] = d->iridescence_thickness[0], o->iridescence_thickness[1] = d->iridescence_thickness[1];
    const struct { const sy_texture_ref *in; sy_gltf_shim_wtexref *out; } slots[] = {
        {&d->base_color_texture, &o->base_color_tex},     {&d->metallic_roughness_texture, &o->metallic_roughness_tex},
        {&d->normal_texture, &o->normal_tex},             {&d->occlusion_texture, &o->occlusion_tex},
        {&d->emissive_texture, &o->emissive_tex},         {&d->transmission_texture, &o->transmission_tex},
        {&d->specular_texture, &o->specular_tex},         {&d->specular_color_texture, &o->specular_color_tex},
        {&d->clearcoat_texture, &o->clearcoat_tex},       {&d->clearcoat_roughness_texture, &o->clearcoat_roughness_tex},
        {&d->clearcoat_normal_texture, &o->clearcoat_normal_tex}, {&d->sheen_color_texture, &o->sheen_color_tex},
        {&d->sheen_roughness_texture, &o->sheen_roughness_tex}, {&d->thickness_texture, &o->thickness_tex},
        {&d->iridescence_texture, &o->iridescence_tex},   {&d->iridescence_thickness_texture, &o->iridescence_thickness_tex},
        {&d->anisotropy_texture, &o->anisotropy_tex}};
    _Static_assert(sizeof slots / sizeof slots[0] == SY_MATERIAL_TEXTURE_SLOTS, "every texture slot of sy_material_data");
    for (size_t i = 0; i < sizeof slots / sizeof slots[0]; ++i) {
        sy_result r = texref(w, slots[i].in, slots[i].out);
        if (r != SY_OK) return r;
    }
    return SY_OK;
}

static sy_result material_index(writer *w, sy_material m, int32_t *out)
{
    uint32_t key = m.id ? m.id : UINT32_MAX;
    if (idmap_find(&w->materials, key, out)) return SY_OK;
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
    if (w->full) {
        sy_result r = material_full(w, d, o);
        if (r != SY_OK) return r;
    }
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
    if (idmap_find(&w->meshes, m.id, out)) return SY_OK;
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
        if (w->full) {
            /* tangents without normals mean nothing in glTF (a reader ignores them): not written */
            if (p->normals) o->tangents = array_of(p->tangents, nv, 16);
            o->texcoords1 = array_of(p->texcoords1, nv, 8);
        }
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

/* The 8-bit image px (w x h, ch channels) halved (2 x 2 box; an odd last row or column is
 * averaged with itself) until both sides are at most max_side; *w, *h updated. NULL when out of
 * memory. */
static uint8_t *halve_to(const uint8_t *px, uint32_t *w, uint32_t *h, uint32_t ch, uint32_t max_side)
{
    uint8_t *cur = NULL;
    const uint8_t *src = px;
    uint32_t sw = *w, sh = *h;
    while (sw > max_side || sh > max_side) {
        uint32_t dw = sw > 1 ? (sw + 1) / 2 : 1, dh = sh > 1 ? (sh + 1) / 2 : 1;
        uint8_t *dst = malloc((size_t)dw * dh * ch);
        if (!dst) {
            free(cur);
            return NULL;
        }
        for (uint32_t y = 0; y < dh; ++y) {
            uint32_t y0 = sh > 1 ? 2 * y : 0, y1 = y0 + 1 < sh ? y0 + 1 : y0;
            for (uint32_t x = 0; x < dw; ++x) {
                uint32_t x0 = sw > 1 ? 2 * x : 0, x1 = x0 + 1 < sw ? x0 + 1 : x0;
                for (uint32_t c = 0; c < ch; ++c) {
                    uint32_t v = src[((size_t)y0 * sw + x0) * ch + c] + src[((size_t)y0 * sw + x1) * ch + c] +
                                 src[((size_t)y1 * sw + x0) * ch + c] + src[((size_t)y1 * sw + x1) * ch + c];
                    dst[((size_t)y * dw + x) * ch + c] = (uint8_t)((v + 2) / 4);
                }
            }
        }
        free(cur);
        cur = dst, src = dst, sw = dw, sh = dh;
    }
    *w = sw, *h = sh;
    return cur;
}

/* >>textures: one glTF image (PNG, libpng's simplified writer) and sampler per core texture */
static sy_result texture_index(writer *w, sy_texture t, int32_t *out)
{
    *out = 0;
    if (idmap_find(&w->textures, t.id, out)) return SY_OK; /* index + 1, 0: left out */
    const sy_texture_data *d = sy_texture_get(w->s, t);
    if (!d) return sy_error_set(w->err, SY_ERR_INVALID_HANDLE, "write glTF: texture %u is stale", t.id);
    const sy_image_info *ii = &d->info;
    int32_t index = 0;
    if (ii->format == SY_PIXEL_F32) {
        sy_log(SY_LOG_WARNING, "gltf", d->name, "texture %u: float pixels, which glTF cannot hold: left out", t.id);
    } else if (!ii->width || !ii->height || ii->channels < 1 || ii->channels > 4 ||
               sy_blob_size(d->pixels) != (size_t)ii->width * ii->height * ii->channels) {
        sy_log(SY_LOG_WARNING, "gltf", d->name, "texture %u: no image: left out", t.id);
    } else {
        static const png_uint_32 formats[4] = {PNG_FORMAT_GRAY, PNG_FORMAT_GA, PNG_FORMAT_RGB, PNG_FORMAT_RGBA};
        uint32_t tw = ii->width, th = ii->height;
        uint8_t *small = NULL; /* the pixels halved to texture_max_side, when asked */
        const uint8_t *px = sy_blob_data(d->pixels);
        if (w->max_side && (tw > w->max_side || th > w->max_side)) {
            small = halve_to(px, &tw, &th, ii->channels, w->max_side);
            if (!small) return sy_error_set(w->err, SY_ERR_OUT_OF_MEMORY, "write glTF: texture %u: out of memory", t.id);
            px = small;
        }
        png_image im = {.version = PNG_IMAGE_VERSION, .width = tw, .height = th, .format = formats[ii->channels - 1]};
        png_alloc_size_t size = 0;
        if (!png_image_write_get_memory_size(im, size, 0, px, 0, NULL)) {
            free(small);
            return sy_error_set(w->err, SY_ERR_IO, "write glTF: texture %u: %s", t.id, im.message);
        }
        uint8_t *png = malloc(size ? size : 1);
        if (!png) {
            free(small);
            return sy_error_set(w->err, SY_ERR_OUT_OF_MEMORY, "write glTF: texture %u: out of memory", t.id);
        }
        if (!png_image_write_to_memory(&im, png, &size, 0, px, 0, NULL)) {
            free(png), free(small);
            return sy_error_set(w->err, SY_ERR_IO, "write glTF: texture %u: %s", t.id, im.message);
        }
        free(small);
        sy_gltf_shim_wtexture *nt = realloc(w->wtex, sizeof *nt * (w->tex_count + 1));
        if (!nt) {
            free(png);
            return sy_error_set(w->err, SY_ERR_OUT_OF_MEMORY, "write glTF: out of memory");
        }
        w->wtex = nt;
        static const int32_t wraps[3] = {10497, 33071, 33648}, filters[2] = {9729, 9728};
        const sy_sampler *sm = &d->sampler;
        nt[w->tex_count] = (sy_gltf_shim_wtexture){
            .name = d->name, .png = png, .png_size = size, .wrap_s = wraps[sm->wrap_s < 3 ? sm->wrap_s : 0],
            .wrap_t = wraps[sm->wrap_t < 3 ? sm->wrap_t : 0], .min_filter = filters[sm->min_filter < 2 ? sm->min_filter : 0],
            .mag_filter = filters[sm->mag_filter < 2 ? sm->mag_filter : 0]};
        index = (int32_t)++w->tex_count;
    }
    if (!idmap_put(&w->textures, t.id, (uint32_t)index)) return sy_error_set(w->err, SY_ERR_OUT_OF_MEMORY, "write glTF: out of memory");
    *out = index;
    return SY_OK;
}

static void writer_free(writer *w)
{
    for (uint32_t i = 0; i < w->mesh_count; ++i) free(w->prims[i]);
    for (uint32_t i = 0; i < w->tex_count; ++i) free((void *)w->wtex[i].png);
    free(w->prims), free(w->wmeshes), free(w->wmats), free(w->wtex);
    idmap_free(&w->meshes), idmap_free(&w->materials), idmap_free(&w->textures);
}

sy_result sy_gltf_write_placements(const sy_scene *s, const sy_gltf_placement *placements, uint32_t count,
                                   const sy_gltf_write_options *opts, uint8_t **glb_out, size_t *len_out, sy_error *err)
{
    *glb_out = NULL;
    *len_out = 0;
    writer w = {.s = s, .full = opts && opts->textures, .max_side = opts ? opts->texture_max_side : 0, .err = err};
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
                                 .textures = w.wtex, .texture_count = w.tex_count,
                                 .nodes = nodes, .node_count = count};
        r = sy_gltf_shim_write_glb(&doc, glb_out, len_out, err);
    }
    writer_free(&w);
    free(nodes);
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

/* bytes to path through a temporary file renamed into place (sy_file.h) */
static sy_result write_atomic(const char *path, const uint8_t *bytes, size_t len, sy_error *err)
{
    sy_atomic_file af = {0};
    sy_result r = sy_atomic_file_begin(path, &af, err);
    if (r != SY_OK) return r;
    if (fwrite(bytes, 1, len, af.fp) != len) {
        sy_atomic_file_abort(&af);
        return sy_error_set(err, SY_ERR_IO, "%s: write failed", path);
    }
    return sy_atomic_file_commit(&af, err);
}

sy_result sy_gltf_write_subtree_file(const sy_scene *s, sy_node root, const sy_gltf_write_options *opts,
                                     const char *path, sy_error *err)
{
    uint8_t *glb = NULL;
    size_t len = 0;
    sy_result r = sy_gltf_write_subtree(s, root, opts, &glb, &len, err);
    if (r == SY_OK) r = write_atomic(path, glb, len, err);
    free(glb);
    return r;
}

/* >>scene: the node hierarchy under root with its meshes, materials, textures, cameras, lights */
typedef struct scene_writer {
    writer w;
    sy_gltf_shim_wnode *nodes;
    int32_t **children; /* per node, freed at the end */
    uint32_t node_count, node_cap;
    idmap cameras, lights;
    sy_gltf_shim_wcamera *cams;
    sy_gltf_shim_wlight *lights_out;
    uint32_t cam_count, light_count;
} scene_writer;

/* The index (1-based) of camera or light id in the file, added on its first use (t: SY_TYPE_CAMERA
 * or SY_TYPE_LIGHT). */
static sy_result camera_or_light_index(scene_writer *sw, sy_object_type t, uint32_t id, int32_t *out)
{
    bool cam = t == SY_TYPE_CAMERA;
    idmap *m = cam ? &sw->cameras : &sw->lights;
    if (idmap_find(m, id, out)) return SY_OK;
    const void *obj = sy_object_get(sw->w.s, t, id);
    if (!obj) return sy_error_set(sw->w.err, SY_ERR_INVALID_HANDLE, "write glTF: %s %u is stale", cam ? "camera" : "light", id);
    uint32_t *count = cam ? &sw->cam_count : &sw->light_count;
    bool grown = false;
    if (cam) {
        const sy_camera_data *d = obj;
        sy_gltf_shim_wcamera *n = realloc(sw->cams, sizeof *n * (*count + 1));
        if ((grown = n != NULL)) {
            sw->cams = n;
            n[*count] = (sy_gltf_shim_wcamera){.name = d->name, .orthographic = d->projection == SY_PROJECTION_ORTHOGRAPHIC,
                                               .yfov = d->yfov, .aspect = d->aspect, .znear = d->znear, .zfar = d->zfar,
                                               .xmag = d->xmag, .ymag = d->ymag};
        }
    } else {
        const sy_light_data *d = obj;
        sy_gltf_shim_wlight *n = realloc(sw->lights_out, sizeof *n * (*count + 1));
        static const char *const types[3] = {"point", "spot", "directional"};
        if ((grown = n != NULL)) {
            sw->lights_out = n;
            n[*count] = (sy_gltf_shim_wlight){.name = d->name, .type = types[d->type < 3 ? d->type : 0],
                                              .color = {d->color[0], d->color[1], d->color[2]}, .intensity = d->intensity,
                                              .range = d->range, .inner_cone = d->inner_cone, .outer_cone = d->outer_cone};
        }
    }
    if (grown) *out = (int32_t)++*count;
    if (grown && idmap_put(m, id, (uint32_t)*out)) return SY_OK;
    return sy_error_set(sw->w.err, SY_ERR_OUT_OF_MEMORY, "write glTF: out of memory");
}

/* Node n and its subtree (pre-order); *index_out: its glTF index, -1 when it is left out (hidden).
 * A node reached along several paths is written once per path (glTF nodes form a tree). */
static sy_result emit_node(scene_writer *sw, sy_node n, uint32_t depth, int32_t *index_out)
{
    *index_out = -1;
    const sy_node_data *d = sy_node_get(sw->w.s, n);
    if (!d) return sy_error_set(sw->w.err, SY_ERR_INVALID_HANDLE, "write glTF: node %u is stale", n.id);
    if (depth >= SY_GLTF_MAX_DEPTH)
        return sy_error_set(sw->w.err, SY_ERR_LIMIT, "write glTF: node %u lies deeper than %u levels", n.id, SY_GLTF_MAX_DEPTH);
    if (!(d->flags & SY_NODE_VISIBLE)) {
        sy_log(SY_LOG_WARNING, "gltf", d->name, "node %u is hidden, which glTF cannot say: left out with its subtree", n.id);
        return SY_OK;
    }
    if (sw->node_count == SY_GLTF_MAX_PLACEMENTS)
        return sy_error_set(sw->w.err, SY_ERR_LIMIT, "write glTF: more than %u nodes", SY_GLTF_MAX_PLACEMENTS);
    if (sw->node_count == sw->node_cap) {
        uint32_t nc = sw->node_cap ? sw->node_cap * 2 : 64;
        sy_gltf_shim_wnode *nn = realloc(sw->nodes, sizeof *nn * nc);
        if (nn) sw->nodes = nn;
        int32_t **ncld = nn ? realloc(sw->children, sizeof *ncld * nc) : NULL;
        if (ncld) sw->children = ncld;
        if (!nn || !ncld) return sy_error_set(sw->w.err, SY_ERR_OUT_OF_MEMORY, "write glTF: out of memory");
        sw->node_cap = nc;
    }
    uint32_t me = sw->node_count++;
    sy_gltf_shim_wnode o = {.name = d->name, .mesh = -1, .id = -1};
    sw->children[me] = NULL;
    const sy_transform *t = &d->transform;
    o.trs = t->mode == SY_TRANSFORM_TRS;
    for (int k = 0; k < 16; ++k) o.matrix[k] = t->matrix.m[k];
    for (int k = 0; k < 3; ++k) o.translation[k] = t->translation[k], o.scale[k] = t->scale[k];
    for (int k = 0; k < 4; ++k) o.rotation[k] = t->rotation[k];
    sy_result r = SY_OK;
    if (d->mesh.id) r = mesh_index(&sw->w, d->mesh, &o.mesh);
    if (r == SY_OK && d->camera.id) r = camera_or_light_index(sw, SY_TYPE_CAMERA, d->camera.id, &o.camera);
    if (r == SY_OK && d->light.id) r = camera_or_light_index(sw, SY_TYPE_LIGHT, d->light.id, &o.light);
    sw->nodes[me] = o;
    if (r != SY_OK) return r;
    uint32_t nc = 0;
    const uint32_t *kids = sy_node_children(d, &nc);
    int32_t *mine = nc ? malloc(sizeof *mine * nc) : NULL;
    if (nc && !mine) return sy_error_set(sw->w.err, SY_ERR_OUT_OF_MEMORY, "write glTF: out of memory");
    sw->children[me] = mine;
    uint32_t used = 0;
    for (uint32_t i = 0; i < nc; ++i) {
        int32_t ci;
        if ((r = emit_node(sw, (sy_node){kids[i]}, depth + 1, &ci)) != SY_OK) return r;
        if (ci >= 0) mine[used++] = ci;
    }
    sw->nodes[me].children = mine;
    sw->nodes[me].child_count = used;
    *index_out = (int32_t)me;
    return SY_OK;
}

sy_result sy_gltf_write_scene(const sy_scene *s, sy_node root, const sy_gltf_write_options *opts, bool binary,
                              uint8_t **out, size_t *len_out, sy_error *err)
{
    *out = NULL;
    *len_out = 0;
    scene_writer sw = {.w = {.s = s, .full = true, .max_side = opts ? opts->texture_max_side : 0, .err = err}};
    const sy_node_data *rd = sy_node_get(s, root);
    sy_result r = rd ? SY_OK : sy_error_set(err, SY_ERR_INVALID_HANDLE, "write glTF: root node %u is stale", root.id);
    int32_t *roots = NULL;
    uint32_t root_count = 0;
    if (r == SY_OK) {
        /* a plain root (identity, nothing attached, visible) stands for the scene: its children are
         * scene 0's nodes; any other root is written as the one root node */
        sy_mat4 id = sy_mat4_identity();
        bool plain = !rd->mesh.id && !rd->camera.id && !rd->light.id && (rd->flags & SY_NODE_VISIBLE) &&
                     !memcmp(&rd->transform.matrix, &id, sizeof id);
        uint32_t nc = 0;
        const uint32_t *kids = plain ? sy_node_children(rd, &nc) : &root.id;
        if (!plain) nc = 1;
        roots = malloc(sizeof *roots * (nc ? nc : 1));
        if (!roots) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "write glTF: out of memory");
        for (uint32_t i = 0; r == SY_OK && i < nc; ++i) {
            int32_t ci;
            r = emit_node(&sw, (sy_node){kids[i]}, 0, &ci);
            if (r == SY_OK && ci >= 0) roots[root_count++] = ci;
        }
    }
    if (r == SY_OK) {
        for (uint32_t b = sy_scene_next(s, SY_TYPE_BACKGROUND, 0); b; b = sy_scene_next(s, SY_TYPE_BACKGROUND, b))
            sy_log(SY_LOG_WARNING, "gltf", NULL, "background %u (the world: colour, gradient, environment map): glTF cannot hold it: left out", b);
        for (uint32_t a = sy_scene_next(s, SY_TYPE_ANIMATION, 0); a; a = sy_scene_next(s, SY_TYPE_ANIMATION, a)) {
            const sy_animation_data *ad = sy_object_get(s, SY_TYPE_ANIMATION, a);
            sy_log(SY_LOG_WARNING, "gltf", ad->name, "animation %#x: not written (the writer has no animations yet); the nodes are written in their current pose", a);
        }
        sy_gltf_shim_wdoc doc = {.generator = opts && opts->generator ? opts->generator : "Switchyard",
                                 .materials = sw.w.wmats, .material_count = sw.w.mat_count,
                                 .meshes = sw.w.wmeshes, .mesh_count = sw.w.mesh_count,
                                 .nodes = sw.nodes, .node_count = sw.node_count, .roots = roots, .root_count = root_count,
                                 .textures = sw.w.wtex, .texture_count = sw.w.tex_count,
                                 .cameras = sw.cams, .camera_count = sw.cam_count,
                                 .lights = sw.lights_out, .light_count = sw.light_count};
        r = sy_gltf_shim_write(&doc, binary, out, len_out, err);
    }
    for (uint32_t i = 0; i < sw.node_count; ++i) free(sw.children[i]);
    free(sw.children), free(sw.nodes), free(sw.cams), free(sw.lights_out), free(roots);
    idmap_free(&sw.cameras), idmap_free(&sw.lights);
    writer_free(&sw.w);
    return r;
}

sy_result sy_gltf_write_scene_file(const sy_scene *s, sy_node root, const sy_gltf_write_options *opts, const char *path,
                                   sy_error *err)
{
    size_t n = strlen(path);
    bool glb = n >= 4 && !strcasecmp(path + n - 4, ".glb"), gltf = n >= 5 && !strcasecmp(path + n - 5, ".gltf");
    if (!glb && !gltf) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: the output must end in .glb or .gltf", path);
    uint8_t *bytes = NULL;
    size_t len = 0;
    sy_result r = sy_gltf_write_scene(s, root, opts, glb, &bytes, &len, err);
    if (r == SY_OK) r = write_atomic(path, bytes, len, err);
    free(bytes);
    return r;
}
