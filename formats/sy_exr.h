/** @file
 * sy_exr.h — OpenEXR output of render layers (colour, depth, feature AOVs) and input of any
 * scanline or tiled OpenEXR image (reference renders, environment maps), on the OpenEXR C core API.
 *
 * Conventions (those of sy_layer, sy_mediator.h): pixel (x, y) with row 0 at the TOP, which is also the EXR
 * orientation (y grows downwards in the data window). Colour stays linear scene-referred; depth is
 * linear distance with +INFINITY for "nothing hit", stored as FLOAT so it survives exactly.
 *
 * Files are written through sy_atomic_file (temp file, fsync, rename): a failed write leaves no
 * file and no partial file, and an existing target stays untouched.
 *
 * The reader treats its input as untrusted: malformed, truncated or hostile files give an error
 * naming the file and the reason, never a crash; sizes are capped (SY_EXR_MAX_*) with checked
 * arithmetic before anything is allocated from them.
 *
 * Thread-safety: no shared mutable state; distinct calls may run concurrently on distinct files.
 * A sy_exr_image is plain data; reading it from several threads at once is safe. */
#ifndef SY_EXR_H
#define SY_EXR_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Limits applied by the reader (and the writer, for symmetry). */
#define SY_EXR_MAX_SIDE 65536                 /**< pixels per side of the data window */
#define SY_EXR_MAX_PIXELS (1u << 28)          /**< width * height */
#define SY_EXR_MAX_CHANNELS 1024 /**< channels per image */
#define SY_EXR_MAX_SAMPLES ((size_t)1 << 30)  /**< width * height * channels (4 GiB of floats) */

/** Storage type of a channel in the file. Values match nothing outside this header. */
typedef enum sy_exr_pixel_type {
    SY_EXR_PIXEL_FLOAT = 0, /**< 32-bit float: exact (the default) */
    SY_EXR_PIXEL_HALF = 1,  /**< 16-bit float: 11 significant bits, max 65504, keeps +-INF */
    SY_EXR_PIXEL_UINT = 2,  /**< 32-bit unsigned integer: reported by the reader, not written */
    SY_EXR_PIXEL_MAX_ENUM = 0x7fffffff
} sy_exr_pixel_type;

/** Lossless compressions only: render outputs are reference data. */
typedef enum sy_exr_compression {
    SY_EXR_COMPRESSION_DEFAULT = 0, /* = ZIP */
    SY_EXR_COMPRESSION_NONE = 1,
    SY_EXR_COMPRESSION_RLE = 2,
    SY_EXR_COMPRESSION_ZIPS = 3,    /**< zlib, one scanline per chunk */
    SY_EXR_COMPRESSION_ZIP = 4,     /**< zlib, 16 scanlines per chunk */
    SY_EXR_COMPRESSION_PIZ = 5,     /**< wavelet + Huffman, good for noisy images */
    SY_EXR_COMPRESSION_MAX_ENUM = 0x7fffffff
} sy_exr_compression;

/** One channel to write. The value of pixel (x, y) is
 *     data[((size_t)y * width + x) * pixel_stride + offset]
 * so an interleaved RGBA buffer gives four channels with the same data, pixel_stride 4 and
 * offsets 0..3, and a separate plane gives pixel_stride 1, offset 0.
 * Ownership: data is borrowed for the duration of the write call only. */
typedef struct sy_exr_channel_desc {
    const char *name;       /**< "R", "G", "B", "A", "Z", "albedo.R", ... (1..255 bytes, unique) */
    const float *data; /**< the values (see above) */
    size_t pixel_stride;    /**< in floats; 0 means 1 */
    size_t offset;          /**< in floats, added to every pixel's index */
    sy_exr_pixel_type type; /**< FLOAT (default) or HALF */
} sy_exr_channel_desc;

/** One string attribute of the header (metadata such as "sy:samples" = "128"). Names must not
 * collide with the required attributes (channels, compression, dataWindow, ...).
 * Ownership: borrowed for the duration of the write call only. */
typedef struct sy_exr_attribute {
    const char *name;  /**< 1..SY_EXR_MAX_ATTRIBUTE_NAME bytes */
    const char *value; /**< any length up to SY_EXR_MAX_ATTRIBUTE_VALUE bytes */
} sy_exr_attribute;
#define SY_EXR_MAX_ATTRIBUTES 64 /**< string attributes per header */
#define SY_EXR_MAX_ATTRIBUTE_NAME 255 /**< bytes of an attribute name */
#define SY_EXR_MAX_ATTRIBUTE_VALUE 4096 /**< bytes of an attribute value */

/** A single-part scanline image to write; zero-initialised fields mean the defaults. */
typedef struct sy_exr_write_desc {
    /** @{ 1..SY_EXR_MAX_SIDE each */
    int width, height; /** @} */
    sy_exr_compression compression; /**< default ZIP */
    const sy_exr_channel_desc *channels; /**< the channels to write */
    int channel_count;              /**< 1..SY_EXR_MAX_CHANNELS */
    const sy_exr_attribute *attributes; /**< extra string attributes, may be NULL */
    int attribute_count;                /**< 0..SY_EXR_MAX_ATTRIBUTES */
} sy_exr_write_desc;

/** Writes desc to path (temp file + rename). Channels may be given in any order (the file stores
 * them sorted by name). Errors name the file and the reason.
 * Ownership: borrows everything in desc for the duration of the call. */
sy_result sy_exr_write(const char *path, const sy_exr_write_desc *desc, sy_error *err);

/** Convenience for a render layer: rgba is w*h interleaved premultiplied linear RGBA floats, row 0 at
 * the top, written as channels R, G, B, A of type color_type (HALF or FLOAT); depth, when not NULL,
 * is w*h floats written as channel Z, always FLOAT (so +INFINITY and metres survive exactly).
 * ZIP compression. */
sy_result sy_exr_write_rgba(const char *path, int width, int height, const float *rgba, const float *depth,
                            sy_exr_pixel_type color_type, sy_error *err);

/** The same with extra string attributes in the header (attribute_count 0..SY_EXR_MAX_ATTRIBUTES). */
sy_result sy_exr_write_rgba_attrs(const char *path, int width, int height, const float *rgba, const float *depth,
                                  sy_exr_pixel_type color_type, const sy_exr_attribute *attributes,
                                  int attribute_count, sy_error *err);

/** One channel of a read image. */
typedef struct sy_exr_plane {
    char *name;                   /**< as in the file, NUL-terminated */
    sy_exr_pixel_type stored_type; /**< how the file stored it (HALF, FLOAT or UINT) */
    float *data;                  /**< width * height floats, row 0 at the top; UINT converted to float */
} sy_exr_plane;

/** A string attribute of a read header (owned copies). */
typedef struct sy_exr_text {
    /** @{ attribute name and value (NUL-terminated) */
    char *name, *value; /** @} */
} sy_exr_text;

/** A decoded image: the data window of the first part, level 0 of a tiled part (sy_exr_image_free). */
typedef struct sy_exr_image {
    /** @{ data window size */
    int width, height; /** @} */
    /** @{ data window minimum (usually 0, 0) */
    int origin_x, origin_y; /** @} */
    int channel_count; /**< entries of channels */
    sy_exr_plane *channels;     /**< sorted by name, as the file lists them */
    int attribute_count;        /**< the header's string attributes, in file order (at most SY_EXR_MAX_ATTRIBUTES
                                   are kept; longer values are cut at SY_EXR_MAX_ATTRIBUTE_VALUE bytes) */
    sy_exr_text *attributes; /**< the attributes (see attribute_count) */
} sy_exr_image;

/** Reads the first part of the OpenEXR file at path (scanline or tiled; HALF, FLOAT and UINT
 * channels) into float planes. Multi-part files: only part 0 is read. Deep images and sub-sampled
 * channels give SY_ERR_UNSUPPORTED; damaged files SY_ERR_PARSE; a missing file SY_ERR_NOT_FOUND;
 * sizes beyond SY_EXR_MAX_* SY_ERR_LIMIT.
 * Ownership: on success the caller owns *out and releases it with sy_exr_image_free; on failure
 * *out is NULL. */
sy_result sy_exr_read(const char *path, sy_exr_image **out, sy_error *err);

/** Limits of a read; zero fields mean the SY_EXR_MAX_* defaults (larger values are capped to them). */
typedef struct sy_exr_read_options {
    uint64_t max_pixels; /**< width * height of the data window */
    size_t max_samples;  /**< width * height * channels */
} sy_exr_read_options;

/** Reads an OpenEXR image held in memory (size bytes at data, borrowed for the call) with the given
 * limits (opts NULL = defaults); `name` names it in messages. Otherwise as sy_exr_read.
 * Before anything is allocated from the header, the data window is checked against the limits and
 * against the input size: width * height * channel bytes must fit the bytes present at the best
 * ratio the compression can reach (1:1 uncompressed, 64:1 RLE, ~1032:1 zlib, ...), and the chunk
 * offset table must fit; otherwise SY_ERR_PARSE ("truncated"). sy_exr_read applies the same. */
sy_result sy_exr_read_memory(const void *data, size_t size, const char *name, const sy_exr_read_options *opts,
                             sy_exr_image **out, sy_error *err);

/** The plane of the channel called name (exact, case-sensitive match), or NULL if there is none.
 * Ownership: the pointer belongs to img and lives until sy_exr_image_free. */
const float *sy_exr_image_channel(const sy_exr_image *img, const char *name);

/** Releases img and everything it owns. NULL is a no-op. */
void sy_exr_image_free(sy_exr_image *img);

#ifdef __cplusplus
}
#endif
#endif /* SY_EXR_H */
