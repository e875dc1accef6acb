/* sy_web_views.c — the saved views (bookmarks) every page of sy web shares (docs/WEB.md, "Saved
 * views"; sy_bookmarks.h, the file sy view keeps too): read from the views' file at create; a
 * page's save puts the shared view now (the orbit, with the camera's field of view) in a slot and
 * rewrites the file; a recall moves the shared orbit there and has the render thread set the
 * saved field of view on the camera; the "views" message lists them for the pages. */
#include "sy_web_internal.h"

#include "sy_log.h"

#include <cjson/cJSON.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

sy_result sy_webi_views_init(sy_web *w, const sy_web_desc *desc, sy_error *err)
{
    w->fov = sy_interactive_fov(desc->scene, desc->camera);
    w->views_version = 1; /* every page is sent the list after its hello */
    if (!desc->bookmarks) return SY_OK;
    sy_error be = {0};
    sy_result r = sy_bookmarks_load(desc->bookmarks, w->marks, &be);
    if (r != SY_OK && r != SY_ERR_NOT_FOUND) { /* a file the user can still mend is never overwritten */
        sy_log(SY_LOG_WARNING, "web", NULL, "%s (saved views are kept in memory only; the file is left as it is)", be.message);
        snprintf(w->views_note, sizeof w->views_note, "the views' file could not be read: new views are kept by the server only");
        return SY_OK;
    }
    if (!(w->bookmarks = strdup(desc->bookmarks))) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory");
    return SY_OK;
}

static bool same_view(const sy_bookmark *a, const sy_bookmark *b)
{
    return a->set && b->set && !memcmp(a->eye, b->eye, sizeof a->eye) && !memcmp(a->target, b->target, sizeof a->target) &&
           !memcmp(a->up, b->up, sizeof a->up) && a->fov == b->fov;
}

web_view_done sy_webi_view_message(sy_web *w, const sy_web_input *in, const char *peer)
{
    sy_bookmark *b = &w->marks[in->slot];
    if (in->on) {
        sy_bookmark v = sy_bookmark_of_orbit(&w->in.orbit);
        v.fov = w->fov; /* 0 (an orthographic camera): the recalling camera keeps its own */
        sy_error e = {0};
        if (sy_bookmark_check(&v, &e) != SY_OK) { /* an orbit always makes a view: kept as a guard */
            sy_log(SY_LOG_WARNING, "web", peer, "view %u not saved: %s", in->slot, e.message);
            return WEB_VIEW_NONE;
        }
        if (same_view(b, &v)) return WEB_VIEW_NONE; /* the same view again: no write (a page that repeats saves costs nothing) */
        *b = v;
        return WEB_VIEW_SAVED;
    }
    if (!b->set) {
        sy_log(SY_LOG_WARNING, "web", peer, "ignored a message: view %u: no view is saved there", in->slot);
        return WEB_VIEW_NONE;
    }
    w->in.orbit = sy_orbit_of_bookmark(b);
    if (b->fov > 0.0f && w->fov > 0.0f && b->fov != w->fov) w->fov_req = w->fov = b->fov; /* the render thread sets it */
    return WEB_VIEW_RECALLED;
}

void sy_webi_views_write(sy_web *w, const char *peer)
{
    sy_bookmark marks[SY_BOOKMARKS_MAX + 1];
    pthread_mutex_lock(&w->mu);
    memcpy(marks, w->marks, sizeof marks);
    pthread_mutex_unlock(&w->mu);
    sy_error e = {0};
    bool failed = w->bookmarks && sy_bookmarks_save(w->bookmarks, marks, &e) != SY_OK; /* the network thread's alone */
    if (failed) sy_log(SY_LOG_WARNING, "web", peer, "the saved views are kept by the server only: %s", e.message);
    pthread_mutex_lock(&w->mu);
    if (failed) snprintf(w->views_note, sizeof w->views_note, "not written, kept by the server only: %.150s", e.message);
    else if (w->bookmarks) w->views_note[0] = 0;
    w->views_version++;
    pthread_mutex_unlock(&w->mu);
}

char *sy_webi_views_json(sy_web *w, uint64_t *sent)
{
    if (w->views_version == *sent) return NULL;
    cJSON *o = cJSON_CreateObject(), *arr = cJSON_AddArrayToObject(o, "views");
    cJSON_AddStringToObject(o, "t", "views");
    for (uint32_t i = 1; i <= SY_BOOKMARKS_MAX; ++i) {
        const sy_bookmark *b = &w->marks[i];
        if (!b->set) continue;
        cJSON *v = cJSON_CreateObject();
        cJSON_AddNumberToObject(v, "n", i);
        cJSON_AddItemToObject(v, "eye", cJSON_CreateFloatArray(b->eye, 3));
        cJSON_AddItemToObject(v, "target", cJSON_CreateFloatArray(b->target, 3));
        if (b->fov > 0.0f) cJSON_AddNumberToObject(v, "fov", b->fov * 180.0 / 3.14159265358979323846); /* degrees */
        cJSON_AddItemToArray(arr, v);
    }
    cJSON_AddBoolToObject(o, "kept", w->bookmarks != NULL); /* in a file (else by the server only) */
    if (w->views_note[0]) cJSON_AddStringToObject(o, "note", w->views_note);
    char *s = cJSON_PrintUnformatted(o);
    cJSON_Delete(o);
    if (s) *sent = w->views_version;
    return s;
}

bool sy_webi_views_set_fov(sy_web *w, float fov)
{
    sy_error e = {0};
    sy_result r = sy_interactive_set_fov(w->d.scene, w->d.camera, fov, &e);
    if (r != SY_OK) sy_log(SY_LOG_WARNING, "web", NULL, "a saved view's field of view: %s", e.message);
    return r == SY_OK;
}
