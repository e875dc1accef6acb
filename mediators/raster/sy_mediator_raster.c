/* sy_mediator_raster.c — core scene -> OpenGL rasterizer adapter (see sy_mediator_raster.h).
 *
 * Sections: >>tables (id-indexed mirrors)  >>textures/materials/meshes/lights  >>nodes and
 * placements  >>sync  >>render  >>class */
#include "sy_mediator_raster.h"

#include "sy_gl.h"

#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ERRLEN 256
#define IDX(id) ((id) & SY_HANDLE_INDEX_MASK)

/* >>tables: every mirror is an array indexed by the handle's slot index, holding the full id so
 * a stale id never matches. */
typedef struct tex_m {
    uint32_t id;
    sy_image_info info;
    sy_sampler sampler;
    sy_blob *pixels;
    sy_gl_texture gl;
} tex_m;

typedef struct mat_m {
    uint32_t id;
    sy_material_data d; /* POD fields only (name not kept) */
    sy_gl_material gl;
} mat_m;

typedef struct prim_m {
    sy_gl_mesh gl;
    uint32_t material; /* core material id */
} prim_m;

typedef struct mesh_m {
    uint32_t id;
    prim_m *prims;
    uint32_t prim_count;
    uint32_t *users; /* node ids */
    uint32_t user_count, user_capacity;
} mesh_m;

typedef struct light_m {
    uint32_t id;
    sy_light_data d;
    uint32_t *users;
    uint32_t user_count, user_capacity;
} light_m;

typedef struct bg_m {
    uint32_t id;
    float color[4];
} bg_m;

typedef struct placement {
    sy_mat4 world;
    bool visible;
    sy_gl_instance *inst; /* one per primitive of the node's mesh */
    uint32_t inst_count;
    sy_gl_light light;
} placement;

typedef struct node_m {
    uint32_t id;
    sy_mat4 local;
    uint32_t *children;
    uint32_t child_count;
    uint32_t mesh, light, flags;
    uint32_t *parents;
    uint32_t parent_count, parent_capacity;
    placement *pl;
    uint32_t pl_count;
    uint32_t visit; /* sync epoch */
} node_m;

typedef struct raster_state {
    sy_gl_device *dev;
    uint32_t root;
    tex_m *tex;
    uint32_t tex_cap;
    mat_m *mat;
    uint32_t mat_cap;
    mesh_m *mesh;
    uint32_t mesh_cap;
    light_m *light;
    uint32_t light_cap;
    bg_m *bg;
    uint32_t bg_cap;
    node_m *node;
    uint32_t node_cap;
    uint32_t *dirty; /* node ids to re-place */
    uint32_t dirty_count, dirty_capacity;
    uint32_t epoch;
    sy_mediator_raster_counters counters;
    uint64_t frames_rendered;
    double last_sync_seconds, last_render_seconds;
} raster_state;

static bool grow(void **arr, uint32_t *cap, size_t elem, uint32_t index)
{
    if (index < *cap) return true;
    uint32_t nc = *cap ? *cap : 64;
    while (nc <= index) nc *= 2;
    void *n = realloc(*arr, elem * nc);
    if (!n) return false;
    memset((char *)n + elem * *cap, 0, elem * (nc - *cap));
    *arr = n;
    *cap = nc;
    return true;
}

#define LOOKUP(st_, arr_, cap_, id_) ((id_) && IDX(id_) < (st_)->cap_ && (st_)->arr_[IDX(id_)].id == (id_) ? &(st_)->arr_[IDX(id_)] : NULL)

static bool push_u32(uint32_t **items, uint32_t *count, uint32_t *cap, uint32_t v)
{
    if (*count == *cap) {
        uint32_t nc = *cap ? *cap * 2 : 4;
        uint32_t *n = realloc(*items, sizeof *n * nc);
        if (!n) return false;
        *items = n;
        *cap = nc;
    }
    (*items)[(*count)++] = v;
    return true;
}

static void remove_u32(uint32_t *items, uint32_t *count, uint32_t v)
{
    for (uint32_t i = 0; i < *count; ++i)
        if (items[i] == v) {
            items[i] = items[--*count];
            return;
        }
}

static sy_result gl_fail(sy_error *err, sy_gl_result r, const char *what, const char *msg)
{
    return sy_error_set(err, r == SY_GL_ERROR_OUT_OF_MEMORY ? SY_ERR_OUT_OF_MEMORY : SY_ERR_BACKEND, "raster: %s: %s", what, msg);
}

static void mark_node_dirty(raster_state *st, uint32_t id)
{
    push_u32(&st->dirty, &st->dirty_count, &st->dirty_capacity, id);
}

/* >>textures */
static sy_gl_texture gl_texture_of(const raster_state *st, uint32_t id)
{
    const tex_m *t = LOOKUP(st, tex, tex_cap, id);
    sy_gl_texture none = {0};
    return t ? t->gl : none;
}

static sy_gl_texture_ref texref(const raster_state *st, const sy_texture_ref *r)
{
    sy_gl_texture_ref o = {gl_texture_of(st, r->texture.id), r->texcoord};
    return o;
}

static sy_result material_upload(raster_state *st, mat_m *m, sy_error *err)
{
    char e[ERRLEN];
    sy_gl_material_desc d;
    sy_gl_material_desc_init(&d);
    memcpy(d.base_color, m->d.base_color, sizeof d.base_color);
    d.base_color_texture = texref(st, &m->d.base_color_texture);
    d.metallic = m->d.metallic;
    d.roughness = m->d.roughness;
    d.metallic_roughness_texture = texref(st, &m->d.metallic_roughness_texture);
    for (int i = 0; i < 3; ++i) d.emissive[i] = m->d.emissive[i] * m->d.emissive_strength;
    d.emissive_texture = texref(st, &m->d.emissive_texture);
    d.normal_texture = texref(st, &m->d.normal_texture);
    d.normal_scale = m->d.normal_texture.scale;
    d.occlusion_texture = texref(st, &m->d.occlusion_texture);
    d.occlusion_strength = m->d.occlusion_texture.scale;
    d.transmission = m->d.transmission;
    d.ior = m->d.ior >= 1.0f ? m->d.ior : 1.5f;
    d.alpha_mode = (sy_gl_alpha_mode)m->d.alpha_mode;
    d.alpha_cutoff = m->d.alpha_cutoff;
    d.double_sided = m->d.double_sided != 0;
    d.unlit = m->d.unlit != 0;
    sy_gl_result r = m->gl.id ? sy_gl_material_update(st->dev, m->gl, &d, e, sizeof e)
                              : sy_gl_material_create(st->dev, &d, &m->gl, e, sizeof e);
    return r == SY_GL_OK ? SY_OK : gl_fail(err, r, "material", e);
}

static bool material_uses_texture(const sy_material_data *d, uint32_t tex)
{
    return d->base_color_texture.texture.id == tex || d->metallic_roughness_texture.texture.id == tex ||
           d->normal_texture.texture.id == tex || d->emissive_texture.texture.id == tex ||
           d->occlusion_texture.texture.id == tex;
}

static sy_result texture_upload(raster_state *st, tex_m *t, sy_error *err)
{
    char e[ERRLEN];
    if (t->gl.id) sy_gl_texture_destroy(st->dev, t->gl);
    t->gl.id = 0;
    size_t elem = t->info.format == SY_PIXEL_F32 ? 4 : 1, need;
    if (!t->pixels || t->info.width == 0 || t->info.height == 0 ||
        !sy_size_mul((size_t)t->info.width * t->info.height, (size_t)t->info.channels * elem, &need) ||
        sy_blob_size(t->pixels) != need)
        return SY_OK; /* incomplete texture: materials render without it */
    sy_gl_texture_desc d = {
        .width = t->info.width,
        .height = t->info.height,
        .channels = t->info.channels,
        .format = t->info.format == SY_PIXEL_U8_SRGB     ? SY_GL_TEXEL_UNORM8_SRGB
                  : t->info.format == SY_PIXEL_U8_LINEAR ? SY_GL_TEXEL_UNORM8
                                                         : SY_GL_TEXEL_FLOAT32,
        .pixels = sy_blob_data(t->pixels),
        .wrap_s = (sy_gl_wrap)t->sampler.wrap_s,
        .wrap_t = (sy_gl_wrap)t->sampler.wrap_t,
        .nearest = t->sampler.mag_filter == SY_FILTER_NEAREST,
    };
    sy_gl_result r = sy_gl_texture_create(st->dev, &d, &t->gl, e, sizeof e);
    if (r != SY_GL_OK) return gl_fail(err, r, "texture", e);
    /* materials referring to this texture get the new back-end handle */
    for (uint32_t i = 0; i < st->mat_cap; ++i) {
        mat_m *m = &st->mat[i];
        if (m->id && m->gl.id && material_uses_texture(&m->d, t->id)) {
            sy_result rr = material_upload(st, m, err);
            if (rr != SY_OK) return rr;
        }
    }
    return SY_OK;
}

/* >>meshes */
static void mesh_free_prims(raster_state *st, mesh_m *m)
{
    for (uint32_t i = 0; i < m->prim_count; ++i)
        if (m->prims[i].gl.id) sy_gl_mesh_destroy(st->dev, m->prims[i].gl);
    free(m->prims);
    m->prims = NULL;
    m->prim_count = 0;
}

static sy_result mesh_upload(raster_state *st, mesh_m *m, const sy_primitive_list *pl, sy_error *err)
{
    char e[ERRLEN];
    mesh_free_prims(st, m);
    if (pl->count == 0) return SY_OK;
    m->prims = calloc(pl->count, sizeof *m->prims);
    if (!m->prims) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "mesh: out of memory");
    m->prim_count = pl->count;
    for (uint32_t i = 0; i < pl->count; ++i) {
        const sy_primitive *p = &pl->items[i];
        uint32_t nv = sy_primitive_vertex_count(p), nt = sy_primitive_triangle_count(p);
        m->prims[i].material = p->material.id;
        if (nt == 0) continue;
        sy_gl_mesh_desc d = {
            .positions = sy_blob_data(p->positions),
            .normals = sy_blob_data(p->normals),
            .uv = {sy_blob_data(p->texcoords0), sy_blob_data(p->texcoords1)},
            .colors = sy_blob_data(p->colors),
            .indices = sy_blob_data(p->indices),
            .vertex_count = nv,
            .triangle_count = nt,
        };
        sy_gl_result r = sy_gl_mesh_create(st->dev, &d, &m->prims[i].gl, e, sizeof e);
        if (r != SY_GL_OK) return gl_fail(err, r, "mesh primitive", e);
    }
    return SY_OK;
}

/* >>nodes and placements */
static void placement_clear(raster_state *st, placement *p)
{
    for (uint32_t i = 0; i < p->inst_count; ++i)
        if (p->inst[i].id) sy_gl_instance_destroy(st->dev, p->inst[i]);
    free(p->inst);
    p->inst = NULL;
    p->inst_count = 0;
    if (p->light.id) sy_gl_light_destroy(st->dev, p->light);
    p->light.id = 0;
}

static void light_desc(const sy_light_data *l, const sy_mat4 *w, sy_gl_light_desc *d)
{
    memset(d, 0, sizeof *d);
    d->type = l->type == SY_LIGHT_SPOT ? SY_GL_LIGHT_SPOT : l->type == SY_LIGHT_DIRECTIONAL ? SY_GL_LIGHT_DIRECTIONAL
                                                                                          : SY_GL_LIGHT_POINT;
    memcpy(d->color, l->color, sizeof d->color);
    d->intensity = l->intensity;
    d->range = l->range;
    d->inner_cone_angle = l->inner_cone;
    d->outer_cone_angle = l->outer_cone;
    float o[3] = {0, 0, 0}, z[3] = {0, 0, -1};
    sy_mat4_transform_point(w, o, d->position);
    sy_mat4_transform_dir(w, z, d->direction);
}

/* Brings a placement's instances and light in line with the node's mesh/light and the world
 * matrix; only what changed is touched. */
static sy_result placement_sync(raster_state *st, node_m *n, placement *p, bool mesh_changed, sy_error *err)
{
    char e[ERRLEN];
    const mesh_m *m = LOOKUP(st, mesh, mesh_cap, n->mesh);
    uint32_t want = m ? m->prim_count : 0;
    bool visible = p->visible && (n->flags & SY_NODE_VISIBLE);
    if (mesh_changed || want != p->inst_count) {
        for (uint32_t i = 0; i < p->inst_count; ++i)
            if (p->inst[i].id) sy_gl_instance_destroy(st->dev, p->inst[i]);
        free(p->inst);
        p->inst = NULL;
        p->inst_count = 0;
        if (want) {
            p->inst = calloc(want, sizeof *p->inst);
            if (!p->inst) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster: instances: out of memory");
            p->inst_count = want;
            for (uint32_t i = 0; i < want; ++i) {
                if (!m->prims[i].gl.id) continue;
                const mat_m *mm = LOOKUP(st, mat, mat_cap, m->prims[i].material);
                sy_gl_instance_desc d = {.mesh = m->prims[i].gl,
                                         .material = mm ? mm->gl : (sy_gl_material){0},
                                         .hidden = !visible};
                memcpy(d.transform, p->world.m, sizeof d.transform);
                sy_gl_result r = sy_gl_instance_create(st->dev, &d, &p->inst[i], e, sizeof e);
                if (r != SY_GL_OK) return gl_fail(err, r, "instance", e);
            }
        }
    } else {
        for (uint32_t i = 0; i < p->inst_count; ++i) {
            if (!p->inst[i].id) continue;
            sy_gl_result r = sy_gl_instance_set_transform(st->dev, p->inst[i], p->world.m, e, sizeof e);
            if (r == SY_GL_OK) r = sy_gl_instance_set_visible(st->dev, p->inst[i], visible);
            if (r != SY_GL_OK) return gl_fail(err, r, "instance transform", e);
        }
    }
    const light_m *l = LOOKUP(st, light, light_cap, n->light);
    if (l && visible) {
        sy_gl_light_desc d;
        light_desc(&l->d, &p->world, &d);
        sy_gl_result r = p->light.id ? sy_gl_light_update(st->dev, p->light, &d, e, sizeof e)
                                     : sy_gl_light_create(st->dev, &d, &p->light, e, sizeof e);
        if (r != SY_GL_OK) return gl_fail(err, r, "light", e);
    } else if (p->light.id) {
        sy_gl_light_destroy(st->dev, p->light);
        p->light.id = 0;
    }
    return SY_OK;
}

/* Recomputes the placements of node id and of its whole subtree (children first use their
 * parents' new placements). mesh_changed forces new instances for the first node. */
static sy_result replace_subtree(raster_state *st, uint32_t id, bool mesh_changed, sy_error *err)
{
    uint32_t *stack = NULL, count = 0, cap = 0;
    sy_result r = SY_OK;
    push_u32(&stack, &count, &cap, id);
    bool first = true;
    while (count && r == SY_OK) {
        uint32_t nid = stack[--count];
        node_m *n = LOOKUP(st, node, node_cap, nid);
        if (!n) continue;
        /* placements from the parents' placements (a DAG node gets one per path) */
        uint32_t want = 0;
        bool is_root = st->root ? nid == st->root : n->parent_count == 0;
        if (is_root) want = 1;
        else
            for (uint32_t i = 0; i < n->parent_count; ++i) {
                node_m *pn = LOOKUP(st, node, node_cap, n->parents[i]);
                if (pn) want += pn->pl_count;
            }
        if (want != n->pl_count) {
            for (uint32_t i = want; i < n->pl_count; ++i) placement_clear(st, &n->pl[i]);
            placement *np = realloc(n->pl, sizeof *np * (want ? want : 1));
            if (!np) {
                r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "placements: out of memory");
                break;
            }
            for (uint32_t i = n->pl_count; i < want; ++i) memset(&np[i], 0, sizeof np[i]);
            n->pl = np;
            n->pl_count = want;
        }
        uint32_t k = 0;
        if (is_root) {
            n->pl[0].world = n->local;
            n->pl[0].visible = true;
        } else {
            for (uint32_t i = 0; i < n->parent_count; ++i) {
                node_m *pn = LOOKUP(st, node, node_cap, n->parents[i]);
                if (!pn) continue;
                for (uint32_t j = 0; j < pn->pl_count; ++j, ++k) {
                    n->pl[k].world = sy_mat4_mul(&pn->pl[j].world, &n->local);
                    n->pl[k].visible = pn->pl[j].visible && (pn->flags & SY_NODE_VISIBLE);
                }
            }
        }
        for (uint32_t i = 0; i < n->pl_count && r == SY_OK; ++i) r = placement_sync(st, n, &n->pl[i], first && mesh_changed, err);
        st->counters.last_sync_placements += n->pl_count;
        n->visit = st->epoch;
        first = false;
        for (uint32_t c = 0; c < n->child_count; ++c) push_u32(&stack, &count, &cap, n->children[c]);
    }
    free(stack);
    return r;
}

static void node_free(raster_state *st, node_m *n)
{
    for (uint32_t i = 0; i < n->pl_count; ++i) placement_clear(st, &n->pl[i]);
    free(n->pl);
    free(n->children);
    free(n->parents);
    memset(n, 0, sizeof *n);
}

static void set_children(raster_state *st, node_m *n, const uint32_t *ch, uint32_t count)
{
    for (uint32_t i = 0; i < n->child_count; ++i) {
        node_m *c = LOOKUP(st, node, node_cap, n->children[i]);
        if (c) {
            remove_u32(c->parents, &c->parent_count, n->id);
            mark_node_dirty(st, c->id);
        }
    }
    free(n->children);
    n->children = NULL;
    n->child_count = 0;
    if (count) {
        n->children = malloc(sizeof *n->children * count);
        if (n->children) {
            memcpy(n->children, ch, sizeof *ch * count);
            n->child_count = count;
        }
    }
    for (uint32_t i = 0; i < n->child_count; ++i) {
        node_m *c = LOOKUP(st, node, node_cap, n->children[i]);
        if (c) {
            push_u32(&c->parents, &c->parent_count, &c->parent_capacity, n->id);
            mark_node_dirty(st, c->id);
        }
    }
}

/* >>sync */
static sy_result apply_entry(raster_state *st, const sy_change *e, sy_error *err)
{
    uint32_t idx = IDX(e->id);
    bool destroyed = (e->flags & SY_CHANGE_DESTROYED) != 0;
    switch (e->type) {
    case SY_TYPE_TEXTURE: {
        tex_m *t = LOOKUP(st, tex, tex_cap, e->id);
        if (destroyed) {
            if (t) {
                if (t->gl.id) sy_gl_texture_destroy(st->dev, t->gl);
                sy_blob_release(t->pixels);
                memset(t, 0, sizeof *t);
            }
            return SY_OK;
        }
        if (!t) {
            if (!grow((void **)&st->tex, &st->tex_cap, sizeof *st->tex, idx))
                return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
            t = &st->tex[idx];
            memset(t, 0, sizeof *t);
            t->id = e->id;
        }
        const sy_texture_data *d = e->data;
        if (e->mask & SY_BIT(SY_TEXTURE_INFO)) t->info = d->info;
        if (e->mask & SY_BIT(SY_TEXTURE_SAMPLER)) t->sampler = d->sampler;
        if (e->mask & SY_BIT(SY_TEXTURE_PIXELS)) {
            sy_blob_release(t->pixels);
            t->pixels = sy_blob_retain(d->pixels);
        }
        if (e->mask & (SY_BIT(SY_TEXTURE_INFO) | SY_BIT(SY_TEXTURE_SAMPLER) | SY_BIT(SY_TEXTURE_PIXELS)))
            return texture_upload(st, t, err);
        return SY_OK;
    }
    case SY_TYPE_MATERIAL: {
        mat_m *m = LOOKUP(st, mat, mat_cap, e->id);
        if (destroyed) {
            if (m) {
                if (m->gl.id) sy_gl_material_destroy(st->dev, m->gl);
                memset(m, 0, sizeof *m);
            }
            return SY_OK;
        }
        if (!m) {
            if (!grow((void **)&st->mat, &st->mat_cap, sizeof *st->mat, idx))
                return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
            m = &st->mat[idx];
            memset(m, 0, sizeof *m);
            m->id = e->id;
            m->d = *(const sy_material_data *)sy_object_defaults(SY_TYPE_MATERIAL);
        }
        /* a creation carries every field (partial updates are merged in rt_sync) */
        m->d = *(const sy_material_data *)e->data;
        m->d.name = NULL; /* not owned by the mirror */
        if (e->mask == SY_BIT(SY_MATERIAL_NAME) || e->mask == SY_BIT(SY_FIELD_ATTACHMENTS)) return SY_OK;
        return material_upload(st, m, err);
    }
    case SY_TYPE_MESH: {
        mesh_m *m = LOOKUP(st, mesh, mesh_cap, e->id);
        if (destroyed) {
            if (m) {
                for (uint32_t i = 0; i < m->user_count; ++i) mark_node_dirty(st, m->users[i]);
                mesh_free_prims(st, m);
                free(m->users);
                memset(m, 0, sizeof *m);
            }
            return SY_OK;
        }
        if (!m) {
            if (!grow((void **)&st->mesh, &st->mesh_cap, sizeof *st->mesh, idx))
                return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
            m = &st->mesh[idx];
            memset(m, 0, sizeof *m);
            m->id = e->id;
        }
        if (e->mask & SY_BIT(SY_MESH_PRIMITIVES)) {
            sy_result r = mesh_upload(st, m, &((const sy_mesh_data *)e->data)->primitives, err);
            if (r != SY_OK) return r;
            /* users need new instances: drop the old ones, then re-place the users */
            for (uint32_t i = 0; i < m->user_count; ++i) {
                node_m *n = LOOKUP(st, node, node_cap, m->users[i]);
                if (n)
                    for (uint32_t k = 0; k < n->pl_count; ++k) {
                        placement *p = &n->pl[k];
                        for (uint32_t j = 0; j < p->inst_count; ++j)
                            if (p->inst[j].id) sy_gl_instance_destroy(st->dev, p->inst[j]);
                        free(p->inst);
                        p->inst = NULL;
                        p->inst_count = 0;
                    }
                mark_node_dirty(st, m->users[i]);
            }
        }
        return SY_OK;
    }
    case SY_TYPE_LIGHT: {
        light_m *l = LOOKUP(st, light, light_cap, e->id);
        if (destroyed) {
            if (l) {
                for (uint32_t i = 0; i < l->user_count; ++i) mark_node_dirty(st, l->users[i]);
                free(l->users);
                memset(l, 0, sizeof *l);
            }
            return SY_OK;
        }
        if (!l) {
            if (!grow((void **)&st->light, &st->light_cap, sizeof *st->light, idx))
                return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
            l = &st->light[idx];
            memset(l, 0, sizeof *l);
            l->id = e->id;
            l->d = *(const sy_light_data *)sy_object_defaults(SY_TYPE_LIGHT);
        }
        const sy_light_data *d = e->data;
        if (e->mask & SY_BIT(SY_LIGHT_TYPE)) l->d.type = d->type;
        if (e->mask & SY_BIT(SY_LIGHT_COLOR)) memcpy(l->d.color, d->color, sizeof d->color);
        if (e->mask & SY_BIT(SY_LIGHT_INTENSITY)) l->d.intensity = d->intensity;
        if (e->mask & SY_BIT(SY_LIGHT_RANGE)) l->d.range = d->range;
        if (e->mask & SY_BIT(SY_LIGHT_INNER_CONE)) l->d.inner_cone = d->inner_cone;
        if (e->mask & SY_BIT(SY_LIGHT_OUTER_CONE)) l->d.outer_cone = d->outer_cone;
        for (uint32_t i = 0; i < l->user_count; ++i) mark_node_dirty(st, l->users[i]);
        return SY_OK;
    }
    case SY_TYPE_BACKGROUND: {
        bg_m *b = LOOKUP(st, bg, bg_cap, e->id);
        if (destroyed) {
            if (b) memset(b, 0, sizeof *b);
            return SY_OK;
        }
        if (!b) {
            if (!grow((void **)&st->bg, &st->bg_cap, sizeof *st->bg, idx))
                return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
            b = &st->bg[idx];
            memset(b, 0, sizeof *b);
            b->id = e->id;
            memcpy(b->color, ((const sy_background_data *)sy_object_defaults(SY_TYPE_BACKGROUND))->color, sizeof b->color);
        }
        if (e->mask & SY_BIT(SY_BACKGROUND_COLOR)) memcpy(b->color, ((const sy_background_data *)e->data)->color, sizeof b->color);
        return SY_OK;
    }
    case SY_TYPE_NODE: {
        node_m *n = LOOKUP(st, node, node_cap, e->id);
        if (destroyed) {
            if (n) {
                for (uint32_t i = 0; i < n->child_count; ++i) {
                    node_m *c = LOOKUP(st, node, node_cap, n->children[i]);
                    if (c) {
                        remove_u32(c->parents, &c->parent_count, n->id);
                        mark_node_dirty(st, c->id);
                    }
                }
                mesh_m *m = LOOKUP(st, mesh, mesh_cap, n->mesh);
                if (m) remove_u32(m->users, &m->user_count, n->id);
                light_m *l = LOOKUP(st, light, light_cap, n->light);
                if (l) remove_u32(l->users, &l->user_count, n->id);
                node_free(st, n);
            }
            return SY_OK;
        }
        if (!n) {
            if (!grow((void **)&st->node, &st->node_cap, sizeof *st->node, idx))
                return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
            n = &st->node[idx];
            memset(n, 0, sizeof *n);
            n->id = e->id;
            n->local = sy_mat4_identity();
            n->flags = SY_NODE_VISIBLE;
        }
        const sy_node_data *d = e->data;
        bool dirty = (e->flags & SY_CHANGE_CREATED) != 0;
        if (e->mask & SY_BIT(SY_NODE_TRANSFORM)) {
            n->local = d->transform.matrix;
            dirty = true;
        }
        if (e->mask & SY_BIT(SY_NODE_FLAGS)) {
            n->flags = d->flags;
            dirty = true;
        }
        if (e->mask & SY_BIT(SY_NODE_MESH)) {
            mesh_m *om = LOOKUP(st, mesh, mesh_cap, n->mesh), *nm = LOOKUP(st, mesh, mesh_cap, d->mesh.id);
            if (om) remove_u32(om->users, &om->user_count, n->id);
            if (nm) push_u32(&nm->users, &nm->user_count, &nm->user_capacity, n->id);
            n->mesh = d->mesh.id;
            for (uint32_t k = 0; k < n->pl_count; ++k) { /* force new instances */
                placement *p = &n->pl[k];
                for (uint32_t j = 0; j < p->inst_count; ++j)
                    if (p->inst[j].id) sy_gl_instance_destroy(st->dev, p->inst[j]);
                free(p->inst);
                p->inst = NULL;
                p->inst_count = 0;
            }
            dirty = true;
        }
        if (e->mask & SY_BIT(SY_NODE_LIGHT)) {
            light_m *ol = LOOKUP(st, light, light_cap, n->light), *nl = LOOKUP(st, light, light_cap, d->light.id);
            if (ol) remove_u32(ol->users, &ol->user_count, n->id);
            if (nl) push_u32(&nl->users, &nl->user_count, &nl->user_capacity, n->id);
            n->light = d->light.id;
            dirty = true;
        }
        if (e->mask & SY_BIT(SY_NODE_CHILDREN)) {
            uint32_t nc;
            const uint32_t *ch = sy_node_children(d, &nc);
            set_children(st, n, ch, nc);
            dirty = true;
        }
        if (dirty) mark_node_dirty(st, n->id);
        return SY_OK;
    }
    default: return SY_OK;
    }
}

static sy_result raster_sync(void *state, const sy_changes *changes, sy_error *err)
{
    raster_state *st = state;
    double t_sync = sy_time_now();
    st->counters.last_sync_placements = 0;
    st->counters.last_sync_entries = sy_changes_count(changes);
    sy_result r = SY_OK;
    /* Entries come ordered: destructions, then textures, materials, meshes, lights, cameras,
     * backgrounds, nodes; so every reference is resolvable when a node is placed. Nodes are
     * first all mirrored (children may precede parents), then re-placed. */
    for (uint32_t i = 0; i < sy_changes_count(changes); ++i) { /* node mirrors first: children may precede */
        const sy_change *e = sy_changes_get(changes, i);
        if (e->type != SY_TYPE_NODE || !(e->flags & SY_CHANGE_CREATED)) continue;
        const node_m *existing = LOOKUP(st, node, node_cap, e->id);
        if (existing) continue;
        if (!grow((void **)&st->node, &st->node_cap, sizeof *st->node, IDX(e->id)))
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster mediator: out of memory");
        node_m *n = &st->node[IDX(e->id)];
        memset(n, 0, sizeof *n);
        n->id = e->id;
        n->local = sy_mat4_identity();
        n->flags = SY_NODE_VISIBLE;
    }
    for (uint32_t i = 0; i < sy_changes_count(changes) && r == SY_OK; ++i) {
        const sy_change *e = sy_changes_get(changes, i);
        if (e->type == SY_TYPE_MATERIAL && !(e->flags & SY_CHANGE_DESTROYED) && !(e->flags & SY_CHANGE_CREATED)) {
            /* partial material update: merge masked fields into the mirror */
            mat_m *m = LOOKUP(st, mat, mat_cap, e->id);
            if (m) {
                const sy_material_data *d = e->data;
                sy_material_data merged = m->d;
#define TAKE(bit, member) if (e->mask & SY_BIT(bit)) memcpy(&merged.member, &d->member, sizeof merged.member)
                TAKE(SY_MATERIAL_BASE_COLOR, base_color);
                TAKE(SY_MATERIAL_BASE_COLOR_TEXTURE, base_color_texture);
                TAKE(SY_MATERIAL_METALLIC, metallic);
                TAKE(SY_MATERIAL_ROUGHNESS, roughness);
                TAKE(SY_MATERIAL_METALLIC_ROUGHNESS_TEXTURE, metallic_roughness_texture);
                TAKE(SY_MATERIAL_NORMAL_TEXTURE, normal_texture);
                TAKE(SY_MATERIAL_OCCLUSION_TEXTURE, occlusion_texture);
                TAKE(SY_MATERIAL_EMISSIVE, emissive);
                TAKE(SY_MATERIAL_EMISSIVE_STRENGTH, emissive_strength);
                TAKE(SY_MATERIAL_EMISSIVE_TEXTURE, emissive_texture);
                TAKE(SY_MATERIAL_ALPHA_MODE, alpha_mode);
                TAKE(SY_MATERIAL_ALPHA_CUTOFF, alpha_cutoff);
                TAKE(SY_MATERIAL_DOUBLE_SIDED, double_sided);
                TAKE(SY_MATERIAL_TRANSMISSION, transmission);
                TAKE(SY_MATERIAL_TRANSMISSION_TEXTURE, transmission_texture);
                TAKE(SY_MATERIAL_IOR, ior);
                TAKE(SY_MATERIAL_UNLIT, unlit);
#undef TAKE
                m->d = merged;
                if (e->mask & ~(SY_BIT(SY_MATERIAL_NAME) | SY_BIT(SY_FIELD_ATTACHMENTS))) r = material_upload(st, m, err);
                continue;
            }
        }
        r = apply_entry(st, e, err);
    }
    st->epoch++;
    for (uint32_t i = 0; i < st->dirty_count && r == SY_OK; ++i) {
        node_m *n = LOOKUP(st, node, node_cap, st->dirty[i]);
        if (!n || n->visit == st->epoch) continue; /* already re-placed through an ancestor */
        r = replace_subtree(st, n->id, false, err);
    }
    st->dirty_count = 0;
    sy_gl_stats gs;
    sy_gl_device_stats(st->dev, &gs);
    st->counters.meshes = gs.meshes;
    st->counters.instances = gs.instances;
    st->counters.materials = gs.materials;
    st->counters.textures = gs.textures;
    st->counters.lights = gs.lights;
    st->last_sync_seconds = sy_time_now() - t_sync;
    return r;
}

/* >>render */
static void camera_of(const sy_camera_view *v, sy_gl_camera *cam)
{
    memcpy(cam->camera_to_world, v->camera_to_world.m, sizeof cam->camera_to_world);
    cam->orthographic = v->projection == SY_PROJECTION_ORTHOGRAPHIC;
    memcpy(cam->window, v->window, sizeof cam->window);
    cam->near_clip = v->znear;
    cam->far_clip = v->zfar;
}

static void apply_background(raster_state *st, uint32_t background_id)
{
    const bg_m *b = LOOKUP(st, bg, bg_cap, background_id);
    sy_gl_set_background(st->dev, b && b->color[3] > 0.0f, b ? b->color : NULL);
}

static sy_result check_layer(const sy_render_request *req, const sy_layer *layer, sy_error *err)
{
    if (layer->width != req->rect_w || layer->height != req->rect_h)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "raster: layer %ux%u does not match the request rectangle %ux%u",
                            layer->width, layer->height, req->rect_w, req->rect_h);
    return SY_OK;
}

static sy_result raster_render(void *state, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    raster_state *st = state;
    char e[ERRLEN];
    sy_result rr = check_layer(req, layer, err);
    if (rr != SY_OK) return rr;
    double t0 = sy_time_now();
    apply_background(st, req->background_id);
    sy_gl_camera cam;
    camera_of(&req->camera, &cam);
    sy_gl_render_desc d = {req->full_width, req->full_height, req->rect_x, req->rect_y, req->rect_w, req->rect_h};
    sy_gl_result r = sy_gl_render(st->dev, &cam, &d, layer->rgba, layer->depth, e, sizeof e);
    if (r != SY_GL_OK) return gl_fail(err, r, "render", e);
    if (req->progress) {
        sy_progress p = {1, 1};
        req->progress(req->progress_user, &p);
    }
    st->frames_rendered++;
    st->last_render_seconds = sy_time_now() - t0;
    return SY_OK;
}

sy_result sy_mediator_raster_render_floor(void *state, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    raster_state *st = state;
    char e[ERRLEN];
    sy_result rr = check_layer(req, layer, err);
    if (rr != SY_OK) return rr;
    apply_background(st, req->background_id);
    sy_gl_camera cam;
    camera_of(&req->camera, &cam);
    sy_gl_render_desc d = {req->full_width, req->full_height, req->rect_x, req->rect_y, req->rect_w, req->rect_h};
    sy_gl_result r = sy_gl_render_floor(st->dev, &cam, &d, layer->rgba, e, sizeof e);
    return r == SY_GL_OK ? SY_OK : gl_fail(err, r, "floor render", e);
}

/* >>class */
static void raster_destroy(void *state)
{
    raster_state *st = state;
    if (!st) return;
    for (uint32_t i = 0; i < st->node_cap; ++i)
        if (st->node[i].id) node_free(st, &st->node[i]);
    for (uint32_t i = 0; i < st->mesh_cap; ++i) {
        mesh_free_prims(st, &st->mesh[i]);
        free(st->mesh[i].users);
    }
    for (uint32_t i = 0; i < st->light_cap; ++i) free(st->light[i].users);
    for (uint32_t i = 0; i < st->tex_cap; ++i) sy_blob_release(st->tex[i].pixels);
    sy_gl_device_destroy(st->dev);
    free(st->tex);
    free(st->mat);
    free(st->mesh);
    free(st->light);
    free(st->bg);
    free(st->node);
    free(st->dirty);
    free(st);
}

static void log_warning(void *user, const char *msg)
{
    raster_state *st = user;
    st->counters.warnings++;
    snprintf(st->counters.last_warning, sizeof st->counters.last_warning, "%s", msg);
    fprintf(stderr, "sy: warning: %s\n", msg);
}

static sy_result raster_create(const sy_mediator_create_args *args, void **state_out, sy_error *err)
{
    *state_out = NULL;
    long msaa, shadow, max_tex, ww, wh;
    sy_result r;
    sy_gl_provider provider = SY_GL_PROVIDER_OSMESA;
    const char *gl = sy_params_get(args->params, "gl");
    if (gl && !sy_gl_provider_parse(gl, &provider))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "raster: parameter gl=%s: expected osmesa, egl or glfw", gl);
    if ((r = sy_params_get_int(args->params, "msaa", 4, 1, 32, &msaa, err)) ||
        (r = sy_params_get_int(args->params, "shadow_map_size", 2048, 16, 16384, &shadow, err)) ||
        (r = sy_params_get_int(args->params, "max_texture_size", 0, 0, 1 << 20, &max_tex, err)) ||
        (r = sy_params_get_int(args->params, "window_width", 640, 1, 16384, &ww, err)) ||
        (r = sy_params_get_int(args->params, "window_height", 480, 1, 16384, &wh, err)))
        return r;
    raster_state *st = calloc(1, sizeof *st);
    if (!st) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "raster mediator: out of memory");
    char e[ERRLEN];
    sy_gl_device_desc dd = {.provider = provider,
                            .msaa = (uint32_t)msaa,
                            .shadow_map_size = (uint32_t)shadow,
                            .max_texture_size = (uint32_t)max_tex,
                            .window_width = (uint32_t)ww,
                            .window_height = (uint32_t)wh,
                            .log = log_warning,
                            .log_user = st};
    sy_gl_result gr = sy_gl_device_create(&dd, &st->dev, e, sizeof e);
    if (gr != SY_GL_OK) {
        free(st);
        return sy_error_set(err, gr == SY_GL_ERROR_NO_CONTEXT ? SY_ERR_UNSUPPORTED : SY_ERR_BACKEND, "raster: %s", e);
    }
    st->root = args->root_node_id;
    *state_out = st;
    return SY_OK;
}

static void raster_stats(void *state, sy_mediator_stats *out)
{
    raster_state *st = state;
    out->samples = st->frames_rendered ? 1 : 0;
    out->last_sync_seconds = st->last_sync_seconds;
    out->last_render_seconds = st->last_render_seconds;
}

static const sy_mediator_class raster_class = {
    .name = "raster",
    .caps = SY_CAP_DEPTH | SY_CAP_TILES,
    .create = raster_create,
    .destroy = raster_destroy,
    .sync = raster_sync,
    .render = raster_render,
    .stats = raster_stats,
};

const sy_mediator_class *sy_mediator_raster_class(void) { return &raster_class; }

void sy_mediator_raster_counters_get(void *state, sy_mediator_raster_counters *out)
{
    raster_state *st = state;
    *out = st->counters;
    sy_gl_stats gs;
    sy_gl_device_stats(st->dev, &gs);
    out->vertex_buffer_uploads = gs.frame.vertex_buffer_uploads;
    out->vertex_bytes = gs.frame.vertex_bytes;
    out->uniform_buffer_uploads = gs.frame.uniform_buffer_uploads;
    out->texture_uploads = gs.frame.texture_uploads;
    out->model_matrix_updates = gs.frame.model_matrix_updates;
    out->total_vertex_buffer_uploads = gs.total.vertex_buffer_uploads;
    out->total_texture_uploads = gs.total.texture_uploads;
    out->msaa_samples = gs.msaa_samples;
    out->shadow_maps = gs.shadow_maps;
    out->draw_calls = gs.draw_calls;
    out->triangles_drawn = gs.triangles_drawn;
}

const char *sy_mediator_raster_info(void *state) { return sy_gl_device_info(((raster_state *)state)->dev); }
