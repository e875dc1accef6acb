/** @file
 * sy_bookmarks.h — saved views (bookmarks) of the interactive front-ends: up to 9 numbered views,
 * each an eye, a target and an up direction, kept in a small text file (sy view saves them with
 * Ctrl+1..9 and recalls them with Shift+1..9; `sy render --bookmark FILE:N` renders one). Turned
 * into an orbit (sy_orbit.h) or a camera-to-world matrix.
 *
 * File format (UTF-8 text, at most SY_BOOKMARKS_FILE_MAX bytes): lines "N EX EY EZ TX TY TZ UX UY UZ
 * [FOV]" (N 1..9, then eye, target and up, finite numbers, then optionally the vertical field of
 * view in degrees, above 0 and below 180; a line without it, as files written before it was saved,
 * keeps the camera's own), blank lines and lines starting with '#' ignored; a slot given twice
 * keeps the last line.
 *
 * Ownership: the caller's arrays. Thread-safety: pure functions and one file per call. */
#ifndef SY_BOOKMARKS_H
#define SY_BOOKMARKS_H

#include "sy_common.h"
#include "sy_orbit.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SY_BOOKMARKS_MAX 9               /**< slots 1..9 */
#define SY_BOOKMARKS_FILE_MAX (64 * 1024) /**< the largest bookmarks file read */

/** One saved view. */
typedef struct sy_bookmark {
    bool set;        /**< the slot holds a view */
    float eye[3];    /**< camera position (world) */
    float target[3]; /**< the point looked at (world), not eye */
    float up[3];     /**< up direction, not parallel to target - eye */
    float fov;       /**< vertical field of view, radians, in (0, pi); 0: not saved (the camera's own) */
} sy_bookmark;

/** SY_OK when b is a view a camera can take: finite, within SY_COORD_MAX, eye != target, up not
 * zero nor parallel to the viewing direction (sy_mat4_look_at), fov 0 or in (0, pi); else SY_ERR_INVALID_ARGUMENT saying
 * why. */
sy_result sy_bookmark_check(const sy_bookmark *b, sy_error *err);

/** Reads path into slots[1..SY_BOOKMARKS_MAX] (slots[0] unused; every slot cleared first). A
 * missing file: SY_ERR_NOT_FOUND (the caller may start empty). A file too large, a line that is not
 * "N" and nine numbers, N outside 1..9, a view sy_bookmark_check refuses: SY_ERR_PARSE naming
 * "FILE:LINE" and the reason (nothing kept). */
sy_result sy_bookmarks_load(const char *path, sy_bookmark slots[SY_BOOKMARKS_MAX + 1], sy_error *err);

/** Writes the set slots of slots[1..SY_BOOKMARKS_MAX] to path (replaced through a temporary file in
 * the same folder, so a reader never sees half a file). SY_ERR_IO naming the file when it cannot. */
sy_result sy_bookmarks_save(const char *path, const sy_bookmark slots[SY_BOOKMARKS_MAX + 1], sy_error *err);

/** The view of an orbit: eye and target, up (0, 1, 0) (an orbit has no roll); fov 0 (the caller
 * sets the camera's). */
sy_bookmark sy_bookmark_of_orbit(const sy_orbit *o);

/** The orbit looking from b's eye at its target (its up is dropped: orbits keep +Y up; the pitch
 * is limited to +-1.55 radians as sy_orbit_rotate does). */
sy_orbit sy_orbit_of_bookmark(const sy_bookmark *b);

/** b's camera-to-world matrix (sy_mat4_look_at); false when b fails sy_bookmark_check. */
bool sy_bookmark_matrix(const sy_bookmark *b, sy_mat4 *out);

#ifdef __cplusplus
}
#endif
#endif /* SY_BOOKMARKS_H */
