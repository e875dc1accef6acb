/* sy_exr.c — OpenEXR writer and reader on the OpenEXR C core API (see sy_exr.h).
 *
 * Both directions use our own I/O callbacks: the writer pwrite()s into a sy_atomic_file, the reader
 * pread()s from a descriptor it opened itself and reports the true file size so the library can
 * validate offsets. Library messages are collected through the context's error handler into a
 * per-call buffer (no global state) and appended to our own error message. */
#include "sy_exr.h"

#include "sy_file.h"

#include <openexr.h>

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- >>io: callbacks and error capture shared by reader and writer ---- */

/* Per-call I/O state handed to the library as user_data. */
typedef struct exr_io {
    int fd;
    const uint8_t *mem; /* reader from memory (sy_exr_read_memory): the bytes, fd unused */
    int64_t size;  /* reader: file size in bytes */
    int os_errno;  /* reader: errno of a failed pread (0: reads only ever came up short) */
    char msg[256]; /* first message the library reported for this context */
} exr_io;

static void exr_io_on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)code;
    void *ud = NULL;
    if (!ctxt || exr_get_user_data(ctxt, &ud) != EXR_ERR_SUCCESS || !ud || !msg) return;
    exr_io *io = ud;
    if (io->msg[0] == '\0') snprintf(io->msg, sizeof io->msg, "%s", msg);
}

static int64_t exr_io_read(exr_const_context_t ctxt, void *ud, void *buffer, uint64_t sz, uint64_t offset,
                           exr_stream_error_func_ptr_t error_cb)
{
    exr_io *io = ud;
    if (offset > (uint64_t)INT64_MAX || sz > (uint64_t)INT64_MAX - offset) {
        if (error_cb) error_cb(ctxt, EXR_ERR_READ_IO, "read request beyond any possible file size");
        return -1;
    }
    uint8_t *p = buffer;
    if (io->mem) { /* from memory: a short count past the end, as pread gives */
        uint64_t avail = offset < (uint64_t)io->size ? (uint64_t)io->size - offset : 0;
        uint64_t n = sz < avail ? sz : avail;
        if (n) memcpy(p, io->mem + offset, (size_t)n);
        return (int64_t)n;
    }
    uint64_t done = 0;
    while (done < sz) {
        size_t want = (sz - done) > (uint64_t)(SSIZE_MAX / 2) ? (size_t)(SSIZE_MAX / 2) : (size_t)(sz - done);
        ssize_t n = pread(io->fd, p + done, want, (off_t)(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            io->os_errno = errno;
            if (error_cb) error_cb(ctxt, EXR_ERR_READ_IO, "read failed: %s", strerror(io->os_errno));
            return -1;
        }
        if (n == 0) break; /* end of file: a short count, as pread gives */
        done += (uint64_t)n;
    }
    return (int64_t)done;
}

static int64_t exr_io_size(exr_const_context_t ctxt, void *ud)
{
    (void)ctxt;
    return ((const exr_io *)ud)->size;
}

static int64_t exr_io_write(exr_const_context_t ctxt, void *ud, const void *buffer, uint64_t sz, uint64_t offset,
                            exr_stream_error_func_ptr_t error_cb)
{
    exr_io *io = ud;
    if (offset > (uint64_t)INT64_MAX || sz > (uint64_t)INT64_MAX - offset) {
        if (error_cb) error_cb(ctxt, EXR_ERR_WRITE_IO, "write request beyond any possible file size");
        return -1;
    }
    const uint8_t *p = buffer;
    uint64_t done = 0;
    while (done < sz) {
        size_t want = (sz - done) > (uint64_t)(SSIZE_MAX / 2) ? (size_t)(SSIZE_MAX / 2) : (size_t)(sz - done);
        ssize_t n = pwrite(io->fd, p + done, want, (off_t)(offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            if (error_cb)
                error_cb(ctxt, EXR_ERR_WRITE_IO, "write of %" PRIu64 " bytes at offset %" PRIu64 " failed: %s", sz,
                         offset, n < 0 ? strerror(errno) : "no progress");
            return -1;
        }
        done += (uint64_t)n;
    }
    return (int64_t)sz;
}

/* Records "path: what: <library reason> (<library message>)" and returns code. */
static sy_result exr_fail(sy_error *err, sy_result code, const char *path, const char *what, exr_result_t rv,
                          const exr_io *io)
{
    const char *reason = exr_get_default_error_message(rv);
    if (io && io->msg[0])
        return sy_error_set(err, code, "%s: %s: %s (%s)", path, what, reason ? reason : "error", io->msg);
    return sy_error_set(err, code, "%s: %s: %s", path, what, reason ? reason : "error");
}

/* Library result -> our category for failures while reading a file. A short read means the file
 * ends too early (malformed), only a failing read system call is an I/O error. */
static sy_result read_code(exr_result_t rv, const exr_io *io)
{
    switch (rv) {
    case EXR_ERR_OUT_OF_MEMORY: return SY_ERR_OUT_OF_MEMORY;
    case EXR_ERR_FILE_ACCESS: return SY_ERR_IO;
    case EXR_ERR_READ_IO: return io->os_errno ? SY_ERR_IO : SY_ERR_PARSE;
    case EXR_ERR_FEATURE_NOT_IMPLEMENTED: return SY_ERR_UNSUPPORTED;
    default: return SY_ERR_PARSE;
    }
}

/* ---- >>writer ---- */

static exr_compression_t map_compression(sy_exr_compression c, bool *ok)
{
    *ok = true;
    switch (c) {
    case SY_EXR_COMPRESSION_DEFAULT:
    case SY_EXR_COMPRESSION_ZIP: return EXR_COMPRESSION_ZIP;
    case SY_EXR_COMPRESSION_NONE: return EXR_COMPRESSION_NONE;
    case SY_EXR_COMPRESSION_RLE: return EXR_COMPRESSION_RLE;
    case SY_EXR_COMPRESSION_ZIPS: return EXR_COMPRESSION_ZIPS;
    case SY_EXR_COMPRESSION_PIZ: return EXR_COMPRESSION_PIZ;
    default: *ok = false; return EXR_COMPRESSION_ZIP;
    }
}

/* The single validation pass over a write desc. */
static sy_result validate_write_desc(const char *path, const sy_exr_write_desc *d, bool *long_names, sy_error *err)
{
    *long_names = false;
    if (d->width < 1 || d->height < 1 || d->width > SY_EXR_MAX_SIDE || d->height > SY_EXR_MAX_SIDE)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: image size %dx%d outside 1..%d per side", path,
                            d->width, d->height, SY_EXR_MAX_SIDE);
    size_t pixels = (size_t)d->width * (size_t)d->height; /* both <= 65536: no overflow */
    if (pixels > SY_EXR_MAX_PIXELS)
        return sy_error_set(err, SY_ERR_LIMIT, "%s: image %dx%d has more than %u pixels", path, d->width, d->height,
                            SY_EXR_MAX_PIXELS);
    if (!d->channels || d->channel_count < 1 || d->channel_count > SY_EXR_MAX_CHANNELS)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: need 1..%d channels, got %d", path,
                            SY_EXR_MAX_CHANNELS, d->channels ? d->channel_count : 0);
    bool ok;
    (void)map_compression(d->compression, &ok);
    if (!ok)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: unknown compression %d", path, (int)d->compression);
    if (d->attribute_count < 0 || d->attribute_count > SY_EXR_MAX_ATTRIBUTES ||
        (d->attribute_count && !d->attributes))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: need 0..%d attributes, got %d", path,
                            SY_EXR_MAX_ATTRIBUTES, d->attribute_count);
    for (int a = 0; a < d->attribute_count; ++a) {
        const sy_exr_attribute *at = &d->attributes[a];
        size_t nlen = at->name ? strlen(at->name) : 0;
        if (!nlen || nlen > SY_EXR_MAX_ATTRIBUTE_NAME || !at->value || strlen(at->value) > SY_EXR_MAX_ATTRIBUTE_VALUE)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "%s: attribute %d needs a name of 1..%d bytes and a value of at most %d bytes", path, a,
                                SY_EXR_MAX_ATTRIBUTE_NAME, SY_EXR_MAX_ATTRIBUTE_VALUE);
    }
    for (int c = 0; c < d->channel_count; ++c) {
        const sy_exr_channel_desc *ch = &d->channels[c];
        if (!ch->name || !ch->name[0])
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: channel %d has no name", path, c);
        size_t nlen = strlen(ch->name);
        if (nlen > 255)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: channel %d name is %zu bytes, more than 255", path,
                                c, nlen);
        if (nlen > 31) *long_names = true;
        if (!ch->data)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: channel \"%s\" has no data", path, ch->name);
        if (ch->type != SY_EXR_PIXEL_FLOAT && ch->type != SY_EXR_PIXEL_HALF)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: channel \"%s\": pixel type %d cannot be written",
                                path, ch->name, (int)ch->type);
        size_t stride = ch->pixel_stride ? ch->pixel_stride : 1;
        size_t line_bytes, last;
        if (!sy_size_mul((size_t)d->width * 4u, stride, &line_bytes) || line_bytes > (size_t)INT32_MAX ||
            !sy_size_mad(pixels - 1, stride, ch->offset, &last))
            return sy_error_set(err, SY_ERR_LIMIT, "%s: channel \"%s\": pixel stride %zu / offset %zu too large", path,
                                ch->name, ch->pixel_stride, ch->offset);
        for (int k = 0; k < c; ++k)
            if (strcmp(d->channels[k].name, ch->name) == 0)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: channel name \"%s\" appears twice", path,
                                    ch->name);
    }
    return SY_OK;
}

sy_result sy_exr_write(const char *path, const sy_exr_write_desc *desc, sy_error *err)
{
    if (!path || !desc) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_exr_write: path and desc are required");
    bool long_names;
    sy_result rc = validate_write_desc(path, desc, &long_names, err);
    if (rc != SY_OK) return rc;

    bool ok;
    const exr_compression_t comp = map_compression(desc->compression, &ok);
    const int w = desc->width, h = desc->height, nch = desc->channel_count;

    int *map = malloc((size_t)nch * sizeof *map); /* encoder channel index -> desc channel index */
    if (!map) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);

    sy_atomic_file af = {0};
    rc = sy_atomic_file_begin(path, &af, err);
    if (rc != SY_OK) {
        free(map);
        return rc;
    }

    exr_io io = {.fd = af.fd, .size = -1};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_io_on_error;
    init.user_data = &io;
    init.write_fn = exr_io_write;

    exr_context_t ctxt = NULL;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    bool enc_inited = false;
    int part = 0;
    exr_result_t rv = exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv != EXR_ERR_SUCCESS) {
        rc = exr_fail(err, SY_ERR_BACKEND, path, "cannot start the OpenEXR writer", rv, &io);
        goto fail;
    }
    if (long_names && (rv = exr_set_longname_support(ctxt, 1)) != EXR_ERR_SUCCESS) {
        rc = exr_fail(err, SY_ERR_BACKEND, path, "cannot enable long channel names", rv, &io);
        goto fail;
    }
    if ((rv = exr_add_part(ctxt, NULL, EXR_STORAGE_SCANLINE, &part)) != EXR_ERR_SUCCESS ||
        (rv = exr_initialize_required_attr_simple(ctxt, part, w, h, comp)) != EXR_ERR_SUCCESS) {
        rc = exr_fail(err, SY_ERR_BACKEND, path, "cannot set up the image header", rv, &io);
        goto fail;
    }
    for (int c = 0; c < nch; ++c) {
        const sy_exr_channel_desc *ch = &desc->channels[c];
        exr_pixel_type_t t = ch->type == SY_EXR_PIXEL_HALF ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT;
        rv = exr_add_channel(ctxt, part, ch->name, t, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
        if (rv != EXR_ERR_SUCCESS) {
            char what[320];
            snprintf(what, sizeof what, "cannot add channel \"%s\"", ch->name);
            rc = exr_fail(err, SY_ERR_BACKEND, path, what, rv, &io);
            goto fail;
        }
    }
    for (int a = 0; a < desc->attribute_count; ++a) {
        const sy_exr_attribute *at = &desc->attributes[a];
        if ((rv = exr_attr_set_string(ctxt, part, at->name, at->value)) != EXR_ERR_SUCCESS) {
            char what[320];
            snprintf(what, sizeof what, "cannot add the attribute \"%.200s\"", at->name);
            rc = exr_fail(err, SY_ERR_BACKEND, path, what, rv, &io);
            goto fail;
        }
    }
    if ((rv = exr_write_header(ctxt)) != EXR_ERR_SUCCESS) {
        rc = exr_fail(err, SY_ERR_IO, path, "cannot write the header", rv, &io);
        goto fail;
    }

    int32_t lines_per_chunk = 0;
    if ((rv = exr_get_scanlines_per_chunk(ctxt, part, &lines_per_chunk)) != EXR_ERR_SUCCESS || lines_per_chunk < 1) {
        rc = exr_fail(err, SY_ERR_BACKEND, path, "cannot query the scanlines per chunk", rv, &io);
        goto fail;
    }
    for (int y = 0; y < h; y += lines_per_chunk) {
        exr_chunk_info_t ci;
        if ((rv = exr_write_scanline_chunk_info(ctxt, part, y, &ci)) != EXR_ERR_SUCCESS) goto chunk_fail;
        if (!enc_inited) {
            if ((rv = exr_encoding_initialize(ctxt, part, &ci, &enc)) != EXR_ERR_SUCCESS) goto chunk_fail;
            enc_inited = true;
            if (enc.channel_count != nch) {
                rc = sy_error_set(err, SY_ERR_BACKEND, "%s: encoder has %d channels, expected %d", path,
                                  (int)enc.channel_count, nch);
                goto fail;
            }
            for (int c = 0; c < nch; ++c) {
                map[c] = -1;
                for (int k = 0; k < nch; ++k)
                    if (enc.channels[c].channel_name && strcmp(enc.channels[c].channel_name, desc->channels[k].name) == 0)
                        map[c] = k;
                if (map[c] < 0) {
                    rc = sy_error_set(err, SY_ERR_BACKEND, "%s: encoder channel %d does not match any input", path, c);
                    goto fail;
                }
            }
        } else if ((rv = exr_encoding_update(ctxt, part, &ci, &enc)) != EXR_ERR_SUCCESS) {
            goto chunk_fail;
        }
        for (int c = 0; c < nch; ++c) {
            const sy_exr_channel_desc *ch = &desc->channels[map[c]];
            size_t stride = ch->pixel_stride ? ch->pixel_stride : 1;
            exr_coding_channel_info_t *ec = &enc.channels[c];
            ec->encode_from_ptr = (const uint8_t *)(ch->data + (size_t)ci.start_y * (size_t)w * stride + ch->offset);
            ec->user_pixel_stride = (int32_t)(stride * sizeof(float));
            ec->user_line_stride = (int32_t)((size_t)w * stride * sizeof(float));
            ec->user_bytes_per_element = (int16_t)sizeof(float);
            ec->user_data_type = EXR_PIXEL_FLOAT;
        }
        if (y == 0 && (rv = exr_encoding_choose_default_routines(ctxt, part, &enc)) != EXR_ERR_SUCCESS)
            goto chunk_fail;
        if ((rv = exr_encoding_run(ctxt, part, &enc)) != EXR_ERR_SUCCESS) goto chunk_fail;
        continue;
    chunk_fail: {
        char what[64];
        snprintf(what, sizeof what, "cannot write the chunk at scanline %d", y);
        rc = exr_fail(err, SY_ERR_IO, path, what, rv, &io);
        goto fail;
    }
    }
    if (enc_inited) exr_encoding_destroy(ctxt, &enc);
    enc_inited = false;
    rv = exr_finish(&ctxt); /* writes the chunk offset table */
    ctxt = NULL;
    if (rv != EXR_ERR_SUCCESS) {
        rc = exr_fail(err, SY_ERR_IO, path, "cannot finish the file", rv, &io);
        goto fail;
    }
    free(map);
    return sy_atomic_file_commit(&af, err);

fail:
    if (enc_inited) exr_encoding_destroy(ctxt, &enc);
    if (ctxt) exr_finish(&ctxt);
    sy_atomic_file_abort(&af);
    free(map);
    return rc;
}

sy_result sy_exr_write_rgba(const char *path, int width, int height, const float *rgba, const float *depth,
                            sy_exr_pixel_type color_type, sy_error *err)
{
    return sy_exr_write_rgba_attrs(path, width, height, rgba, depth, color_type, NULL, 0, err);
}

sy_result sy_exr_write_rgba_attrs(const char *path, int width, int height, const float *rgba, const float *depth,
                                  sy_exr_pixel_type color_type, const sy_exr_attribute *attributes,
                                  int attribute_count, sy_error *err)
{
    if (!rgba) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: no colour data", path ? path : "(null)");
    if (color_type != SY_EXR_PIXEL_HALF && color_type != SY_EXR_PIXEL_FLOAT)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: colour must be stored HALF or FLOAT",
                            path ? path : "(null)");
    sy_exr_channel_desc ch[5] = {
        {.name = "R", .data = rgba, .pixel_stride = 4, .offset = 0, .type = color_type},
        {.name = "G", .data = rgba, .pixel_stride = 4, .offset = 1, .type = color_type},
        {.name = "B", .data = rgba, .pixel_stride = 4, .offset = 2, .type = color_type},
        {.name = "A", .data = rgba, .pixel_stride = 4, .offset = 3, .type = color_type},
        {.name = "Z", .data = depth, .pixel_stride = 1, .offset = 0, .type = SY_EXR_PIXEL_FLOAT},
    };
    sy_exr_write_desc d = {
        .width = width,
        .height = height,
        .compression = SY_EXR_COMPRESSION_ZIP,
        .channels = ch,
        .channel_count = depth ? 5 : 4,
        .attributes = attributes,
        .attribute_count = attribute_count,
    };
    return sy_exr_write(path, &d, err);
}

/* ---- >>reader ---- */

void sy_exr_image_free(sy_exr_image *img)
{
    if (!img) return;
    if (img->channels) {
        for (int c = 0; c < img->channel_count; ++c) {
            free(img->channels[c].name);
            free(img->channels[c].data);
        }
        free(img->channels);
    }
    for (int i = 0; i < img->attribute_count; ++i) free(img->attributes[i].name), free(img->attributes[i].value);
    free(img->attributes);
    free(img);
}

/* Copies part 0's string attributes (the metadata sy writes, and any other tool's) into img. */
static sy_result read_text_attributes(exr_const_context_t ctxt, sy_exr_image *img, const char *path, sy_error *err)
{
    int32_t n = 0;
    if (exr_get_attribute_count(ctxt, 0, &n) != EXR_ERR_SUCCESS || n <= 0) return SY_OK;
    img->attributes = calloc((size_t)(n < SY_EXR_MAX_ATTRIBUTES ? n : SY_EXR_MAX_ATTRIBUTES), sizeof *img->attributes);
    if (!img->attributes) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory for the header", path);
    for (int32_t i = 0; i < n && img->attribute_count < SY_EXR_MAX_ATTRIBUTES; ++i) {
        const exr_attribute_t *a = NULL;
        if (exr_get_attribute_by_index(ctxt, 0, EXR_ATTR_LIST_FILE_ORDER, i, &a) != EXR_ERR_SUCCESS || !a ||
            a->type != EXR_ATTR_STRING || !a->string || !a->name)
            continue;
        int32_t len = a->string->length < 0 ? 0 : a->string->length;
        if (len > SY_EXR_MAX_ATTRIBUTE_VALUE) len = SY_EXR_MAX_ATTRIBUTE_VALUE;
        sy_exr_text *t = &img->attributes[img->attribute_count];
        t->name = strdup(a->name);
        t->value = malloc((size_t)len + 1);
        if (!t->name || !t->value) {
            free(t->name), free(t->value);
            t->name = t->value = NULL;
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory for the header", path);
        }
        if (len) memcpy(t->value, a->string->str, (size_t)len);
        t->value[len] = 0;
        img->attribute_count++;
    }
    return SY_OK;
}

const float *sy_exr_image_channel(const sy_exr_image *img, const char *name)
{
    if (!img || !name) return NULL;
    for (int c = 0; c < img->channel_count; ++c)
        if (strcmp(img->channels[c].name, name) == 0) return img->channels[c].data;
    return NULL;
}

/* State of one read call, so the helpers share one error path. */
typedef struct exr_reader {
    const char *path;
    uint64_t max_pixels;
    size_t max_samples;
    exr_context_t ctxt;
    exr_io io;
    exr_decode_pipeline_t dec;
    bool dec_inited;
    sy_exr_image *img;
} exr_reader;

/* Decodes one chunk whose top-left pixel is (px, py) relative to the data window. */
static sy_result decode_chunk(exr_reader *r, const exr_chunk_info_t *ci, int64_t px, int64_t py, sy_error *err)
{
    sy_exr_image *img = r->img;
    if (ci->width < 1 || ci->height < 1 || px < 0 || py < 0 || px > img->width - (int64_t)ci->width ||
        py > img->height - (int64_t)ci->height)
        return sy_error_set(err, SY_ERR_PARSE, "%s: chunk %d (%dx%d at %" PRId64 ",%" PRId64 ") lies outside the %dx%d data window",
                            r->path, ci->idx, ci->width, ci->height, px, py, img->width, img->height);
    exr_result_t rv;
    if (!r->dec_inited) {
        rv = exr_decoding_initialize(r->ctxt, 0, ci, &r->dec);
        if (rv == EXR_ERR_SUCCESS) r->dec_inited = true;
    } else {
        rv = exr_decoding_update(r->ctxt, 0, ci, &r->dec);
    }
    if (rv != EXR_ERR_SUCCESS) {
        char what[64];
        snprintf(what, sizeof what, "cannot prepare chunk %d", ci->idx);
        return exr_fail(err, read_code(rv, &r->io), r->path, what, rv, &r->io);
    }
    if (r->dec.channel_count != img->channel_count)
        return sy_error_set(err, SY_ERR_PARSE, "%s: chunk %d has %d channels, the header %d", r->path, ci->idx,
                            (int)r->dec.channel_count, img->channel_count);
    for (int c = 0; c < img->channel_count; ++c) {
        exr_coding_channel_info_t *ch = &r->dec.channels[c];
        if (ch->width != ci->width || ch->height != ci->height || !ch->channel_name ||
            strcmp(ch->channel_name, img->channels[c].name) != 0)
            return sy_error_set(err, SY_ERR_PARSE, "%s: chunk %d: channel %d does not match the header", r->path,
                                ci->idx, c);
        float *base = img->channels[c].data + (size_t)py * (size_t)img->width + (size_t)px;
        ch->decode_to_ptr = (uint8_t *)base;
        ch->user_pixel_stride = (int32_t)sizeof(float);
        ch->user_line_stride = (int32_t)((size_t)img->width * sizeof(float)); /* <= 65536 * 4 */
        ch->user_bytes_per_element = (int16_t)sizeof(float);
        /* UINT is fetched as raw 32-bit integers and converted after decoding. */
        ch->user_data_type = ch->data_type == EXR_PIXEL_UINT ? EXR_PIXEL_UINT : EXR_PIXEL_FLOAT;
    }
    rv = exr_decoding_choose_default_routines(r->ctxt, 0, &r->dec);
    if (rv == EXR_ERR_SUCCESS) rv = exr_decoding_run(r->ctxt, 0, &r->dec);
    if (rv != EXR_ERR_SUCCESS) {
        char what[64];
        snprintf(what, sizeof what, "cannot decode chunk %d", ci->idx);
        return exr_fail(err, read_code(rv, &r->io), r->path, what, rv, &r->io);
    }
    return SY_OK;
}

static sy_result read_scanlines(exr_reader *r, const exr_attr_box2i_t *dw, sy_error *err)
{
    int32_t lines = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(r->ctxt, 0, &lines);
    if (rv != EXR_ERR_SUCCESS || lines < 1)
        return exr_fail(err, SY_ERR_PARSE, r->path, "bad scanlines per chunk", rv, &r->io);
    for (int64_t y = dw->min.y; y <= dw->max.y; y += lines) {
        exr_chunk_info_t ci;
        rv = exr_read_scanline_chunk_info(r->ctxt, 0, (int)y, &ci);
        if (rv != EXR_ERR_SUCCESS) {
            char what[64];
            snprintf(what, sizeof what, "cannot locate the chunk of scanline %" PRId64, y);
            return exr_fail(err, read_code(rv, &r->io), r->path, what, rv, &r->io);
        }
        sy_result rc = decode_chunk(r, &ci, 0, (int64_t)ci.start_y - dw->min.y, err);
        if (rc != SY_OK) return rc;
    }
    return SY_OK;
}

static sy_result read_tiles(exr_reader *r, sy_error *err)
{
    int32_t tw = 0, th = 0, lw = 0, lh = 0;
    exr_result_t rv = exr_get_tile_sizes(r->ctxt, 0, 0, 0, &tw, &th);
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_level_sizes(r->ctxt, 0, 0, 0, &lw, &lh);
    if (rv != EXR_ERR_SUCCESS) return exr_fail(err, SY_ERR_PARSE, r->path, "bad tile description", rv, &r->io);
    if (tw < 1 || th < 1 || lw != r->img->width || lh != r->img->height)
        return sy_error_set(err, SY_ERR_PARSE, "%s: tiles %dx%d, level 0 %dx%d do not fit the %dx%d data window",
                            r->path, tw, th, lw, lh, r->img->width, r->img->height);
    int64_t ntx = ((int64_t)lw + tw - 1) / tw, nty = ((int64_t)lh + th - 1) / th;
    for (int64_t ty = 0; ty < nty; ++ty) {
        for (int64_t tx = 0; tx < ntx; ++tx) {
            exr_chunk_info_t ci;
            rv = exr_read_tile_chunk_info(r->ctxt, 0, (int)tx, (int)ty, 0, 0, &ci);
            if (rv != EXR_ERR_SUCCESS) {
                char what[64];
                snprintf(what, sizeof what, "cannot locate tile (%" PRId64 ",%" PRId64 ")", tx, ty);
                return exr_fail(err, read_code(rv, &r->io), r->path, what, rv, &r->io);
            }
            sy_result rc = decode_chunk(r, &ci, tx * tw, ty * th, err);
            if (rc != SY_OK) return rc;
        }
    }
    return SY_OK;
}

/* Upper bound of (raw pixel bytes) / (stored bytes) per compression, with margin: RLE stores at most
 * 128 bytes in 2, deflate at most ~1032:1 (PXR24: zlib over 24-bit floats), PIZ's Huffman run codes
 * ~410:1, B44A 32 bytes in 3, DWA a DC value per 8x8 block through zlib. Unknown methods: the DWA bound. */
static uint64_t max_ratio(exr_compression_t c)
{
    switch (c) {
    case EXR_COMPRESSION_NONE: return 1;
    case EXR_COMPRESSION_RLE: return 64;
    case EXR_COMPRESSION_ZIPS: case EXR_COMPRESSION_ZIP: return 1100;
    case EXR_COMPRESSION_PXR24: return 1500;
    case EXR_COMPRESSION_PIZ: return 4096;
    case EXR_COMPRESSION_B44: case EXR_COMPRESSION_B44A: return 16;
    default: return (uint64_t)1 << 17;
    }
}

/* Header checks and allocation of the planes; everything taken from the file is validated here. */
static sy_result read_header(exr_reader *r, exr_storage_t *storage, exr_attr_box2i_t *dw, sy_error *err)
{
    const char *path = r->path;
    int parts = 0;
    exr_result_t rv = exr_get_count(r->ctxt, &parts);
    if (rv != EXR_ERR_SUCCESS || parts < 1) return exr_fail(err, SY_ERR_PARSE, path, "no image part", rv, &r->io);
    if ((rv = exr_get_storage(r->ctxt, 0, storage)) != EXR_ERR_SUCCESS)
        return exr_fail(err, SY_ERR_PARSE, path, "bad storage type", rv, &r->io);
    if (*storage != EXR_STORAGE_SCANLINE && *storage != EXR_STORAGE_TILED)
        return sy_error_set(err, SY_ERR_UNSUPPORTED, "%s: deep images are not supported", path);
    if ((rv = exr_get_data_window(r->ctxt, 0, dw)) != EXR_ERR_SUCCESS)
        return exr_fail(err, SY_ERR_PARSE, path, "bad data window", rv, &r->io);
    int64_t w = (int64_t)dw->max.x - dw->min.x + 1, h = (int64_t)dw->max.y - dw->min.y + 1;
    if (w < 1 || h < 1)
        return sy_error_set(err, SY_ERR_PARSE, "%s: empty or inverted data window (%d,%d)-(%d,%d)", path, dw->min.x,
                            dw->min.y, dw->max.x, dw->max.y);
    if (w > SY_EXR_MAX_SIDE || h > SY_EXR_MAX_SIDE || (uint64_t)w * (uint64_t)h > r->max_pixels)
        return sy_error_set(err, SY_ERR_LIMIT, "%s: image %" PRId64 "x%" PRId64 " exceeds the limit of %d per side / %" PRIu64 " pixels",
                            path, w, h, SY_EXR_MAX_SIDE, r->max_pixels);
    const exr_attr_chlist_t *chl = NULL;
    if ((rv = exr_get_channels(r->ctxt, 0, &chl)) != EXR_ERR_SUCCESS || !chl)
        return exr_fail(err, SY_ERR_PARSE, path, "bad channel list", rv, &r->io);
    if (chl->num_channels < 1 || chl->num_channels > SY_EXR_MAX_CHANNELS || !chl->entries)
        return sy_error_set(err, chl->num_channels < 1 ? SY_ERR_PARSE : SY_ERR_LIMIT, "%s: %d channels (need 1..%d)",
                            path, chl->num_channels, SY_EXR_MAX_CHANNELS);
    size_t pixels = (size_t)w * (size_t)h, samples;
    if (!sy_size_mul(pixels, (size_t)chl->num_channels, &samples) || samples > r->max_samples)
        return sy_error_set(err, SY_ERR_LIMIT, "%s: %" PRId64 "x%" PRId64 " pixels x %d channels exceeds %zu samples",
                            path, w, h, chl->num_channels, r->max_samples);

    /* The pixels must fit the bytes present: raw size (data window x channel bytes) at most the
     * file size times the best ratio the compression can reach, so a small hostile header cannot
     * make us allocate planes its file could never fill. */
    exr_compression_t comp = EXR_COMPRESSION_NONE;
    if ((rv = exr_get_compression(r->ctxt, 0, &comp)) != EXR_ERR_SUCCESS)
        return exr_fail(err, SY_ERR_PARSE, path, "bad compression", rv, &r->io);
    uint64_t raw = 0, ratio = max_ratio(comp);
    for (int c = 0; c < chl->num_channels; ++c)
        raw += (uint64_t)pixels * (chl->entries[c].pixel_type == EXR_PIXEL_HALF ? 2u : 4u);
    if (raw / ratio > (uint64_t)r->io.size)
        return sy_error_set(err, SY_ERR_PARSE,
                            "%s: truncated: a %" PRId64 "x%" PRId64 " data window with %d channels holds %" PRIu64
                            " bytes of pixels, more than %" PRId64 " bytes can carry (compression %d reaches at most %" PRIu64 ":1)",
                            path, w, h, chl->num_channels, raw, r->io.size, (int)comp, ratio);

    /* Every chunk has an 8-byte entry in the offset table: a file too small for its own table is
     * truncated, and refusing it here avoids allocating a table sized by a hostile header. */
    int32_t chunks = 0;
    if ((rv = exr_get_chunk_count(r->ctxt, 0, &chunks)) != EXR_ERR_SUCCESS || chunks < 1)
        return exr_fail(err, SY_ERR_PARSE, path, "bad chunk count", rv, &r->io);
    if ((int64_t)chunks * 8 > r->io.size)
        return sy_error_set(err, SY_ERR_PARSE, "%s: truncated: %d chunks need a %" PRId64 "-byte offset table, the file has %" PRId64 " bytes",
                            path, chunks, (int64_t)chunks * 8, r->io.size);

    sy_exr_image *img = calloc(1, sizeof *img);
    if (!img) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    r->img = img;
    img->width = (int)w;
    img->height = (int)h;
    img->origin_x = dw->min.x;
    img->origin_y = dw->min.y;
    img->channels = calloc((size_t)chl->num_channels, sizeof *img->channels);
    if (!img->channels) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    img->channel_count = chl->num_channels;
    for (int c = 0; c < chl->num_channels; ++c) {
        const exr_attr_chlist_entry_t *e = &chl->entries[c];
        if (e->x_sampling != 1 || e->y_sampling != 1)
            return sy_error_set(err, SY_ERR_UNSUPPORTED, "%s: channel %d is sub-sampled (%d,%d); not supported", path,
                                c, e->x_sampling, e->y_sampling);
        sy_exr_plane *pl = &img->channels[c];
        switch (e->pixel_type) {
        case EXR_PIXEL_HALF: pl->stored_type = SY_EXR_PIXEL_HALF; break;
        case EXR_PIXEL_FLOAT: pl->stored_type = SY_EXR_PIXEL_FLOAT; break;
        case EXR_PIXEL_UINT: pl->stored_type = SY_EXR_PIXEL_UINT; break;
        default:
            return sy_error_set(err, SY_ERR_PARSE, "%s: channel %d has unknown pixel type %d", path, c,
                                (int)e->pixel_type);
        }
        size_t nlen = e->name.length > 0 && e->name.str ? (size_t)e->name.length : 0;
        if (nlen == 0) return sy_error_set(err, SY_ERR_PARSE, "%s: channel %d has no name", path, c);
        pl->name = malloc(nlen + 1);
        pl->data = calloc(pixels, sizeof(float));
        if (!pl->name || !pl->data)
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: cannot allocate channel %d (%zu pixels)", path, c,
                                pixels);
        memcpy(pl->name, e->name.str, nlen);
        pl->name[nlen] = '\0';
    }
    return SY_OK;
}

static sy_result read_image(exr_reader *rp, const sy_exr_read_options *opts, sy_exr_image **out, sy_error *err);

sy_result sy_exr_read(const char *path, sy_exr_image **out, sy_error *err)
{
    if (out) *out = NULL;
    if (!path || !out) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_exr_read: path and out are required");

    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        int e = errno;
        return sy_error_set(err, e == ENOENT ? SY_ERR_NOT_FOUND : SY_ERR_IO, "%s: cannot open: %s", path, strerror(e));
    }
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return sy_error_set(err, SY_ERR_IO, "%s: not a regular file", path);
    }
    exr_reader r = {.path = path, .io = {.fd = fd, .size = (int64_t)st.st_size}};
    sy_result rc = read_image(&r, NULL, out, err);
    close(fd);
    return rc;
}

sy_result sy_exr_read_memory(const void *data, size_t size, const char *name, const sy_exr_read_options *opts,
                             sy_exr_image **out, sy_error *err)
{
    if (out) *out = NULL;
    if (!data || !name || !out || size > (size_t)INT64_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_exr_read_memory: data, name and out are required");
    exr_reader r = {.path = name, .io = {.fd = -1, .mem = data, .size = (int64_t)size}};
    return read_image(&r, opts, out, err);
}

/* The reader behind sy_exr_read and sy_exr_read_memory: r has path and io set up. */
static sy_result read_image(exr_reader *rp, const sy_exr_read_options *opts, sy_exr_image **out, sy_error *err)
{
    exr_reader r = *rp;
    const char *path = r.path;
    sy_result rc = SY_OK;
    r.max_pixels = opts && opts->max_pixels && opts->max_pixels < SY_EXR_MAX_PIXELS ? opts->max_pixels : SY_EXR_MAX_PIXELS;
    r.max_samples = opts && opts->max_samples && opts->max_samples < SY_EXR_MAX_SAMPLES ? opts->max_samples
                                                                                        : SY_EXR_MAX_SAMPLES;

    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_io_on_error;
    init.user_data = &r.io;
    init.read_fn = exr_io_read;
    init.size_fn = exr_io_size;
    init.max_image_width = SY_EXR_MAX_SIDE;
    init.max_image_height = SY_EXR_MAX_SIDE;
    init.max_tile_width = SY_EXR_MAX_SIDE;
    init.max_tile_height = SY_EXR_MAX_SIDE;
    /* A damaged chunk table is an error, not something to guess around. */
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;

    exr_result_t rv = exr_start_read(&r.ctxt, path, &init);
    if (rv != EXR_ERR_SUCCESS) {
        rc = exr_fail(err, read_code(rv, &r.io), path, "not a readable OpenEXR file", rv, &r.io);
        goto done;
    }
    exr_storage_t storage;
    exr_attr_box2i_t dw;
    rc = read_header(&r, &storage, &dw, err);
    if (rc == SY_OK) rc = storage == EXR_STORAGE_TILED ? read_tiles(&r, err) : read_scanlines(&r, &dw, err);
    if (rc == SY_OK) rc = read_text_attributes(r.ctxt, r.img, path, err);
    if (rc != SY_OK) goto done;

    /* UINT planes hold raw integers so far (the decoder wrote 4-byte integers): convert in place. */
    size_t pixels = (size_t)r.img->width * (size_t)r.img->height;
    for (int c = 0; c < r.img->channel_count; ++c) {
        sy_exr_plane *pl = &r.img->channels[c];
        if (pl->stored_type != SY_EXR_PIXEL_UINT) continue;
        for (size_t i = 0; i < pixels; ++i) {
            uint32_t u;
            memcpy(&u, &pl->data[i], sizeof u);
            pl->data[i] = (float)u;
        }
    }

done:
    if (r.dec_inited) exr_decoding_destroy(r.ctxt, &r.dec);
    if (r.ctxt) exr_finish(&r.ctxt);
    if (rc != SY_OK) {
        sy_exr_image_free(r.img);
        return rc;
    }
    *out = r.img;
    return SY_OK;
}
