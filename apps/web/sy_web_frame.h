/** @file
 * sy_web_frame.h — the binary frame of sy web's stream, format 3 (docs/WEB.md, "Binary frames"):
 * a 192-byte little-endian header (size, back-end, samples, the frame's camera and orbit, the
 * depth range, the payload's codec), the payload (the JPEG, or a video viewer's VP8 / VP9 frame:
 * sy_web_video.h), then the depth channel: view depth on a grid of every fourth pixel and the last
 * column and row (the page's warp mesh has a vertex every 2, 4 or 8 pixels: at 4 and 8 exactly the
 * grid's; between grid points 1 / depth is interpolated), 12-bit log-quantised, each value
 * minus its MED (LOCO-I) prediction, split into a low-byte and a high-byte plane and deflated (zlib
 * format: the page inflates it with the browser's own DecompressionStream("deflate"); zstd, which
 * the cluster uses, has no decoder in the browser). A frame whose depth is the one its viewer was
 * last sent (a progressive back-end's refinement of the same view) carries none and says so
 * (SY_WEB_FRAME_SAME_DEPTH). The server packs frames with sy_web_frame_pack; clients
 * (sy_web_client.h, the tests) read them with sy_web_frame_parse and sy_web_frame_depth.
 *
 * Ownership: buffers returned are malloc()ed and owned by the caller (free()).
 * Thread-safety: pure functions on caller-owned data. */
#ifndef SY_WEB_FRAME_H
#define SY_WEB_FRAME_H

#include "sy_common.h"
#include "sy_objects.h" /* before sy_request.h */
#include "sy_orbit.h"
#include "sy_request.h"
#include "sy_web_video.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SY_WEB_FRAME_MAGIC 0x33465953u /**< "SYF3": "SYF" and the format's digit */
#define SY_WEB_FRAME_VERSION 3u        /**< the format (the page sends it in its size message: "v") */
#define SY_WEB_FRAME_HEADER 192u       /**< header bytes */
#define SY_WEB_DEPTH_GRID_LOG12 2u     /**< the depth coding (header offset 52): 12-bit log depth on the grid */
#define SY_WEB_DEPTH_STEP 4u           /**< the grid's step in pixels (and its last column and row) */
#define SY_WEB_FRAME_PROGRESSIVE 1u    /**< flags: the back-end accumulates samples while the view rests */
#define SY_WEB_FRAME_KEYFRAME 2u       /**< flags: a video payload that is a keyframe (decodable alone) */
/** flags: no depth channel in this frame (depth bytes 0): its depth is the last depth channel this
 * viewer was sent (a frame of the same size and camera; the header's depth range is that one's). */
#define SY_WEB_FRAME_SAME_DEPTH 4u

/** A frame's header (docs/WEB.md). */
typedef struct sy_web_frame_info {
    uint32_t width;     /**< frame width */
    uint32_t height;    /**< frame height */
    uint32_t backend;   /**< back-end index (registry order, the hello message) */
    uint32_t samples;   /**< samples per pixel accumulated (progressive back-ends) */
    float render_ms;    /**< the server's render time */
    uint64_t seq;       /**< the frame's number */
    uint64_t input_id;  /**< the newest input of this client it answers */
    uint32_t jpeg_len;  /**< payload bytes after the header: the JPEG, or the video frame (codec) */
    uint32_t depth_len; /**< deflated depth bytes after the JPEG (0: no depth) */
    uint32_t depth_coding; /**< SY_WEB_DEPTH_GRID_LOG12 */
    float depth_min, depth_max; /**< the nearest and farthest depth of the frame (view units) */
    sy_camera_view view; /**< camera_to_world, projection, window, znear, zfar (no clip planes) */
    sy_orbit orbit;      /**< the orbit the frame was rendered from (sy_orbit.h) */
    uint32_t flags;      /**< SY_WEB_FRAME_PROGRESSIVE, SY_WEB_FRAME_KEYFRAME, SY_WEB_FRAME_SAME_DEPTH */
    sy_web_codec codec;  /**< the payload: JPEG (0) or a video codec's frame (docs/WEB.md, "The video stream") */
    float quality;       /**< video: the encoder's PSNR of this frame in dB; JPEG: 0 */
} sy_web_frame_info;

/** Patches a packed header h (no prefix) for another payload: its length (fi->jpeg_len), codec
 * and quality, and ORs fi->flags into the flags (a video viewer's copy of a frame). */
void sy_web_frame_set_payload(uint8_t *h, const sy_web_frame_info *fi);

/** Packs a frame: prefix bytes of room (LWS_PRE), the header of fi (jpeg_len, depth_len,
 * depth_coding, depth_min and depth_max are filled in here), the JPEG, then depth (fi->width x
 * fi->height floats, linear view depth, +INFINITY or <= 0 = nothing; NULL: no depth channel) coded
 * as SY_WEB_DEPTH_GRID_LOG12 (the grid of every fourth pixel, see above). *out (malloc) holds
 * prefix + *len bytes. */
sy_result sy_web_frame_pack(sy_web_frame_info *fi, const uint8_t *jpeg, size_t jpeg_len, const float *depth,
                            size_t prefix, uint8_t **out, size_t *len, sy_error *err);

/** Codes a depth channel (width x height floats, as sy_web_frame_pack takes it) alone: *out
 * (malloc) / *len the deflated bytes, *dmin / *dmax the range to put in the header. */
sy_result sy_web_frame_depth_code(const float *depth, uint32_t width, uint32_t height, uint8_t **out, size_t *len,
                                  float *dmin, float *dmax, sy_error *err);

/** sy_web_frame_pack with a depth channel already coded (sy_web_frame_depth_code: zlen bytes at z,
 * range dmin..dmax; zlen 0: none): the server keeps a view's coded depth for its refinements. */
sy_result sy_web_frame_pack_coded(sy_web_frame_info *fi, const uint8_t *jpeg, size_t jpeg_len, const uint8_t *z,
                                  size_t zlen, float dmin, float dmax, size_t prefix, uint8_t **out, size_t *len,
                                  sy_error *err);

/** Marks a packed header h (no prefix) as a frame without its depth channel whose depth is the
 * last one its viewer was sent (depth bytes 0, SY_WEB_FRAME_SAME_DEPTH): the message is then the
 * header and the payload only. */
void sy_web_frame_drop_depth(uint8_t *h);

/** Reads a frame's header from len bytes; SY_ERR_PROTOCOL naming the reason for anything that is
 * not a whole format-3 frame (magic, version, sizes that do not add up to len, an unknown payload
 * codec or depth coding, SY_WEB_FRAME_SAME_DEPTH with depth bytes). *jpeg and *depth
 * (may be NULL) point into data. */
sy_result sy_web_frame_parse(const uint8_t *data, size_t len, sy_web_frame_info *fi, const uint8_t **jpeg,
                             const uint8_t **depth, sy_error *err);

/** Decodes a frame's depth channel into *out (malloc, width x height floats, each pixel
 * sy_web_depth_grid_at; +INFINITY where nothing was hit); SY_ERR_PROTOCOL when it does not inflate
 * to exactly 2 bytes per grid value ((ceil((width - 1) / 4) + 1) x (ceil((height - 1) / 4) + 1))
 * or holds a value beyond the 12-bit scale. */
sy_result sy_web_frame_depth(const sy_web_frame_info *fi, const uint8_t *depth, float **out, sy_error *err);

/** The depth of pixel (x, y) of a width x height frame from its grid g (gw x gh depths, 0 =
 * nothing; docs/WEB.md, depth coding 2), as the page's warp takes it: a grid point's own value;
 * between grid points 1 / depth interpolated bilinearly from the (up to 4) grid points around it,
 * or where one of them has nothing, the nearest one's value (0: nothing). */
float sy_web_depth_grid_at(const float *g, uint32_t gw, uint32_t gh, uint32_t width, uint32_t height, uint32_t x, uint32_t y);

#ifdef __cplusplus
}
#endif
#endif /* SY_WEB_FRAME_H */
