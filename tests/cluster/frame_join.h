/* frame_join.h — a receiver's reassembly of cluster messages from a byte stream of frames, for the
 * tests that feed the wire format raw bytes (test_cluster_proto's stream test, the
 * fuzz_cluster_decode target). Header-only, test-only.
 *
 * The first message is read under the handshake's budget, every later one under the session's
 * (frame_join_next switches). frame_join_take reads one frame: its header is checked against the
 * budget and the frames before it (sy_cluster_frame_check), its body appended to j->body. When a
 * frame completes a message, j->first (the header of its first frame), j->body and j->size are
 * that message; the caller decodes (or takes) the body, then calls frame_join_next. */
#ifndef SY_TEST_FRAME_JOIN_H
#define SY_TEST_FRAME_JOIN_H

#include "sy_cluster.h"

#include <stdlib.h>
#include <string.h>

typedef struct frame_join {
    sy_cluster_budget session;     /* the budget after the first message */
    bool tags_from_frames;         /* session.tagged follows each frame's flag (tags not checked) */
    const sy_cluster_budget *budget; /* the budget now */
    uint8_t *body;                 /* the message so far (malloc()ed; the caller may take it) */
    size_t size;                   /* its body bytes */
    uint32_t type;                 /* its type, 0 before its first frame */
    sy_cluster_header first;       /* the header of its first frame */
} frame_join;

/* The handshake's budget: the first message of a stream. */
static const sy_cluster_budget frame_join_handshake = {SY_CLUSTER_HANDSHAKE_MAX_FRAME, SY_CLUSTER_HANDSHAKE_MAX_FRAME,
                                                       false, false};

/* A joiner at the start of a stream whose session allows frames of max_frame and messages of
 * max_message bytes, chunked, untagged (tags_from_frames: tagged where a frame says so). */
static inline frame_join frame_join_start(size_t max_frame, size_t max_message, bool tags_from_frames)
{
    frame_join j;
    memset(&j, 0, sizeof j);
    j.session = (sy_cluster_budget){max_frame, max_message, true, false};
    j.tags_from_frames = tags_from_frames;
    j.budget = &frame_join_handshake;
    return j;
}

/* Reads the frame at buf + *pos (buf holds n bytes) and moves *pos past it: 1 when it completed a
 * message, 0 when more frames of the message follow, -1 when the stream ends inside the header or
 * the frame, or the frame is refused (err says why). */
static inline int frame_join_take(frame_join *j, const uint8_t *buf, size_t n, size_t *pos, sy_error *err)
{
    sy_cluster_header h;
    size_t follow;
    if (n - *pos < SY_CLUSTER_HEADER_SIZE) return sy_error_set(err, SY_ERR_PARSE, "stream ends inside a header"), -1;
    if (sy_cluster_parse_header(buf + *pos, &h, err) != SY_OK) return -1;
    if (j->tags_from_frames) j->session.tagged = (h.flags & SY_CLUSTER_FLAG_TAGGED) != 0;
    if (sy_cluster_frame_check(&h, j->budget, j->size, j->type, &follow, err) != SY_OK) return -1;
    *pos += SY_CLUSTER_HEADER_SIZE;
    if (follow > n - *pos) return sy_error_set(err, SY_ERR_PARSE, "stream ends inside a frame"), -1;
    uint8_t *nb = realloc(j->body, j->size + h.body_size + 1);
    if (!nb) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory joining frames"), -1;
    j->body = nb;
    memcpy(j->body + j->size, buf + *pos, h.body_size);
    *pos += follow;
    if (!j->type) j->first = h;
    j->type = h.type;
    j->size += h.body_size;
    return (h.flags & SY_CLUSTER_FLAG_MORE) ? 0 : 1;
}

/* After a complete message: the next one starts, under the session's budget. */
static inline void frame_join_next(frame_join *j)
{
    j->size = 0;
    j->type = 0;
    j->budget = &j->session;
}

#endif /* SY_TEST_FRAME_JOIN_H */
