/* test_replica_property.c — property test: random edit sequences on an origin scene, replicated
 * through serialised change lists, must give replicas equal to the origin.
 *
 *   usage: test_replica_property [seeds [first_seed [ops]]]   (defaults 3000, 1, 30)
 *
 * Per seed (deterministic splitmix64 PRNG): a random starting scene (a few objects of every type,
 * meshes on nodes, a hierarchy), then ~30 random operations on the origin — create and
 * destroy every object type, set every kind of field (names, TRS and matrix transforms, acyclic
 * child lists, meshes of random small primitives with shared blobs, materials with texture refs,
 * textures, lights, cameras, backgrounds, flags, animation clips and the clock moving nodes) and
 * attachments of every kind, with commits in
 * between. At random moments the origin commits and its consumers pull:
 *   origin --(wire)--> rep1 --(wire)--> rep2     (a replica of a replica)
 *   origin --(wire)--> rep3                      (a consumer added at a random moment, maybe with
 *                                                 changes pending; it pulls less often)
 * Every pulled list is serialised (blob payloads only the first time the receiver sees them, as a
 * sender would track it) and deserialised into the receiver's blob store, then applied. After every
 * pull the receiver must be sy_scene_equal to its source. Each scene's world matrices and bounds
 * are also checked against a from-scratch recomputation, and replicas' against the origin's where
 * the placement is unambiguous (single-parent chains). On failure the seed and the difference
 * are printed; rerun one seed with `test_replica_property 1 SEED`. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../support/sy_check.h"
#include "../support/sy_test_rng.h"
#include "sy_anim.h"
#include "sy_changes.h"

/* ------------------------------------------------------------------ PRNG */
static uint64_t rng_state;
static uint64_t rnd(void) { return sy_test_splitmix64(&rng_state); }
static uint32_t rn(uint32_t n) { return n ? (uint32_t)(rnd() % n) : 0; }
static bool chance(uint32_t percent) { return rn(100) < percent; }
/* exactly representable values, sometimes -0 */
static float rf(float lo, float hi)
{
    if (chance(3)) return -0.0f;
    float t = (float)rn(257) / 256.0f;
    return lo + (hi - lo) * t;
}

/* ------------------------------------------------------------------ a link: consumer + wire + receiver */
typedef struct link {
    sy_scene *src, *dst;
    uint32_t consumer;     /* on src; 0 = not yet added */
    sy_blob_store *sent;   /* sender side: blobs whose payload went out on this link */
    sy_blob_store *store;  /* receiver side */
    uint64_t pulls, bytes, payload_bytes;
    const char *name;
} link;

static bool send_once(void *user, const sy_blob *b)
{
    link *l = user;
    if (sy_blob_store_get(l->sent, sy_blob_hash(b))) return false;
    sy_error e = {0};
    if (sy_blob_store_put(l->sent, (sy_blob *)b, &e) != SY_OK) abort();
    l->payload_bytes += sy_blob_size(b);
    return true;
}

static int link_open(link *l, sy_scene *src, const char *name)
{
    sy_error e = {0};
    memset(l, 0, sizeof *l);
    l->src = src;
    l->name = name;
    CHECK_OK(sy_scene_create(&l->dst, &e), e);
    CHECK_OK(sy_blob_store_create(&l->sent, &e), e);
    CHECK_OK(sy_blob_store_create(&l->store, &e), e);
    CHECK_OK(sy_scene_consumer_add(src, &l->consumer, &e), e);
    return 0;
}

static void link_close(link *l)
{
    sy_scene_destroy(l->dst);
    sy_blob_store_destroy(l->sent);
    sy_blob_store_destroy(l->store);
    memset(l, 0, sizeof *l);
}

/* ------------------------------------------------------------------ reference world matrices and bounds */
typedef struct node_ref {
    uint32_t id;
    int state; /* 0 unvisited, 1 in progress, 2 done */
    sy_mat4 world;
    int lstate;
    sy_bounds local;
} node_ref;

typedef struct refs {
    node_ref *items;
    uint32_t count;
} refs;

static node_ref *ref_find(refs *r, uint32_t id)
{
    for (uint32_t i = 0; i < r->count; ++i)
        if (r->items[i].id == id) return &r->items[i];
    return NULL;
}

static int ref_world(const sy_scene *s, refs *r, node_ref *n)
{
    if (n->state == 2) return 0;
    CHECK_MSG(n->state == 0, "node %#x: cycle through parents", n->id);
    n->state = 1;
    const sy_node_data *d = sy_object_get(s, SY_TYPE_NODE, n->id);
    sy_node p = sy_node_parent(s, (sy_node){n->id}, 0);
    if (p.id) {
        node_ref *pr = ref_find(r, p.id);
        CHECK_MSG(pr != NULL, "node %#x: parent %#x is not live", n->id, p.id);
        CHECK(ref_world(s, r, pr) == 0);
        n->world = sy_mat4_mul(&pr->world, &d->transform.matrix);
    } else {
        n->world = d->transform.matrix;
    }
    n->state = 2;
    return 0;
}

static int ref_local_bounds(const sy_scene *s, refs *r, node_ref *n)
{
    if (n->lstate == 2) return 0;
    CHECK_MSG(n->lstate == 0, "node %#x: cycle through children", n->id);
    n->lstate = 1;
    const sy_node_data *d = sy_object_get(s, SY_TYPE_NODE, n->id);
    sy_bounds b = sy_bounds_empty();
    const sy_mesh_data *md = sy_mesh_get(s, d->mesh);
    if (md)
        for (uint32_t i = 0; i < md->primitives.count; ++i) {
            const sy_blob *pb = md->primitives.items[i].positions;
            const float *p = sy_blob_data(pb);
            for (size_t v = 0; v < sy_blob_size(pb) / 12; ++v) sy_bounds_add_point(&b, p + 3 * v);
        }
    uint32_t nc;
    const uint32_t *ch = sy_node_children(d, &nc);
    for (uint32_t k = 0; k < nc; ++k) {
        node_ref *c = ref_find(r, ch[k]);
        if (!c) continue; /* stale child: absent */
        CHECK(ref_local_bounds(s, r, c) == 0);
        const sy_node_data *cd = sy_object_get(s, SY_TYPE_NODE, c->id);
        sy_bounds cb = sy_bounds_transform(&c->local, &cd->transform.matrix);
        sy_bounds_add_bounds(&b, &cb);
    }
    n->local = b;
    n->lstate = 2;
    return 0;
}

static bool bounds_same(const sy_bounds *a, const sy_bounds *b)
{
    if (sy_bounds_is_empty(a) || sy_bounds_is_empty(b)) return sy_bounds_is_empty(a) && sy_bounds_is_empty(b);
    return memcmp(a, b, sizeof *a) == 0;
}

/* Parent lists, world matrices and bounds of a committed scene against a from-scratch computation. */
static int check_graph(const sy_scene *s, refs *r, const char *what)
{
    sy_error e = {0};
    r->count = 0;
    uint32_t n = sy_scene_count(s, SY_TYPE_NODE);
    r->items = realloc(r->items, sizeof *r->items * (n ? n : 1));
    CHECK(r->items);
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id; id = sy_scene_next(s, SY_TYPE_NODE, id))
        r->items[r->count++] = (node_ref){.id = id};
    CHECK(r->count == n);
    /* parents == the live nodes whose child list names the node, each once */
    for (uint32_t i = 0; i < n; ++i) {
        uint32_t id = r->items[i].id, expected = 0;
        for (uint32_t j = 0; j < n; ++j) {
            uint32_t nc;
            const uint32_t *ch = sy_node_children(sy_object_get(s, SY_TYPE_NODE, r->items[j].id), &nc);
            for (uint32_t k = 0; k < nc; ++k)
                if (ch[k] == id) expected++;
        }
        uint32_t pc = sy_node_parent_count(s, (sy_node){id});
        CHECK_MSG(pc == expected, "%s: node %#x has %u parents, %u nodes list it", what, id, pc, expected);
        for (uint32_t k = 0; k < pc; ++k) {
            sy_node p = sy_node_parent(s, (sy_node){id}, k);
            const sy_node_data *pd = sy_node_get(s, p);
            CHECK_MSG(pd != NULL, "%s: node %#x parent %u is stale", what, id, k);
            uint32_t nc, hits = 0;
            const uint32_t *ch = sy_node_children(pd, &nc);
            for (uint32_t q = 0; q < nc; ++q) hits += ch[q] == id;
            CHECK(hits == 1);
            for (uint32_t q = 0; q < k; ++q) CHECK(sy_node_parent(s, (sy_node){id}, q).id != p.id);
        }
    }
    sy_bounds scene_b = sy_bounds_empty();
    for (uint32_t i = 0; i < n; ++i) {
        node_ref *nr = &r->items[i];
        CHECK(ref_world(s, r, nr) == 0);
        CHECK(ref_local_bounds(s, r, nr) == 0);
        sy_mat4 w;
        CHECK_OK(sy_node_world_matrix(s, (sy_node){nr->id}, &w, &e), e);
        CHECK_MSG(sy_mat4_equal(&w, &nr->world), "%s: node %#x world matrix is not parent world * local", what, nr->id);
        sy_bounds wb, eb = sy_bounds_transform(&nr->local, &nr->world);
        CHECK_OK(sy_node_world_bounds(s, (sy_node){nr->id}, &wb, &e), e);
        CHECK_MSG(bounds_same(&wb, &eb), "%s: node %#x world bounds (%g %g %g)-(%g %g %g) expected (%g %g %g)-(%g %g %g)",
                  what, nr->id, wb.min[0], wb.min[1], wb.min[2], wb.max[0], wb.max[1], wb.max[2], eb.min[0], eb.min[1],
                  eb.min[2], eb.max[0], eb.max[1], eb.max[2]);
        if (sy_node_parent_count(s, (sy_node){nr->id}) == 0) sy_bounds_add_bounds(&scene_b, &eb);
    }
    sy_bounds sb = sy_scene_world_bounds(s);
    CHECK_MSG(bounds_same(&sb, &scene_b), "%s: scene world bounds", what);
    for (uint32_t id = sy_scene_next(s, SY_TYPE_MESH, 0); id; id = sy_scene_next(s, SY_TYPE_MESH, id)) {
        const sy_mesh_data *md = sy_object_get(s, SY_TYPE_MESH, id);
        sy_bounds b = sy_bounds_empty(), mb;
        for (uint32_t i = 0; i < md->primitives.count; ++i) {
            const sy_blob *pb = md->primitives.items[i].positions;
            for (size_t v = 0; v < sy_blob_size(pb) / 12; ++v) sy_bounds_add_point(&b, (const float *)sy_blob_data(pb) + 3 * v);
        }
        CHECK_OK(sy_mesh_bounds(s, (sy_mesh){id}, &mb, &e), e);
        CHECK_MSG(bounds_same(&b, &mb), "%s: mesh %#x bounds", what, id);
    }
    return 0;
}

/* A node's placement is unambiguous when every node on its primary chain has one parent at most. */
static bool single_chain(const sy_scene *s, uint32_t id)
{
    for (int depth = 0; id && depth < 1000; ++depth) {
        uint32_t pc = sy_node_parent_count(s, (sy_node){id});
        if (pc > 1) return false;
        id = pc ? sy_node_parent(s, (sy_node){id}, 0).id : 0;
    }
    return true;
}

static int check_same_placement(const sy_scene *a, const sy_scene *b, const char *what)
{
    sy_error e = {0};
    for (uint32_t id = sy_scene_next(a, SY_TYPE_NODE, 0); id; id = sy_scene_next(a, SY_TYPE_NODE, id)) {
        if (!single_chain(a, id)) continue;
        CHECK(single_chain(b, id));
        sy_mat4 wa, wb;
        CHECK_OK(sy_node_world_matrix(a, (sy_node){id}, &wa, &e), e);
        CHECK_OK(sy_node_world_matrix(b, (sy_node){id}, &wb, &e), e);
        CHECK_MSG(sy_mat4_equal(&wa, &wb), "%s: node %#x placed differently", what, id);
        sy_bounds ba, bb;
        CHECK_OK(sy_node_world_bounds(a, (sy_node){id}, &ba, &e), e);
        CHECK_OK(sy_node_world_bounds(b, (sy_node){id}, &bb, &e), e);
        CHECK_MSG(bounds_same(&ba, &bb), "%s: node %#x bounds differ", what, id);
    }
    sy_bounds sa = sy_scene_world_bounds(a), sb = sy_scene_world_bounds(b);
    CHECK_MSG(bounds_same(&sa, &sb), "%s: scene bounds differ", what);
    return 0;
}

/* ------------------------------------------------------------------ replication step */
static refs g_refs;

/* Pulls the link's consumer, sends the list over the wire, applies it and commits the receiver. */
static int link_sync(link *l)
{
    sy_error e = {0};
    CHECK(!sy_scene_has_pending(l->src));
    sy_changes *c;
    CHECK_OK(sy_scene_consumer_pull(l->src, l->consumer, &c, &e), e);
    void *data;
    size_t size;
    CHECK_OK(sy_changes_serialize(c, send_once, l, &data, &size, &e), e);
    /* now and then, a corrupted copy of this real message: an error or a valid list, never a
     * crash or a leak (into a throw-away store, so the receiver is not affected) */
    if (size && chance(10)) {
        unsigned char *bad = malloc(size);
        CHECK(bad);
        memcpy(bad, data, size);
        bad[rn((uint32_t)size)] ^= (unsigned char)(1u << rn(8));
        sy_blob_store *scratch;
        CHECK_OK(sy_blob_store_create(&scratch, &e), e);
        sy_changes *junk = NULL;
        sy_error je = {0};
        if (sy_changes_deserialize(bad, chance(20) ? rn((uint32_t)size) : size, scratch, NULL, &junk, &je) == SY_OK)
            sy_changes_release(junk);
        else
            CHECK(junk == NULL && je.message[0]);
        sy_blob_store_destroy(scratch);
        free(bad);
    }
    sy_changes *d;
    CHECK_OK(sy_changes_deserialize(data, size, l->store, NULL, &d, &e), e);
    free(data);
    CHECK(sy_changes_count(d) == sy_changes_count(c));
    sy_changes_release(c);
    CHECK_OK(sy_scene_apply(l->dst, d, &e), e);
    sy_changes_release(d);
    CHECK_OK(sy_scene_commit(l->dst, NULL, &e), e);
    l->pulls++;
    l->bytes += size;
    CHECK_MSG(sy_scene_equal(l->src, l->dst, &e), "%s: replica differs from its source: %s", l->name, e.message);
    CHECK_MSG(sy_scene_equal(l->dst, l->src, &e), "%s: source differs from its replica: %s", l->name, e.message);
    /* every payload went over once and arrived */
    CHECK(sy_blob_store_count(l->store) == sy_blob_store_count(l->sent));
    CHECK(check_graph(l->dst, &g_refs, l->name) == 0);
    CHECK(check_same_placement(l->src, l->dst, l->name) == 0);
    return 0;
}

/* ------------------------------------------------------------------ random edits */
/* Every blob made during a seed (the pool holds one reference until the seed ends, so blobs
 * handed out stay valid while an operation assembles its values). */
typedef struct blob_pool {
    sy_blob **items;
    uint32_t count, capacity;
} blob_pool;

static sy_blob *pool_keep(blob_pool *p, sy_blob *b) /* takes the caller's reference */
{
    if (p->count == p->capacity) {
        p->capacity = p->capacity ? p->capacity * 2 : 64;
        p->items = realloc(p->items, sizeof *p->items * p->capacity);
        if (!p->items) abort();
    }
    p->items[p->count++] = b;
    return b;
}

static sy_blob *new_blob(const void *data, size_t size)
{
    sy_blob *b = NULL;
    sy_error e = {0};
    if (sy_blob_create_copy(data, size, &b, &e) != SY_OK) abort();
    return b;
}

/* A blob of exactly `size` bytes; shared with earlier ones (same object or same content) often. */
static sy_blob *sized_blob(blob_pool *p, size_t size, bool floats)
{
    if (chance(60)) {
        uint32_t start = rn(p->count ? p->count : 1);
        for (uint32_t k = 0; k < p->count; ++k) {
            sy_blob *b = p->items[(start + k) % p->count];
            bool fits = sy_blob_size(b) == size;
            for (size_t i = 0; fits && floats && i + 4 <= size; i += 4) {
                float f;
                memcpy(&f, (const unsigned char *)sy_blob_data(b) + i, 4);
                fits = fabsf(f) <= SY_COORD_MAX; /* random bytes would make NaN or out-of-range positions */
            }
            if (fits) {
                if (chance(20)) return pool_keep(p, new_blob(sy_blob_data(b), size)); /* equal content, new blob */
                return b;
            }
        }
    }
    unsigned char *buf = malloc(size ? size : 1);
    if (!buf) abort();
    if (floats) {
        for (size_t i = 0; i + 4 <= size; i += 4) {
            float f = rf(-8, 8);
            memcpy(buf + i, &f, 4);
        }
    } else {
        for (size_t i = 0; i < size; ++i) buf[i] = (unsigned char)rnd();
    }
    sy_blob *b = new_blob(buf, size);
    free(buf);
    return pool_keep(p, b);
}

static uint32_t pick(const sy_scene *s, uint32_t type) /* a random live object, 0 when none */
{
    uint32_t n = sy_scene_count(s, type);
    if (!n) return 0;
    uint32_t k = rn(n), id = sy_scene_next(s, type, 0);
    while (k--) id = sy_scene_next(s, type, id);
    return id;
}

static uint32_t pick_or_none(const sy_scene *s, uint32_t type) { return chance(25) ? 0 : pick(s, type); }

static const char *rand_name(void)
{
    static const char *names[] = {NULL, "", "a", "node", "a longer name with spaces", "\xc3\xa9t\xc3\xa9", "x"};
    return names[rn(sizeof names / sizeof names[0])];
}

/* true when `target` is reachable downwards from `from` over live children */
static bool reaches(const sy_scene *s, uint32_t from, uint32_t target, int depth)
{
    if (from == target) return true;
    if (depth > 200) return true; /* cannot happen in an acyclic scene; be safe */
    const sy_node_data *d = sy_object_get(s, SY_TYPE_NODE, from);
    if (!d) return false;
    uint32_t nc;
    const uint32_t *ch = sy_node_children(d, &nc);
    for (uint32_t k = 0; k < nc; ++k)
        if (reaches(s, ch[k], target, depth + 1)) return true;
    return false;
}

static sy_texture_ref rand_texref(const sy_scene *s)
{
    sy_texture_ref t = {{pick_or_none(s, SY_TYPE_TEXTURE)}, rn(2), rf(0, 2), {rf(-1, 1), rf(-1, 1)}, rf(-3, 3),
                        {rf(0, 4), rf(0, 4)}};
    if (chance(30)) t = (sy_texture_ref){{0}, 0, 1, {0, 0}, 0, {1, 1}};
    return t;
}

static int op_node(sy_scene *s, blob_pool *bp)
{
    (void)bp;
    sy_error e = {0};
    sy_node n = {pick(s, SY_TYPE_NODE)};
    if (!n.id) return 0;
    switch (rn(9)) {
    case 0: {
        float t[3] = {rf(-10, 10), rf(-10, 10), rf(-10, 10)}, q[4] = {rf(-1, 1), rf(-1, 1), rf(-1, 1), rf(-1, 1)},
              sc[3] = {rf(0.5f, 2), rf(0.5f, 2), rf(-2, 2)};
        if (chance(30)) q[0] = q[1] = q[2] = 0, q[3] = 1;
        CHECK_OK(sy_node_set_trs(s, n, t, q, sc, &e), e);
        break;
    }
    case 1: {
        sy_mat4 m;
        for (int i = 0; i < 16; ++i) m.m[i] = rf(-4, 4);
        if (chance(50)) m.m[3] = m.m[7] = m.m[11] = 0, m.m[15] = 1;
        CHECK_OK(sy_node_set_matrix(s, n, &m, &e), e);
        break;
    }
    case 2:
    case 3: {
        /* a valid child list: live nodes that are not n and do not reach n (not ancestors) */
        sy_node kids[5];
        uint32_t nk = 0, want = rn(5);
        for (uint32_t tries = 0; tries < 12 && nk < want; ++tries) {
            uint32_t c = pick(s, SY_TYPE_NODE);
            bool dup = false;
            for (uint32_t k = 0; k < nk; ++k) dup |= kids[k].id == c;
            if (!c || dup || reaches(s, c, n.id, 0)) continue;
            kids[nk++].id = c;
        }
        uint32_t have;
        const uint32_t *cur = sy_node_children(sy_node_get(s, n), &have);
        bool already = false;
        for (uint32_t k = 0; k < have && nk; ++k) already |= cur[k] == kids[0].id;
        if (chance(20) && nk && !already) {
            CHECK_OK(sy_node_add_child(s, n, kids[0], &e), e);
            uint32_t nc;
            sy_node_children(sy_node_get(s, n), &nc);
            CHECK(nc >= 1);
        } else {
            CHECK_OK(sy_node_set_children(s, n, kids, nk, &e), e);
        }
        break;
    }
    case 4: CHECK_OK(sy_node_set_mesh(s, n, (sy_mesh){pick_or_none(s, SY_TYPE_MESH)}, &e), e); break;
    case 5: CHECK_OK(sy_node_set_light(s, n, (sy_light){pick_or_none(s, SY_TYPE_LIGHT)}, &e), e); break;
    case 6: CHECK_OK(sy_node_set_camera(s, n, (sy_camera){pick_or_none(s, SY_TYPE_CAMERA)}, &e), e); break;
    case 7: CHECK_OK(sy_node_set_flags(s, n, rn(8), &e), e); break;
    default: {
        /* refused edits: a cycle, a non-finite transform; nothing changes */
        sy_node anc = n; /* n itself when no other ancestor turns up */
        for (uint32_t tries = 0; tries < 6 && anc.id == n.id; ++tries) {
            uint32_t a = pick(s, SY_TYPE_NODE);
            if (reaches(s, a, n.id, 0)) anc.id = a;
        }
        const sy_node_data *before = sy_node_get(s, n);
        sy_blob *ch = sy_blob_retain(before->children);
        CHECK_ERR(sy_node_set_children(s, n, &anc, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
        const float bad[4] = {0, NAN, 0, 1};
        CHECK_ERR(sy_node_set_trs(s, n, bad, bad, bad, &e), SY_ERR_INVALID_ARGUMENT, e);
        CHECK(sy_node_get(s, n)->children == ch);
        sy_blob_release(ch);
        break;
    }
    }
    return 0;
}

static int op_mesh(sy_scene *s, blob_pool *bp)
{
    sy_error e = {0};
    sy_mesh m = {pick(s, SY_TYPE_MESH)};
    if (!m.id) return 0;
    sy_primitive prims[3];
    uint32_t np = rn(4);
    for (uint32_t i = 0; i < np; ++i) {
        static const uint32_t counts[] = {3, 4, 6};
        uint32_t nv = counts[rn(3)];
        sy_primitive *p = &prims[i];
        memset(p, 0, sizeof *p);
        p->positions = sized_blob(bp, 12 * (size_t)nv, true);
        if (chance(50)) p->normals = sized_blob(bp, 12 * (size_t)nv, true);
        if (chance(30)) p->tangents = sized_blob(bp, 16 * (size_t)nv, true);
        if (chance(50)) p->texcoords0 = sized_blob(bp, 8 * (size_t)nv, true);
        if (chance(20)) p->texcoords1 = chance(50) ? p->texcoords0 : sized_blob(bp, 8 * (size_t)nv, true);
        if (chance(30)) p->colors = sized_blob(bp, 16 * (size_t)nv, true);
        if (nv % 3 != 0 || chance(50)) {
            uint32_t nt = 1 + rn(3), idx[9];
            for (uint32_t k = 0; k < 3 * nt; ++k) idx[k] = rn(nv);
            /* an index blob from the pool only fits when its indices are in range: make a new one */
            p->indices = pool_keep(bp, new_blob(idx, 12 * (size_t)nt));
        }
        p->material.id = pick_or_none(s, SY_TYPE_MATERIAL);
    }
    CHECK_OK(sy_mesh_set_primitives(s, m, prims, np, &e), e);
    /* a refused set: an index past the vertex count */
    if (np && chance(20)) {
        uint32_t bad[3] = {0, 1, 99};
        sy_primitive q = prims[0];
        q.indices = new_blob(bad, sizeof bad);
        CHECK_ERR(sy_mesh_set_primitives(s, m, &q, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
        sy_blob_release(q.indices);
        CHECK(sy_mesh_get(s, m)->primitives.count == np);
    }
    return 0;
}

static int op_material(sy_scene *s)
{
    sy_error e = {0};
    sy_material m = {pick(s, SY_TYPE_MATERIAL)};
    if (!m.id) return 0;
    sy_material_data d = *sy_material_get(s, m);
    d.name = (char *)(chance(80) ? sy_material_get(s, m)->name : rand_name());
    int edits = 1 + (int)rn(4);
    for (int k = 0; k < edits; ++k) switch (rn(20)) {
        case 0: d.base_color[rn(4)] = rf(0, 1); break;
        case 1: d.base_color_texture = rand_texref(s); break;
        case 2: d.metallic = rf(0, 1); break;
        case 3: d.roughness = rf(0, 1); break;
        case 4: d.metallic_roughness_texture = rand_texref(s); break;
        case 5: d.normal_texture = rand_texref(s); break;
        case 6: d.occlusion_texture = rand_texref(s); break;
        case 7: d.emissive[rn(3)] = rf(0, 5), d.emissive_strength = rf(0, 10); break;
        case 8: d.emissive_texture = rand_texref(s); break;
        case 9: d.alpha_mode = rn(3), d.alpha_cutoff = rf(0, 1); break;
        case 10: d.double_sided = rn(2), d.unlit = rn(2); break;
        case 11: d.transmission = rf(0, 1), d.transmission_texture = rand_texref(s); break;
        case 12: d.ior = chance(20) ? 0.0f : rf(1, 2.5f); break;
        case 13: d.clearcoat = rf(0, 1), d.clearcoat_roughness = rf(0, 1), d.clearcoat_normal_texture = rand_texref(s); break;
        case 14: d.sheen_color[rn(3)] = rf(0, 1), d.sheen_roughness = rf(0, 1), d.sheen_color_texture = rand_texref(s); break;
        case 15: d.specular = rf(0, 1), d.specular_color[rn(3)] = rf(0, 3), d.specular_texture = rand_texref(s); break;
        case 16:
            d.thickness = rf(0, 2), d.attenuation_distance = rf(0, 3), d.attenuation_color[rn(3)] = rf(0, 1);
            d.thickness_texture = rand_texref(s);
            break;
        case 17:
            d.iridescence = rf(0, 1), d.iridescence_ior = rf(1, 2), d.iridescence_thickness[rn(2)] = rf(0, 800);
            d.iridescence_thickness_texture = rand_texref(s);
            break;
        case 18: d.anisotropy = rf(0, 1), d.anisotropy_rotation = rf(-4, 4), d.anisotropy_texture = rand_texref(s); break;
        default: break; /* sometimes a no-op set */
        }
    CHECK_OK(sy_material_set(s, m, &d, &e), e);
    return 0;
}

static int op_texture(sy_scene *s, blob_pool *bp)
{
    sy_error e = {0};
    sy_texture t = {pick(s, SY_TYPE_TEXTURE)};
    if (!t.id) return 0;
    if (chance(30)) {
        sy_sampler smp = {rn(3), rn(3), rn(2), rn(2)};
        CHECK_OK(sy_texture_set_sampler(s, t, &smp, &e), e);
        return 0;
    }
    sy_image_info info = {1 + rn(3), 1 + rn(3), 1 + rn(4), 1 + rn(3)};
    size_t size = (size_t)info.width * info.height * info.channels * (info.format == SY_PIXEL_F32 ? 4 : 1);
    sy_blob *px = sized_blob(bp, size, info.format == SY_PIXEL_F32);
    CHECK_OK(sy_texture_set_image(s, t, &info, px, &e), e);
    return 0;
}

static int op_light_camera_background(sy_scene *s)
{
    sy_error e = {0};
    switch (rn(3)) {
    case 0: {
        sy_light l = {pick(s, SY_TYPE_LIGHT)};
        if (!l.id) return 0;
        sy_light_data d = *sy_light_get(s, l);
        d.type = rn(3);
        d.color[rn(3)] = rf(0, 1);
        d.intensity = rf(0, 100);
        d.range = chance(50) ? 0 : rf(0, 50);
        d.inner_cone = rf(0, 0.5f);
        d.outer_cone = rf(0.5f, 1.5f);
        CHECK_OK(sy_light_set(s, l, &d, &e), e);
        break;
    }
    case 1: {
        sy_camera c = {pick(s, SY_TYPE_CAMERA)};
        if (!c.id) return 0;
        sy_camera_data d = *sy_camera_get(s, c);
        d.projection = rn(2);
        d.yfov = 0.1f + (float)rn(200) / 100.0f;
        d.aspect = chance(50) ? 0 : rf(0.5f, 2);
        d.znear = 0.01f + (float)rn(100) / 64.0f;
        d.zfar = chance(50) ? 0 : rf(10, 1000);
        d.xmag = rf(0, 5);
        d.ymag = rf(0, 5);
        CHECK_OK(sy_camera_set(s, c, &d, &e), e);
        break;
    }
    default: {
        sy_background b = {pick(s, SY_TYPE_BACKGROUND)};
        if (!b.id) return 0;
        sy_background_data d = *sy_background_get(s, b);
        for (int i = 0; i < 4; ++i) d.color[i] = rf(-1, 2);
        d.environment.id = pick_or_none(s, SY_TYPE_TEXTURE);
        d.intensity = rf(0, 4);
        CHECK_OK(sy_background_set(s, b, &d, &e), e);
        break;
    }
    }
    return 0;
}

static int op_attachment(sy_scene *s, blob_pool *bp)
{
    sy_error e = {0};
    uint32_t type = 1 + rn(SY_TYPE_COUNT - 1), id = pick(s, type);
    if (!id) return 0;
    static const char *keys[] = {"a", "b", "pt.volume", "raster.hint", "z"};
    const char *key = keys[rn(5)];
    if (chance(25)) {
        sy_result r = sy_object_remove_attachment(s, type, id, key, &e);
        CHECK(r == SY_OK || r == SY_ERR_NOT_FOUND);
        CHECK(r == SY_OK || sy_object_find_attachment(s, type, id, key) == NULL);
        return 0;
    }
    sy_attachment a = {.key = (char *)key, .kind = 1 + rn(5)};
    static const char *strs[] = {"", "s", "a string value"};
    switch (a.kind) {
    case SY_ATTACH_INT: a.value.i = (int64_t)rnd() >> rn(64); break;
    case SY_ATTACH_FLOAT: {
        a.value.f = chance(10) ? (double)NAN : (double)rf(-1e3f, 1e3f);
        break;
    }
    case SY_ATTACH_VEC4:
        for (int i = 0; i < 4; ++i) a.value.v[i] = rf(-1, 1);
        break;
    case SY_ATTACH_STRING: a.value.s = (char *)strs[rn(3)]; break;
    default: a.value.blob = chance(10) ? NULL : sized_blob(bp, 1 + rn(40), false); break;
    }
    CHECK_OK(sy_object_set_attachment(s, type, id, &a, &e), e);
    const sy_attachment *f = sy_object_find_attachment(s, type, id, key);
    CHECK(f && f->kind == a.kind && strcmp(f->key, key) == 0 && f->key != key);
    switch (a.kind) {
    case SY_ATTACH_INT: CHECK(f->value.i == a.value.i); break;
    case SY_ATTACH_FLOAT: CHECK(memcmp(&f->value.f, &a.value.f, sizeof(double)) == 0); break;
    case SY_ATTACH_VEC4: CHECK(memcmp(f->value.v, a.value.v, sizeof a.value.v) == 0); break;
    case SY_ATTACH_STRING: CHECK(strcmp(f->value.s, a.value.s) == 0 && f->value.s != a.value.s); break;
    default: CHECK(f->value.blob == a.value.blob); break;
    }
    return 0;
}

/* An animation gets a random clip (1 to 4 channels on live nodes, materials, lights or cameras, each
 * with its own sampler of 1 to 5 keys, any path; interpolation any for node paths, LINEAR or STEP
 * for the others); sometimes the origin's clock is set, which moves nodes and changes the others. */
static int op_animation(sy_scene *s)
{
    sy_error e = {0};
    sy_animation a = {pick(s, SY_TYPE_ANIMATION)};
    if (!a.id) CHECK_OK(sy_animation_create(s, rand_name(), &a, &e), e);
    uint32_t nc = sy_scene_count(s, SY_TYPE_NODE) ? 1 + rn(4) : 0;
    float times[4][5], values[4][5 * 3 * 4];
    sy_anim_sampler_desc sd[4];
    sy_anim_channel ch[4];
    for (uint32_t c = 0; c < nc; ++c) {
        /* a node path, or a material / light / camera one when such an object lives */
        uint32_t path = rn(SY_ANIM_PATH_COUNT), target = pick(s, sy_anim_path_target(path));
        if (!target) path = rn(SY_ANIM_WEIGHTS + 1), target = pick(s, SY_TYPE_NODE);
        bool property = path > SY_ANIM_WEIGHTS;
        uint32_t comps = path == SY_ANIM_WEIGHTS ? 1 + rn(3) : sy_anim_path_components(path);
        /* property values in (0, 1) with LINEAR or STEP: valid for every colour, factor, intensity and yfov */
        uint32_t keys = 1 + rn(5), interp = property ? rn(2) : rn(SY_INTERP_COUNT), per = interp == SY_INTERP_CUBICSPLINE ? 3 : 1;
        float t = rf(-1, 1);
        for (uint32_t k = 0; k < keys; ++k) times[c][k] = t += 0.0625f + fabsf(rf(0.01f, 1)); /* rf may give -0 */
        for (uint32_t k = 0; k < keys * per * comps; ++k)
            values[c][k] = property ? 0.05f + 0.9f * (float)rn(257) / 256.0f : rf(-5, 5);
        if (path == SY_ANIM_ROTATION)
            for (uint32_t k = 0; k < keys * per; ++k) values[c][4 * k + 3] = 6.0f; /* never the zero quaternion */
        sd[c] = (sy_anim_sampler_desc){interp, comps, keys, times[c], values[c]};
        ch[c] = (sy_anim_channel){target, path, c};
    }
    CHECK_OK(sy_animation_set_clip(s, a, sd, nc, ch, nc, &e), e);
    if (chance(50)) CHECK_OK(sy_scene_set_time(s, chance(50) ? a : (sy_animation){0}, rf(-1, 6), &e), e);
    return 0;
}

static int op_create_destroy(sy_scene *s)
{
    sy_error e = {0};
    uint32_t type = 1 + rn(SY_TYPE_COUNT - 1);
    if (type != SY_TYPE_NODE && chance(30)) type = SY_TYPE_NODE; /* more nodes */
    if (chance(35) && sy_scene_count(s, type)) {
        uint32_t id = pick(s, type);
        CHECK_OK(sy_object_destroy(s, type, id, &e), e);
        CHECK(!sy_object_is_valid(s, type, id));
        CHECK_ERR(sy_object_destroy(s, type, id, &e), SY_ERR_INVALID_HANDLE, e);
    } else {
        uint32_t id;
        CHECK_OK(sy_object_create(s, type, rand_name(), &id, &e), e);
        CHECK(sy_object_is_valid(s, type, id));
        /* sometimes created and destroyed before anyone sees it */
        if (chance(10)) CHECK_OK(sy_object_destroy(s, type, id, &e), e);
    }
    return 0;
}

static int op_name(sy_scene *s)
{
    sy_error e = {0};
    uint32_t type = 1 + rn(SY_TYPE_COUNT - 1), id = pick(s, type);
    if (!id) return 0;
    const char *name = rand_name();
    CHECK_OK(sy_object_set_field(s, type, id, SY_FIELD_NAME, &name, &e), e);
    const char *got = *(char *const *)sy_object_get(s, type, id);
    CHECK(name ? (got && strcmp(got, name) == 0) : got == NULL);
    return 0;
}

/* A random starting scene, so that short edit sequences work on hierarchies of meshes with
 * materials and textures rather than on a nearly empty scene. */
static int populate(sy_scene *s, blob_pool *bp)
{
    sy_error e = {0};
    static const struct {
        uint32_t type, max;
    } plan[] = {{SY_TYPE_TEXTURE, 3}, {SY_TYPE_MATERIAL, 3}, {SY_TYPE_MESH, 3}, {SY_TYPE_LIGHT, 2},
                {SY_TYPE_CAMERA, 2},  {SY_TYPE_BACKGROUND, 1}, {SY_TYPE_NODE, 10}};
    for (size_t i = 0; i < sizeof plan / sizeof plan[0]; ++i)
        for (uint32_t n = rn(plan[i].max + 1); n; --n) {
            uint32_t id;
            CHECK_OK(sy_object_create(s, plan[i].type, rand_name(), &id, &e), e);
        }
    for (uint32_t n = rn(4); n; --n) CHECK(op_texture(s, bp) == 0);
    for (uint32_t n = rn(4); n; --n) CHECK(op_material(s) == 0);
    for (uint32_t n = 1 + rn(3); n; --n) CHECK(op_mesh(s, bp) == 0);
    for (uint32_t n = rn(3); n; --n) CHECK(op_light_camera_background(s) == 0);
    /* nodes: meshes, transforms, then a hierarchy */
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id; id = sy_scene_next(s, SY_TYPE_NODE, id)) {
        if (chance(70)) CHECK_OK(sy_node_set_mesh(s, (sy_node){id}, (sy_mesh){pick(s, SY_TYPE_MESH)}, &e), e);
        float t[3] = {rf(-10, 10), rf(-10, 10), rf(-10, 10)}, q[4] = {0, 0, rf(-1, 1), 1}, sc[3] = {rf(0.5f, 2), 1, 1};
        if (chance(70)) CHECK_OK(sy_node_set_trs(s, (sy_node){id}, t, q, sc, &e), e);
    }
    for (uint32_t n = rn(8); n; --n) {
        sy_node p = {pick(s, SY_TYPE_NODE)}, c = {pick(s, SY_TYPE_NODE)};
        if (!p.id || reaches(s, c.id, p.id, 0)) continue;
        uint32_t have;
        const uint32_t *cur = sy_node_children(sy_node_get(s, p), &have);
        bool already = false;
        for (uint32_t k = 0; k < have; ++k) already |= cur[k] == c.id;
        if (!already) CHECK_OK(sy_node_add_child(s, p, c, &e), e);
    }
    if (chance(50)) CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    return 0;
}

/* ------------------------------------------------------------------ one seed */
static int run_seed(uint64_t seed, int ops, uint64_t *stats)
{
    sy_error e = {0};
    long live0 = sy_blob_live_count();
    rng_state = seed * 0x2545f4914f6cdd1dull + 1;
    sy_scene *origin;
    CHECK_OK(sy_scene_create(&origin, &e), e);
    link l1, l2, l3;
    CHECK(link_open(&l1, origin, "rep1") == 0);
    CHECK(link_open(&l2, l1.dst, "rep2 (replica of rep1)") == 0);
    memset(&l3, 0, sizeof l3);
    int l3_at = (int)rn((uint32_t)ops + 1); /* when the late consumer joins */
    blob_pool bp = {0};

    CHECK_MSG(populate(origin, &bp) == 0, "populating");
    for (int op = 0; op < ops; ++op) {
        if (op == l3_at) CHECK(link_open(&l3, origin, "rep3 (late consumer)") == 0);
        uint32_t k = rn(100);
        int r;
        if (k < 22) r = op_create_destroy(origin);
        else if (k < 42) r = op_node(origin, &bp);
        else if (k < 50) r = op_mesh(origin, &bp);
        else if (k < 56) r = op_material(origin);
        else if (k < 61) r = op_texture(origin, &bp);
        else if (k < 68) r = op_light_camera_background(origin);
        else if (k < 76) r = op_attachment(origin, &bp);
        else if (k < 79) r = op_name(origin);
        else if (k < 81) r = op_animation(origin);
        else if (k < 88) {
            r = 0;
            CHECK_OK(sy_scene_commit(origin, NULL, &e), e);
        } else {
            /* commit, then some consumers pull */
            CHECK_OK(sy_scene_commit(origin, NULL, &e), e);
            CHECK(check_graph(origin, &g_refs, "origin") == 0);
            r = 0;
            if (chance(80)) {
                CHECK(link_sync(&l1) == 0);
                if (chance(70)) CHECK(link_sync(&l2) == 0);
            }
            if (l3.consumer && chance(50)) CHECK(link_sync(&l3) == 0);
        }
        CHECK_MSG(r == 0, "operation %d", op);
    }
    /* the end: everyone catches up */
    CHECK_OK(sy_scene_commit(origin, NULL, &e), e);
    CHECK(check_graph(origin, &g_refs, "origin") == 0);
    CHECK(link_sync(&l1) == 0);
    CHECK(link_sync(&l2) == 0);
    CHECK_MSG(sy_scene_equal(origin, l2.dst, &e), "rep2 differs from the origin: %s", e.message);
    if (!l3.consumer) CHECK(link_open(&l3, origin, "rep3 (late consumer)") == 0);
    CHECK(link_sync(&l3) == 0);
    /* a later pull with nothing new is empty and keeps everyone equal */
    CHECK_OK(sy_scene_commit(origin, NULL, &e), e);
    sy_changes *c;
    CHECK_OK(sy_scene_consumer_pull(origin, l1.consumer, &c, &e), e);
    CHECK(sy_changes_count(c) == 0);
    sy_changes_release(c);
    CHECK(sy_scene_log_length(origin) == 0);

    stats[0] += l1.pulls + l2.pulls + l3.pulls;
    stats[1] += l1.bytes + l2.bytes + l3.bytes;
    stats[2] += l1.payload_bytes + l2.payload_bytes + l3.payload_bytes;
    for (uint32_t t = 1; t < SY_TYPE_COUNT; ++t) stats[3] += sy_scene_count(origin, t);
    link_close(&l2); /* before l1: its source is l1's replica */
    link_close(&l1);
    link_close(&l3);
    sy_scene_destroy(origin);
    for (uint32_t i = 0; i < bp.count; ++i) sy_blob_release(bp.items[i]);
    free(bp.items);
    CHECK_MSG(sy_blob_live_count() == live0, "%ld blobs leaked", sy_blob_live_count() - live0);
    return 0;
}

int main(int argc, char **argv)
{
    long seeds = argc > 1 ? atol(argv[1]) : 3000;
    uint64_t first = argc > 2 ? (uint64_t)atoll(argv[2]) : 1;
    int ops = argc > 3 ? atoi(argv[3]) : 30;
    if (seeds <= 0 || ops <= 0) {
        fprintf(stderr, "usage: %s [seeds [first_seed [ops]]]\n", argv[0]);
        return 2;
    }
    double t0 = sy_time_now();
    uint64_t stats[4] = {0};
    int failures = 0;
    for (long i = 0; i < seeds; ++i) {
        uint64_t seed = first + (uint64_t)i;
        if (run_seed(seed, ops, stats) != 0) {
            fprintf(stderr, "FAILED: seed %llu (rerun: %s 1 %llu %d)\n", (unsigned long long)seed, argv[0],
                    (unsigned long long)seed, ops);
            if (++failures >= 5) break;
        }
    }
    free(g_refs.items);
    printf("%ld seeds x %d ops: %llu pulls, %llu wire bytes (%llu payload), %llu live objects at the ends, %.2f s, "
           "%d failed\n",
           seeds, ops, (unsigned long long)stats[0], (unsigned long long)stats[1], (unsigned long long)stats[2],
           (unsigned long long)stats[3], sy_time_now() - t0, failures);
    return failures ? 1 : 0;
}
