/* sy_governor.c — the frame-time governor of interactive views (see sy_governor.h): a cost model
 * fitted from reported frame times, and the plan of each frame (moving: the largest resolution that
 * fits the budget; still: full resolution, then progressive samples per frame within the budget). */
#include "sy_governor.h"

#include "sy_mediator.h" /* SY_CAP_PROGRESSIVE, SY_CAP_FILTERS */

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define GOV_DEFAULT_BUDGET_MS 33.0
#define GOV_DEFAULT_MIN_SCALE 0.125f
#define GOV_DEFAULT_MAX_SAMPLES 65536u
#define GOV_DEFAULT_SETTLE_MS 150.0
#define GOV_FORGET 0.7          /* weight of the older frames per report */
#define GOV_MOVING_TARGET 0.80  /* most of the budget a moving frame aims at */
#define GOV_REFINE_TARGET 0.85  /* ... a refining frame */
#define GOV_LEAST_TARGET 0.50   /* least of the budget a frame aims at, however noisy the times */
#define GOV_RATIOS 32           /* measured / predicted times kept for the spread */
#define GOV_OUTLIER 4.0         /* a report counts at most this factor off the prediction */
#define GOV_INITIAL_SCALE 0.25f /* a moving frame without any cost model */
#define GOV_SCALE_STEPS 64.0f   /* scales are multiples of 1/64 (rounded down) */

enum { FIT_PLAIN = 0, FIT_REFINE = 1 };

/* Exponentially weighted least squares of t = fixed + per * x. */
typedef struct gov_fit {
    double w, sx, sy, sxx, sxy; /* decayed sums */
    double fixed, per;          /* the model */
    uint32_t n;                 /* reports since the last reset */
    uint32_t surprises;         /* consecutive reports more than 2x off the prediction */
    double last_x, last_t;      /* the previous report */
    float ratios[GOV_RATIOS];   /* measured / predicted of the last reports (a ring) */
    uint32_t ratio_count;       /* reports in the ring (at most GOV_RATIOS) */
    uint32_t ratio_next;
} gov_fit;

struct sy_governor {
    sy_governor_desc d;
    gov_fit fit[2];
    bool started;          /* planned at least once */
    bool pending_change;   /* reset: the next plan starts over */
    bool need_moving;      /* a change not yet answered by a moving frame */
    bool redraw;           /* sy_governor_redraw */
    bool refined_once;     /* non-progressive: the full frame of this view was planned */
    double last_change_ms;
    uint32_t last_w, last_h, last_caps;
    float scale;             /* the last moving frame's scale, 0 = none since the reset */
    sy_governor_frame moving; /* the last moving frame (what a waiting frame describes) */
    uint64_t refined;        /* progressive: samples planned at full size since the last change */
    uint32_t last_refine_n;  /* samples of the last refining frame of this view */
};

static void fit_add(gov_fit *f, double x, double t)
{
    f->w = f->w * GOV_FORGET + 1.0;
    f->sx = f->sx * GOV_FORGET + x;
    f->sy = f->sy * GOV_FORGET + t;
    f->sxx = f->sxx * GOV_FORGET + x * x;
    f->sxy = f->sxy * GOV_FORGET + x * t;
    f->n++;
    double mx = f->sx / f->w, my = f->sy / f->w;
    double vx = f->sxx / f->w - mx * mx, cxy = f->sxy / f->w - mx * my;
    /* the fixed part only from frames of clearly different sizes; otherwise keep the last estimate
     * (0 at first: proportional, which undershoots while growing) */
    if (vx > 0.0625 * mx * mx && cxy > 0.0) {
        double per = cxy / vx, fixed = my - per * mx;
        f->fixed = 0.5 * f->fixed + 0.5 * fixed;
    }
    f->fixed = fmin(fmax(f->fixed, 0.0), 0.9 * my);
    f->per = mx > 0.0 ? (my - f->fixed) / mx : 0.0;
}

static void fit_observe(gov_fit *f, double x, double t)
{
    double raw = t;
    if (f->n >= 2) {
        double pred = f->fixed + f->per * x;
        if (pred > 0.0) { /* the spread of the times around the model */
            f->ratios[f->ratio_next] = (float)fmin(t / pred, 100.0);
            f->ratio_next = (f->ratio_next + 1) % GOV_RATIOS;
            if (f->ratio_count < GOV_RATIOS) f->ratio_count++;
        }
        bool off = pred > 0.0 && (t > 2.0 * pred || t < 0.5 * pred);
        f->surprises = off ? f->surprises + 1 : 0;
        if (f->surprises >= 2) { /* a lasting change (another back-end, scene, machine load): start over
                                    from the two reports that showed it */
            double px = f->last_x, pt = f->last_t;
            memset(f, 0, sizeof *f);
            fit_add(f, px, pt);
            fit_add(f, x, t);
            f->last_x = x, f->last_t = raw;
            return;
        }
        /* bounded influence of one report (a stall, another process) */
        if (pred > 0.0) t = fmin(fmax(t, pred / GOV_OUTLIER), pred * GOV_OUTLIER);
    }
    fit_add(f, x, t);
    f->last_x = x, f->last_t = raw;
}

/* The time a frame aims at: most * budget, less where the measured times spread (another process
 * taking the cores now and then): budget / the ring's second largest measured / predicted ratio
 * (about its 95th percentile; the largest alone is a stall), so that the slow frames still fit;
 * never below GOV_LEAST_TARGET of the budget. */
static double fit_target(const gov_fit *f, double budget, double most)
{
    if (!f || f->ratio_count < 8) return most * budget;
    float a = 0.0f, b = 0.0f; /* largest, second largest */
    for (uint32_t i = 0; i < f->ratio_count; ++i) {
        float r = f->ratios[i];
        if (r > a) b = a, a = r;
        else if (r > b) b = r;
    }
    double share = b > 0.0f ? 1.0 / b : most;
    return fmin(fmax(share, GOV_LEAST_TARGET), most) * budget;
}

/* The model for a kind of frame: its own fit, else the other one's, else NULL. */
static const gov_fit *fit_for(const sy_governor *g, int kind)
{
    if (g->fit[kind].n) return &g->fit[kind];
    if (g->fit[!kind].n) return &g->fit[!kind];
    return NULL;
}

sy_result sy_governor_create(const sy_governor_desc *d, sy_governor **out, sy_error *err)
{
    *out = NULL;
    sy_governor_desc s = d ? *d : (sy_governor_desc){0};
    if (!isfinite(s.budget_ms) || s.budget_ms < 0.0)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "governor: budget_ms %g must be a finite value > 0 (0 = 33)",
                            s.budget_ms);
    if (!isfinite(s.settle_ms) || s.settle_ms < 0.0)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "governor: settle_ms %g must be a finite value >= 0 (0 = 150)",
                            s.settle_ms);
    if (!(s.min_scale >= 0.0f && s.min_scale <= 1.0f))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "governor: min_scale %g must lie in [0, 1] (0 = 0.125)",
                            (double)s.min_scale);
    if (s.budget_ms == 0.0) s.budget_ms = GOV_DEFAULT_BUDGET_MS;
    if (s.min_scale == 0.0f) s.min_scale = GOV_DEFAULT_MIN_SCALE;
    if (s.max_samples == 0) s.max_samples = GOV_DEFAULT_MAX_SAMPLES;
    if (s.settle_ms == 0.0) s.settle_ms = GOV_DEFAULT_SETTLE_MS;
    sy_governor *g = calloc(1, sizeof *g);
    if (!g) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "governor: out of memory");
    g->d = s;
    *out = g;
    return SY_OK;
}

void sy_governor_destroy(sy_governor *g) { free(g); }

void sy_governor_settings(const sy_governor *g, sy_governor_desc *out) { *out = g->d; }

void sy_governor_reset(sy_governor *g)
{
    memset(g->fit, 0, sizeof g->fit);
    g->scale = 0.0f;
    g->pending_change = true;
}

void sy_governor_redraw(sy_governor *g) { g->redraw = true; }

void sy_governor_set_min_scale(sy_governor *g, float min_scale)
{
    if (!(min_scale >= 0.0f && min_scale <= 1.0f)) return;
    g->d.min_scale = min_scale == 0.0f ? GOV_DEFAULT_MIN_SCALE : min_scale;
}

bool sy_governor_cost(const sy_governor *g, bool moving, double *fixed_ms, double *per_ms)
{
    const gov_fit *f = &g->fit[moving ? FIT_PLAIN : FIT_REFINE];
    *fixed_ms = f->n ? f->fixed : 0.0;
    *per_ms = f->n ? f->per : 0.0;
    return f->n > 0;
}

/* width x height of scale s of the display (each at least 1, at most the display's). */
static void size_of(uint32_t dw, uint32_t dh, float s, sy_governor_frame *out)
{
    double w = floor((double)dw * s + 0.5), h = floor((double)dh * s + 0.5);
    out->width = w < 1.0 ? 1u : w > dw ? dw : (uint32_t)w;
    out->height = h < 1.0 ? 1u : h > dh ? dh : (uint32_t)h;
    out->scale = (float)((double)out->width / (double)dw);
}

/* The largest scale whose predicted time fits the moving target. */
static float moving_scale(const sy_governor *g, double pixels)
{
    const float lo = g->d.min_scale;
    const gov_fit *f = fit_for(g, FIT_PLAIN);
    float s;
    if (!f || !(f->per > 0.0)) {
        s = g->scale > 0.0f ? g->scale : GOV_INITIAL_SCALE;
    } else {
        double target = fit_target(f, g->d.budget_ms, GOV_MOVING_TARGET) - f->fixed;
        double fit = target > 0.0 ? target / (f->per * pixels) : 0.0; /* share of the display's pixels */
        s = fit >= 1.0 ? 1.0f : (float)sqrt(fit > 0.0 ? fit : 0.0);
    }
    if (g->scale > 0.0f && s > 2.0f * g->scale) s = 2.0f * g->scale; /* grow at most 2x per frame */
    s = floorf(s * GOV_SCALE_STEPS) / GOV_SCALE_STEPS;
    if (s < lo) s = lo;
    if (s > 1.0f) s = 1.0f;
    return s;
}

/* Samples of the next refining frame at full size (progressive), >= 1. */
static uint32_t refine_samples(const sy_governor *g, double pixels)
{
    uint64_t left = g->d.max_samples > g->refined ? g->d.max_samples - g->refined : 1;
    if (!g->last_refine_n) return 1; /* the first full-size pass: one sample, whatever the model says */
    const gov_fit *f = fit_for(g, FIT_REFINE);
    double n = 1.0;
    if (f && f->per > 0.0) {
        double target = fit_target(f, g->d.budget_ms, GOV_REFINE_TARGET) - f->fixed;
        n = target > 0.0 ? floor(target / (f->per * pixels)) : 1.0;
    }
    double most = 2.0 * g->last_refine_n; /* grow at most 2x per frame */
    if (n > most) n = most;
    if (n > (double)left) n = (double)left;
    return n < 1.0 ? 1u : (uint32_t)n;
}

void sy_governor_plan(sy_governor *g, uint32_t dw, uint32_t dh, uint32_t caps, bool view_changed, double now_ms,
                      sy_governor_frame *out)
{
    memset(out, 0, sizeof *out);
    if (!isfinite(now_ms)) now_ms = g->last_change_ms;
    bool changed = view_changed || g->pending_change || !g->started || dw != g->last_w || dh != g->last_h ||
                   caps != g->last_caps;
    g->started = true;
    g->pending_change = false;
    g->last_w = dw, g->last_h = dh, g->last_caps = caps;
    if (changed) {
        g->last_change_ms = now_ms;
        g->need_moving = true;
        g->refined = 0;
        g->refined_once = false;
        g->last_refine_n = 0;
        g->redraw = false;
    }
    if (now_ms < g->last_change_ms) now_ms = g->last_change_ms; /* a clock that went back */
    if (!dw || !dh) { /* nothing to show */
        out->idle = true;
        g->need_moving = false;
        return;
    }
    const double pixels = (double)dw * (double)dh;
    const bool progressive = caps & SY_CAP_PROGRESSIVE;
    double since = now_ms - g->last_change_ms;
    if (since < g->d.settle_ms) { /* moving */
        if (!g->need_moving && g->moving.width) { /* answered: wait for the view to settle */
            *out = g->moving;
            out->wait_ms = g->d.settle_ms - since;
            return;
        }
        float s = moving_scale(g, pixels);
        size_of(dw, dh, s, out);
        out->samples = 1;
        out->moving = true;
        out->preview = (caps & SY_CAP_PREVIEW) ? SY_GOVERNOR_PREVIEW : 1.0f;
        g->scale = s;
        g->need_moving = false;
        g->moving = *out;
        return;
    }
    /* still: refine */
    g->need_moving = false;
    bool done = progressive ? g->refined >= g->d.max_samples : g->refined_once;
    if (done && !g->redraw) {
        out->width = dw, out->height = dh, out->scale = 1.0f;
        out->idle = true;
        return;
    }
    out->width = dw, out->height = dh, out->scale = 1.0f;
    out->preview = 1.0f;
    out->filter = (caps & SY_CAP_FILTERS) != 0;
    out->samples = done ? 1u : progressive ? refine_samples(g, pixels) : 1u;
    g->redraw = false;
    g->refined_once = true;
    g->refined += out->samples;
    if (progressive) g->last_refine_n = out->samples;
}

void sy_governor_report(sy_governor *g, const sy_governor_frame *f, double render_ms)
{
    if (!f || f->idle || f->wait_ms > 0.0 || !f->width || !f->height || !isfinite(render_ms) || render_ms < 0.0) return;
    uint32_t n = f->samples ? f->samples : 1;
    double x = (double)f->width * (double)f->height * n;
    fit_observe(&g->fit[f->filter || n > 1 ? FIT_REFINE : FIT_PLAIN], x, render_ms);
}
