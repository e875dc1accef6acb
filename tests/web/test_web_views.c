/* test_web_views.c — test_web's saved-views part (web_views; test_web.c lists what each part checks):
 * a server whose views' file holds one view, a page saving the shared view (the same again: nothing
 * sent), moving, recalling it and the file's view (the frames' cameras and field of view as
 * saved), an empty slot recalled (nothing moves), a read-only server (recalls, refuses saves), and
 * an unreadable file (left as it is, views kept by the server). */
#include "web_test.h"

#include "sy_bookmarks.h"

#include <cjson/cJSON.h>

/* The next "views" list (parsed; the caller deletes it); NULL after reporting. */
static cJSON *next_views(sy_web_client *c)
{
    sy_error err = {0};
    char *t = NULL;
    if (sy_web_client_next_text(c, 20000, "views", &t, &err) != SY_OK) {
        fprintf(stderr, "views: %s\n", err.message);
        return NULL;
    }
    cJSON *o = cJSON_Parse(t);
    free(t);
    return o;
}

/* The entry for slot n in a "views" list (NULL: none). */
static const cJSON *view_in(const cJSON *list, int n)
{
    const cJSON *v;
    cJSON_ArrayForEach(v, cJSON_GetObjectItemCaseSensitive(list, "views"))
        if (cJSON_GetObjectItemCaseSensitive(v, "n")->valuedouble == n) return v;
    return NULL;
}

static int view_count(const cJSON *list)
{
    return cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(list, "views"));
}

/* The first frame answering input id (80 x 60). */
static int frame_for(sy_web_client *c, uint64_t id, sy_web_frame_info *fi)
{
    do {
        if (web_next_frame(c, fi, NULL, NULL)) return 1;
    } while (fi->input_id < id || fi->width != 80);
    return 0;
}

/* The frame's camera position and vertical field of view (radians). */
static void frame_eye(const sy_web_frame_info *fi, float eye[3])
{
    for (int i = 0; i < 3; ++i) eye[i] = fi->view.camera_to_world.m[12 + i];
}
static float frame_fov(const sy_web_frame_info *fi)
{
    return 2.0f * atanf(0.5f * (fi->view.window[3] - fi->view.window[2]));
}
static float dist3(const float a[3], const float b[3])
{
    return sqrtf((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/* A viewer of a new server (web_bookmarks: file) past its hello. */
static int start(server *s, sy_web_client **c, const char *file, bool read_only)
{
    sy_error err = {0};
    web_bookmarks = file, web_read_only = read_only;
    if (web_start_viewer(s, c, &err)) return 1;
    char *t = NULL;
    CHECK_OK(sy_web_client_next_text(*c, 20000, "hello", &t, &err), err);
    free(t);
    return 0;
}

static int send_text(sy_web_client *c, const char *m)
{
    sy_error err = {0};
    CHECK_OK(sy_web_client_send(c, m, &err), err);
    return 0;
}

int test_views(void)
{
    char path[96], bad[96];
    snprintf(path, sizeof path, "/tmp/sy_test_web_views_%d.bookmarks", (int)getpid());
    snprintf(bad, sizeof bad, "/tmp/sy_test_web_views_bad_%d.bookmarks", (int)getpid());
    /* the file as sy view writes it: view 2 from (3, 2, 4) at (0, 0.5, 0), 30 degrees */
    FILE *f = fopen(path, "w");
    CHECK(f && fputs("# sy bookmarks\n2 3 2 4 0 0.5 0 0 1 0 30\n", f) >= 0 && fclose(f) == 0);
    const float eye2[3] = {3, 2, 4};
    server s;
    sy_web_client *c = NULL;
    sy_error err = {0};
    int failed = start(&s, &c, path, false);
    cJSON *l = failed ? NULL : next_views(c);
    sy_web_frame_info f0, fi;
    float e0[3], e[3];
    failed |= !l || view_count(l) != 1 || !view_in(l, 2) || !cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(l, "kept")) ||
              fabs(cJSON_GetObjectItemCaseSensitive(view_in(l, 2), "fov")->valuedouble - 30.0) > 1e-4;
    cJSON_Delete(l), l = NULL;
    if (failed) fprintf(stderr, "views: the file's view 2 was not listed\n");
    /* the view now saved as 5: listed to the page, written to the file with the camera's fov */
    failed = failed || send_text(c, "{\"t\":\"size\",\"w\":80,\"h\":60,\"v\":3}") || frame_for(c, 0, &f0);
    if (!failed) frame_eye(&f0, e0);
    failed = failed || send_text(c, "{\"t\":\"view\",\"n\":5,\"save\":true}") || !(l = next_views(c));
    if (!failed) {
        CHECK(view_count(l) == 2 && view_in(l, 2) && view_in(l, 5));
        sy_bookmark got[SY_BOOKMARKS_MAX + 1];
        CHECK_OK(sy_bookmarks_load(path, got, &err), err);
        CHECK(got[2].set && got[5].set && dist3(got[2].eye, eye2) < 1e-6f && dist3(got[5].eye, e0) < 1e-4f &&
              fabsf(got[5].fov - frame_fov(&f0)) < 1e-5f);
    }
    cJSON_Delete(l), l = NULL;
    /* the same view saved again: nothing written, no list (a page repeating saves costs nothing) */
    if (!failed) {
        char *t = NULL;
        CHECK(send_text(c, "{\"t\":\"view\",\"n\":5,\"save\":true}") == 0);
        CHECK(sy_web_client_next_text(c, 500, "views", &t, &err) == SY_ERR_IO);
    }
    /* moved away, then view 5 recalled: the frame's camera is where it was saved */
    failed = failed || send_text(c, "{\"t\":\"drag\",\"dx\":60,\"dy\":25,\"id\":1}") || frame_for(c, 1, &fi);
    if (!failed) {
        frame_eye(&fi, e);
        CHECK(dist3(e, e0) > 0.05f);
    }
    failed = failed || send_text(c, "{\"t\":\"view\",\"n\":5,\"id\":2}") || frame_for(c, 2, &fi);
    if (!failed) {
        frame_eye(&fi, e);
        CHECK(dist3(e, e0) < 1e-3f * (1.0f + fi.orbit.dist));
        for (int k = 0; k < 3; ++k) /* the same viewing direction */
            CHECK(fabsf(fi.view.camera_to_world.m[8 + k] - f0.view.camera_to_world.m[8 + k]) < 1e-4f);
    }
    /* the file's view 2: its eye and its 30 degree field of view (set on the camera) */
    failed = failed || send_text(c, "{\"t\":\"view\",\"n\":2,\"id\":3}") || frame_for(c, 3, &fi);
    sy_web_frame_info f2 = fi;
    if (!failed) {
        frame_eye(&fi, e);
        CHECK(dist3(e, eye2) < 1e-3f && fabsf(frame_fov(&fi) - 30.0f * 3.14159265f / 180.0f) < 1e-4f);
    }
    /* an empty slot: nothing moves (the wheel after it zooms view 2 alone) */
    failed = failed || send_text(c, "{\"t\":\"view\",\"n\":7,\"id\":4}") || send_text(c, "{\"t\":\"wheel\",\"steps\":1,\"id\":5}") ||
             frame_for(c, 5, &fi);
    if (!failed) {
        CHECK(fi.orbit.yaw == f2.orbit.yaw && fi.orbit.pitch == f2.orbit.pitch && fabsf(fi.orbit.dist - 0.9f * f2.orbit.dist) < 1e-4f);
        for (int k = 0; k < 3; ++k) CHECK(fi.orbit.target[k] == f2.orbit.target[k]);
    }
    sy_web_client_close(c);
    failed |= web_stop(&s);
    /* read-only: a recall moves the camera, a save is refused (no list, the file unchanged) */
    failed = failed || start(&s, &c, path, true);
    if (!failed) {
        l = next_views(c);
        CHECK(l && view_count(l) == 2);
        cJSON_Delete(l), l = NULL;
        failed = send_text(c, "{\"t\":\"size\",\"w\":80,\"h\":60,\"v\":3}") || frame_for(c, 0, &f0) ||
                 send_text(c, "{\"t\":\"view\",\"n\":1,\"save\":true}") || send_text(c, "{\"t\":\"view\",\"n\":2,\"id\":1}") ||
                 frame_for(c, 1, &fi);
        char *t = NULL;
        CHECK(sy_web_client_next_text(c, 500, "views", &t, &err) == SY_ERR_IO);
        sy_bookmark got[SY_BOOKMARKS_MAX + 1];
        CHECK_OK(sy_bookmarks_load(path, got, &err), err);
        CHECK(!got[1].set && got[2].set && got[5].set);
        if (!failed) {
            frame_eye(&fi, e);
            CHECK(dist3(e, eye2) < 1e-3f);
        }
        sy_web_client_close(c);
        failed |= web_stop(&s);
    }
    /* an unreadable file: left as it is; saves are kept by the server and say so */
    f = fopen(bad, "w");
    CHECK(f && fputs("2 3 2 4 0 0.5 0 0 1 0 30\n5 not a view\n", f) >= 0 && fclose(f) == 0);
    failed = failed || start(&s, &c, bad, false);
    if (!failed) {
        l = next_views(c);
        CHECK(l && view_count(l) == 0 && cJSON_IsFalse(cJSON_GetObjectItemCaseSensitive(l, "kept")) &&
              cJSON_IsString(cJSON_GetObjectItemCaseSensitive(l, "note")));
        cJSON_Delete(l), l = NULL;
        failed = send_text(c, "{\"t\":\"view\",\"n\":1,\"save\":true}") || !(l = next_views(c));
        CHECK(l && view_count(l) == 1 && view_in(l, 1));
        cJSON_Delete(l), l = NULL;
        char text[128] = "";
        f = fopen(bad, "r");
        CHECK(f && fread(text, 1, sizeof text - 1, f) > 0 && fclose(f) == 0);
        CHECK(!strcmp(text, "2 3 2 4 0 0.5 0 0 1 0 30\n5 not a view\n"));
        sy_web_client_close(c);
        failed |= web_stop(&s);
    }
    web_bookmarks = NULL, web_read_only = false;
    remove(path), remove(bad);
    return failed;
}
