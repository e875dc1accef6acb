/* sy_cluster_mpi.c — the MPI transport (see sy_cluster_mpi.h): byte streams over MPI point-to-point
 * messages, a listener that takes connection requests from any rank, the job secret and the
 * server ranks' lifetime. */
#include "sy_cluster_mpi.h"
#include "sy_cluster_transport.h"

#include <mpi.h>
#include <sodium.h>

#include <limits.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define TAG_CONNECT 1        /* a client asks for a stream: int32 stream id */
#define TAG_DATA_BASE 1000   /* a stream's messages: TAG_DATA_BASE + its id */
#define TAG_IDS 1000000      /* stream ids wrap here (tags stay far below MPI_TAG_UB >= 32767? see init) */
#define CHUNK_MAX (1 << 30)  /* one MPI message at most (MPI counts are int) */

static int g_rank = -1, g_size = 0, g_tag_ids = TAG_IDS;
static atomic_uint g_next_id;

/* Polls with a growing sleep: 20 us at first (latency), up to 1 ms (idle waits cost no core). */
static void backoff(unsigned *us)
{
    struct timespec ts = {0, (long)*us * 1000L};
    nanosleep(&ts, NULL);
    if (*us < 1000) *us *= 2;
}

/* >>streams */
typedef struct pending_send {
    MPI_Request req;
    void *buf;
    struct pending_send *next;
} pending_send;

typedef struct mpi_strm {
    sy_cluster_stream base;
    int peer_rank, tag;
    atomic_bool closed;
    atomic_flag eof_sent;
    uint8_t *rx;           /* the last message received, partly handed out */
    size_t rx_len, rx_off;
    pending_send *sends;   /* sends past their deadline, freed once complete */
} mpi_strm;

static void reap_sends(mpi_strm *s, bool cancel)
{
    for (pending_send **pp = &s->sends; *pp;) {
        pending_send *p = *pp;
        int done = 0;
        if (cancel) {
            MPI_Cancel(&p->req);
            MPI_Wait(&p->req, MPI_STATUS_IGNORE);
            done = 1;
        } else MPI_Test(&p->req, &done, MPI_STATUS_IGNORE);
        if (done) {
            *pp = p->next;
            free(p->buf);
            free(p);
        } else pp = &p->next;
    }
}

static sy_stream_status strm_send(mpi_strm *s, const sy_cluster_iov *iov, unsigned n, double deadline, size_t *moved,
                                  char *msg, size_t msg_len)
{
    size_t total = 0;
    for (unsigned i = 0; i < n; ++i) total += iov[i].len;
    if (total > CHUNK_MAX) total = CHUNK_MAX; /* the caller sends the rest in the next call */
    uint8_t *buf = malloc(total ? total : 1);
    if (!buf) {
        snprintf(msg, msg_len, "out of memory for a %zu-byte message", total);
        return SY_STREAM_FAILED;
    }
    size_t off = 0;
    for (unsigned i = 0; i < n && off < total; ++i) {
        size_t k = iov[i].len < total - off ? iov[i].len : total - off;
        memcpy(buf + off, iov[i].buf, k);
        off += k;
    }
    MPI_Request req;
    if (MPI_Isend(buf, (int)total, MPI_BYTE, s->peer_rank, s->tag, MPI_COMM_WORLD, &req) != MPI_SUCCESS) {
        free(buf);
        snprintf(msg, msg_len, "MPI_Isend to rank %d failed", s->peer_rank);
        return SY_STREAM_FAILED;
    }
    unsigned us = 20;
    for (;;) {
        int done = 0;
        MPI_Test(&req, &done, MPI_STATUS_IGNORE);
        if (done) break;
        bool late = deadline > 0 && sy_time_now() > deadline;
        if (late || atomic_load(&s->closed)) { /* the buffer stays until MPI is done with it */
            pending_send *p = malloc(sizeof *p);
            if (p) {
                *p = (pending_send){req, buf, s->sends};
                s->sends = p;
            } else {
                MPI_Cancel(&req);
                MPI_Wait(&req, MPI_STATUS_IGNORE);
                free(buf);
            }
            atomic_store(&s->closed, true); /* a stream cut mid-message cannot be used again */
            snprintf(msg, msg_len, "%s", late ? "rank did not take the data before the deadline" : "closed");
            return late ? SY_STREAM_TIMEDOUT : SY_STREAM_CLOSED;
        }
        backoff(&us);
    }
    free(buf);
    reap_sends(s, false);
    *moved = total;
    return SY_STREAM_OK;
}

static sy_stream_status strm_recv(mpi_strm *s, const sy_cluster_iov *iov, unsigned n, double deadline, size_t *moved,
                                  char *msg, size_t msg_len)
{
    if (s->rx_off == s->rx_len) {
        free(s->rx);
        s->rx = NULL;
        s->rx_len = s->rx_off = 0;
        unsigned us = 20;
        MPI_Message m;
        MPI_Status st;
        for (;;) {
            int flag = 0;
            if (atomic_load(&s->closed)) {
                snprintf(msg, msg_len, "closed");
                return SY_STREAM_CLOSED;
            }
            MPI_Improbe(s->peer_rank, s->tag, MPI_COMM_WORLD, &flag, &m, &st);
            if (flag) break;
            if (deadline > 0 && sy_time_now() > deadline) {
                snprintf(msg, msg_len, "no data before the deadline");
                return SY_STREAM_TIMEDOUT;
            }
            backoff(&us);
        }
        int count = 0;
        MPI_Get_count(&st, MPI_BYTE, &count);
        uint8_t *buf = malloc(count > 0 ? (size_t)count : 1);
        if (!buf) {
            MPI_Mrecv(NULL, 0, MPI_BYTE, &m, MPI_STATUS_IGNORE); /* cannot: drop the stream */
            atomic_store(&s->closed, true);
            snprintf(msg, msg_len, "out of memory for a %d-byte message", count);
            return SY_STREAM_FAILED;
        }
        MPI_Mrecv(buf, count, MPI_BYTE, &m, MPI_STATUS_IGNORE);
        if (count == 0) { /* the peer closed the stream */
            free(buf);
            atomic_store(&s->closed, true);
            snprintf(msg, msg_len, "connection shut by rank %d", s->peer_rank);
            return SY_STREAM_CLOSED;
        }
        s->rx = buf;
        s->rx_len = (size_t)count;
    }
    size_t got = 0;
    for (unsigned i = 0; i < n && s->rx_off < s->rx_len; ++i) {
        size_t k = s->rx_len - s->rx_off < iov[i].len ? s->rx_len - s->rx_off : iov[i].len;
        memcpy(iov[i].buf, s->rx + s->rx_off, k);
        s->rx_off += k;
        got += k;
    }
    *moved = got;
    return SY_STREAM_OK;
}

static sy_stream_status strm_io(sy_cluster_stream *base, bool send, const sy_cluster_iov *iov, unsigned n,
                                double deadline, size_t *moved, char *msg, size_t msg_len)
{
    mpi_strm *s = (mpi_strm *)base;
    *moved = 0;
    if (atomic_load(&s->closed) && (send || s->rx_off == s->rx_len)) {
        snprintf(msg, msg_len, "closed");
        return SY_STREAM_CLOSED;
    }
    return send ? strm_send(s, iov, n, deadline, moved, msg, msg_len) : strm_recv(s, iov, n, deadline, moved, msg, msg_len);
}

static void strm_close(sy_cluster_stream *base)
{
    mpi_strm *s = (mpi_strm *)base;
    atomic_store(&s->closed, true);
    if (!atomic_flag_test_and_set(&s->eof_sent)) /* an empty message: end of stream for the peer */
        MPI_Send(NULL, 0, MPI_BYTE, s->peer_rank, s->tag, MPI_COMM_WORLD);
}

static void strm_free(sy_cluster_stream *base)
{
    mpi_strm *s = (mpi_strm *)base;
    if (!s) return;
    strm_close(base);
    reap_sends(s, true);
    free(s->rx);
    free(s);
}

static const sy_cluster_stream_ops mpi_stream_ops = {strm_io, strm_close, strm_free};

static mpi_strm *strm_new(int peer, int id)
{
    mpi_strm *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->base.ops = &mpi_stream_ops;
    s->peer_rank = peer;
    s->tag = TAG_DATA_BASE + id;
    atomic_init(&s->closed, false);
    atomic_flag_clear(&s->eof_sent);
    snprintf(s->base.peer, sizeof s->base.peer, "mpi rank %d (stream %d)", peer, id);
    snprintf(s->base.host, sizeof s->base.host, "mpi rank %d", peer);
    return s;
}

/* >>listener */
typedef struct mpi_lst {
    sy_cluster_listener base;
    atomic_bool closed;
} mpi_lst;

static sy_stream_status lst_accept(sy_cluster_listener *base, sy_cluster_stream **out, char *msg, size_t msg_len)
{
    mpi_lst *l = (mpi_lst *)base;
    *out = NULL;
    unsigned us = 20;
    for (;;) {
        if (atomic_load(&l->closed)) return SY_STREAM_CLOSED;
        int flag = 0;
        MPI_Message m;
        MPI_Status st;
        MPI_Improbe(MPI_ANY_SOURCE, TAG_CONNECT, MPI_COMM_WORLD, &flag, &m, &st);
        if (!flag) {
            backoff(&us);
            continue;
        }
        int32_t id = -1;
        int count = 0;
        MPI_Get_count(&st, MPI_BYTE, &count);
        if (count != (int)sizeof id) {
            uint8_t junk[64];
            MPI_Mrecv(count <= (int)sizeof junk ? junk : NULL, count <= (int)sizeof junk ? count : 0, MPI_BYTE, &m,
                      MPI_STATUS_IGNORE);
            snprintf(msg, msg_len, "mpi rank %d: connection request of %d bytes refused", st.MPI_SOURCE, count);
            return SY_STREAM_FAILED;
        }
        MPI_Mrecv(&id, (int)sizeof id, MPI_BYTE, &m, MPI_STATUS_IGNORE);
        if (id < 0 || id >= g_tag_ids) {
            snprintf(msg, msg_len, "mpi rank %d: stream id %d out of range", st.MPI_SOURCE, (int)id);
            return SY_STREAM_FAILED;
        }
        mpi_strm *s = strm_new(st.MPI_SOURCE, id);
        if (!s) {
            snprintf(msg, msg_len, "mpi rank %d: out of memory", st.MPI_SOURCE);
            return SY_STREAM_FAILED;
        }
        *out = &s->base;
        return SY_STREAM_OK;
    }
}

static void lst_close(sy_cluster_listener *base) { atomic_store(&((mpi_lst *)base)->closed, true); }
static void lst_free(sy_cluster_listener *base) { free(base); }
static const sy_cluster_listener_ops mpi_listener_ops = {lst_accept, lst_close, lst_free};

static sy_result mpi_listen(const char *url, const sy_cluster_listen_opts *o, sy_cluster_listener **out, sy_error *err)
{
    (void)o;
    if (g_rank < 0) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: MPI is not initialised", url);
    if (strcmp(url, "mpi://") && strcmp(url, "mpi://*"))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: an MPI server listens on mpi:// (any rank)", url);
    mpi_lst *l = calloc(1, sizeof *l);
    if (!l) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", url);
    l->base.ops = &mpi_listener_ops;
    l->base.trusted = true; /* ranks are the launcher's: no secret file needed to listen */
    atomic_init(&l->closed, false);
    *out = &l->base;
    return SY_OK;
}

static sy_result mpi_dial(const char *url, const sy_cluster_dial_opts *o, sy_cluster_stream **out, sy_error *err)
{
    (void)o;
    if (g_rank < 0) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: MPI is not initialised", url);
    char *end = NULL;
    long r = strtol(url + 6, &end, 10);
    if (end == url + 6 || *end || r < 0 || r >= g_size || r == g_rank)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: not another rank of this job (0..%d, this is %d)", url,
                            g_size - 1, g_rank);
    int32_t id = (int32_t)(atomic_fetch_add(&g_next_id, 1) % (unsigned)g_tag_ids);
    mpi_strm *s = strm_new((int)r, id);
    if (!s) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", url);
    if (MPI_Send(&id, (int)sizeof id, MPI_BYTE, (int)r, TAG_CONNECT, MPI_COMM_WORLD) != MPI_SUCCESS) {
        free(s);
        return sy_error_set(err, SY_ERR_IO, "%s: cannot connect: MPI_Send failed", url);
    }
    *out = &s->base;
    return SY_OK;
}

static const sy_cluster_transport mpi_transport = {.scheme = "mpi", .listen = mpi_listen, .dial = mpi_dial};

/* >>job */
bool sy_cluster_mpi_launched(void)
{
    static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"};
    for (size_t i = 0; i < sizeof vars / sizeof vars[0]; ++i)
        if (getenv(vars[i])) return true;
    return getenv("SLURM_PROCID") && getenv("SLURM_NTASKS"); /* srun --mpi=pmix */
}

sy_result sy_cluster_mpi_init(int *rank, int *size, sy_error *err)
{
    int provided = 0, inited = 0;
    MPI_Initialized(&inited);
    if (!inited && MPI_Init_thread(NULL, NULL, MPI_THREAD_MULTIPLE, &provided) != MPI_SUCCESS)
        return sy_error_set(err, SY_ERR_BACKEND, "MPI: MPI_Init_thread failed");
    if (inited) MPI_Query_thread(&provided);
    if (provided < MPI_THREAD_MULTIPLE)
        return sy_error_set(err, SY_ERR_UNSUPPORTED,
                            "MPI: the library offers thread level %d, the cluster needs MPI_THREAD_MULTIPLE (%d)", provided,
                            MPI_THREAD_MULTIPLE);
    MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &g_size);
    void *ub = NULL;
    int flag = 0;
    MPI_Comm_get_attr(MPI_COMM_WORLD, MPI_TAG_UB, &ub, &flag);
    if (flag && ub) {
        int tag_ub = *(int *)ub;
        if (tag_ub - TAG_DATA_BASE < g_tag_ids) g_tag_ids = tag_ub - TAG_DATA_BASE;
        if (g_tag_ids < 64) return sy_error_set(err, SY_ERR_UNSUPPORTED, "MPI: tags end at %d, too few streams", tag_ub);
    }
    *rank = g_rank;
    *size = g_size;
    if (sodium_init() < 0) return sy_error_set(err, SY_ERR_BACKEND, "MPI: libsodium failed to initialise");
    return sy_cluster_transport_register(&mpi_transport, err);
}

sy_result sy_cluster_mpi_job_secret(uint8_t secret[32], sy_error *err)
{
    if (g_rank < 0) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "MPI: not initialised");
    if (g_rank == 0) randombytes_buf(secret, 32);
    if (MPI_Bcast(secret, 32, MPI_BYTE, 0, MPI_COMM_WORLD) != MPI_SUCCESS)
        return sy_error_set(err, SY_ERR_IO, "MPI: the job secret could not be broadcast");
    return SY_OK;
}

/* Rank 0's release: a non-blocking barrier every rank enters (servers poll it, so no core spins). */
static void release_wait(volatile int *stop)
{
    MPI_Request req;
    MPI_Ibarrier(MPI_COMM_WORLD, &req);
    for (;;) {
        int done = 0;
        MPI_Test(&req, &done, MPI_STATUS_IGNORE);
        if (done) break;
        struct timespec ts = {0, 10000000L};
        nanosleep(&ts, NULL);
    }
    if (stop) *stop = 1;
}

static void *release_main(void *arg)
{
    release_wait(arg);
    return NULL;
}

sy_result sy_cluster_mpi_serve(const sy_cluster_server_opts *opts, const uint8_t *secret, size_t secret_len,
                               sy_error *err)
{
    volatile int stop = 0;
    sy_cluster_server_opts o = *opts;
    o.listen_url = "mpi://";
    o.secret = secret;
    o.secret_len = secret_len;
    o.stop = &stop;
    sy_cluster_server *s = NULL;
    sy_result r = sy_cluster_server_create(&o, &s, err);
    pthread_t th;
    bool waiter = false;
    if (r == SY_OK) waiter = pthread_create(&th, NULL, release_main, (void *)&stop) == 0;
    if (r == SY_OK && !waiter) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "MPI: cannot start the release thread");
    if (r == SY_OK) r = sy_cluster_server_run(s, err);
    if (waiter) pthread_join(th, NULL);
    else release_wait(NULL); /* rank 0 still releases every rank: do not leave it waiting */
    sy_cluster_server_destroy(s);
    return r;
}

bool sy_cluster_mpi_urls(char *buf, size_t len)
{
    size_t off = 0;
    if (len) buf[0] = 0;
    for (int r = 1; r < g_size; ++r) {
        int n = snprintf(buf + off, len - off, "%smpi://%d", r > 1 ? "," : "", r);
        if (n < 0 || (size_t)n >= len - off) return false;
        off += (size_t)n;
    }
    return g_size > 1;
}

void sy_cluster_mpi_release(void) { release_wait(NULL); }

void sy_cluster_mpi_finalize(void)
{
    int inited = 0, finalized = 0;
    MPI_Initialized(&inited);
    MPI_Finalized(&finalized);
    if (inited && !finalized) MPI_Finalize();
}
