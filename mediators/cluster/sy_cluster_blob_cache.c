/* sy_cluster_blob_cache.c — the render server's blob cache, shared by every session and outliving
 * them: hash -> blob in a hash table, least recently used evicted first once the payload bytes
 * exceed the budget (sy serve --blob-cache-mb). Used by the serving thread only. */
#include "sy_cluster_internal.h"

#include <stdlib.h>
#include <string.h>

static cache_entry **cache_slot(blob_cache *c, sy_hash128 h)
{
    cache_entry **p = &c->buckets[(size_t)(h.lo ^ h.hi) & (c->nbuckets - 1)];
    while (*p && !sy_hash_equal((*p)->hash, h)) p = &(*p)->chain;
    return p;
}

static void cache_unlink_lru(blob_cache *c, cache_entry *e)
{
    if (e->older) e->older->newer = e->newer;
    else c->oldest = e->newer;
    if (e->newer) e->newer->older = e->older;
    else c->newest = e->older;
    e->older = e->newer = NULL;
}

static void cache_push_newest(blob_cache *c, cache_entry *e)
{
    e->older = c->newest;
    e->newer = NULL;
    if (c->newest) c->newest->newer = e;
    c->newest = e;
    if (!c->oldest) c->oldest = e;
}

/* Borrowed blob (marked most recently used) or NULL. */
sy_blob *sy_clu_cache_get(blob_cache *c, sy_hash128 h)
{
    if (!c->nbuckets) return NULL;
    cache_entry *e = *cache_slot(c, h);
    if (!e) return NULL;
    cache_unlink_lru(c, e);
    cache_push_newest(c, e);
    return e->blob;
}

static void cache_evict_oldest(blob_cache *c)
{
    cache_entry *e = c->oldest;
    cache_entry **p = cache_slot(c, e->hash);
    *p = e->chain;
    cache_unlink_lru(c, e);
    c->bytes -= sy_blob_size(e->blob);
    c->count--;
    c->evictions++;
    sy_blob_release(e->blob);
    free(e);
}

/* Caches a reference to b (a blob larger than the whole budget is not cached). */
void sy_clu_cache_put(blob_cache *c, sy_blob *b)
{
    size_t size = sy_blob_size(b);
    if (size > c->budget || sy_clu_cache_get(c, sy_blob_hash(b))) return;
    if (c->count + 1 > c->nbuckets) { /* grow and rehash: load factor <= 1 */
        size_t nb = c->nbuckets ? c->nbuckets * 2 : 256;
        cache_entry **nbk = calloc(nb, sizeof *nbk);
        if (!nbk) return; /* a cache that cannot grow just does not cache */
        for (size_t i = 0; i < c->nbuckets; ++i)
            for (cache_entry *e = c->buckets[i], *next; e; e = next) {
                next = e->chain;
                size_t j = (size_t)(e->hash.lo ^ e->hash.hi) & (nb - 1);
                e->chain = nbk[j];
                nbk[j] = e;
            }
        free(c->buckets);
        c->buckets = nbk;
        c->nbuckets = nb;
    }
    cache_entry *e = calloc(1, sizeof *e);
    if (!e) return;
    e->blob = sy_blob_retain(b);
    e->hash = sy_blob_hash(b);
    cache_entry **p = cache_slot(c, e->hash);
    *p = e;
    cache_push_newest(c, e);
    c->count++;
    c->bytes += size;
    while (c->bytes > c->budget && c->oldest != e) cache_evict_oldest(c);
}

void sy_clu_cache_free(blob_cache *c)
{
    while (c->oldest) cache_evict_oldest(c);
    free(c->buckets);
    memset(c, 0, sizeof *c);
}
