/** @file
 * sy_file.h — whole-file reading with a size limit, and atomic (temp-then-rename) file output.
 *
 * Every file reader in formats/ goes through sy_file_read_all so that a size limit is always applied
 * to untrusted input, and every writer goes through sy_atomic_file so that a failed write never
 * leaves half a file behind: the data goes to "<path>.tmp-XXXXXX" in the target's directory, is
 * flushed and fsync'ed, and only then renamed over the target. Until the rename an existing target
 * stays untouched.
 *
 * Errors name the file and the reason (see core/sy_common.h).
 * Thread-safety: distinct handles may be used from distinct threads; the only shared state is the
 * process-wide list of temporary files in progress (behind a lock), which sy_atomic_file_cancel_all
 * empties. One sy_atomic_file must not be used from two threads at once. */
#ifndef SY_FILE_H
#define SY_FILE_H

#include "sy_common.h"

#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Reads the whole file at `path` into a fresh buffer.
 * Refuses (SY_ERR_LIMIT) files larger than max_bytes, without reading them. A missing file gives
 * SY_ERR_NOT_FOUND, anything else that cannot be read (a directory, an I/O error) SY_ERR_IO.
 * The buffer holds *size_out bytes followed by one extra '\0' byte (handy for text formats); it is
 * never NULL on success, even for an empty file.
 * Ownership: on success the caller owns *data_out and releases it with free(); on failure
 * *data_out is NULL and *size_out is 0. */
sy_result sy_file_read_all(const char *path, size_t max_bytes, void **data_out, size_t *size_out,
                           sy_error *err);

/** An output file in progress. Zero-initialise ({0}) before sy_atomic_file_begin; the fields are
 * readable by the caller, never to be changed by it. */
typedef struct sy_atomic_file {
    FILE *fp;       /**< write the content here (or through fd, not both at once) */
    int fd;         /**< the descriptor behind fp, for positional writers (pwrite) */
    char *path;     /**< the final target path (owned copy) */
    char *tmp_path; /**< the temporary file in the same directory (owned) */
} sy_atomic_file;

/** Creates the temporary file "<path>.tmp-XXXXXX" (mode 0666 minus the umask) and opens it for
 * binary writing. Fails with a message naming the path when the directory does not exist or is not
 * writable; nothing is created then.
 * Ownership: on success *af holds resources that exactly one of sy_atomic_file_commit or
 * sy_atomic_file_abort releases. On failure *af is left zeroed and needs no cleanup. */
sy_result sy_atomic_file_begin(const char *path, sy_atomic_file *af, sy_error *err);

/** Flushes, fsyncs and closes the temporary file, then renames it over the target (and fsyncs the
 * directory, best effort). On any failure the temporary file is removed and an existing target is
 * left as it was. Always releases the handle (*af is zeroed afterwards, success or not). */
sy_result sy_atomic_file_commit(sy_atomic_file *af, sy_error *err);

/** Closes and removes the temporary file; the target is untouched. Safe on a zeroed, committed or
 * already aborted handle (does nothing then). *af is zeroed afterwards. */
void sy_atomic_file_abort(sy_atomic_file *af);

/** Model files stay in their folder: checks a file that a model names by `uri` (a glTF buffer or
 * image URI, an X3D url) before it is read. `path` is the uri already joined to the referring
 * file's folder. The file is allowed when its real path (symbolic links and ".." resolved) lies
 * inside the model's folder `model_dir` (the folder of the top-level model file; "" = the working
 * directory) or inside one of the extra `roots`. An absolute uri and a "file:" uri are refused
 * unless they lie inside one of the extra roots (the model's folder alone never admits them).
 * On success *real_out is the resolved path to read (malloc()ed, the caller frees it), so the file
 * read is the file checked. A file that does not exist gives SY_ERR_NOT_FOUND; a refusal
 * SY_ERR_LIMIT with a message naming `model`, the uri and the option that admits more folders
 * (--allow-path DIR, the loaders' allowed_roots). Thread-safe (no shared state). */
sy_result sy_path_confine(const char *model, const char *uri, const char *path, const char *model_dir,
                          const char *const *roots, size_t root_count, char **real_out, sy_error *err);

/** Removes every temporary file that an unfinished sy_atomic_file of this process holds, and makes
 * every later sy_atomic_file_begin and sy_atomic_file_commit fail ("output was cancelled"): for a
 * process that is about to end on SIGINT / SIGTERM (apps/sy/sy_signals.c calls it from its
 * signal-waiting thread). A commit that already renamed its file is finished and stays. Returns
 * the number of files removed. Thread-safe (one lock shared with begin / commit / abort); it takes
 * a lock, so it is not for use inside an asynchronous signal handler. There is no way back: the
 * cancelled state lasts for the life of the process. */
size_t sy_atomic_file_cancel_all(void);

/** A function sy_atomic_file_commit calls first, with the target and the temporary path, before it
 * flushes and renames: the temporary file exists and the target is untouched while it runs. */
typedef void (*sy_atomic_file_hook)(const char *path, const char *tmp_path);

/** Test support: sets the commit hook (NULL: none, the default). The sy tool sets one only when a
 * test asks it to stop at that point (SY_TEST_PAUSE=commit, apps/sy/sy_testpoint.h), so that a test can
 * interrupt a write in progress without racing it. Process-wide; thread-safe (an atomic pointer),
 * but meant to be set once before any output begins. */
void sy_atomic_file_set_commit_hook(sy_atomic_file_hook hook);

#ifdef __cplusplus
}
#endif
#endif /* SY_FILE_H */
