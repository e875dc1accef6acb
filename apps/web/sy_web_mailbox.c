/* sy_web_mailbox.c — what the network thread and the render thread of the sy_web server share
 * (under mu): the jobs they pass each other, the newest frame
 * (sy_web_internal.h; docs/WEB.md, "Threads"). */
#include "sy_web_internal.h"

#include <stdlib.h>

void sy_webi_frame_release(sy_web *w, web_frame *f)
{
    if (!f) return;
    pthread_mutex_lock(&w->mu);
    bool last = --f->refs == 0;
    pthread_mutex_unlock(&w->mu);
    if (last) sy_webi_frame_free(f);
}

void sy_webi_frame_free(web_frame *f)
{
    if (!f) return;
    free(f->buf);
    free(f->rgba);
    free(f);
}

void sy_webi_job_free(web_job *j)
{
    if (!j) return;
    free(j->body);
    free(j->resp.body);
    free(j);
}

/* Render thread -> network thread: wake the service loop (it runs EVENT_WAIT_CANCELLED). */
void sy_webi_wake_network(sy_web *w)
{
    if (w->ctx) lws_cancel_service(w->ctx);
}

/* Network thread -> render thread: j appended to the queue whose tail pointer is *tail. */
static void post_to(sy_web *w, web_job ***tail, web_job *j)
{
    pthread_mutex_lock(&w->mu);
    j->state = JOB_PENDING;
    j->next = NULL;
    **tail = j;
    *tail = &j->next;
    pthread_cond_signal(&w->cv);
    pthread_mutex_unlock(&w->mu);
}

void sy_webi_post_job(sy_web *w, web_job *j) { post_to(w, &w->pending_tail, j); }

void sy_webi_post_still(sy_web *w, web_job *j) { post_to(w, &w->stills_tail, j); }

bool sy_webi_job_abandoned(sy_web *w, const web_job *j)
{
    pthread_mutex_lock(&w->mu);
    bool gone = j->abandoned;
    pthread_mutex_unlock(&w->mu);
    return gone;
}
