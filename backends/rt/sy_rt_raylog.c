/* sy_rt_raylog.c — the path tracer's optional ray log (see sy_rt_raylog.h). */
#include "sy_rt_raylog.h"

#include <stdlib.h>
#include <string.h>

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

/* >>log */
sy_rt_result sy_rt_ray_log_create(sy_rt_device *dev, sy_rt_ray_log **out)
{
    if (!out) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "ray log: NULL argument");
    sy_rt_ray_log *log = calloc(1, sizeof *log);
    if (!log) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "ray log: out of memory");
    pthread_mutex_init(&log->lock, NULL);
    *out = log;
    return SY_RT_OK;
}

void sy_rt_ray_buf_free(sy_rt_ray_buf *buf)
{
    free(buf->v);
    memset(buf, 0, sizeof *buf);
}

void sy_rt_ray_log_destroy(sy_rt_ray_log *log)
{
    if (!log) return;
    sy_rt_ray_buf_free(&log->intersect);
    sy_rt_ray_buf_free(&log->occluded);
    pthread_mutex_destroy(&log->lock);
    free(log);
}

void sy_rt_ray_log_clear(sy_rt_ray_log *log)
{
    log->intersect.n = log->occluded.n = 0;
    log->intersect.failed = log->occluded.failed = false;
    log->kind_count[0] = log->kind_count[1] = 0;
}

/* Room for `more` rays; false (and buf->failed) when memory runs out. */
static bool buf_reserve(sy_rt_ray_buf *buf, size_t more)
{
    if (buf->failed) return false;
    if (buf->n + more <= buf->cap) return true;
    size_t cap = buf->cap ? buf->cap : 1024u;
    while (cap < buf->n + more) {
        if (cap > SIZE_MAX / 2u / sizeof *buf->v) return buf->failed = true, false;
        cap *= 2u;
    }
    sy_rt_logged_ray *v = realloc(buf->v, cap * sizeof *v);
    if (!v) return buf->failed = true, false;
    buf->v = v;
    buf->cap = cap;
    return true;
}

static sy_rt_logged_ray *buf_push(sy_rt_ray_buf *buf, sy_rt_v3 org, sy_rt_v3 dir, float tnear, float tfar)
{
    if (!buf_reserve(buf, 1u)) return NULL;
    sy_rt_logged_ray *r = &buf->v[buf->n++];
    r->org[0] = org.x, r->org[1] = org.y, r->org[2] = org.z, r->tnear = tnear;
    r->dir[0] = dir.x, r->dir[1] = dir.y, r->dir[2] = dir.z, r->tfar = tfar;
    r->mask = 0xffffffffu; /* as sy_rt_intersect and sy_rt_segment_clear cast them */
    r->flags = 0;
    return r;
}

void sy_rt_ray_buf_add_hit(sy_rt_ray_buf *buf, uint32_t kind, sy_rt_v3 org, sy_rt_v3 dir, float tnear, float tfar,
                           const struct RTCRayHit *rh)
{
    sy_rt_logged_ray *r = buf_push(buf, org, dir, tnear, tfar);
    if (!r) return;
    r->geom = rh->hit.geomID;
    r->prim = rh->hit.geomID == RTC_INVALID_GEOMETRY_ID ? RTC_INVALID_GEOMETRY_ID : rh->hit.primID;
    r->inst = rh->hit.geomID == RTC_INVALID_GEOMETRY_ID ? RTC_INVALID_GEOMETRY_ID : rh->hit.instID[0];
    r->kind = kind;
}

void sy_rt_ray_buf_add_occluded(sy_rt_ray_buf *buf, sy_rt_v3 org, sy_rt_v3 dir, float tnear, float tfar, bool occluded)
{
    sy_rt_logged_ray *r = buf_push(buf, org, dir, tnear, tfar);
    if (!r) return;
    r->geom = occluded ? 1u : 0u;
    r->prim = r->inst = 0;
    r->kind = SY_RT_RAY_SHADOW | 0x80000000u; /* marks an occlusion query until sorted into the log */
}

static void move_into(sy_rt_ray_buf *dst, const sy_rt_logged_ray *v, size_t n)
{
    if (!n || !buf_reserve(dst, n)) return;
    memcpy(dst->v + dst->n, v, n * sizeof *v);
    dst->n += n;
}

void sy_rt_ray_log_append(sy_rt_ray_log *log, sy_rt_ray_buf *buf)
{
    pthread_mutex_lock(&log->lock);
    if (buf->failed) log->intersect.failed = true;
    /* runs of equal query type keep the tile's order within each query type */
    size_t i = 0;
    while (i < buf->n) {
        bool occ = (buf->v[i].kind & 0x80000000u) != 0;
        size_t j = i;
        while (j < buf->n && ((buf->v[j].kind & 0x80000000u) != 0) == occ) {
            buf->v[j].kind &= 0x7fffffffu;
            log->kind_count[buf->v[j].kind ? 1 : 0]++;
            ++j;
        }
        move_into(occ ? &log->occluded : &log->intersect, buf->v + i, j - i);
        i = j;
    }
    pthread_mutex_unlock(&log->lock);
    buf->n = 0;
    buf->failed = false;
}


/* >>stage timers */
const char *sy_rt_stage_name(sy_rt_stage s)
{
    static const char *const names[SY_RT_STAGE_COUNT] = {
        "random numbers, camera ray", "traversal (extension rays)", "traversal (shadow rays)",
        "hit fetch (surface)",        "BSDF set-up",                "shading (emission, MIS, rest)",
        "light selection + point",
        "BSDF evaluation (light)",    "BSDF sampling, roulette",    "accumulation"};
    return (unsigned)s < SY_RT_STAGE_COUNT ? names[s] : "?";
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

double sy_rt_stage_lap_cost(void)
{
    enum { RUNS = 9, LAPS = 4096 };
    uint64_t per[RUNS];
    for (int r = 0; r < RUNS; ++r) {
        sy_rt_stage_clock c;
        memset(&c, 0, sizeof c);
        c.last = sy_rt_stage_tick();
        for (int i = 0; i < LAPS; ++i) sy_rt_stage_lap(&c, (sy_rt_stage)(i % SY_RT_STAGE_COUNT));
        uint64_t sum = 0;
        for (int s = 0; s < SY_RT_STAGE_COUNT; ++s) sum += c.ticks[s];
        per[r] = sum;
    }
    qsort(per, RUNS, sizeof *per, cmp_u64);
    return (double)per[RUNS / 2] / LAPS;
}

void sy_rt_stage_times_add(sy_rt_stage_times *t, const sy_rt_stage_clock *c, uint64_t samples)
{
    for (int s = 0; s < SY_RT_STAGE_SLOTS; ++s) {
        if (c->ticks[s]) atomic_fetch_add(&t->ticks[s], c->ticks[s]);
        if (c->laps[s]) atomic_fetch_add(&t->laps[s], c->laps[s]);
    }
    atomic_fetch_add(&t->samples, samples);
    if (c->dropped) atomic_fetch_add(&t->dropped, c->dropped);
}
