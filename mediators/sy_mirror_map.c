/* sy_mirror_map.c — a mediator's per-object tables keyed by handle or id (see sy_mirror_map.h). */
#include "sy_mirror_map.h"

#include <stdlib.h>
#include <string.h>

static uint32_t map_hash(uint32_t k) { k ^= k >> 16; k *= 0x7feb352dU; k ^= k >> 15; k *= 0x846ca68bU; return k ^ (k >> 16); }

void *sy_mirror_map_get(const sy_mirror_map *m, uint32_t key)
{
    if (!m->cap || !key) return NULL;
    for (uint32_t i = map_hash(key) & (m->cap - 1), n = 0; n < m->cap; ++n, i = (i + 1) & (m->cap - 1)) {
        if (m->used[i] == 0) return NULL;
        if (m->used[i] == 1 && m->keys[i] == key) return (char *)m->vals + (size_t)i * m->elem;
    }
    return NULL;
}

void sy_mirror_map_free(sy_mirror_map *m)
{
    free(m->keys);
    free(m->used);
    free(m->vals);
    m->keys = NULL, m->used = NULL, m->vals = NULL;
    m->cap = m->live = m->filled = 0;
}

void *sy_mirror_map_put(sy_mirror_map *m, uint32_t key)
{
    void *v = sy_mirror_map_get(m, key);
    if (v) return v;
    if ((m->filled + 1) * 4 >= m->cap * 3) {
        sy_mirror_map old = *m;
        uint32_t nc = m->cap ? m->cap * 2 : 64;
        while ((m->live + 1) * 4 >= nc * 3 / 2) nc *= 2;
        m->keys = calloc(nc, sizeof *m->keys);
        m->used = calloc(nc, 1);
        m->vals = calloc(nc, m->elem);
        if (!m->keys || !m->used || !m->vals) {
            free(m->keys), free(m->used), free(m->vals);
            *m = old;
            return NULL;
        }
        m->cap = nc;
        m->live = m->filled = 0;
        for (uint32_t i = 0; i < old.cap; ++i)
            if (old.used[i] == 1) memcpy(sy_mirror_map_put(m, old.keys[i]), (char *)old.vals + (size_t)i * old.elem, old.elem);
        sy_mirror_map_free(&old);
    }
    uint32_t i = map_hash(key) & (m->cap - 1);
    while (m->used[i] == 1) i = (i + 1) & (m->cap - 1);
    if (m->used[i] == 0) m->filled++;
    m->used[i] = 1;
    m->keys[i] = key;
    m->live++;
    v = (char *)m->vals + (size_t)i * m->elem;
    memset(v, 0, m->elem);
    return v;
}

void sy_mirror_map_del(sy_mirror_map *m, uint32_t key)
{
    void *v = sy_mirror_map_get(m, key);
    if (!v) return;
    uint32_t i = (uint32_t)(((char *)v - (char *)m->vals) / m->elem);
    m->used[i] = 2;
    m->keys[i] = 0;
    m->live--;
}

void *sy_mirror_map_slot(const sy_mirror_map *m, uint32_t slot)
{
    return slot < m->cap && m->used[slot] == 1 ? (char *)m->vals + (size_t)slot * m->elem : NULL;
}
