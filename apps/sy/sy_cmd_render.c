/* sy_cmd_render.c — `sy render SCENE|DIR`: one image of a scene with a back-end (options, output
 * and its metadata, feature buffers, stereo, overlays, sequences and video, and --cluster through
 * sy_cluster_cli.h; a progressive back-end's passes and motion blur: sy_render_passes.h). */
#include "sy_commands.h"
#include "sy_cli.h"
#include "sy_cluster_cli.h"
#include "sy_compose.h"
#include "sy_load.h"
#include "sy_mediator_cluster.h"
#include "sy_output.h"
#include "sy_render_passes.h"
#include "sy_signals.h"
#include "sy_testpoint.h"
#include "sy_video.h"

#include "sy_anim.h"
#include "sy_exr.h"
#include "sy_file.h"
#include "sy_log.h"
#include "sy_mediators.h"
#include "sy_viewport.h"

#include <dirent.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* A scene file's extension, as the loaders' names suggest (the content decides later). */
static bool is_scene_name(const char *name)
{
    return sy_cli_ends_with(name, ".gltf") || sy_cli_ends_with(name, ".glb") || sy_cli_ends_with(name, ".x3d");
}

static int cmp_names(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

/* `sy render DIR`: the one scene file in dir (into out), looked for directly in it and, when there
 * is none, one folder down (a Khronos sample's glTF/, glTF-Binary/ ...); several: an error that
 * lists them. */
static sy_result scene_in_folder(const char *dir, char *out, size_t out_len, sy_error *err)
{
    enum { MAX_LISTED = 12 };
    char *found[64];
    uint32_t n = 0, total = 0;
    for (int depth = 0; depth < 2 && total == 0; ++depth) {
        DIR *d = opendir(dir);
        if (!d) return sy_error_set(err, SY_ERR_IO, "%s: cannot read the folder: %s", dir, strerror(errno));
        struct dirent *de;
        while ((de = readdir(d))) {
            if (de->d_name[0] == '.') continue;
            char path[4096];
            snprintf(path, sizeof path, "%s%s%s", dir, sy_cli_ends_with(dir, "/") ? "" : "/", de->d_name);
            struct stat st;
            if (stat(path, &st) != 0) continue;
            if (depth == 0 && S_ISREG(st.st_mode) && is_scene_name(de->d_name)) {
                if (n < 64) found[n++] = strdup(path);
                total++;
            } else if (depth == 1 && S_ISDIR(st.st_mode)) {
                DIR *sd = opendir(path);
                struct dirent *se;
                while (sd && (se = readdir(sd))) {
                    char sub[4096 + 256];
                    snprintf(sub, sizeof sub, "%s/%s", path, se->d_name);
                    if (se->d_name[0] == '.' || !is_scene_name(se->d_name) || stat(sub, &st) != 0 || !S_ISREG(st.st_mode))
                        continue;
                    if (n < 64) found[n++] = strdup(sub);
                    total++;
                }
                if (sd) closedir(sd);
            }
        }
        closedir(d);
    }
    for (uint32_t i = 0; i < n; ++i)
        if (!found[i]) { /* strdup failed */
            for (uint32_t k = 0; k < n; ++k) free(found[k]);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", dir);
        }
    qsort(found, n, sizeof *found, cmp_names);
    sy_result r = SY_OK;
    if (total == 1) {
        if (snprintf(out, out_len, "%s", found[0]) >= (int)out_len)
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: path too long", found[0]);
    } else if (total == 0) {
        r = sy_error_set(err, SY_ERR_NOT_FOUND, "%s: no scene file (.gltf, .glb, .x3d) in the folder or one folder down", dir);
    } else {
        char list[2048] = "";
        size_t used = 0;
        for (uint32_t i = 0; i < n && i < MAX_LISTED && used < sizeof list; ++i)
            used += (size_t)snprintf(list + used, sizeof list - used, "\n  %s", found[i]);
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: %u scene files; name one:%s%s", dir, total, list,
                         total > MAX_LISTED ? "\n  ..." : "");
    }
    for (uint32_t i = 0; i < n; ++i) free(found[i]);
    return r;
}

/* `sy render SCENE` without -o: STEM.png in the current folder (STEM: the file's name without its
 * extension; "demo" for the built-in scene). */
static void default_output(const char *scene, char *out, size_t out_len)
{
    const char *base = strrchr(scene, '/');
    base = base ? base + 1 : scene;
    const char *dot = strrchr(base, '.');
    int n = dot && dot != base ? (int)(dot - base) : (int)strlen(base);
    snprintf(out, out_len, "%.*s.png", n, base);
}

/* --frames A:B[:STEP]: frame numbers A..B inclusive (A <= B), every STEP-th (default 1); false on
 * anything else. "N" alone (the cluster's old repeat count, now --repeat) is false too. */
static bool parse_frame_range(const char *s, uint32_t *a, uint32_t *b, uint32_t *step)
{
    char buf[64];
    char *c1 = strlen(s) < sizeof buf ? strchr(strcpy(buf, s), ':') : NULL, *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
    if (!c1) return false;
    *c1 = '\0';
    if (c2) *c2 = '\0';
    uint64_t x = 0, y = 0, z = 1;
    if (!sy_cli_parse_uint(buf, 0, 100000000u, &x) || !sy_cli_parse_uint(c1 + 1, x, 100000000u, &y) ||
        (c2 && !sy_cli_parse_uint(c2 + 1, 1, 100000000u, &z)))
        return false;
    *a = (uint32_t)x, *b = (uint32_t)y, *step = (uint32_t)z;
    return true;
}

/* The output of one frame of a sequence: the pattern's first run of '#' replaced by the frame
 * number, zero-padded to the run's length (longer numbers are written in full). */
static void frame_path(const char *pattern, uint32_t frame, char *out, size_t out_len)
{
    const char *p = strchr(pattern, '#');
    size_t run = strspn(p, "#");
    snprintf(out, out_len, "%.*s%0*u%s", (int)(p - pattern), pattern, (int)run, frame, p + run);
}

/* Writes the back-end's feature buffers (SY_CAP_AOVS) as channels of one EXR: colour and depth
 * as R G B A Z, the ID planes as object_id and instance_id (float even with --half), every other
 * plane as NAME.{R,G,B} (normal: NAME.{X,Y,Z}), e.g. variance.R. */
static sy_result write_aov_exr(const char *path, sy_context *ctx, const out_opts *o, sy_error *err)
{
    sy_aovs a;
    sy_result r = sy_context_aovs(ctx, &a, err);
    if (r != SY_OK) return r;
    sy_exr_channel_desc ch[4 * SY_AOVS_MAX];
    int n = 0;
    static const char *const rgba[4] = {"R", "G", "B", "A"}, *const rgb[4] = {"R", "G", "B", "A"},
                             *const xyz[3] = {"X", "Y", "Z"};
    char names[SY_AOVS_MAX][4][48];
    sy_exr_pixel_type ct = o->half ? SY_EXR_PIXEL_HALF : SY_EXR_PIXEL_FLOAT;
    for (uint32_t k = 0; k < a.count; ++k) {
        const sy_aov_plane *p = &a.planes[k];
        if (!strcmp(p->name, "color")) {
            for (uint32_t i = 0; i < 4 && i < p->channels; ++i) ch[n++] = (sy_exr_channel_desc){rgba[i], p->data, p->channels, i, ct};
        } else if (!strcmp(p->name, "depth")) {
            ch[n++] = (sy_exr_channel_desc){"Z", p->data, p->channels, 0, SY_EXR_PIXEL_FLOAT};
        } else if (!strcmp(p->name, "object_id") || !strcmp(p->name, "instance_id")) { /* ids: exact floats */
            ch[n++] = (sy_exr_channel_desc){p->name, p->data, p->channels, 0, SY_EXR_PIXEL_FLOAT};
        } else {
            bool normal = !strcmp(p->name, "normal");
            for (uint32_t i = 0; i < p->channels && i < (normal ? 3u : 4u); ++i) {
                snprintf(names[k][i], sizeof names[k][i], "%s.%s", p->name, normal ? xyz[i] : rgb[i]);
                ch[n++] = (sy_exr_channel_desc){names[k][i], p->data, p->channels, i, ct};
            }
        }
    }
    sy_exr_write_desc wd = {.width = (int)a.width, .height = (int)a.height, .channels = ch, .channel_count = n,
                            .attributes = o->attrs, .attribute_count = o->attr_count};
    r = sy_exr_write(path, &wd, err);
    sy_aovs_free(&a);
    return r;
}

/* NAME.EXT -> NAME_left.EXT and NAME_right.EXT */
static sy_result eye_paths(const char *outp, char *lp, char *rp, size_t n, sy_error *err)
{
    const char *dot = strrchr(outp, '.');
    size_t stem = dot ? (size_t)(dot - outp) : strlen(outp);
    if ((size_t)snprintf(lp, n, "%.*s_left%s", (int)stem, outp, dot ? dot : "") >= n ||
        (size_t)snprintf(rp, n, "%.*s_right%s", (int)stem, outp, dot ? dot : "") >= n)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: path too long", outp);
    return SY_OK;
}

/* `--gl PROVIDER` (raster back-end): appended to the back-end parameters as gl=PROVIDER. */
static const char *render_gl_params(const char *params, const char *provider, char *buf, size_t len)
{
    snprintf(buf, len, "%s%sgl=%s", params ? params : "", params && *params ? "," : "", provider);
    return buf;
}

/* `--filter NAME [--threshold T]` (path tracer display filter): appended to the back-end
 * parameters as filter=NAME,threshold=T; the mediator validates them (sy_mediator_rt.h). */
static const char *render_filter_params(const char *params, const char *filter, const char *threshold, char *buf,
                                        size_t len)
{
    snprintf(buf, len, "%s%s%s%s%s%s", params ? params : "", params && *params ? "," : "", filter ? "filter=" : "",
             filter ? filter : "", filter && threshold ? "," : "", threshold ? "threshold=" : "");
    if (threshold) strncat(buf, threshold, len - strlen(buf) - 1);
    return buf;
}

/* One line per cluster frame on stderr: servers, failures, bytes (the cluster mediator's statistics). */
static void cluster_report(sy_scene *scene, sy_context_pool *pool, const sy_compose_spec *spec, uint32_t frame,
                           uint32_t servers)
{
    sy_params pp;
    sy_context *ctx = NULL;
    sy_error e = {0};
    if (sy_params_parse(spec->params, &pp, &e) != SY_OK ||
        sy_context_pool_get(pool, scene, spec->backend, &pp, spec->root.id, &ctx, &e) != SY_OK ||
        !(sy_context_caps(ctx) & SY_CAP_REMOTE))
        return;
    sy_cluster_frame_stats st;
    uint32_t mode = 0;
    sy_cluster_cli_last_frame(ctx, &st, &mode);
    sy_log(SY_LOG_NOTE, "sy", NULL,
           "cluster frame %u (%s): %u/%u servers, %u failed, %u reassigned, %.3f s, "
           "%llu bytes sent (%llu scene), %llu received",
           frame + 1, sy_cluster_cli_mode_name(mode), st.servers_live, servers, st.servers_failed, st.reassigned,
           st.seconds, (unsigned long long)st.bytes_sent, (unsigned long long)st.scene_bytes,
           (unsigned long long)st.bytes_received);
    if (mode == SY_CLUSTER_COOPERATIVE)
        sy_log(SY_LOG_NOTE, "sy", NULL, "cluster: merged %llu samples per pixel", (unsigned long long)st.samples);
}

/* >>frames mode: `--frames A:B --cluster-mode frames`, whole frames on the servers from a work queue */
typedef struct frames_run {
    const char *pattern, *shown, *scene, *params;
    const uint32_t *numbers;     /* frame numbers of the job's frames */
    const out_opts *oo;
    uint32_t w, h, samples, total, skipped, written;
    double t0, last_print;
    bool tty;
} frames_run;

/* Writes a finished frame (on the cluster client's threads, one call at a time) and shows progress
 * on a terminal: frames done, frames per minute, ETA. */
static sy_result frames_done(void *user, uint32_t index, const sy_layer *img, uint32_t server, sy_error *err)
{
    frames_run *fr = user;
    char path[4096], renderer[64], size_str[48], samples_str[32], server_str[16];
    frame_path(fr->pattern, fr->numbers[index], path, sizeof path);
    snprintf(renderer, sizeof renderer, "Switchyard %s", sy_version());
    snprintf(size_str, sizeof size_str, "%ux%u", fr->w, fr->h);
    snprintf(samples_str, sizeof samples_str, "%u", fr->samples ? fr->samples : 1u);
    snprintf(server_str, sizeof server_str, "%u", server + 1);
    const char *kv[][2] = {{"sy:renderer", renderer}, {"sy:backend", fr->shown}, {"sy:params", fr->params},
                           {"sy:size", size_str},     {"sy:samples", samples_str}, {"sy:source", fr->scene},
                           {"sy:server", server_str}};
    sy_exr_attribute attrs[sizeof kv / sizeof kv[0]];
    sy_png_text texts[sizeof kv / sizeof kv[0]];
    out_opts o = *fr->oo;
    sy_cli_out_metadata(&o, kv, sizeof kv / sizeof kv[0], attrs, texts);
    size_t bad = sy_layer_count_nonfinite(img);
    if (bad) sy_log(SY_LOG_WARNING, "sy", path, "%zu pixels are not finite", bad);
    sy_result r = sy_cli_write_image(path, img, &o, err); /* atomically: --resume trusts what exists */
    if (r != SY_OK) return r;
    fr->written++;
    double now = sy_time_now(), el = now - fr->t0;
    if (fr->tty && (now - fr->last_print > 0.1 || fr->written == fr->total)) {
        double fpm = el > 0 ? 60.0 * fr->written / el : 0.0;
        fprintf(stderr, "\rframes: %u of %u done, %.1f frames/min, ETA %.0f s   ", fr->written, fr->total, fpm,
                fpm > 0 ? 60.0 * (fr->total - fr->written) / fpm : 0.0);
        fflush(stderr);
        fr->last_print = now;
    }
    return SY_OK;
}

/* The whole sequence in frames mode: the frames --resume does not skip, each one's time and camera
 * view (the client's scene is moved frame by frame to compute the view; the servers set the time on
 * their replicas), rendered by the servers as they come free. Returns the exit status. */
static int render_frames_mode(loaded *ld, const sy_compose_spec *spec, const sy_cluster_cli_opts *clo, const char *remote,
                              const char *params, uint32_t w, uint32_t h, uint32_t samples, const char *clip, uint32_t fa,
                              uint32_t fb, uint32_t fstep, double fps, bool resume, const char *pattern, const out_opts *oo,
                              const char *scene)
{
    uint32_t nseq = (fb - fa) / fstep + 1, n = 0, skipped = 0;
    uint32_t *numbers = malloc((size_t)nseq * sizeof *numbers);
    double *times = malloc((size_t)nseq * sizeof *times);
    sy_camera_view *views = malloc((size_t)nseq * sizeof *views);
    sy_error err = {0};
    sy_result r = numbers && times && views ? SY_OK : sy_error_set(&err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    bool animated = sy_scene_count(ld->scene, SY_TYPE_ANIMATION) > 0;
    sy_animation clip_h = sy_cli_default_clip(ld); /* the servers' clock plays the same clip */
    if (r == SY_OK && clip && animated && sy_animation_find(ld->scene, clip, &clip_h, &err) != SY_OK) {
        fprintf(stderr, "sy render: error: --clip %s: %s\n", clip, err.message);
        free(numbers), free(times), free(views);
        return 2;
    }
    for (uint32_t fi = 0; fi < nseq && r == SY_OK; ++fi) {
        uint32_t frame = fa + fi * fstep;
        char path[4096];
        struct stat ost;
        frame_path(pattern, frame, path, sizeof path);
        if (resume && stat(path, &ost) == 0) { /* written whole (atomically) or not at all */
            skipped++;
            continue;
        }
        /* the camera may be animated: its view at this frame's time */
        int st = animated || n == 0 ? sy_cli_set_time(ld, clip, frame / fps, &err) : 0;
        if (st) {
            free(numbers), free(times), free(views);
            return st == 2 ? 2 : sy_cli_fail(&err);
        }
        numbers[n] = frame;
        times[n] = frame / fps;
        r = sy_compose_camera_view(ld->scene, spec, w, h, &views[n], &err);
        n++;
    }
    char shown[160];
    frames_run fr = {.pattern = pattern, .shown = shown, .scene = scene, .params = params, .numbers = numbers, .oo = oo,
                     .w = w, .h = h, .samples = samples, .total = n, .skipped = skipped, .t0 = sy_time_now(),
                     .tty = sy_is_terminal(2)};
    sy_cluster_frames_stats fs;
    memset(&fs, 0, sizeof fs);
    uint32_t servers = 0;
    snprintf(shown, sizeof shown, "%s in frames mode", remote);
    if (r == SY_OK && n) {
        sy_cluster_frames_job job = {.frame = {.mode = SY_CLUSTER_FRAMES,
                                               .backend = remote,
                                               .params = params,
                                               .root_id = ld->root.id,
                                               .background_id = ld->background.id,
                                               .width = w,
                                               .height = h,
                                               .samples = samples,
                                               .depth = true,
                                               .half = clo->half_pixels},
                                     .count = n,
                                     .times = animated ? times : NULL,
                                     .cameras = views,
                                     .clip_id = clip_h.id,
                                     .done = frames_done,
                                     .done_user = &fr};
        /* a whole path-traced frame may take minutes: without --timeout-ms a server has 10 minutes per
         * frame (a killed server's connection fails at once; the deadline only catches a stalled one) */
        sy_cluster_cli_opts fclo = *clo;
        if (!fclo.timeout_ms) fclo.timeout_ms = 600000;
        r = sy_cluster_cli_render_frames(&fclo, ld->scene, &job, &fs, &servers, &err);
        if (fr.tty) fprintf(stderr, "\r%*s\r", 78, "");
    }
    if (r == SY_OK) {
        printf("%s: frames %u..%u step %u at %g fps: %u written, %u skipped (existing), %ux%u, %s, %.3f s\n", pattern, fa,
               fb, fstep, fps, fr.written, skipped, w, h, shown, sy_time_now() - fr.t0);
        if (n) {
            char per[512] = "";
            size_t used = 0;
            for (uint32_t i = 0; i < servers && i < SY_CLUSTER_MAX_SERVERS && used < sizeof per; ++i)
                used += (size_t)snprintf(per + used, sizeof per - used, "%s%u", i ? " " : "", fs.per_server[i]);
            printf("frames mode: %u servers, frames per server %s, %u re-queued, %u server failures, %.1f frames/min\n",
                   servers, per, fs.requeued, fs.servers_failed, fs.seconds > 0 ? 60.0 * fs.frames / fs.seconds : 0.0);
        }
    }
    free(numbers), free(times), free(views);
    return r == SY_OK ? 0 : sy_cli_fail(&err);
}

int sy_cmd_render(int argc, char **argv)
{
    const char *scene = NULL, *backend = NULL, *outp = NULL, *camera = NULL, *params = NULL;
    const char *gl_provider = NULL;
    const char *filter = NULL, *threshold = NULL; /* --filter / --threshold (path tracer) */
    bool temporal = false;                        /* --temporal (path tracer, a sequence) */
    const char *overlay = NULL, *composite = "depth";
    uint32_t w = 0, h = 0;
    out_opts oo = {.png = {.tonemap = SY_TONEMAP_DISPLAY}}; /* the library's display tone map */
    sy_compose_spec spec = {.eye_separation = 0.065f, .zero_parallax = 2.0f};
    sy_error perr = {0};
    sy_cluster_cli_opts clo = {0};
    sy_cli_pt_opts po = {0};
    double at = 0.0;           /* --at: the scene's time in seconds */
    bool at_given = false;
    const char *clip = NULL;   /* --clip NAME|INDEX: one animation; without it every clip plays */
    bool seq = false, resume = false; /* --frames A:B[:STEP]: an image sequence; --resume */
    uint32_t fa = 0, fb = 0, fstep = 1;
    double fps = 24.0;
    bool fps_given = false;
    uint32_t max_memory_mb = 0;
    sy_shutter shutter = {0.0, 0.0, 0}; /* --shutter / --motion-blur / --shutter-samples: motion blur */
    bool shutter_given = false, motion_blur = false, sub_frames = false;
    uint32_t shutter_steps = 0; /* --shutter-steps: time steps of the one-render path (curved motion); 0 = chosen
                                 * from the motion (motion_steps_auto) */
    const sy_cli_opt opts[] = {
        SY_CLI_OPT_TEXT(NULL, 'b', &backend), SY_CLI_OPT_TEXT(NULL, 'o', &outp),
        SY_CLI_OPT_UINT("spp", OPT_SPP, &po.spp, 1, 1u << 24), SY_CLI_OPT_UINT("seed", OPT_SEED, &po.seed, 0, UINT32_MAX),
        SY_CLI_OPT_REAL("time", OPT_TIME, &po.time_budget, DBL_TRUE_MIN, DBL_MAX), SY_CLI_OPT_FLAG("aov", OPT_AOV, &po.aov),
        SY_CLI_OPT_TEXT("camera", OPT_CAMERA, &camera), SY_CLI_OPT_TEXT("params", OPT_PARAMS, &params),
        SY_CLI_OPT_TEXT("gl", OPT_GL, &gl_provider),          /* raster: gl=... parameter */
        SY_CLI_OPT_TEXT("filter", OPT_FILTER, &filter),       /* pathtracer: filter=... */
        SY_CLI_OPT_TEXT("threshold", OPT_THRESHOLD, &threshold), /* pathtracer: threshold=... */
        SY_CLI_OPT_FLAG("temporal", OPT_TEMPORAL, &temporal),     /* pathtracer: temporal=1 (moving frames: camera or objects) */
        SY_CLI_OPT_FLAG("half", OPT_HALF, &oo.half), SY_CLI_OPT_FLOAT("exposure", OPT_EXPOSURE, &oo.png.exposure_stops, -FLT_MAX, FLT_MAX),
        SY_CLI_OPT_CODE("tonemap", OPT_TONEMAP, true), SY_CLI_OPT_CODE("stereo", OPT_STEREO, true),
        SY_CLI_OPT_FLOAT_ANY("eye-sep", OPT_EYE_SEP, &spec.eye_separation), /* the range: sy_compose says why */
        SY_CLI_OPT_FLOAT_ANY("zero-parallax", OPT_ZERO_PARALLAX, &spec.zero_parallax),
        SY_CLI_OPT_TEXT("overlay", OPT_OVERLAY, &overlay), SY_CLI_OPT_TEXT("composite", OPT_COMPOSITE, &composite),
        SY_CLI_OPT_CODE("frames", OPT_FRAMES, true), SY_CLI_OPT_CODE("fps", OPT_FPS, true), /* a sequence */
        SY_CLI_OPT_FLAG("resume", OPT_RESUME, &resume),
        SY_CLI_OPT_UINT("repeat", OPT_REPEAT, &clo.frames, 1, 100000000u), /* cluster: frames through the same window */
        SY_CLI_OPT_UINT("max-memory", OPT_MAX_MEMORY, &max_memory_mb, 1, 1u << 30),
        SY_CLI_OPT_CODE("at", OPT_AT, true), SY_CLI_OPT_CODE("clip", OPT_CLIP, true), /* the scene clock */
        SY_CLI_OPT_CODE("shutter", OPT_SHUTTER, true), SY_CLI_OPT_FLAG("motion-blur", OPT_MOTION_BLUR, &motion_blur),
        SY_CLI_OPT_UINT("shutter-samples", OPT_SHUTTER_SAMPLES, &shutter.samples, 1, SY_SHUTTER_SAMPLES_MAX),
        SY_CLI_OPT_UINT("shutter-steps", OPT_SHUTTER_STEPS, &shutter_steps, 2, SY_MOTION_STEPS_MAX),
        SY_CLI_OPT_CODE("clip-cap", OPT_CLIP_CAP, true), /* section caps (with --clip A,B,C,D) */
        SY_CLI_OPT_FLAG("sub-frames", OPT_SUB_FRAMES, &sub_frames)};
    sy_cli_parser p = {SY_CLI_ARGS("render", argc, argv, opts), .w = &w, .h = &h, .min_size = 1, .cluster = true,
                       .view = true};
    int c;
    while ((c = sy_cli_parse(&p)) != -1) {
        switch (c) {
        case OPT_STOP: return p.status;
        case OPT_TONEMAP:
            if (!strcmp(optarg, "aces")) oo.png.tonemap = SY_TONEMAP_ACES;
            else if (!strcmp(optarg, "reinhard")) oo.png.tonemap = SY_TONEMAP_REINHARD;
            else if (!strcmp(optarg, "clamp")) oo.png.tonemap = SY_TONEMAP_CLAMP;
            else return sy_cli_bad_value("--tonemap", optarg);
            break;
        case OPT_STEREO:
            if (sy_stereo_mode_parse(optarg, &spec.stereo, &perr) != SY_OK) return sy_cli_fail(&perr);
            break;
        case OPT_FRAMES:
            if (!strchr(optarg, ':')) {
                fprintf(stderr, "sy render: error: --frames %s: a sequence is --frames A:B[:STEP] (frame numbers); "
                                "the cluster's repeat count is --repeat N\n", optarg);
                return 2;
            }
            if (!parse_frame_range(optarg, &fa, &fb, &fstep)) return sy_cli_bad_value("--frames", optarg);
            seq = true;
            break;
        case OPT_FPS:
            if (!sy_cli_parse_double(optarg, 1e-3, 1e6, &fps)) return sy_cli_bad_value("--fps", optarg);
            fps_given = true;
            break;
        case OPT_AT: /* seconds on the scene clock: finite, from 0 */
            if (!sy_cli_parse_double(optarg, 0.0, 1e9, &at)) return sy_cli_bad_value("--at", optarg);
            at_given = true;
            break;
        case OPT_SHUTTER: { /* OPEN,CLOSE or S: seconds after the frame's time (sy_shutter_parse) */
            sy_error se = {0};
            if (sy_shutter_parse(optarg, &shutter, &se) != SY_OK) {
                fprintf(stderr, "sy render: error: --shutter: %s\n", se.message);
                return 2;
            }
            shutter_given = true;
            break;
        }
        case OPT_CLIP: /* A,B,C,D (a comma): a section plane; else an animation clip */
            if (!sy_cli_is_clip_plane(optarg)) clip = optarg;
            else if (sy_cli_add_clip_plane(optarg, spec.clip_planes, &spec.clip_count)) return 2;
            break;
        case OPT_CLIP_CAP:
            if (sy_cli_parse_cap_color(optarg, spec.clip_cap_color)) return 2;
            spec.clip_cap = true;
            break;
        default: /* --cluster ... (sy_cluster_cli.c) */
            if (!sy_cluster_cli_getopt(c, optarg, &clo)) return sy_cli_bad_value(sy_cli_option_name(p.lo, c), optarg);
        }
    }
    const bool progressive_opts = po.spp || po.time_budget > 0 || po.aov; /* --spp / --time / --aov given */
    for (; optind < argc; ++optind) {
        if (scene) return sy_cli_usage_of("render", "one SCENE at a time");
        scene = argv[optind];
    }
    if (clo.cluster && !strcmp(clo.cluster, "mpi")) { /* mpirun -np N sy render ... --cluster mpi */
        bool served = false;
        sy_error merr = {0};
        sy_result mr = sy_cluster_cli_mpi_start(&clo, &served, &merr);
        if (served) return mr == SY_OK ? 0 : sy_cli_fail(&merr); /* a server rank: rank 0 is done */
        if (mr != SY_OK) return sy_cli_fail(&merr);
    }
    if (!scene) return sy_cli_usage_of("render", "a SCENE is required");
    if ((fps_given || resume) && !seq) return sy_cli_usage_of("render", "--fps and --resume belong to --frames A:B");
    if (seq && at_given) return sy_cli_usage_of("render", "--frames sets the time of each frame; --at is one time");
    bool video = outp && sy_video_is_path(outp); /* -o anim.mp4|webm: one video of the frames */
    if (video && !seq) return sy_cli_usage_of("render", "a video (-o .mp4, .webm) needs --frames A:B");
    if (video && (resume || spec.stereo == SY_STEREO_SEPARATE || po.aov))
        return sy_cli_usage_of("render", "a video is written whole: no --resume, --stereo separate or --aov");
    if (seq && !video && (!outp || !strchr(outp, '#')))
        return sy_cli_usage_of("render", "--frames needs -o with a run of '#' for the frame number (out_####.png)");
    if (seq && clo.frames) return sy_cli_usage_of("render", "--frames and --repeat: one or the other");
    if (temporal && !seq) return sy_cli_usage_of("render", "--temporal belongs to --frames A:B (a moving camera's frames)");
    if (seq && strlen(outp) > 4000) return sy_cli_usage_of("render", "-o: the frames' path is too long");
    if (motion_blur && shutter_given) return sy_cli_usage_of("render", "--motion-blur is --shutter 0,0.5/FPS: give one of them");
    if (shutter.samples && !shutter_given && !motion_blur)
        return sy_cli_usage_of("render", "--shutter-samples belongs to --shutter or --motion-blur");
    if (sub_frames && !shutter_given && !motion_blur)
        return sy_cli_usage_of("render", "--sub-frames belongs to --shutter or --motion-blur");
    if (shutter_steps && !shutter_given && !motion_blur)
        return sy_cli_usage_of("render", "--shutter-steps belongs to --shutter or --motion-blur");
    if (motion_blur) shutter.close = 0.5 / fps, shutter_given = true; /* a 180-degree shutter */
    if (!shutter.samples) shutter.samples = 16; /* see docs/CLI.md "Motion blur" */
    bool blur = shutter_given && sy_shutter_blurs(&shutter);
    if (blur && (clo.cluster || po.aov || temporal))
        return sy_cli_usage_of("render", "--shutter / --motion-blur: a local render without --cluster, --aov or --temporal");
    if (shutter_given && !blur) at += shutter.open; /* an instant: the scene at the shutter's time */
    bool frames_mode = clo.cluster && clo.mode && !strcmp(clo.mode, "frames");
    if (frames_mode && !seq)
        return sy_cli_usage_of("render", "--cluster-mode frames renders sequences: give --frames A:B and -o out_####.exr");
    if (frames_mode && (video || spec.stereo != SY_STEREO_NONE || overlay || po.aov || po.time_budget > 0 || filter ||
                        threshold))
        return sy_cli_usage_of("render", "--cluster-mode frames writes each frame as an image of a mono render at fixed "
                                         "samples: no video, --stereo, --overlay, --aov, --time, --filter or --threshold");
    sy_error err = {0};
    char in_folder[4096], auto_out[1024];
    struct stat sst;
    if (stat(scene, &sst) == 0 && S_ISDIR(sst.st_mode)) { /* sy render DIR: its one scene file */
        if (scene_in_folder(scene, in_folder, sizeof in_folder, &err) != SY_OK) return sy_cli_fail(&err);
        scene = in_folder;
    }
    if (!backend && !(backend = sy_cli_default_backend(&err))) return sy_cli_fail(&err);
    if (!outp) { /* STEM.png here; the line that reports the render names it */
        default_output(scene, auto_out, sizeof auto_out);
        outp = auto_out;
    }
    char gl_params[256];
    if (gl_provider) params = render_gl_params(params, gl_provider, gl_params, sizeof gl_params);
    char filter_params[512];
    if (filter || threshold) params = render_filter_params(params, filter, threshold, filter_params, sizeof filter_params);
    char temporal_params[540]; /* filter_params + ",temporal=1" */
    if (temporal) { /* --temporal: the path tracer's temporal=1 (a frame whose camera moved reuses the last) */
        snprintf(temporal_params, sizeof temporal_params, "%s%stemporal=1", params ? params : "",
                 params && *params ? "," : "");
        params = temporal_params;
    }
    char memory_params[600];
    if (max_memory_mb) { /* --max-memory MB: the back-end's declared memory limit (max_memory_mb) */
        const sy_mediator_class *mc = sy_mediator_find(backend);
        if (mc && !sy_param_find(&mc->param_table, "max_memory_mb")) {
            sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "--max-memory: back-end '%s' has no memory limit (no max_memory_mb "
                         "parameter)", backend);
            return sy_cli_fail(&err);
        }
        snprintf(memory_params, sizeof memory_params, "%s%smax_memory_mb=%u", params ? params : "",
                 params && *params ? "," : "", max_memory_mb);
        params = memory_params;
    }
    /* the output's folder must take a file before anything is loaded or rendered (an unwritable
     * one was found only after the render): a temporary file is created there and removed */
    sy_atomic_file probe = {0};
    if (sy_atomic_file_begin(outp, &probe, &err) != SY_OK) return sy_cli_fail(&err);
    sy_atomic_file_abort(&probe);
    sy_params given = {0};
    if (sy_params_parse(params, &given, &err) != SY_OK) { /* a key twice ("spp=1,spp=2"): a usage error */
        sy_log(SY_LOG_ERROR, "sy", NULL, "%s", err.message);
        return 2;
    }
    if (video && sy_video_check(outp, &err) != SY_OK) return sy_cli_fail(&err); /* built without video */
    if (!video && !sy_cli_is_output_path(outp)) { /* before any loading or rendering */
        sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "%s: output must end in " OUTPUT_KINDS, outp);
        return sy_cli_fail(&err);
    }
    /* --cluster: the main viewport's back-end becomes the cluster mediator (the servers render with
     * -b BACKEND); everything below is the same render path as a local one */
    const char *remote = backend;
    char cluster_params[1400];
    uint32_t cluster_mode = 0, cluster_servers = 0;
    if (clo.cluster && !frames_mode) {
        if (sy_cluster_cli_setup(&clo, backend, params, cluster_params, sizeof cluster_params, &cluster_mode,
                                 &cluster_servers, NULL, &err) != SY_OK)
            return sy_cli_fail(&err);
        if (cluster_mode == SY_CLUSTER_STEREO && spec.stereo == SY_STEREO_NONE) spec.stereo = SY_STEREO_SBS;
        backend = SY_MEDIATOR_CLUSTER_NAME;
        params = cluster_params;
    }
    char shown[96]; /* the back-end as reported: "whitted", or "whitted on 2 servers (sort-first)" */
    if (clo.cluster && !frames_mode)
        snprintf(shown, sizeof shown, "%s on %u server%s (%s)", remote, cluster_servers, cluster_servers == 1 ? "" : "s",
                 sy_cluster_cli_mode_name(cluster_mode));
    else snprintf(shown, sizeof shown, "%s", remote);
    const sy_mediator_class *bcls = sy_mediator_find(backend);
    sy_params bparams = {0};
    if (!bcls) {
        sy_context *none = NULL;
        sy_context_create(NULL, backend, NULL, 0, &none, &err); /* the error that lists the back-ends */
        return sy_cli_fail(&err);
    }
    if (sy_params_parse(params, &bparams, &err) != SY_OK) return sy_cli_fail(&err);
    if (sy_mediator_class_check_params(bcls, &bparams, &err) != SY_OK) { /* unknown key, bad value: usage */
        sy_log(SY_LOG_ERROR, "sy", NULL, "%s", err.message); /* --params, --filter, --threshold, --gl */
        return 2;
    }
    uint32_t caps = sy_mediator_class_caps(bcls, &bparams);
    const sy_mediator_class *rcls = sy_mediator_find(remote);
    if (spec.clip_cap && !spec.clip_count) {
        fprintf(stderr, "sy render: error: --clip-cap: caps fill the cut faces of section planes: give --clip A,B,C,D too\n");
        return 2;
    }
    if (spec.clip_count && !(caps & SY_CAP_CLIP)) {
        sy_log(SY_LOG_ERROR, "sy", NULL, "--clip: back-end %s%s cannot cut with section planes (sy backends lists those with 'clip')",
               remote, clo.cluster ? " on the cluster" : "");
        return 2;
    }
    if (temporal && !(caps & SY_CAP_FILTERS)) {
        sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "--temporal needs a back-end with display filters, such as a "
                     "local -b pathtracer (got -b %s%s)", remote, clo.cluster ? " with --cluster" : "");
        return sy_cli_fail(&err);
    }
    if ((filter || threshold) && !(caps & SY_CAP_FILTERS)) {
        sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "--filter and --threshold need a back-end with display filters, "
                     "such as a local -b pathtracer (got -b %s%s)",
                     remote, clo.cluster ? " with --cluster: its strips would be filtered apart" : "");
        return sy_cli_fail(&err);
    }
    bool progressive = (caps & SY_CAP_PROGRESSIVE) != 0;
    /* a cluster in sort-first / balanced mode over a progressive back-end: --spp is the samples of each request */
    bool remote_spp = clo.cluster && !progressive && rcls && (rcls->caps & SY_CAP_PROGRESSIVE) && po.spp && !po.aov &&
                      !(po.time_budget > 0);
    if (progressive_opts && !progressive && !remote_spp) {
        sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "--spp, --time and --aov need a progressive back-end; '%s'%s is not",
                     remote, clo.cluster ? " on the cluster in this mode (cooperative is)" : "");
        return sy_cli_fail(&err);
    }
    if (po.aov && !(caps & SY_CAP_AOVS)) {
        sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "--aov: back-end %s%s keeps no feature buffers", remote,
                     clo.cluster ? " on the cluster" : "");
        return sy_cli_fail(&err);
    }
    if (po.aov && (!sy_cli_ends_with(outp, ".exr") || spec.stereo != SY_STEREO_NONE || overlay)) {
        sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "%s: --aov needs an .exr output of a local mono render without overlay",
                     outp);
        return sy_cli_fail(&err);
    }
    loaded ld;
    if (sy_cli_load(scene, camera, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
    /* the scene clock (sy_anim.h): after the load, so the camera framed the loaded pose and the same
     * camera shows every time; the moved nodes reach every back-end (and cluster server) as changes */
    if (at_given || clip || (shutter_given && at > 0)) {
        int st = sy_cli_set_time(&ld, clip, at, &err);
        if (st) {
            sy_cli_loaded_free(&ld);
            return st == 2 ? 2 : sy_cli_fail(&err);
        }
    }
    if (blur && !sy_scene_count(ld.scene, SY_TYPE_ANIMATION)) {
        sy_log(SY_LOG_NOTE, "sy", NULL, "--shutter: the scene has no animations; nothing moves, so one render");
        blur = false;
    }
    sy_cli_default_size(&ld, &w, &h);
    if (ld.is_x3d) sy_cli_fit_x3d_cameras(&ld, w, h); /* X3D fieldOfView is the smaller side's angle */
    sy_context_pool *pool = NULL;
    sy_layer img = {0}, img_right = {0};
    double secs = 0;
    spec.backend = backend;
    spec.params = params;
    spec.root = ld.root;
    spec.camera = ld.camera;
    spec.background = ld.background;
    if (frames_mode) { /* the servers render the frames; nothing is rendered here */
        uint32_t fsamples = progressive ? (po.spp ? po.spp : 64) : po.spp;
        int fst = render_frames_mode(&ld, &spec, &clo, remote, params, w, h, fsamples, clip, fa, fb, fstep, fps, resume,
                                     outp, &oo, scene);
        sy_cli_loaded_free(&ld);
        return fst;
    }
    sy_result r = overlay ? sy_cli_add_overlay(&ld, overlay, composite, &spec, &err) : SY_OK;
    if (r == SY_OK) r = sy_context_pool_create(&pool, &err);
    uint64_t samples = 0;
    bool interrupted = false;
    /* --frames A:B[:STEP]: every frame through the same loaded scene, pool and window (the scene
     * clock moves nodes; the back-ends sync the changes); one frame otherwise */
    const char *pattern = outp;
    char frame_out[4096];
    uint32_t nseq = seq ? (fb - fa) / fstep + 1 : 1, written = 0, skipped = 0;
    double seq_t0 = sy_time_now();
    bool seq_tty = seq && sy_is_terminal(2);
    sy_video *vid = NULL; /* -o anim.mp4|webm: opened at the first frame */
    uint8_t *vid_rgba = NULL;
    double frame_time = at; /* the scene time of this image (motion blur opens its shutter there) */
    for (uint32_t fi = 0; fi < nseq && r == SY_OK && !interrupted; ++fi) {
    if (seq) {
        uint32_t frame = fa + fi * fstep;
        frame_time = frame / fps;
        if (!video) frame_path(pattern, frame, frame_out, sizeof frame_out);
        outp = video ? pattern : frame_out;
        struct stat ost;
        if (resume && stat(outp, &ost) == 0) {
            skipped++;
            continue;
        }
        /* a scene without animations: the note (or --clip's usage error) once */
        bool once = written + skipped && !sy_scene_count(ld.scene, SY_TYPE_ANIMATION);
        int st = once ? 0 : sy_cli_set_time(&ld, clip, frame / fps, &err);
        if (st) {
            sy_context_pool_destroy(pool);
            sy_cli_loaded_free(&ld);
            return st == 2 ? 2 : sy_cli_fail(&err);
        }
        oo.attr_count = 0;
        /* every frame starts its own accumulation (sample 0, the same seed), moved or not: frame k is
         * what `sy render --at T` of a fresh load renders, bit for bit (sy_context_restart) */
        sy_params rp;
        sy_context *rc = NULL;
        sy_error ignore = {0};
        if (sy_params_parse(spec.params, &rp, &ignore) == SY_OK &&
            sy_context_pool_get(pool, ld.scene, spec.backend, &rp, ld.root.id, &rc, &ignore) == SY_OK)
            sy_context_restart(rc);
    }
    progress_state ps = {shown, sy_time_now(), 0, sy_is_terminal(2) && !seq, false};
    sy_window_render_opts ro = {.progress = sy_cli_progress_cb, .progress_user = &ps, .seed = po.seed};
    double t0 = sy_time_now();
    sy_context *pctx = NULL;
    char samples_str[32], secs_str[32];
    bool blur_native = false; /* the back-end interpolated the motion per ray (SY_CAP_MOTION) */
    if (r == SY_OK && blur) {
        if (progressive)
            sy_signals_set_graceful("finishing the current pass, then writing the image accumulated so far");
        r = sy_cli_render_blurred(&ld, clip, frame_time, &shutter, &spec, w, h, progressive ? &po : NULL, pool, &ro, &img,
                           &img_right, &secs, &samples, &pctx, sub_frames, shutter_steps, &blur_native, &err);
        t0 = sy_time_now() - secs;
        interrupted = sy_signals_interrupted();
    } else if (r == SY_OK && progressive) {
        /* the first Ctrl-C ends the render after the pass in progress and keeps its image */
        sy_signals_set_graceful("finishing the current pass, then writing the image accumulated so far");
        r = sy_cli_render_progressive(&ld, &spec, w, h, &po, pool, &img, &img_right, &secs, &samples, &pctx, &err);
        t0 = sy_time_now() - secs;
        interrupted = sy_signals_interrupted();
    } else if (r == SY_OK && clo.cluster) {
        /* --frames N: N frames through the same window (balanced strips adapt from frame to frame) */
        if (remote_spp) ro.sample_count = po.spp;
        uint32_t frames = clo.frames ? clo.frames : 1;
        for (uint32_t i = 0; i < frames && r == SY_OK; ++i) {
            sy_layer_destroy(&img);
            sy_layer_destroy(&img_right);
            r = sy_compose_render(ld.scene, pool, &spec, w, h, &ro, &img, &img_right, &err);
            if (r == SY_OK) cluster_report(ld.scene, pool, &spec, i, cluster_servers);
        }
    } else if (r == SY_OK) r = sy_compose_render(ld.scene, pool, &spec, w, h, &ro, &img, &img_right, &err);
    secs = sy_time_now() - t0;
    /* the image's metadata (EXR header attributes, PNG text chunks): what made it and how */
    sy_exr_attribute attrs[14];
    sy_png_text texts[14];
    char renderer[64], size_str[48], camera_str[256], matrix_str[16 * 18] = "", proj_str[64] = "", shutter_str[96] = "";
    if (r == SY_OK) {
        if (blur && blur_native) /* one render, each pixel sample at its own time (SY_CAP_MOTION) */
            snprintf(shutter_str, sizeof shutter_str, "%.9g,%.9g s after %.9g s, a time per pixel sample", shutter.open,
                     shutter.close, frame_time);
        else if (blur)
            snprintf(shutter_str, sizeof shutter_str, "%.9g,%.9g s after %.9g s, %u time samples", shutter.open,
                     shutter.close, frame_time, shutter.samples);
        if (!progressive && !blur) { /* what the main back-end accumulated (a single pass: 1) */
            sy_params mp;
            sy_context *mc = NULL;
            sy_mediator_stats ms = {0};
            sy_error ignore = {0};
            if (sy_params_parse(spec.params, &mp, &ignore) == SY_OK &&
                sy_context_pool_get(pool, ld.scene, spec.backend, &mp, ld.root.id, &mc, &ignore) == SY_OK)
                sy_context_stats(mc, &ms);
            samples = ms.samples;
        }
        snprintf(renderer, sizeof renderer, "Switchyard %s", sy_version());
        snprintf(samples_str, sizeof samples_str, "%llu", (unsigned long long)samples);
        snprintf(secs_str, sizeof secs_str, "%.3f", secs);
        snprintf(size_str, sizeof size_str, "%ux%u%s", w, h,
                 spec.stereo == SY_STEREO_NONE ? "" : spec.stereo == SY_STEREO_SEPARATE ? " per eye" : " per eye, stereo");
        sy_mat4 cm = sy_mat4_identity();
        bool has_cam = ld.camera.id && sy_node_world_matrix(ld.scene, ld.camera, &cm, NULL) == SY_OK;
        if (has_cam)
            snprintf(camera_str, sizeof camera_str, "%s at (%g, %g, %g) looking along (%g, %g, %g)",
                     sy_cli_load_opts.view.look_at ? "the --look-at camera" : sy_cli_load_opts.view.orbit ? "the --orbit camera"
                     : camera ? camera : "the scene's first camera", (double)cm.m[12], (double)cm.m[13], (double)cm.m[14],
                     (double)-cm.m[8], (double)-cm.m[9], (double)-cm.m[10]);
        else snprintf(camera_str, sizeof camera_str, "a view framing the scene's bounds");
        /* the exact view, for a renderer that is to see the same (tests/cycles/materials.sh): the
         * camera-to-world matrix (column-major, as glTF) and the projection's vertical extent */
        const sy_node_data *cnd = has_cam ? sy_node_get(ld.scene, ld.camera) : NULL;
        const sy_camera_data *ccd = cnd ? sy_camera_get(ld.scene, cnd->camera) : NULL;
        if (ccd) {
            for (int k = 0, n = 0; k < 16; ++k)
                n += snprintf(matrix_str + n, sizeof matrix_str - (size_t)n, "%s%.9g", k ? " " : "", (double)cm.m[k]);
            if (ccd->projection == SY_PROJECTION_ORTHOGRAPHIC) snprintf(proj_str, sizeof proj_str, "orthographic ymag %.9g", (double)ccd->ymag);
            else snprintf(proj_str, sizeof proj_str, "perspective yfov %.9g", (double)ccd->yfov);
        }
        const char *kv[][2] = {{"sy:renderer", renderer}, {"sy:backend", shown}, {"sy:params", params},
                               {"sy:camera", camera_str}, {"sy:camera_to_world", matrix_str}, {"sy:projection", proj_str},
                               {"sy:size", size_str}, {"sy:samples", samples_str},
                               {"sy:seconds", secs_str}, {"sy:source", scene},
                               {"sy:shutter", shutter_str}, {"sy:interrupted", interrupted ? "1" : NULL}};
        _Static_assert(sizeof kv / sizeof kv[0] <= sizeof attrs / sizeof attrs[0], "room for every attribute");
        sy_cli_out_metadata(&oo, kv, sizeof kv / sizeof kv[0], attrs, texts);
    }
    bool say = !seq; /* a sequence: progress on a terminal, one line at the end */
    if (r == SY_OK && clo.cluster && cluster_mode == SY_CLUSTER_MULTI_DISPLAY) {
        printf("multi-display: %ux%u wall presented by the servers, %s, %.3f s\n", w, h, remote, secs);
    } else if (r == SY_OK) {
        size_t bad = sy_layer_count_nonfinite(&img) + (img_right.rgba ? sy_layer_count_nonfinite(&img_right) : 0);
        if (bad) sy_log(SY_LOG_WARNING, "sy", outp, "%zu pixels are not finite", bad);
        if (spec.stereo == SY_STEREO_SEPARATE) {
            char lp[4096], rp[4096];
            r = eye_paths(outp, lp, rp, sizeof lp, &err);
            if (r == SY_OK) r = sy_cli_write_image(lp, &img, &oo, &err);
            if (r == SY_OK) r = sy_cli_write_image(rp, &img_right, &oo, &err);
            if (r == SY_OK && say) printf("%s, %s: %ux%u per eye, %s, %.3f s\n", lp, rp, w, h, shown, secs);
        } else {
            if (video) { /* tone mapped as for PNG, over black */
                if (!vid && (r = sy_video_open(outp, img.width, img.height, fps, &vid, &err)) == SY_OK &&
                    !(vid_rgba = malloc((size_t)img.width * img.height * 4)))
                    r = sy_error_set(&err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", outp);
                if (r == SY_OK) {
                    sy_png_encode_over_black(img.rgba, (size_t)img.width * img.height, &oo.png, vid_rgba);
                    r = sy_video_add(vid, vid_rgba, &err);
                }
            } else r = po.aov ? write_aov_exr(outp, pctx, &oo, &err) : sy_cli_write_image(outp, &img, &oo, &err);
            if (r == SY_OK && !say) {
            } else if (r == SY_OK && progressive)
                printf("%s: %ux%u, %s, %llu samples per pixel, %.3f s (%.2f samples/s)%s\n", outp, img.width,
                       img.height, shown, (unsigned long long)samples, secs,
                       secs > 0 ? (double)samples / secs : 0.0, interrupted ? ", interrupted" : "");
            else if (r == SY_OK) printf("%s: %ux%u, %s, %.3f s\n", outp, img.width, img.height, shown, secs);
            if (r == SY_OK && say && progressive && filter && pctx) { /* the display filter's report (issue 7) */
                sy_filter_info fi;
                sy_context_filter_info(pctx, &fi);
                /* the pass count and blend mean something for the filters that pass on a schedule
                 * (pixel: the blend factor, radiance: the share in correction); the others filter
                 * every frame (last_pass_samples 0) */
                char pass[96] = "";
                if (fi.last_pass_samples)
                    snprintf(pass, sizeof pass, ", last pass at %u spp, mean blend %.3f", fi.last_pass_samples,
                             fi.mean_blend);
                printf("filter %s: threshold %g, last filter %.1f ms%s, NaN/Inf: %llu pixels, %llu samples\n", fi.name,
                       (double)fi.threshold, fi.seconds * 1e3, pass, (unsigned long long)fi.nonfinite_pixels,
                       (unsigned long long)fi.nonfinite_samples);
            }
        }
    }
    sy_layer_destroy(&img);
    sy_layer_destroy(&img_right);
    if (r == SY_OK && seq) {
        written++;
        double el = sy_time_now() - seq_t0, per = el / written;
        uint32_t left = nseq - fi - 1;
        if (seq_tty)
            fprintf(stderr, "\rframe %u (%u of %u), %.1f frames/min, ETA %.0f s   ", fa + fi * fstep, fi + 1, nseq,
                    per > 0 ? 60.0 / per : 0.0, per * left), fflush(stderr);
    }
    interrupted = interrupted || sy_signals_interrupted();
    } /* the frames */
    if (seq_tty) fprintf(stderr, "\r%*s\r", 78, "");
    if (vid && r == SY_OK && !interrupted) r = sy_video_finish(vid, NULL, &err);
    else sy_video_abort(vid); /* an error or an interrupt: no half video */
    free(vid_rgba);
    if (r == SY_OK && seq)
        printf("%s: frames %u..%u step %u at %g fps: %u written, %u skipped (existing), %ux%u, %s, %.3f s\n", pattern, fa,
               fb, fstep, fps, written, skipped, w, h, shown, sy_time_now() - seq_t0);
    sy_context_pool_destroy(pool);
    sy_cli_loaded_free(&ld);
    interrupted = interrupted || (progressive && sy_signals_interrupted()); /* also while writing */
    if (r == SY_OK && interrupted) {
        fprintf(stderr, "sy render: interrupted: wrote the image of %llu samples per pixel (sy:samples in the EXR "
                        "header); exit status 130\n", (unsigned long long)samples);
        return 130;
    }
    return r == SY_OK ? 0 : sy_cli_fail(&err);
}
