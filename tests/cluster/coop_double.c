/* coop_double.c — the "coop_test" progressive mediator double (see coop_double.h). */
#include "coop_double.h"

#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct coop_state {
    double *sum; /* per pixel of the full image */
    uint32_t w, h;
    uint64_t samples;
} coop_state;

float coop_double_sample(uint32_t x, uint32_t y, uint32_t s)
{
    uint64_t v = ((uint64_t)x * 73856093u) ^ ((uint64_t)y * 19349663u) ^ ((uint64_t)s * 83492791u);
    v ^= v >> 33;
    v *= 0xff51afd7ed558ccdull;
    v ^= v >> 33;
    v *= 0xc4ceb9fe1a85ec53ull;
    v ^= v >> 33;
    return (float)(v >> 40) / (float)(1u << 24);
}

static sy_result coop_create(const sy_mediator_create_args *args, void **state_out, sy_error *err)
{
    (void)args;
    coop_state *st = calloc(1, sizeof *st);
    if (!st) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "coop_test: out of memory");
    *state_out = st;
    return SY_OK;
}

static void coop_destroy(void *state)
{
    coop_state *st = state;
    free(st->sum);
    free(st);
}

static sy_result coop_sync(void *state, const sy_changes *changes, sy_error *err)
{
    (void)state, (void)changes, (void)err;
    return SY_OK;
}

static sy_result coop_render(void *state, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    coop_state *st = state;
    if (!st->sum || st->w != req->full_width || st->h != req->full_height) {
        free(st->sum);
        st->sum = calloc((size_t)req->full_width * req->full_height, sizeof *st->sum);
        if (!st->sum) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "coop_test: out of memory");
        st->w = req->full_width;
        st->h = req->full_height;
        st->samples = 0;
    }
    uint32_t n = req->sample_count ? req->sample_count : 1;
    const char *trace = getenv("COOP_DOUBLE_TRACE");
    if (trace && trace[0]) { /* "FIRST COUNT" per render call, appended when the call starts */
        char line[48];
        int len = snprintf(line, sizeof line, "%u %u\n", req->sample_first, n);
        int fd = open(trace, O_WRONLY | O_CREAT | O_APPEND, 0644);
        if (fd >= 0) {
            if (write(fd, line, (size_t)len) != len) { /* a test reading the trace sees the line missing */
            }
            close(fd);
        }
    }
    for (uint32_t y = 0; y < req->rect_h; ++y)
        for (uint32_t x = 0; x < req->rect_w; ++x) {
            uint32_t gx = req->rect_x + x, gy = req->rect_y + y;
            double *acc = &st->sum[(size_t)gy * st->w + gx];
            for (uint32_t s = 0; s < n; ++s) *acc += coop_double_sample(gx, gy, req->sample_first + s);
        }
    st->samples += n;
    for (uint32_t y = 0; y < req->rect_h; ++y)
        for (uint32_t x = 0; x < req->rect_w; ++x) {
            float v = (float)(st->sum[(size_t)(req->rect_y + y) * st->w + req->rect_x + x] / (double)st->samples);
            float *p = &layer->rgba[((size_t)y * req->rect_w + x) * 4];
            p[0] = v, p[1] = v * 0.5f, p[2] = 1.0f - v, p[3] = 1.0f;
            layer->depth[(size_t)y * req->rect_w + x] = 1.0f + v;
        }
    return SY_OK;
}

static void coop_stats(void *state, sy_mediator_stats *out)
{
    const coop_state *st = state;
    memset(out, 0, sizeof *out);
    out->samples = st->samples;
}

static const sy_mediator_class coop_class = {
    .name = "coop_test",
    .caps = SY_CAP_PROGRESSIVE | SY_CAP_TILES | SY_CAP_DEPTH | SY_CAP_SAMPLE_RANGES,
    .create = coop_create,
    .destroy = coop_destroy,
    .sync = coop_sync,
    .render = coop_render,
    .stats = coop_stats,
};

sy_result coop_double_register(sy_error *err)
{
    return sy_mediator_register(&coop_class, err);
}
