/* test_governor.c — the frame-time governor (core/sy_governor.h) against a synthetic cost model
 * (frame ms = fixed + per x pixels x samples, with deterministic +-10 % noise) on a simulated clock:
 * moving frames converge within the budget and use it, a fixed part above the budget drives the
 * scale to its minimum, a still view grows back to full size and refines by samples within the
 * budget up to max_samples then idles, sizes never exceed the display (1x1 .. 2^32-1 squared, 0),
 * a back-end switch (reset) re-learns, redraw and invalid settings. No real time is measured. */
#include "../support/sy_check.h"
#include "sy_governor.h"
#include "sy_mediator.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct cost_model {
    double fixed, per; /* ms, ms per pixel-sample */
    uint32_t rng;
} cost_model;

static double noise(cost_model *m) /* 0.9 .. 1.1 */
{
    m->rng = m->rng * 1664525u + 1013904223u;
    return 0.9 + 0.2 * (double)(m->rng >> 8) / (double)(1u << 24);
}

static double true_cost(const cost_model *m, const sy_governor_frame *f)
{
    return m->fixed + m->per * (double)f->width * f->height * (f->samples ? f->samples : 1);
}

/* Plans and "renders" one frame: reports its noisy cost and advances the clock by it (+1 ms). */
static double step(sy_governor *g, cost_model *m, uint32_t w, uint32_t h, uint32_t caps, bool changed, double *now,
                   sy_governor_frame *f)
{
    sy_governor_plan(g, w, h, caps, changed, *now, f);
    if (f->idle) return 0.0;
    if (f->wait_ms > 0.0) {
        *now += f->wait_ms;
        return 0.0;
    }
    double t = true_cost(m, f) * noise(m);
    sy_governor_report(g, f, t);
    *now += t + 1.0;
    return t;
}

/* A governor with the default settings after `frames` moving frames of w x h (no caps) under m,
 * the clock from *now; *f the last frame. NULL (a failed, counted check) when it cannot be made. */
static sy_governor *moving_for(cost_model *m, uint32_t w, uint32_t h, int frames, double *now, sy_governor_frame *f)
{
    sy_error e = {0};
    sy_governor *g = NULL;
    EXPECT_OK(sy_governor_create(NULL, &g, &e), e);
    for (int i = 0; g && i < frames; ++i) step(g, m, w, h, 0, true, now, f);
    return g;
}

static int test_settings(void)
{
    sy_error e = {0};
    sy_governor *g = NULL;
    CHECK_OK(sy_governor_create(NULL, &g, &e), e);
    sy_governor_desc d;
    sy_governor_settings(g, &d);
    CHECK(d.budget_ms == 33.0 && d.min_scale == 0.125f && d.max_samples == 65536 && d.settle_ms == 150.0);
    double fx, per;
    CHECK(!sy_governor_cost(g, true, &fx, &per) && fx == 0.0 && per == 0.0);
    sy_governor_destroy(g);
    sy_governor_destroy(NULL);
    CHECK_ERR(sy_governor_create(&(sy_governor_desc){.budget_ms = -1}, &g, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK(strstr(e.message, "budget_ms") && g == NULL);
    CHECK_ERR(sy_governor_create(&(sy_governor_desc){.budget_ms = NAN}, &g, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_governor_create(&(sy_governor_desc){.settle_ms = INFINITY}, &g, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK(strstr(e.message, "settle_ms"));
    CHECK_ERR(sy_governor_create(&(sy_governor_desc){.min_scale = 1.5f}, &g, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK(strstr(e.message, "min_scale"));
    CHECK_ERR(sy_governor_create(&(sy_governor_desc){.min_scale = NAN}, &g, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_OK(sy_governor_create(&(sy_governor_desc){.budget_ms = 20, .min_scale = 0.5f, .max_samples = 7, .settle_ms = 10},
                                &g, &e),
             e);
    sy_governor_settings(g, &d);
    CHECK(d.budget_ms == 20.0 && d.min_scale == 0.5f && d.max_samples == 7 && d.settle_ms == 10.0);
    sy_governor_destroy(g);
    return 0;
}

/* Moving every frame: after a few frames each frame's (noise-free) cost fits the budget and uses
 * at least half of it, unless full size already fits or the minimum scale is reached. */
static int converge_case(double fixed, double full_ms, uint32_t caps)
{
    sy_error e = {0};
    sy_governor *g = NULL;
    CHECK_OK(sy_governor_create(NULL, &g, &e), e);
    const uint32_t W = 1280, H = 720;
    cost_model m = {.fixed = fixed, .per = (full_ms - fixed) / ((double)W * H), .rng = 7};
    double now = 1000.0;
    sy_governor_frame f;
    for (int i = 0; i < 120; ++i) {
        step(g, &m, W, H, caps, true, &now, &f);
        CHECK(f.moving && !f.idle && f.wait_ms == 0.0 && f.samples == 1 && !f.filter);
        CHECK(f.width >= 1 && f.width <= W && f.height >= 1 && f.height <= H);
        CHECK(f.scale >= 0.125f - 1e-6f && f.scale <= 1.0f);
        if (i < 12) continue;
        double c = true_cost(&m, &f);
        CHECK_MSG(c <= 33.0, "fixed %g full %g: frame %d costs %.2f ms at scale %.3f", fixed, full_ms, i, c,
                  (double)f.scale);
        CHECK_MSG(c >= 16.5 || f.scale == 1.0f || f.scale <= 0.125f + 1e-6f,
                  "fixed %g full %g: frame %d costs only %.2f ms at scale %.3f", fixed, full_ms, i, c, (double)f.scale);
    }
    double fx, per;
    CHECK(sy_governor_cost(g, true, &fx, &per));
    CHECK_MSG(fx >= 0.0 && fx <= fixed + 5.0 && per > 0.0, "model fixed %g per %g against %g, %g", fx, per, fixed, m.per);
    sy_governor_destroy(g);
    return 0;
}

static int test_converges(void)
{
    if (converge_case(2.0, 200.0, 0)) return 1;                  /* a ray tracer: mostly per pixel */
    if (converge_case(2.0, 200.0, SY_CAP_PROGRESSIVE | SY_CAP_FILTERS)) return 1;
    if (converge_case(12.0, 60.0, 0)) return 1;                  /* a large fixed part */
    if (converge_case(0.5, 1500.0, SY_CAP_PROGRESSIVE)) return 1; /* very slow: near the minimum scale */
    if (converge_case(1.0, 20.0, 0)) return 1;                   /* full size fits */
    /* full size fits: it gets there */
    cost_model m = {.fixed = 1.0, .per = 10.0 / (640.0 * 480.0), .rng = 3};
    double now = 0.0;
    sy_governor_frame f;
    sy_governor *g = moving_for(&m, 640, 480, 20, &now, &f);
    if (!g) return 1;
    CHECK(f.width == 640 && f.height == 480 && f.scale == 1.0f);
    sy_governor_destroy(g);
    return 0;
}

/* A fixed part above the budget (a rasterizer whose vertex work alone is too slow): the minimum
 * scale, never 0 pixels. */
static int test_fixed_over_budget(void)
{
    sy_error e = {0};
    sy_governor *g = NULL;
    CHECK_OK(sy_governor_create(&(sy_governor_desc){.min_scale = 0.25f}, &g, &e), e);
    cost_model m = {.fixed = 50.0, .per = 1e-4, .rng = 11};
    double now = 0.0;
    sy_governor_frame f;
    for (int i = 0; i < 40; ++i) {
        step(g, &m, 800, 600, 0, true, &now, &f);
        if (i >= 8) CHECK_MSG(f.width == 200 && f.height == 150, "frame %d: %ux%u", i, f.width, f.height);
    }
    sy_governor_destroy(g);
    return 0;
}

/* After moving: waits while the view settles, then full size; progressive back-ends add samples
 * per frame, each frame within the budget once it has learnt, up to max_samples, then idle. */
static int still_case(uint32_t caps)
{
    sy_error e = {0};
    sy_governor *g = NULL;
    const uint32_t maxs = 300;
    CHECK_OK(sy_governor_create(&(sy_governor_desc){.max_samples = maxs}, &g, &e), e);
    const uint32_t W = 640, H = 480;
    cost_model m = {.fixed = 1.0, .per = 4.0 / ((double)W * H), .rng = 5}; /* 5 ms per full-size sample */
    double now = 0.0;
    sy_governor_frame f;
    for (int i = 0; i < 30; ++i) step(g, &m, W, H, caps, true, &now, &f);
    CHECK(f.moving);
    /* no change: first a wait for the settle time, the frame describing the last moving one */
    double t0 = now;
    sy_governor_plan(g, W, H, caps, false, now, &f);
    CHECK(f.wait_ms > 0.0 && f.wait_ms <= 150.0 && f.moving && f.width > 0);
    sy_governor_plan(g, W, H, caps, false, now + 10.0, &f);
    CHECK(f.wait_ms > 0.0); /* still waiting */
    now = t0 + 200.0;
    uint64_t total = 0;
    uint32_t frames = 0, biggest = 0;
    for (;;) {
        step(g, &m, W, H, caps, false, &now, &f);
        if (f.idle) break;
        CHECK(!f.moving && f.wait_ms == 0.0 && f.width == W && f.height == H && f.scale == 1.0f);
        CHECK(f.filter == ((caps & SY_CAP_FILTERS) != 0));
        CHECK(f.samples >= 1);
        if (frames == 0) CHECK(f.samples == 1);
        if (frames >= 4) CHECK_MSG(true_cost(&m, &f) <= 33.0, "refining frame %u: %u samples cost %.1f ms", frames,
                                   f.samples, true_cost(&m, &f));
        total += f.samples;
        biggest = f.samples > biggest ? f.samples : biggest;
        CHECK(++frames < 1000);
    }
    if (caps & SY_CAP_PROGRESSIVE) {
        CHECK_MSG(total == maxs, "refined to %llu samples", (unsigned long long)total);
        CHECK_MSG(biggest >= 4, "at most %u samples per frame where 6 fit", biggest); /* (33*0.85-1)/4 = 6 */
    } else {
        CHECK(frames == 1 && total == 1);
    }
    /* idle stays idle without input; redraw gives one more frame at full size */
    sy_governor_plan(g, W, H, caps, false, now + 1000.0, &f);
    CHECK(f.idle);
    sy_governor_redraw(g);
    sy_governor_plan(g, W, H, caps, false, now + 1001.0, &f);
    CHECK(!f.idle && !f.moving && f.samples == 1 && f.width == W);
    sy_governor_plan(g, W, H, caps, false, now + 1002.0, &f);
    CHECK(f.idle);
    /* a change moves again at once */
    sy_governor_plan(g, W, H, caps, true, now + 1003.0, &f);
    CHECK(f.moving && !f.idle && f.wait_ms == 0.0 && f.width <= W);
    /* a new display size or new caps count as a change by themselves */
    now += 2000.0;
    sy_governor_plan(g, W, H, caps, false, now, &f);
    CHECK(f.wait_ms > 0.0 || !f.moving);
    sy_governor_plan(g, W / 2, H, caps, false, now, &f);
    CHECK(f.moving && f.wait_ms == 0.0 && f.width <= W / 2);
    sy_governor_plan(g, W / 2, H, caps ^ SY_CAP_PROGRESSIVE, false, now + 500.0, &f);
    CHECK(f.moving && f.wait_ms == 0.0);
    sy_governor_destroy(g);
    return 0;
}

static int test_still(void)
{
    if (still_case(0)) return 1;
    if (still_case(SY_CAP_PROGRESSIVE)) return 1;
    if (still_case(SY_CAP_PROGRESSIVE | SY_CAP_FILTERS)) return 1;
    return 0;
}

/* Sizes: never above the display, never 0 for a non-empty display, an empty display is idle. */
static int test_sizes(void)
{
    sy_error e = {0};
    sy_governor *g = NULL;
    CHECK_OK(sy_governor_create(NULL, &g, &e), e);
    static const uint32_t sizes[][2] = {{1, 1},     {2, 3},      {7, 1},          {1, 9},         {640, 480},
                                        {16384, 16384}, {65535, 1}, {UINT32_MAX, 1}, {UINT32_MAX, UINT32_MAX}};
    cost_model m = {.fixed = 0.5, .per = 1e-5, .rng = 9};
    double now = 0.0;
    sy_governor_frame f;
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; ++k)
        for (int i = 0; i < 30; ++i) {
            uint32_t caps = i & 1 ? SY_CAP_PROGRESSIVE : 0;
            bool changed = i < 20;
            if (i == 20) now += 1000.0;
            sy_governor_plan(g, sizes[k][0], sizes[k][1], caps, changed, now, &f);
            if (f.idle) continue;
            CHECK_MSG(f.width >= 1 && f.width <= sizes[k][0] && f.height >= 1 && f.height <= sizes[k][1],
                      "%ux%u display: %ux%u frame", sizes[k][0], sizes[k][1], f.width, f.height);
            CHECK(f.scale > 0.0f && f.scale <= 1.0f && f.samples >= 1);
            if (f.wait_ms > 0.0) continue;
            sy_governor_report(g, &f, true_cost(&m, &f));
            now += 1.0;
        }
    /* the largest display: the cost model says the minimum scale */
    sy_governor_plan(g, UINT32_MAX, UINT32_MAX, 0, true, now, &f);
    CHECK(f.moving && f.scale <= 0.126f && f.width >= 1);
    static const uint32_t empty[][2] = {{0, 0}, {0, 480}, {640, 0}};
    for (size_t k = 0; k < 3; ++k) {
        sy_governor_plan(g, empty[k][0], empty[k][1], SY_CAP_PROGRESSIVE, true, now, &f);
        CHECK(f.idle && f.width == 0 && f.height == 0 && f.samples == 0 && f.wait_ms == 0.0);
        sy_governor_report(g, &f, 5.0); /* ignored */
    }
    /* bad reports are ignored: the model does not change */
    double fx0, per0, fx1, per1;
    CHECK(sy_governor_cost(g, true, &fx0, &per0));
    sy_governor_frame ok = {.width = 10, .height = 10, .scale = 1, .samples = 1, .moving = true};
    sy_governor_report(g, &ok, NAN);
    sy_governor_report(g, &ok, -1.0);
    sy_governor_report(g, &ok, INFINITY);
    sy_governor_report(g, NULL, 1.0);
    CHECK(sy_governor_cost(g, true, &fx1, &per1) && fx0 == fx1 && per0 == per1);
    /* a clock that goes back or is not finite does not break the plan */
    sy_governor_plan(g, 100, 100, 0, true, now - 5000.0, &f);
    CHECK(f.moving && f.width >= 1 && f.width <= 100);
    sy_governor_plan(g, 100, 100, 0, false, NAN, &f);
    CHECK(f.width >= 1 && f.width <= 100);
    sy_governor_destroy(g);
    return 0;
}

/* Bimodal times (a shared machine: a frame takes 0.7x or 1.4x its cost, one in four slow): the
 * governor aims lower, so that at least 90 % of the frames fit, yet at over a third of the budget. */
static int test_noisy(void)
{
    sy_error e = {0};
    sy_governor *g = NULL;
    CHECK_OK(sy_governor_create(NULL, &g, &e), e);
    const uint32_t W = 800, H = 600;
    cost_model m = {.fixed = 2.0, .per = 300.0 / ((double)W * H), .rng = 77};
    double now = 0.0, sum = 0.0;
    uint32_t fit = 0, n = 0;
    sy_governor_frame f;
    for (int i = 0; i < 200; ++i) {
        sy_governor_plan(g, W, H, 0, true, now, &f);
        double t = true_cost(&m, &f) * (noise(&m) < 0.95 ? 1.4 : 0.7); /* noise(): 0.9 .. 1.1 */
        sy_governor_report(g, &f, t);
        now += t + 1.0;
        if (i < 40) continue;
        n++;
        fit += t <= 33.0;
        sum += t;
    }
    CHECK_MSG(fit >= 0.9 * n, "%u of %u noisy frames within the budget", fit, n);
    CHECK_MSG(sum / n >= 11.0, "mean frame %.1f ms: the budget is wasted", sum / n);
    sy_governor_destroy(g);
    return 0;
}

/* A back-end switch: from a slow one to one 20x faster. With reset the faster one grows to a larger
 * scale within a few frames; without, the model still follows within a few more. */
static int switch_case(bool reset)
{
    const uint32_t W = 1024, H = 768;
    cost_model slow = {.fixed = 1.0, .per = 400.0 / ((double)W * H), .rng = 1};
    cost_model fast = {.fixed = 1.0, .per = 20.0 / ((double)W * H), .rng = 2};
    double now = 0.0;
    sy_governor_frame f;
    sy_governor *g = moving_for(&slow, W, H, 30, &now, &f);
    if (!g) return 1;
    float slow_scale = f.scale;
    CHECK(slow_scale < 0.4f);
    if (reset) sy_governor_reset(g);
    for (int i = 0; i < 30; ++i) {
        step(g, &fast, W, H, 0, true, &now, &f);
        if (i >= 12) CHECK_MSG(true_cost(&fast, &f) <= 33.0, "after the switch, frame %d: %.1f ms", i, true_cost(&fast, &f));
    }
    CHECK_MSG(f.scale == 1.0f, "after the switch (reset %d): scale %.3f", reset, (double)f.scale);
    /* and back to the slow one: within budget again */
    if (reset) sy_governor_reset(g);
    for (int i = 0; i < 30; ++i) {
        step(g, &slow, W, H, 0, true, &now, &f);
        if (getenv("GOV_TRACE")) fprintf(stderr, "reset %d back %d: scale %.3f cost %.1f\n", reset, i, (double)f.scale, true_cost(&slow, &f));
        if (i >= 8) CHECK_MSG(true_cost(&slow, &f) <= 33.0, "back (reset %d), frame %d: %.1f ms", reset, i, true_cost(&slow, &f));
    }
    sy_governor_destroy(g);
    return 0;
}

static int test_switch(void)
{
    if (switch_case(true)) return 1;
    if (switch_case(false)) return 1;
    return 0;
}

/* One stall (a frame 50x slower) moves the scale down a bounded step, not to the minimum for long. */
static int test_stall(void)
{
    cost_model m = {.fixed = 1.0, .per = 60.0 / (800.0 * 600.0), .rng = 4};
    double now = 0.0;
    sy_governor_frame f;
    sy_governor *g = moving_for(&m, 800, 600, 30, &now, &f);
    if (!g) return 1;
    float before = f.scale;
    sy_governor_plan(g, 800, 600, 0, true, now, &f);
    sy_governor_report(g, &f, 50.0 * true_cost(&m, &f));
    for (int i = 0; i < 8; ++i) step(g, &m, 800, 600, 0, true, &now, &f);
    CHECK_MSG(f.scale >= 0.8f * before, "8 frames after a stall: scale %.3f, before %.3f", (double)f.scale, (double)before);
    sy_governor_destroy(g);
    return 0;
}

/* SY_CAP_PREVIEW: moving frames ask for a preview (a quarter of the work), refining frames for full
 * quality; a back-end without the cap always gets full quality. */
static int test_preview(void)
{
    sy_error e = {0};
    for (int with = 0; with < 2; ++with) {
        sy_governor *g = NULL;
        CHECK_OK(sy_governor_create(NULL, &g, &e), e);
        cost_model m = {.fixed = 2.0, .per = 1e-4, .rng = 7};
        uint32_t caps = with ? SY_CAP_PREVIEW : 0u;
        double now = 0.0;
        sy_governor_frame f;
        bool saw_moving = false, saw_still = false;
        for (int i = 0; i < 40; ++i) { /* moving */
            step(g, &m, 640, 480, caps, true, &now, &f);
            if (f.moving && f.wait_ms == 0.0) {
                saw_moving = true;
                CHECK(f.preview == (with ? SY_GOVERNOR_PREVIEW : 1.0f));
            }
        }
        for (int i = 0; i < 20 && !f.idle; ++i) { /* still: refine */
            step(g, &m, 640, 480, caps, false, &now, &f);
            if (!f.moving && !f.idle && f.wait_ms == 0.0) {
                saw_still = true;
                CHECK(f.preview == 1.0f && f.scale == 1.0f);
            }
        }
        CHECK(saw_moving && saw_still);
        sy_governor_destroy(g);
    }
    return 0;
}

SY_CHECK_MAIN("test_governor", SY_TEST(test_settings), SY_TEST(test_converges), SY_TEST(test_fixed_over_budget),
              SY_TEST(test_still), SY_TEST(test_sizes), SY_TEST(test_noisy), SY_TEST(test_switch), SY_TEST(test_stall),
              SY_TEST(test_preview))
