/* test_web_scene.c — test_web's scene-message parts (test_web.c lists what each checks):
 * web_messages (the page's scene messages parsed as documented), web_scene (tree, pick,
 * visibility, planes and caps, environment, exposure through a viewer), web_readonly (a read-only
 * server refuses edits), web_timeline (the scene clock: range, times, play and pause). */
#include "web_test.h"

#include <cjson/cJSON.h>
/* >>the page's scene messages (pick, visibility, selection, planes, tree) */
static int parse_ok(const char *m, sy_web_input *in)
{
    sy_error err = {0};
    sy_result r = sy_web_parse_input(m, strlen(m), in, &err);
    if (r != SY_OK) fprintf(stderr, "refused %s: %s\n", m, err.message);
    return r == SY_OK;
}

int test_messages(void)
{
    sy_web_input in;
    sy_error err = {0};
    CHECK(parse_ok("{\"t\":\"pick\",\"x\":0.25,\"y\":0.75,\"select\":true,\"seq\":9}", &in));
    CHECK(in.type == SY_WEB_INPUT_PICK && in.a == 0.25 && in.b == 0.75 && in.on && in.seq == 9);
    CHECK(parse_ok("{\"t\":\"pick\",\"x\":0,\"y\":0}", &in) && !in.on && in.seq == 0);
    CHECK(parse_ok("{\"t\":\"visible\",\"node\":12,\"on\":false}", &in) && in.type == SY_WEB_INPUT_VISIBLE && in.node == 12 && !in.on);
    CHECK(parse_ok("{\"t\":\"select\",\"node\":0,\"on\":false}", &in) && in.type == SY_WEB_INPUT_SELECT && in.node == 0);
    CHECK(parse_ok("{\"t\":\"isolate\",\"node\":3}", &in) && in.type == SY_WEB_INPUT_ISOLATE && in.node == 3);
    CHECK(parse_ok("{\"t\":\"clip\",\"planes\":[[1,0,0,-0.5],[0,-1,0,2]]}", &in) && in.type == SY_WEB_INPUT_CLIP &&
          in.plane_count == 2 && in.planes[0][3] == -0.5f && in.planes[1][1] == -1.0f);
    CHECK(parse_ok("{\"t\":\"clip\",\"planes\":[]}", &in) && in.plane_count == 0 && in.cap == SY_WEB_CAP_KEEP);
    /* the caps: [r, g, b] on, false / null off, absent as they are */
    CHECK(parse_ok("{\"t\":\"clip\",\"planes\":[[1,0,0,0]],\"cap\":[1,0.25,0]}", &in) && in.cap == SY_WEB_CAP_ON &&
          in.cap_rgb[0] == 1.0f && in.cap_rgb[1] == 0.25f && in.cap_rgb[2] == 0.0f);
    CHECK(parse_ok("{\"t\":\"clip\",\"planes\":[],\"cap\":false}", &in) && in.cap == SY_WEB_CAP_OFF);
    CHECK(parse_ok("{\"t\":\"clip\",\"planes\":[],\"cap\":null}", &in) && in.cap == SY_WEB_CAP_OFF);
    CHECK(parse_ok("{\"t\":\"tree\",\"seq\":4}", &in) && in.type == SY_WEB_INPUT_TREE && in.seq == 4 && !in.node && !in.offset);
    CHECK(parse_ok("{\"t\":\"tree\",\"node\":7,\"offset\":512}", &in) && in.node == 7 && in.offset == 512);
    CHECK(parse_ok("{\"t\":\"exposure\",\"stops\":-1.5}", &in) && in.type == SY_WEB_INPUT_EXPOSURE && in.a == -1.5);
    CHECK(parse_ok("{\"t\":\"environment\",\"name\":\"studio\"}", &in) && in.type == SY_WEB_INPUT_ENVIRONMENT &&
          !strcmp(in.filter, "studio") && sy_web_input_changes_scene(&in));
    CHECK(parse_ok("{\"t\":\"filter\",\"name\":\"atrous\"}", &in) && in.type == SY_WEB_INPUT_FILTER && !strcmp(in.filter, "atrous"));
    /* what a read-only server refuses; the camera, picks and the tree it answers */
    CHECK(sy_web_input_changes_scene(&in));
    CHECK(parse_ok("{\"t\":\"key\",\"k\":\"2\"}", &in) && sy_web_input_changes_scene(&in));
    CHECK(parse_ok("{\"t\":\"key\",\"k\":\"r\"}", &in) && !sy_web_input_changes_scene(&in));
    CHECK(parse_ok("{\"t\":\"pick\",\"x\":0.5,\"y\":0.5,\"select\":true}", &in) && !sy_web_input_changes_scene(&in));
    CHECK(parse_ok("{\"t\":\"tree\"}", &in) && !sy_web_input_changes_scene(&in));
    CHECK(parse_ok("{\"t\":\"drag\",\"dx\":1,\"dy\":2}", &in) && !sy_web_input_changes_scene(&in));
    /* frames rendered ahead: a drag's optional lead, the lead alone (the camera, allowed read-only) */
    CHECK(in.lead[0] == 0 && in.lead[1] == 0);
    CHECK(parse_ok("{\"t\":\"drag\",\"dx\":1,\"dy\":2,\"b\":2,\"lead\":[7.5,-3]}", &in) && in.button == 2 &&
          in.lead[0] == 7.5 && in.lead[1] == -3);
    CHECK(parse_ok("{\"t\":\"lead\",\"lead\":[0,0]}", &in) && in.type == SY_WEB_INPUT_LEAD && in.button == 0 &&
          !sy_web_input_changes_scene(&in));
    CHECK(parse_ok("{\"t\":\"lead\",\"lead\":[-4096,12],\"b\":1}", &in) && in.lead[0] == -4096 && in.button == 1);
    const char *bad_lead[] = {"{\"t\":\"lead\"}", "{\"t\":\"lead\",\"lead\":[1]}", "{\"t\":\"lead\",\"lead\":[1,2,3]}",
                              "{\"t\":\"lead\",\"lead\":[4097,0]}", "{\"t\":\"lead\",\"lead\":[1,null]}",
                              "{\"t\":\"lead\",\"lead\":{\"dx\":1}}", "{\"t\":\"lead\",\"lead\":[0,0],\"b\":3}",
                              "{\"t\":\"drag\",\"dx\":1,\"dy\":0,\"lead\":\"ahead\"}",
                              "{\"t\":\"drag\",\"dx\":1,\"dy\":0,\"lead\":[1e400,0]}"};
    for (size_t i = 0; i < sizeof bad_lead / sizeof bad_lead[0]; ++i)
        CHECK_MSG(sy_web_parse_input(bad_lead[i], strlen(bad_lead[i]), &in, &err) != SY_OK, "accepted %s", bad_lead[i]);
    /* the timeline: a view change (a read-only page may move the clock); the range is the server's */
    CHECK(parse_ok("{\"t\":\"time\",\"s\":1.25}", &in) && in.type == SY_WEB_INPUT_TIME && in.a == 1.25 &&
          !sy_web_input_changes_scene(&in));
    CHECK(parse_ok("{\"t\":\"time\",\"s\":-3}", &in) && in.a == -3);
    CHECK(parse_ok("{\"t\":\"play\",\"on\":true}", &in) && in.type == SY_WEB_INPUT_PLAY && in.on &&
          !sy_web_input_changes_scene(&in));
    CHECK(parse_ok("{\"t\":\"play\",\"on\":false}", &in) && !in.on);
    CHECK(parse_ok("{\"t\":\"anim\",\"clip\":3}", &in) && in.type == SY_WEB_INPUT_ANIM && in.a == 3 &&
          !sy_web_input_changes_scene(&in));
    CHECK(parse_ok("{\"t\":\"anim\",\"clip\":-1}", &in) && in.a == -1);
    /* saved views: a recall is the camera (a read-only page may), a save changes what every page shares */
    CHECK(parse_ok("{\"t\":\"view\",\"n\":3}", &in) && in.type == SY_WEB_INPUT_VIEW && in.slot == 3 && !in.on &&
          !sy_web_input_changes_scene(&in));
    CHECK(parse_ok("{\"t\":\"view\",\"n\":9,\"save\":true,\"id\":4}", &in) && in.slot == 9 && in.on &&
          sy_web_input_changes_scene(&in));
    const char *bad[] = {
        "{\"t\":\"view\"}",                            /* no slot */
        "{\"t\":\"view\",\"n\":0}",                  /* slots 1..9 */
        "{\"t\":\"view\",\"n\":10}",
        "{\"t\":\"view\",\"n\":2.5}",
        "{\"t\":\"view\",\"n\":\"2\"}",
        "{\"t\":\"view\",\"n\":2,\"save\":1}",
                "{\"t\":\"anim\"}",                            /* no clip */
        "{\"t\":\"anim\",\"clip\":-2}",              /* -1 is every clip, nothing below */
        "{\"t\":\"anim\",\"clip\":1.5}",
        "{\"t\":\"anim\",\"clip\":\"Walk\"}",      /* an index, not a name */
        "{\"t\":\"anim\",\"clip\":70000}",           /* beyond SY_WEB_CLIP_MAX */
        "{\"t\":\"time\"}",                            /* no time */
        "{\"t\":\"time\",\"s\":null}",                 /* JSON's NaN (JSON.stringify(NaN)) */
        "{\"t\":\"time\",\"s\":1e400}",                /* infinite */
        "{\"t\":\"time\",\"s\":2e9}",                  /* beyond SY_WEB_TIME_MAX */
        "{\"t\":\"time\",\"s\":\"1\"}",
        "{\"t\":\"play\"}",
        "{\"t\":\"tree\",\"node\":1.5}",            /* node and offset: whole numbers */
        "{\"t\":\"tree\",\"node\":-1}",
        "{\"t\":\"tree\",\"offset\":-2}",
        "{\"t\":\"tree\",\"offset\":\"3\"}",
        "{\"t\":\"play\",\"on\":1}",
        "{\"t\":\"pick\",\"x\":1,\"y\":0.5}",           /* outside: [0, 1) */
        "{\"t\":\"pick\",\"x\":-0.01,\"y\":0.5}",
        "{\"t\":\"pick\",\"x\":0.5}",
        "{\"t\":\"pick\",\"x\":0.5,\"y\":1e400}",
        "{\"t\":\"pick\",\"x\":0.5,\"y\":0.5,\"select\":1}",
        "{\"t\":\"pick\",\"x\":0.5,\"y\":0.5,\"seq\":-1}",
        "{\"t\":\"visible\",\"node\":0,\"on\":true}",      /* no node 0 to show */
        "{\"t\":\"visible\",\"node\":2.5,\"on\":true}",
        "{\"t\":\"visible\",\"node\":4294967296,\"on\":true}",
        "{\"t\":\"visible\",\"node\":\"7\",\"on\":true}",
        "{\"t\":\"visible\",\"node\":7}",
        "{\"t\":\"visible\",\"node\":7,\"on\":\"no\"}",
        "{\"t\":\"select\",\"node\":-1,\"on\":true}",
        "{\"t\":\"isolate\"}",
        "{\"t\":\"clip\",\"planes\":[[0,0,0,1]]}",         /* zero normal */
        "{\"t\":\"clip\",\"planes\":[[1,0,0,1e400]]}",     /* infinite */
        "{\"t\":\"clip\",\"planes\":[[1,0,0,1e30]]}",      /* beyond SY_COORD_MAX */
        "{\"t\":\"clip\",\"planes\":[[1,0,0]]}",
        "{\"t\":\"clip\",\"planes\":[[1,0,0,0,0]]}",
        "{\"t\":\"clip\",\"planes\":[[1,0,\"a\",0]]}",
        "{\"t\":\"clip\",\"planes\":{}}",
        "{\"t\":\"clip\",\"planes\":[],\"cap\":[1,0]}",       /* caps: 3 values in [0, 1] */
        "{\"t\":\"clip\",\"planes\":[],\"cap\":[1,0,2]}",
        "{\"t\":\"clip\",\"planes\":[],\"cap\":[1,0,-0.1]}",
        "{\"t\":\"clip\",\"planes\":[],\"cap\":[1,0,1e400]}",
        "{\"t\":\"clip\",\"planes\":[],\"cap\":[1,\"0\",0]}",
        "{\"t\":\"clip\",\"planes\":[],\"cap\":true}",
        "{\"t\":\"clip\",\"planes\":[],\"cap\":\"#ff0000\"}",
        "{\"t\":\"clip\",\"planes\":[[1,0,0,0],[1,0,0,0],[1,0,0,0],[1,0,0,0],[1,0,0,0],[1,0,0,0],[1,0,0,0]]}",
        "{\"t\":\"tree\",\"seq\":2147483648}",
        "{\"t\":\"exposure\",\"stops\":17}",
        "{\"t\":\"exposure\"}",
        "{\"t\":\"filter\",\"name\":\"\"}",
        "{\"t\":\"filter\",\"name\":\"../x\"}",
        "{\"t\":\"filter\",\"name\":\"ABC\"}",
        "{\"t\":\"environment\"}",
        "{\"t\":\"environment\",\"name\":\"../sky\"}",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        sy_result r = sy_web_parse_input(bad[i], strlen(bad[i]), &in, &err);
        if (r == SY_OK) fprintf(stderr, "accepted %s\n", bad[i]);
        CHECK(r == SY_ERR_INVALID_ARGUMENT && err.message[0]);
    }
    const char *zero = "{\"t\":\"clip\",\"planes\":[[0,0,0,1]]}";
    CHECK(sy_web_parse_input(zero, strlen(zero), &in, &err) == SY_ERR_INVALID_ARGUMENT && strstr(err.message, "clip"));
    return 0;
}

/* The number after "key": in a JSON text (0 when absent). */
static double json_number(const char *text, const char *key)
{
    char k[64];
    snprintf(k, sizeof k, "\"%s\":", key);
    const char *p = text ? strstr(text, k) : NULL;
    return p ? strtod(p + strlen(k), NULL) : 0;
}

/* Sends msg, which the server must refuse: its "refused" answer names reason. 0, or 1 after a
 * failed check. */
static int refused(sy_web_client *c, const char *msg, const char *reason)
{
    sy_error err = {0};
    char *t = NULL;
    CHECK_OK(sy_web_client_send(c, msg, &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "refused", &t, &err), err);
    bool named = strstr(t, reason) != NULL;
    free(t);
    CHECK_MSG(named, "the refusal of %s does not say '%s'", msg, reason);
    return 0;
}

/* Frames until one whose depth at pixel (px, py) of an 80 x 60 frame satisfies want (changed from
 * d0 or equal to it), at most 40 frames, each waited for up to 60 s (a loaded machine, ASan); the
 * depth there in *d. */
static int frame_until(sy_web_client *c, int px, int py, float d0, bool changed, float *d)
{
    sy_error err = {0};
    for (int k = 0; k < 40; ++k) {
        sy_web_frame_info fi;
        float *depth = NULL;
        if (sy_web_client_next_frame_depth(c, 60000, &fi, NULL, NULL, &depth, &err) != SY_OK) {
            fprintf(stderr, "frame_until: %s\n", err.message);
            return 1;
        }
        if (fi.width != 80 || fi.height != 60) {
            free(depth);
            continue;
        }
        *d = depth[py * 80 + px];
        free(depth);
        bool same = isfinite(*d) == isfinite(d0) && (!isfinite(d0) || fabsf(*d - d0) <= 1e-3f * d0);
        if (same != changed) return 0;
    }
    fprintf(stderr, "frame_until: the depth at %d,%d stayed %s %g\n", px, py, changed ? "at" : "away from", d0);
    return 1;
}

/* The first full-size frame (80 x 60) and the covered pixel nearest the centre. */
static int first_frame(sy_web_client *c, int *px, int *py, float *d)
{
    sy_error err = {0};
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"size\",\"w\":80,\"h\":60,\"v\":3}", &err), err);
    sy_web_frame_info fi;
    float *depth = NULL;
    do {
        free(depth);
        depth = NULL;
        CHECK_OK(sy_web_client_next_frame_depth(c, 60000, &fi, NULL, NULL, &depth, &err), err);
    } while (fi.width != 80 || fi.height != 60);
    int best = -1;
    for (int y = 0; y < 60; ++y)
        for (int x = 0; x < 80; ++x)
            if (isfinite(depth[y * 80 + x]) && (best < 0 || abs(x - 40) + abs(y - 30) < abs(best % 80 - 40) + abs(best / 80 - 30)))
                best = y * 80 + x;
    CHECK(best >= 0);
    *px = best % 80, *py = best / 80, *d = depth[best];
    free(depth);
    return 0;
}

int test_scene(uint16_t port)
{
    sy_error err = {0};
    sy_web_client *c = NULL, *other = NULL;
    sy_web_client_opts o = {.host = "127.0.0.1", .port = port, .path = "/ws"};
    CHECK_OK(sy_web_client_connect(&o, 10000, &c, &err), err);
    CHECK_OK(sy_web_client_connect(&o, 10000, &other, &err), err); /* another viewer: told "scene" too */
    int px, py;
    float d0, d;
    if (first_frame(c, &px, &py, &d0)) return 1;
    char *t = NULL, m[256];
    /* the tree: the demo's nodes with their kinds, not cut */
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"tree\",\"seq\":1}", &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "tree", &t, &err), err);
    CHECK(json_number(t, "seq") == 1 && json_number(t, "total") >= 2 && strstr(t, "\"truncated\":false"));
    CHECK(strstr(t, "\"kind\":\"mesh\"") && strstr(t, "\"visible\":true") && strstr(t, "\"min\":[") && strstr(t, "\"planes\":[]"));
    free(t);
    /* pick the covered pixel nearest the centre and select it */
    snprintf(m, sizeof m, "{\"t\":\"pick\",\"x\":%.6f,\"y\":%.6f,\"select\":true,\"seq\":2}", (px + 0.5) / 80.0, (py + 0.5) / 60.0);
    CHECK_OK(sy_web_client_send(c, m, &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "pick", &t, &err), err);
    CHECK(strstr(t, "\"hit\":true") && json_number(t, "seq") == 2 && strstr(t, "\"position\":[") && strstr(t, "\"selected\":true"));
    uint32_t node = (uint32_t)json_number(t, "node");
    CHECK(node > 0 && strstr(t, "\"mesh\":") && strstr(t, "\"material\":") && json_number(t, "distance") > 0);
    CHECK(json_number(t, "distance") >= 0.99 * d0 && json_number(t, "distance") <= 1.2 * d0); /* the depth's point, along its ray */
    free(t);
    CHECK_OK(sy_web_client_next_text(c, 20000, "scene", &t, &err), err);
    free(t);
    CHECK_OK(sy_web_client_next_text(other, 20000, "scene", &t, &err), err);
    free(t);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"tree\",\"seq\":3}", &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "tree", &t, &err), err);
    CHECK(strstr(t, "\"selected\":true"));
    free(t);
    /* hide it: the frame's depth there changes, a pick there names another node (or nothing) */
    snprintf(m, sizeof m, "{\"t\":\"visible\",\"node\":%u,\"on\":false}", node);
    CHECK_OK(sy_web_client_send(c, m, &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "scene", &t, &err), err);
    free(t);
    if (frame_until(c, px, py, d0, true, &d)) return 1;
    snprintf(m, sizeof m, "{\"t\":\"pick\",\"x\":%.6f,\"y\":%.6f,\"seq\":4}", (px + 0.5) / 80.0, (py + 0.5) / 60.0);
    CHECK_OK(sy_web_client_send(c, m, &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "pick", &t, &err), err);
    CHECK(json_number(t, "seq") == 4 && (strstr(t, "\"hit\":false") || (uint32_t)json_number(t, "node") != node));
    free(t);
    /* show it again: the depth comes back */
    snprintf(m, sizeof m, "{\"t\":\"visible\",\"node\":%u,\"on\":true}", node);
    CHECK_OK(sy_web_client_send(c, m, &err), err);
    if (frame_until(c, px, py, d0, false, &d)) return 1;
    /* an unknown node: refused with the reason, nothing changes */
    if (refused(c, "{\"t\":\"visible\",\"node\":4000000000,\"on\":false}", "no node 4000000000")) return 1;
    /* a plane that keeps nothing (z >= 1e6): nothing covered; no plane: back */
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"clip\",\"planes\":[[0,0,1,-1000000]]}", &err), err);
    if (frame_until(c, px, py, d0, true, &d)) return 1;
    CHECK(!isfinite(d));
    /* bad planes are ignored (logged): the planes stay as they were, the stream goes on */
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"clip\",\"planes\":[[0,0,0,1]]}", &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"clip\",\"planes\":[[1,0,0,1e999]]}", &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"pick\",\"x\":1.5,\"y\":0.5}", &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"tree\",\"seq\":5}", &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "tree", &t, &err), err);
    CHECK(json_number(t, "seq") == 5 && strstr(t, "\"planes\":[[0,0,1,-1000000]]") && strstr(t, "\"cap\":null"));
    free(t);
    /* caps: on in a colour (the tree says so), a bad colour refused (kept), a clip without "cap"
     * keeps them, false turns them off */
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"clip\",\"planes\":[[0,0,1,-1000000]],\"cap\":[1,0.5,0]}", &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"clip\",\"planes\":[[0,0,1,-1000000]],\"cap\":[2,0,0]}", &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"clip\",\"planes\":[[0,0,1,-1000000]]}", &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"tree\",\"seq\":7}", &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "tree", &t, &err), err);
    CHECK(json_number(t, "seq") == 7 && strstr(t, "\"cap\":[1,0.5,0]"));
    free(t);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"clip\",\"planes\":[[0,0,1,-1000000]],\"cap\":false}", &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"tree\",\"seq\":8}", &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "tree", &t, &err), err);
    CHECK(json_number(t, "seq") == 8 && strstr(t, "\"cap\":null") && strstr(t, "\"environment\":\"scene\""));
    free(t);
    /* the environment: none, studio, back to the scene's; every page is told ("scene"), the tree
     * names it; an unknown one is refused */
    static const char *const envs[3] = {"none", "studio", "scene"};
    for (int k = 0; k < 3; ++k) {
        snprintf(m, sizeof m, "{\"t\":\"environment\",\"name\":\"%s\"}", envs[k]);
        CHECK_OK(sy_web_client_send(c, m, &err), err);
        CHECK_OK(sy_web_client_next_text(other, 20000, "scene", &t, &err), err);
        free(t);
        snprintf(m, sizeof m, "{\"t\":\"tree\",\"seq\":%d}", 20 + k);
        CHECK_OK(sy_web_client_send(c, m, &err), err);
        CHECK_OK(sy_web_client_next_text(c, 20000, "tree", &t, &err), err);
        char want[64];
        snprintf(want, sizeof want, "\"environment\":\"%s\"", envs[k]);
        CHECK(json_number(t, "seq") == 20 + k && strstr(t, want));
        free(t);
    }
    if (refused(c, "{\"t\":\"environment\",\"name\":\"sky\"}", "no such environment")) return 1;
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"clip\",\"planes\":[]}", &err), err);
    if (frame_until(c, px, py, d0, false, &d)) return 1;
    /* deselect every node */
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"select\",\"node\":0,\"on\":false}", &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"tree\",\"seq\":6}", &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "tree", &t, &err), err);
    CHECK(json_number(t, "seq") == 6 && !strstr(t, "\"selected\":true"));
    free(t);
    /* 80 pages that ask for the tree and leave at once: their answers are dropped, not kept
     * (64 kept would stop every answer); a page asking afterwards is answered */
    /* exposure: +2 stops brighten the stream, back to 0 restores it. Frames rendered before the
     * message may still be on their way (exposure carries no input id): each step reads frames
     * until one shows the change, at most 40 */
    double mean[3] = {0, 0, 0};
    static const char *const expo[3] = {NULL, "{\"t\":\"exposure\",\"stops\":2}", "{\"t\":\"exposure\",\"stops\":0}"};
    for (int k = 0; k < 3; ++k) {
        if (expo[k]) CHECK_OK(sy_web_client_send(c, expo[k], &err), err);
        bool seen = false;
        for (int f = 0; f < 40 && !seen; ++f) {
            sy_web_frame_info fi;
            uint8_t *jp = NULL, *px = NULL;
            size_t jn = 0;
            uint32_t jw = 0, jh = 0;
            CHECK_OK(sy_web_client_next_frame(c, 20000, &fi, &jp, &jn, &err), err);
            if (fi.width != 80) { /* a coarse frame of a change */
                free(jp);
                continue;
            }
            CHECK_OK(sy_jpeg_decode_rgba8(jp, jn, 0, &px, &jw, &jh, &err), err);
            mean[k] = 0;
            for (size_t i = 0; i < (size_t)jw * jh * 4; ++i) if ((i & 3) != 3) mean[k] += px[i];
            mean[k] /= 3.0 * jw * jh;
            free(jp), free(px);
            seen = k == 0 || (k == 1 ? mean[1] > mean[0] * 1.15 : fabs(mean[2] - mean[0]) <= 0.02 * mean[0]);
        }
        CHECK_MSG(seen, "exposure step %d: no frame showed it (mean %.1f, at first %.1f)", k, mean[k], mean[0]);
    }
    printf("exposure: mean %.1f at 0, %.1f at +2 stops, %.1f at 0 again\n", mean[0], mean[1], mean[2]);
    sy_web_client_close(other);
    other = NULL;
    int held = web_hold_render_thread(port); /* their requests wait until they left */
    CHECK(held >= 0);
    for (int k = 0; k < 80; ++k) {
        sy_web_client *gone = NULL;
        for (int a = 0; a < 50 && sy_web_client_connect(&o, 10000, &gone, &err) != SY_OK; ++a) {} /* (the last may still count) */
        CHECK(gone != NULL);
        CHECK_OK(sy_web_client_send(gone, "{\"t\":\"tree\",\"seq\":1}", &err), err);
        sy_web_client_close(gone);
    }
    web_release_render_thread(held);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"tree\",\"seq\":7}", &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "tree", &t, &err), err);
    CHECK(json_number(t, "seq") == 7);
    free(t);
    sy_web_client_close(other);
    sy_web_client_close(c);
    return 0;
}

/* the "time" of a clock message */
static double clock_time(const char *t) { return json_number(t, "time"); }

/* Sends each of the n messages, which the server must refuse without a clock message (none within
 * 0.5 s). 0, or 1 after a failed check. */
static int no_clock(sy_web_client *c, const char *const *msgs, int n)
{
    sy_error err = {0};
    char *t = NULL;
    for (int i = 0; i < n; ++i) CHECK_OK(sy_web_client_send(c, msgs[i], &err), err);
    CHECK(sy_web_client_next_text(c, 500, "clock", &t, &err) == SY_ERR_IO);
    return 0;
}

/* Sends msg; the clock message that answers it must have the time `time` and the end `end` (NAN:
 * any) and contain `has`. 0, or 1 after a failed check. */
static int clock_after(sy_web_client *c, const char *msg, double time, double end, const char *has)
{
    sy_error err = {0};
    char *t = NULL;
    CHECK_OK(sy_web_client_send(c, msg, &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "clock", &t, &err), err);
    bool ok = (isnan(time) || clock_time(t) == time) && (isnan(end) || json_number(t, "end") == end) && strstr(t, has);
    if (!ok) fprintf(stderr, "after %s: %s\n", msg, t);
    free(t);
    CHECK_MSG(ok, "after %s: want time %g, end %g (nan: any), '%s'", msg, time, end, has);
    return 0;
}

/* The scene clock (docs/WEB.md, "The timeline") on a read-only server (a view change: allowed)
 * whose demo has two clips on the same nodes, shrink (2 s) and hold (4 s, later: with every clip
 * at once its keys would win), and plays shrink (sy_web_desc.clip): the hello lists both, the page
 * is sent shrink's range, paused; a time moves the scene (the depth at a covered pixel changes
 * within 40 frames: shrink alone is applied); "anim" switches to hold (its range, the depth back)
 * and to every clip, bad clips are refused; play is answered by clock messages whose
 * time advances; times outside the range, not numbers or on a scene without clips are refused
 * (no clock message follows them); pause stops the clock. */
int test_timeline(void)
{
    sy_error err = {0};
    server s;
    web_read_only = web_read_only_anim = true;
    sy_web_client *c = NULL;
    if (web_start_viewer(&s, &c, &err)) return 1;
    char *t = NULL;
    CHECK_OK(sy_web_client_next_text(c, 20000, "hello", &t, &err), err);
    CHECK_MSG(strstr(t, "\"clips\":[\"shrink\",\"hold\"]"), "%s", t);
    free(t);
    CHECK_OK(sy_web_client_next_text(c, 20000, "clock", &t, &err), err);
    CHECK_MSG(clock_time(t) == 0 && json_number(t, "start") == 0 && json_number(t, "end") == 2 && strstr(t, "\"playing\":false") &&
              strstr(t, "\"clip\":0"), "%s", t);
    free(t);
    int px, py;
    float d0;
    if (first_frame(c, &px, &py, &d0)) return 1;
    /* bad times: refused, no clock message */
    static const char *const bad_times[] = {"{\"t\":\"time\",\"s\":3}", "{\"t\":\"time\",\"s\":-0.5}",
                                            "{\"t\":\"time\",\"s\":null}"};
    if (no_clock(c, bad_times, 3)) return 1;
    /* the end of the clip: every mesh at 1 % of its size, the covered pixel shows something else */
    if (clock_after(c, "{\"t\":\"time\",\"s\":2}", 2, NAN, "\"playing\":false")) return 1;
    float d;
    CHECK_MSG(frame_until(c, px, py, d0, true, &d) == 0, "the depth at (%d, %d) stayed %g at 2 s", px, py, (double)d0);
    /* the page's clip menu: hold (0..4 s, from its start), then its 2 s: the meshes at their own
     * size again; bad clips refused (no clock message) */
    static const char *const bad_clips[] = {"{\"t\":\"anim\",\"clip\":2}", "{\"t\":\"anim\",\"clip\":0.5}",
                                            "{\"t\":\"anim\",\"clip\":-2}"};
    if (no_clock(c, bad_clips, 3) || clock_after(c, "{\"t\":\"anim\",\"clip\":1}", 0, 4, "\"clip\":1") ||
        clock_after(c, "{\"t\":\"time\",\"s\":2}", NAN, NAN, ""))
        return 1;
    CHECK_MSG(frame_until(c, px, py, d0, false, &d) == 0, "hold at 2 s: the depth at (%d, %d) is not %g again", px, py,
              (double)d0);
    if (clock_after(c, "{\"t\":\"anim\",\"clip\":-1}", NAN, 4, "\"clip\":-1") ||
        clock_after(c, "{\"t\":\"anim\",\"clip\":0}", NAN, 2, "\"clip\":0"))
        return 1;
    /* play from 0: the clock messages' time advances (one a second while playing) */
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"time\",\"s\":0}", &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"play\",\"on\":true}", &err), err);
    double last = 0;
    bool advanced = false;
    for (int k = 0; k < 20 && !advanced; ++k) { /* a hang guard: a message a second */
        CHECK_OK(sy_web_client_next_text(c, 20000, "clock", &t, &err), err);
        advanced = strstr(t, "\"playing\":true") && clock_time(t) > 0;
        last = clock_time(t);
        free(t);
    }
    CHECK_MSG(advanced, "playing: the clock stayed at %g", last);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"play\",\"on\":false}", &err), err);
    bool paused = false;
    for (int k = 0; k < 20 && !paused; ++k) {
        CHECK_OK(sy_web_client_next_text(c, 20000, "clock", &t, &err), err);
        paused = strstr(t, "\"playing\":false") != NULL;
        free(t);
    }
    CHECK(paused);
    sy_web_client_close(c);
    web_read_only = web_read_only_anim = false;
    if (web_stop(&s)) return 1;
    /* a scene without clips: no clock message, and a time is refused */
    if (web_start_viewer(&s, &c, &err)) return 1;
    CHECK_OK(sy_web_client_next_text(c, 20000, "hello", &t, &err), err);
    free(t);
    static const char *const a_time[] = {"{\"t\":\"time\",\"s\":0}"};
    if (no_clock(c, a_time, 1)) return 1;
    sy_web_client_close(c);
    return web_stop(&s);
}

int test_readonly(sy_web_client *c)
{
    sy_error err = {0};
    char *t = NULL, m[256];
    CHECK_OK(sy_web_client_next_text(c, 20000, "hello", &t, &err), err);
    CHECK(strstr(t, "\"read_only\":true") && strstr(t, "\"environments\":[\"scene\",\"studio\",\"none\"]") &&
          strstr(t, "\"environment\":\"scene\""));
    free(t);
    int px, py;
    float d0;
    if (first_frame(c, &px, &py, &d0)) return 1;
    /* a pick answers, without selecting */
    snprintf(m, sizeof m, "{\"t\":\"pick\",\"x\":%.6f,\"y\":%.6f,\"select\":true,\"seq\":1}", (px + 0.5) / 80.0, (py + 0.5) / 60.0);
    CHECK_OK(sy_web_client_send(c, m, &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "pick", &t, &err), err);
    CHECK(strstr(t, "\"hit\":true") && strstr(t, "\"selected\":false"));
    uint32_t node = (uint32_t)json_number(t, "node");
    free(t);
    /* hiding, selecting, isolating, planes, back-end keys: refused; nothing changes */
    snprintf(m, sizeof m, "{\"t\":\"visible\",\"node\":%u,\"on\":false}", node);
    CHECK_OK(sy_web_client_send(c, m, &err), err);
    snprintf(m, sizeof m, "{\"t\":\"select\",\"node\":%u,\"on\":true}", node);
    CHECK_OK(sy_web_client_send(c, m, &err), err);
    snprintf(m, sizeof m, "{\"t\":\"isolate\",\"node\":%u}", node);
    CHECK_OK(sy_web_client_send(c, m, &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"clip\",\"planes\":[[0,0,1,-1000000]]}", &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"key\",\"k\":\"2\"}", &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"environment\",\"name\":\"none\"}", &err), err);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"tree\",\"seq\":2}", &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "tree", &t, &err), err);
    CHECK(json_number(t, "seq") == 2 && !strstr(t, "\"visible\":false") && !strstr(t, "\"selected\":true") && strstr(t, "\"planes\":[]") &&
          strstr(t, "\"environment\":\"scene\""));
    free(t);
    CHECK(sy_web_client_next_text(c, 500, "scene", &t, &err) == SY_ERR_IO);
    /* the camera still moves */
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"drag\",\"dx\":40,\"dy\":0,\"id\":1}", &err), err);
    sy_web_frame_info fi;
    do {
        if (web_next_frame(c, &fi, NULL, NULL)) return 1;
    } while (fi.input_id < 1);
    return 0;
}

/* >>web_tree: a scene beyond WEB_TREE_MAX nodes, a page at a time */
/* The next "tree" answer, parsed (the caller deletes it); NULL after a failed check. */
static cJSON *tree_answer(sy_web_client *c, const char *ask)
{
    sy_error err = {0};
    char *t = NULL;
    if (sy_web_client_send(c, ask, &err) != SY_OK || sy_web_client_next_text(c, 20000, "tree", &t, &err) != SY_OK) {
        fprintf(stderr, "tree %s: %s\n", ask, err.message);
        return NULL;
    }
    cJSON *o = cJSON_Parse(t);
    free(t);
    return o;
}

static double num(const cJSON *o, const char *k)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, k);
    return cJSON_IsNumber(v) ? v->valuedouble : -1;
}

/* The listed node named name (NULL when absent). */
static const cJSON *named(const cJSON *nodes, const char *name)
{
    const cJSON *e;
    cJSON_ArrayForEach(e, nodes)
    {
        const cJSON *n = cJSON_GetObjectItemCaseSensitive(e, "name");
        if (cJSON_IsString(n) && !strcmp(n->valuestring, name)) return e;
    }
    return NULL;
}

int test_tree(sy_web_client *c)
{
    sy_error err = {0};
    /* the first answer: the root's tree, at most WEB_TREE_MAX nodes, depth first */
    cJSON *a = tree_answer(c, "{\"t\":\"tree\",\"seq\":1}");
    CHECK(a);
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(a, "nodes");
    int listed = cJSON_GetArraySize(nodes);
    double total = num(a, "total");
    printf("tree: %.0f nodes, %d in the first answer\n", total, listed);
    CHECK_MSG(total > 18022 && listed <= 4096 && listed > 100 && cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(a, "truncated")),
              "total %g, listed %d", total, listed);
    CHECK(num(a, "count") == 1 && num(a, "node") == 0 && num(a, "offset") == 0);
    const cJSON *flat = named(nodes, "flat"), *deep = named(nodes, "deep");
    CHECK(flat && deep);
    CHECK(num(flat, "children") == 12000 && cJSON_IsFalse(cJSON_GetObjectItemCaseSensitive(flat, "open")));
    CHECK(num(deep, "children") == 20 && cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(deep, "open")));
    CHECK(!named(nodes, "flat 0"));
    /* "deep"'s groups: listed, the first ones open (their 300 leaves follow), the last closed */
    int open = 0, closed = 0;
    uint32_t closed_id = 0;
    for (int i = 0; i < 20; ++i) {
        char nm[32];
        snprintf(nm, sizeof nm, "leaf %d", i);
        const cJSON *g = named(nodes, nm);
        CHECK_MSG(g && num(g, "children") == 300 && num(g, "depth") == num(deep, "depth") + 1, "%s", nm);
        bool op = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(g, "open"));
        snprintf(nm, sizeof nm, "leaf %d 299", i);
        CHECK_MSG(!!named(nodes, nm) == op, "leaf %d: open %d", i, op);
        open += op, closed += !op;
        if (!op && !closed_id) closed_id = (uint32_t)num(g, "id");
    }
    printf("tree: deep's groups: %d open, %d closed\n", open, closed);
    CHECK(open >= 5 && closed >= 1);
    uint32_t flat_id = (uint32_t)num(flat, "id");
    cJSON_Delete(a);
    /* "flat"'s children, a page at a time: each child once, in order */
    char ask[128];
    int seen = 0, pages = 0;
    for (uint32_t off = 0; off < 12000; off += 512, ++pages) {
        snprintf(ask, sizeof ask, "{\"t\":\"tree\",\"seq\":%u,\"node\":%u,\"offset\":%u}", 10 + pages, flat_id, off);
        a = tree_answer(c, ask);
        CHECK(a);
        nodes = cJSON_GetObjectItemCaseSensitive(a, "nodes");
        int n = cJSON_GetArraySize(nodes);
        CHECK_MSG(num(a, "count") == 12000 && num(a, "node") == flat_id && num(a, "offset") == off && num(a, "seq") == 10 + pages &&
                  n == (off + 512 <= 12000 ? 512 : 12000 - (int)off), "offset %u: %d nodes", off, n);
        const cJSON *e;
        cJSON_ArrayForEach(e, nodes)
        {
            char nm[32];
            snprintf(nm, sizeof nm, "flat %d", seen++);
            const cJSON *name = cJSON_GetObjectItemCaseSensitive(e, "name");
            CHECK_MSG(cJSON_IsString(name) && !strcmp(name->valuestring, nm) && num(e, "depth") == 0 && num(e, "children") == 0,
                      "%s", nm);
        }
        cJSON_Delete(a);
    }
    CHECK(seen == 12000 && pages == 24);
    /* past the end: no nodes */
    snprintf(ask, sizeof ask, "{\"t\":\"tree\",\"seq\":50,\"node\":%u,\"offset\":12000}", flat_id);
    a = tree_answer(c, ask);
    CHECK(a && cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(a, "nodes")) == 0 && num(a, "count") == 12000);
    cJSON_Delete(a);
    /* the first closed group of "deep" on its own: its 300 leaves */
    snprintf(ask, sizeof ask, "{\"t\":\"tree\",\"seq\":60,\"node\":%u}", closed_id);
    a = tree_answer(c, ask);
    CHECK(a && num(a, "count") == 300 && cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(a, "nodes")) == 300);
    cJSON_Delete(a);
    /* an unknown node: refused with the reason; bad fields: refused by the parser, the stream goes on */
    char *t = NULL;
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"tree\",\"seq\":51,\"node\":4000000000}", &err), err);
    CHECK_OK(sy_web_client_next_text(c, 20000, "refused", &t, &err), err);
    CHECK_MSG(strstr(t, "\"what\":\"tree\"") && strstr(t, "no node 4000000000"), "%s", t);
    free(t);
    CHECK_OK(sy_web_client_send(c, "{\"t\":\"tree\",\"seq\":52,\"offset\":0.5}", &err), err);
    a = tree_answer(c, "{\"t\":\"tree\",\"seq\":53}");
    CHECK(a && num(a, "seq") == 53); /* the bad one got no answer */
    cJSON_Delete(a);
    return 0;
}
