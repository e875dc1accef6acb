/** @file
 * sy_common.h — result codes, error messages, checked arithmetic, growing arrays, uint32_t pairs
 * and the clock, shared by every Switchyard layer above the back-ends (core, mediators, formats,
 * apps).
 *
 * Error convention: every fallible call returns a sy_result (SY_OK == 0) and, when the caller passed
 * a sy_error*, fills it with the code and a human-readable message naming the object / file / place
 * and the reason. The error pointer may be NULL. There is no sticky or global error state.
 * The back-ends (backends/) cannot include this header; their result enums use the same numbers for
 * the codes they share, so a mediator turns one into a sy_result with a cast
 * (mediators/sy_backend_status.h checks the numbers at compile time).
 *
 * Thread-safety: everything here is pure or works on caller-owned memory. */
#ifndef SY_COMMON_H
#define SY_COMMON_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Result codes of every fallible call (SY_OK == 0). */
typedef enum sy_result {
    SY_OK = 0,
    SY_ERR_INVALID_ARGUMENT = 1, /**< a caller passed something the API does not accept */
    SY_ERR_INVALID_HANDLE = 2,   /**< stale or foreign handle */
    SY_ERR_OUT_OF_MEMORY = 3,
    SY_ERR_IO = 4,               /**< file or socket could not be read or written */
    SY_ERR_PARSE = 5,            /**< input data is malformed (file, message) */
    SY_ERR_UNSUPPORTED = 6,      /**< well-formed but uses something we do not implement */
    SY_ERR_LIMIT = 7,            /**< a size or count exceeds a configured limit / would overflow */
    SY_ERR_NOT_FOUND = 8,        /**< named thing (file, camera, back-end) does not exist */
    SY_ERR_BACKEND = 9,          /**< a back-end library reported a failure */
    SY_ERR_PROTOCOL = 10,        /**< network peer violated the protocol */
    SY_ERR_INVALID_OPERATION = 11, /**< a call out of order (rendering a back-end's uncommitted changes) */
    SY_ERR_CANCELLED = 12,       /**< a progress callback asked to stop */
    SY_ERR_SYSTEM = 13,          /**< an operating-system call failed (creating a mutex) */
    SY_RESULT_MAX_ENUM = 0x7fffffff
} sy_result;

#define SY_ERROR_MESSAGE_MAX 512 /**< bytes of a message, NUL included */

/** A result plus its message. Zero-initialise before first use ({0}). */
typedef struct sy_error {
    sy_result code; /**< the result */
    char message[SY_ERROR_MESSAGE_MAX]; /**< what failed and why (NUL-terminated) */
} sy_error;

/** Human-readable name of a result code ("invalid argument", ...). Static storage. */
const char *sy_result_str(sy_result r);

/** Records code + printf-style message in *err (if err is not NULL) and returns code, so that
 * call sites read `return sy_error_set(err, SY_ERR_PARSE, "%s: ...", path);`. */
sy_result sy_error_set(sy_error *err, sy_result code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/** Prepends "prefix: " to an existing message (adds context while an error travels up). */
void sy_error_prefix(sy_error *err, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* ---- checked arithmetic: return false on overflow, *out untouched then ---- */
static inline bool sy_size_add(size_t a, size_t b, size_t *out)
{
    if (a > SIZE_MAX - b) return false;
    *out = a + b;
    return true;
}

static inline bool sy_size_mul(size_t a, size_t b, size_t *out)
{
    if (a != 0 && b > SIZE_MAX / a) return false;
    *out = a * b;
    return true;
}

/** a*b+c, all checked. */
static inline bool sy_size_mad(size_t a, size_t b, size_t c, size_t *out)
{
    size_t t;
    return sy_size_mul(a, b, &t) && sy_size_add(t, c, out);
}

/** Room for one more element in a growing array: *(T **)items holds count elements of elem bytes in
 * *capacity, doubled when full (first when empty). false when out of memory or the size would
 * overflow (nothing changed then). */
bool sy_array_reserve(void *items, size_t count, size_t *capacity, size_t elem, size_t first);

/** Appends v to a growing array of uint32_t (ids, indices): *items holds *count of *capacity, which
 * doubles when full (4 at first). false when out of memory (nothing changed then). */
bool sy_u32_push(uint32_t **items, uint32_t *count, uint32_t *capacity, uint32_t v);

/** A key (an id) and what goes with it, sorted with sy_u32_pair_cmp. */
typedef struct sy_u32_pair {
    uint32_t key;   /**< what the pairs are sorted by first (an id) */
    uint32_t value; /**< what goes with it (an index, another id); sorted by second */
} sy_u32_pair;
/** qsort order of sy_u32_pair: by key, then by value. */
int sy_u32_pair_cmp(const void *a, const void *b);

/** Monotonic wall clock in seconds (for timings and progress only). */
double sy_time_now(void);

/** true when name is one of the entries of list, separated by sep ("a,b,c" with ','); an empty
 * list holds nothing. */
bool sy_name_in_list(const char *name, const char *list, char sep);

/** true when fd refers to a terminal: long jobs print progress only then. */
bool sy_is_terminal(int fd);

/** The library's version, "MAJOR.MINOR.PATCH" (static storage). */
const char *sy_version(void);

#ifdef __cplusplus
}
#endif
#endif /* SY_COMMON_H */
