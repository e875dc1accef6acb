/** @file
 * sy_loader_log.h — what a scene loader says, in one form for every loader (glTF, X3D, the Assimp
 * formats): its error names the file ("<file>: <message>"), and its warnings are all counted, the
 * first `max` kept as malloc()ed copies in the loader's info struct, and logged (sy_log.h) after a
 * successful load followed by how many more there were. Its input, a file or the caller's memory,
 * comes through sy_loader_input under the same size limit.
 * Ownership: the kept messages belong to the info struct (sy_loader_warnings_free). Thread-safety:
 * none beyond the log's; one list per load, on one thread. */
#ifndef SY_LOADER_LOG_H
#define SY_LOADER_LOG_H

#include "sy_common.h"

#include <stdarg.h>

#ifdef __cplusplus
extern "C" {
#endif

/** A loader's warnings, as its info struct holds them (the fields are the struct's own). */
typedef struct sy_loader_warnings {
    char ***list;     /**< the kept messages (allocated on the first, max entries) */
    uint32_t *count;  /**< every warning, kept or not */
    uint32_t *stored; /**< entries of *list */
    uint32_t max;     /**< at most this many kept */
} sy_loader_warnings;

/** The warnings of a loader's info struct `info`, whose fields are named warnings, warning_count
 * and stored_warning_count (every loader's are), keeping at most max (C only). */
#define SY_LOADER_WARNINGS(info, max)                                                                   \
    ((sy_loader_warnings){&(info)->warnings, &(info)->warning_count, &(info)->stored_warning_count, (max)})

/** Sets err to "<file>: <message>" and returns code. */
sy_result sy_loader_fail(sy_error *err, const char *file, sy_result code, const char *fmt, va_list ap);
/** The same with the message's arguments (each loader's fail macro: gltf_fail, asp_fail). */
sy_result sy_loader_failf(sy_error *err, const char *file, sy_result code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/** A loader's input: the caller's memory when mem is not NULL (borrowed; more than max_bytes:
 * SY_ERR_LIMIT "<file>: N bytes exceed the file size limit of M"), else the whole file at path
 * (sy_file_read_all: *owned receives the buffer, the caller's to free(); NULL for memory). *data and
 * *size: the bytes. */
sy_result sy_loader_input(const char *path, const void *mem, size_t mem_size, size_t max_bytes, void **owned,
                          const void **data, size_t *size, sy_error *err);

/** Counts one warning and keeps its message while fewer than max are kept. */
void sy_loader_warn(sy_loader_warnings w, const char *fmt, va_list ap);
/** The same with the message's arguments (each loader's warn macro: gltf_warn, x3d_warn, asp_warn). */
void sy_loader_warnf(sy_loader_warnings w, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/** Logs the kept warnings (module, item each: e.g. the file; NULL when the messages name it), then
 * "N more warnings not shown" (item: file). */
void sy_loader_warnings_log(sy_loader_warnings w, const char *module, const char *item, const char *file);

/** Frees the kept messages and the list; zeroes *list and *stored (the count stays). */
void sy_loader_warnings_free(sy_loader_warnings w);

#ifdef __cplusplus
}
#endif
#endif /* SY_LOADER_LOG_H */
