/* sy_deform_cache.c — the deformed poses shared by every mirror of the process (see
 * sy_deform_cache.h): a hash table of content keys, a least-recently-used list for the byte budget,
 * one mutex and one condition variable (a pose being computed is waited for). */
#include "sy_deform_cache.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#define BUCKETS 4096u
#define MAX_ENTRIES 65536u

typedef struct entry {
    struct entry *next;             /* in its bucket */
    struct entry *lru_prev, *lru_next; /* most recent first */
    sy_hash128 hash;
    unsigned char *key;
    size_t key_size, bytes;
    sy_deform_pose pose;
    uint64_t takers; /* slots that took or made it */
    bool busy;       /* being computed by the thread that made it */
} entry;

static pthread_mutex_t g_mu = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t g_cv = PTHREAD_COND_INITIALIZER;
static entry *g_bucket[BUCKETS];
static entry *g_lru_head, *g_lru_tail;
static uint32_t g_users, g_entries;
static uint64_t g_attached; /* slots in use */
static uint64_t g_bytes, g_computed, g_shared;
static bool g_off; /* sy_deform_cache_set_sharing(false) */

static uint64_t slot_bit(uint32_t slot) { return slot < SY_DEFORM_CACHE_SLOTS ? 1ull << slot : 0ull; }

void sy_deform_pose_release(sy_deform_pose *p)
{
    if (!p) return;
    sy_blob_release(p->positions), sy_blob_release(p->normals), sy_blob_release(p->tangents);
    memset(p, 0, sizeof *p);
}

/* Unlinks e from its bucket and the list and frees it (the lock held). */
static void entry_remove(entry *e)
{
    entry **pp = &g_bucket[e->hash.lo % BUCKETS];
    while (*pp && *pp != e) pp = &(*pp)->next;
    if (*pp) *pp = e->next;
    if (e->lru_prev) e->lru_prev->lru_next = e->lru_next;
    else g_lru_head = e->lru_next;
    if (e->lru_next) e->lru_next->lru_prev = e->lru_prev;
    else g_lru_tail = e->lru_prev;
    g_bytes -= e->bytes;
    g_entries--;
    sy_deform_pose_release(&e->pose);
    free(e->key);
    free(e);
}

static void lru_front(entry *e)
{
    if (g_lru_head == e) return;
    if (e->lru_prev) e->lru_prev->lru_next = e->lru_next;
    if (e->lru_next) e->lru_next->lru_prev = e->lru_prev;
    else if (g_lru_tail == e) g_lru_tail = e->lru_prev;
    e->lru_prev = NULL;
    e->lru_next = g_lru_head;
    if (g_lru_head) g_lru_head->lru_prev = e;
    g_lru_head = e;
    if (!g_lru_tail) g_lru_tail = e;
}

/* Every attached user took it: nobody needs it any more. */
static bool taken_by_all(const entry *e) { return (e->takers & g_attached) == g_attached; }

/* Drops entries past the budgets, least recently used first (the lock held; busy ones stay). */
static void evict(void)
{
    for (entry *e = g_lru_tail; e && (g_bytes > SY_DEFORM_CACHE_MAX_BYTES || g_entries > MAX_ENTRIES);) {
        entry *prev = e->lru_prev;
        if (!e->busy) entry_remove(e);
        e = prev;
    }
}

static void drop_all_ready(bool only_taken)
{
    for (entry *e = g_lru_head; e;) {
        entry *next = e->lru_next;
        if (!e->busy && (!only_taken || taken_by_all(e))) entry_remove(e);
        e = next;
    }
}

void sy_deform_cache_attach(uint32_t *slot)
{
    pthread_mutex_lock(&g_mu);
    uint32_t s = 0;
    while (s < SY_DEFORM_CACHE_SLOTS && (g_attached & slot_bit(s))) ++s;
    g_attached |= slot_bit(s);
    g_users++;
    pthread_mutex_unlock(&g_mu);
    *slot = s;
}

void sy_deform_cache_detach(uint32_t slot)
{
    pthread_mutex_lock(&g_mu);
    g_attached &= ~slot_bit(slot);
    if (g_users) g_users--;
    drop_all_ready(g_users >= 2); /* fewer than two: keep nothing; otherwise what the rest all took */
    pthread_mutex_unlock(&g_mu);
}

void sy_deform_cache_set_sharing(bool on)
{
    pthread_mutex_lock(&g_mu);
    g_off = !on;
    if (g_off) drop_all_ready(false);
    pthread_mutex_unlock(&g_mu);
}

void sy_deform_cache_stats_get(sy_deform_cache_stats *out)
{
    pthread_mutex_lock(&g_mu);
    *out = (sy_deform_cache_stats){g_computed, g_shared, g_entries, g_bytes, g_users};
    pthread_mutex_unlock(&g_mu);
}

/* The content key of in: the source blobs' hashes, the morph weights that count, the joints. */
static unsigned char *key_of(const sy_deform_input *in, size_t *size_out)
{
    const sy_primitive *p = in->primitive;
    uint32_t nt = sy_primitive_target_count(p);
    uint32_t use = nt && in->weights ? (in->weight_count < nt ? in->weight_count : nt) : 0u;
    uint32_t nj = in->joints ? in->joint_count : 0u;
    const sy_blob *src[8] = {p->positions, p->normals, p->tangents, p->joints, p->weights, p->target_positions,
                             p->target_normals, p->target_tangents};
    size_t size = sizeof src / sizeof src[0] * sizeof(sy_hash128) + 8 + 4 * (size_t)use + sizeof(sy_mat4) * (size_t)nj;
    unsigned char *k = malloc(size), *w = k;
    if (!k) return NULL;
    for (size_t i = 0; i < sizeof src / sizeof src[0]; ++i) {
        sy_hash128 h = src[i] ? sy_blob_hash(src[i]) : (sy_hash128){0, 0};
        memcpy(w, &h, sizeof h), w += sizeof h;
    }
    memcpy(w, &use, 4), w += 4;
    memcpy(w, &nj, 4), w += 4;
    if (use) memcpy(w, in->weights, 4 * (size_t)use), w += 4 * (size_t)use;
    if (nj) memcpy(w, in->joints, sizeof(sy_mat4) * (size_t)nj);
    *size_out = size;
    return k;
}

/* Deforms in into fresh blobs (no lock held). */
static sy_result compute(const sy_deform_input *in, sy_deform_pose *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    const sy_primitive *src = in->primitive;
    uint32_t nv = sy_primitive_vertex_count(src);
    float *pos = malloc(sizeof(float) * 3 * (size_t)nv + 1);
    float *nrm = src->normals ? malloc(sizeof(float) * 3 * (size_t)nv + 1) : NULL;
    float *tan = src->tangents ? malloc(sizeof(float) * 4 * (size_t)nv + 1) : NULL;
    if (!pos || (src->normals && !nrm) || (src->tangents && !tan)) {
        free(pos), free(nrm), free(tan);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "deformation: out of memory (%u vertices)", nv);
    }
    double t0 = sy_time_now();
    out->ok = sy_deform_primitive(in, pos, nrm, tan, &out->bounds);
    out->seconds = sy_time_now() - t0;
    if (!out->ok) {
        free(pos), free(nrm), free(tan);
        return SY_OK;
    }
    /* each buffer is the blob's once taken (sy_blob_create_take); on a failure the rest are freed */
    sy_result r = sy_blob_create_take(pos, sizeof(float) * 3 * (size_t)nv, &out->positions, err);
    if (r != SY_OK) free(pos);
    if (nrm && (r != SY_OK || (r = sy_blob_create_take(nrm, sizeof(float) * 3 * (size_t)nv, &out->normals, err)) != SY_OK))
        free(nrm);
    if (tan && (r != SY_OK || (r = sy_blob_create_take(tan, sizeof(float) * 4 * (size_t)nv, &out->tangents, err)) != SY_OK))
        free(tan);
    if (r != SY_OK) {
        double s = out->seconds;
        sy_deform_pose_release(out);
        out->seconds = s;
    }
    return r;
}

static void pose_copy(sy_deform_pose *out, const sy_deform_pose *in)
{
    *out = *in;
    sy_blob_retain(out->positions), sy_blob_retain(out->normals), sy_blob_retain(out->tangents);
}

sy_result sy_deform_cache_take(const sy_deform_input *in, uint32_t slot, sy_deform_pose *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    pthread_mutex_lock(&g_mu);
    bool keep = g_users >= 2 && !g_off;
    pthread_mutex_unlock(&g_mu);
    size_t ks = 0;
    unsigned char *key = keep ? key_of(in, &ks) : NULL;
    if (!key) { /* nobody to share with (or no memory for the key): deform, keep nothing */
        sy_result r = compute(in, out, err);
        pthread_mutex_lock(&g_mu);
        g_computed++;
        pthread_mutex_unlock(&g_mu);
        return r;
    }
    sy_hash128 h = sy_hash_bytes(key, ks);
    entry *e = NULL;
    pthread_mutex_lock(&g_mu);
    for (;;) {
        for (e = g_bucket[h.lo % BUCKETS]; e; e = e->next)
            if (sy_hash_equal(e->hash, h) && e->key_size == ks && memcmp(e->key, key, ks) == 0) break;
        if (!e || !e->busy) break;
        pthread_cond_wait(&g_cv, &g_mu); /* another thread is computing it */
    }
    if (e) { /* made by another call: take it */
        pose_copy(out, &e->pose);
        out->shared = true;
        out->seconds = 0.0;
        e->takers |= slot_bit(slot);
        g_shared++;
        if (taken_by_all(e)) entry_remove(e);
        else lru_front(e);
        pthread_mutex_unlock(&g_mu);
        free(key);
        return SY_OK;
    }
    e = calloc(1, sizeof *e);
    if (!e) { /* no entry: deform without sharing */
        pthread_mutex_unlock(&g_mu);
        free(key);
        sy_result r = compute(in, out, err);
        pthread_mutex_lock(&g_mu);
        g_computed++;
        pthread_mutex_unlock(&g_mu);
        return r;
    }
    e->hash = h, e->key = key, e->key_size = ks, e->busy = true, e->takers = slot_bit(slot);
    e->next = g_bucket[h.lo % BUCKETS];
    g_bucket[h.lo % BUCKETS] = e;
    e->lru_next = g_lru_head;
    if (g_lru_head) g_lru_head->lru_prev = e;
    g_lru_head = e;
    if (!g_lru_tail) g_lru_tail = e;
    g_entries++;
    pthread_mutex_unlock(&g_mu);

    sy_result r = compute(in, out, err);

    pthread_mutex_lock(&g_mu);
    g_computed++;
    e->busy = false;
    if (r == SY_OK) {
        pose_copy(&e->pose, out);
        e->pose.shared = false;
        e->pose.seconds = 0.0;
        e->bytes = (out->positions ? sy_blob_size(out->positions) : 0) + (out->normals ? sy_blob_size(out->normals) : 0) +
                   (out->tangents ? sy_blob_size(out->tangents) : 0);
        g_bytes += e->bytes;
    }
    if (r != SY_OK || g_users < 2 || g_off || e->bytes > SY_DEFORM_CACHE_MAX_BYTES || taken_by_all(e)) entry_remove(e);
    else evict();
    pthread_cond_broadcast(&g_cv);
    pthread_mutex_unlock(&g_mu);
    return r;
}
