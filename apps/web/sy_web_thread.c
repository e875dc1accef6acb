/* sy_web_thread.c — sy_web_run on a thread of its own (see sy_web_thread.h). */
#include "sy_web_thread.h"

#include <pthread.h>
#include <stdlib.h>

struct sy_web_thread {
    sy_web *web;
    pthread_t thread;
    sy_result result; /* what sy_web_run returned */
    sy_error err;
};

static void *web_thread_main(void *arg)
{
    sy_web_thread *t = arg;
    t->result = sy_web_run(t->web, NULL, &t->err);
    return NULL;
}

sy_result sy_web_thread_start(sy_web *w, sy_web_thread **out, sy_error *err)
{
    *out = NULL;
    sy_web_thread *t = calloc(1, sizeof *t);
    if (!t) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory for the server's thread");
    t->web = w;
    if (pthread_create(&t->thread, NULL, web_thread_main, t) != 0) {
        free(t);
        return sy_error_set(err, SY_ERR_SYSTEM, "web: cannot start the server's thread");
    }
    *out = t;
    return SY_OK;
}

sy_result sy_web_thread_join(sy_web_thread *t, sy_error *err)
{
    if (!t) return SY_OK;
    sy_web_stop(t->web);
    pthread_join(t->thread, NULL);
    sy_result r = t->result;
    if (r != SY_OK && err) *err = t->err;
    free(t);
    return r;
}
