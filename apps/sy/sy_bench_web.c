/* sy_bench_web.c — `sy bench web`: input event to the frame that answers it, on loopback (see
 * sy_bench_web.h). The client is apps/web/sy_web_client.h (libwebsockets), the server sy_web in this
 * process, its render loop on a thread of its own (the only one touching the scene meanwhile). */
#include "sy_bench_web.h"

#include "sy_mediator.h"
#include "sy_web_client.h"
#include "sy_web_thread.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double pct(const double *v, uint32_t n, double p)
{
    uint32_t i = (uint32_t)(p * (n - 1) + 0.5);
    return v[i < n ? i : n - 1];
}

sy_result sy_bench_web(const sy_web_desc *desc, uint32_t width, uint32_t height, uint32_t repeats, sy_error *err)
{
    sy_web_desc d = *desc;
    d.listen = "127.0.0.1:0";
    if (!d.backend) d.backend = sy_mediator_default_name(); /* named in the report; "": sy_web_create says so */
    sy_web *web = NULL;
    sy_web_thread *th = NULL;
    sy_result r = sy_web_create(&d, &web, err);
    if (r) return r;
    if ((r = sy_web_thread_start(web, &th, err))) {
        sy_web_destroy(web);
        return r;
    }
    sy_web_client *c = NULL;
    sy_web_client_opts o = {.host = "127.0.0.1", .port = sy_web_port(web), .path = "/ws"};
    double *lat = calloc(repeats, sizeof *lat), *render = calloc(repeats, sizeof *render),
           *over = calloc(repeats, sizeof *over), *wid = calloc(repeats, sizeof *wid);
    if (!lat || !render || !over || !wid) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench web: out of memory");
    if (r == SY_OK) r = sy_web_client_connect(&o, 5000, &c, err);
    char m[128];
    snprintf(m, sizeof m, "{\"t\":\"size\",\"w\":%u,\"h\":%u,\"v\":3}", width, height);
    if (r == SY_OK) r = sy_web_client_send(c, m, err);
    sy_web_frame_info fi = {0};
    /* the first frame at the asked size (a progressive back-end keeps sending: take the newest) */
    double end = sy_time_now() + 30;
    while (r == SY_OK && (fi.width != width || fi.height != height) && sy_time_now() < end)
        r = sy_web_client_next_frame(c, 30000, &fi, NULL, NULL, err);
    uint32_t done = 0;
    for (uint32_t i = 0; r == SY_OK && i < repeats; ++i) {
        uint64_t id = i + 1;
        snprintf(m, sizeof m, "{\"t\":\"drag\",\"dx\":%d,\"dy\":0,\"id\":%llu}", (i & 1) ? -4 : 4, (unsigned long long)id);
        double t0 = sy_time_now();
        r = sy_web_client_send(c, m, err);
        while (r == SY_OK) {
            r = sy_web_client_next_frame(c, 30000, &fi, NULL, NULL, err);
            if (r == SY_OK && fi.input_id >= id) break;
        }
        if (r != SY_OK) break;
        lat[done] = (sy_time_now() - t0) * 1e3;
        render[done] = fi.render_ms;
        wid[done] = fi.width;
        over[done] = lat[done] - fi.render_ms; /* what the stream adds: input, JPEG, socket, wake-ups */
        done++;
        if (sy_is_terminal(1)) fprintf(stdout, "\r%u/%u", done, repeats), fflush(stdout);
    }
    if (sy_is_terminal(1)) fprintf(stdout, "\r");
    sy_web_client_close(c);
    sy_error run_err = {0};
    sy_result run_r = sy_web_thread_join(th, &run_err);
    if (r == SY_OK && run_r != SY_OK) *err = run_err, r = run_r;
    if (r == SY_OK && done) {
        qsort(lat, done, sizeof *lat, cmp_double);
        qsort(render, done, sizeof *render, cmp_double);
        qsort(over, done, sizeof *over, cmp_double);
        qsort(wid, done, sizeof *wid, cmp_double);
        printf("sy bench web: %s, %ux%u frames, %u drags on loopback (input sent -> first frame answering it "
               "received)\n",
               d.backend, width, height, done);
        printf("  latency  p50 %.2f ms  p95 %.2f ms  (min %.2f, max %.2f)\n", pct(lat, done, 0.5), pct(lat, done, 0.95),
               lat[0], lat[done - 1]);
        printf("  answering frames (the governor's moving frames): median width %.0f of %u (min %.0f, max %.0f)\n",
               pct(wid, done, 0.5), width, wid[0], wid[done - 1]);
        printf("  server render per frame: median %.2f ms; latency / render = %.2fx\n", pct(render, done, 0.5),
               pct(render, done, 0.5) > 0 ? pct(lat, done, 0.5) / pct(render, done, 0.5) : 0.0);
        printf("  stream overhead (latency - that frame's render)  p50 %.2f ms  p95 %.2f ms  (min %.2f, max %.2f)\n",
               pct(over, done, 0.5), pct(over, done, 0.95), over[0], over[done - 1]);
    }
    free(lat);
    free(render);
    free(over);
    free(wid);
    sy_web_destroy(web);
    return r;
}
