/* sy_bookmarks.c — saved views (see sy_bookmarks.h): the text file of up to 9 numbered views and
 * their orbits and matrices. */
#include "sy_bookmarks.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

sy_result sy_bookmark_check(const sy_bookmark *b, sy_error *err)
{
    if (!sy_coords_in_range(b->eye, 3) || !sy_coords_in_range(b->target, 3) || !sy_coords_in_range(b->up, 3))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "a number is not finite or beyond %g", (double)SY_COORD_MAX);
    if (b->eye[0] == b->target[0] && b->eye[1] == b->target[1] && b->eye[2] == b->target[2])
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "eye and target are the same point");
    sy_mat4 m;
    if (!sy_mat4_look_at(b->eye, b->target, b->up, &m))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "up is zero or parallel to the viewing direction");
    if (!(b->fov == 0.0f || (b->fov > 0.0f && b->fov < 3.14159265f)))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "the field of view is not above 0 and below 180 degrees");
    return SY_OK;
}

sy_result sy_bookmarks_load(const char *path, sy_bookmark slots[SY_BOOKMARKS_MAX + 1], sy_error *err)
{
    memset(slots, 0, (SY_BOOKMARKS_MAX + 1) * sizeof *slots);
    FILE *f = fopen(path, "rb");
    if (!f)
        return sy_error_set(err, errno == ENOENT ? SY_ERR_NOT_FOUND : SY_ERR_IO, "bookmarks %s: %s", path, strerror(errno));
    char *text = malloc(SY_BOOKMARKS_FILE_MAX + 2);
    if (!text) {
        fclose(f);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bookmarks %s: out of memory", path);
    }
    size_t n = fread(text, 1, SY_BOOKMARKS_FILE_MAX + 1, f);
    bool read_err = ferror(f) != 0;
    fclose(f);
    if (read_err || n > SY_BOOKMARKS_FILE_MAX) {
        free(text);
        return sy_error_set(err, read_err ? SY_ERR_IO : SY_ERR_PARSE, read_err ? "bookmarks %s: read error"
                            : "bookmarks %s: larger than %d bytes: not a bookmarks file", path, SY_BOOKMARKS_FILE_MAX);
    }
    text[n] = '\0';
    sy_bookmark got[SY_BOOKMARKS_MAX + 1];
    memset(got, 0, sizeof got);
    sy_result r = SY_OK;
    unsigned line_no = 0;
    for (char *line = text; r == SY_OK && line && *line;) {
        char *next = strchr(line, '\n');
        if (next) *next++ = '\0';
        line_no++;
        char *s = line;
        while (*s == ' ' || *s == '\t' || *s == '\r') s++;
        if (*s && *s != '#') {
            if (strlen(line) != (size_t)((next ? next - 1 : text + n) - line)) {
                r = sy_error_set(err, SY_ERR_PARSE, "bookmarks %s:%u: a NUL byte: not a text file", path, line_no);
                break;
            }
            double v[11];
            int k = 0;
            char *e = s;
            for (; k < 11; ++k) {
                char *end;
                v[k] = strtod(e, &end);
                if (end == e) break;
                e = end;
            }
            while (*e == ' ' || *e == '\t' || *e == '\r') e++;
            if (k < 10 || *e)
                r = sy_error_set(err, SY_ERR_PARSE, "bookmarks %s:%u: expected \"N EX EY EZ TX TY TZ UX UY UZ [FOV]\" (a slot "
                                 "1..9, nine numbers and the field of view in degrees or nothing)", path, line_no);
            else if (k == 11 && !(v[10] > 0.0 && v[10] < 180.0))
                r = sy_error_set(err, SY_ERR_PARSE, "bookmarks %s:%u: field of view %g: not above 0 and below 180 degrees", path,
                                 line_no, v[10]);
            else if (!(v[0] >= 1 && v[0] <= SY_BOOKMARKS_MAX && v[0] == floor(v[0])))
                r = sy_error_set(err, SY_ERR_PARSE, "bookmarks %s:%u: slot %g is not one of 1..%d", path, line_no, v[0],
                                 SY_BOOKMARKS_MAX);
            if (r == SY_OK) {
                sy_bookmark b = {.set = true};
                for (int i = 0; i < 3; ++i) b.eye[i] = (float)v[1 + i], b.target[i] = (float)v[4 + i], b.up[i] = (float)v[7 + i];
                if (k == 11) b.fov = (float)(v[10] * 3.14159265358979323846 / 180.0);
                sy_error e2 = {0};
                if (sy_bookmark_check(&b, &e2) != SY_OK)
                    r = sy_error_set(err, SY_ERR_PARSE, "bookmarks %s:%u: slot %d: %s", path, line_no, (int)v[0], e2.message);
                else
                    got[(int)v[0]] = b;
            }
        }
        line = next;
    }
    free(text);
    if (r == SY_OK) memcpy(slots, got, sizeof got);
    return r;
}

sy_result sy_bookmarks_save(const char *path, const sy_bookmark slots[SY_BOOKMARKS_MAX + 1], sy_error *err)
{
    size_t len = strlen(path);
    char *tmp = malloc(len + 16);
    if (!tmp) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bookmarks %s: out of memory", path);
    snprintf(tmp, len + 16, "%s.tmp%d", path, (int)(getpid() % 100000));
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        sy_result r = sy_error_set(err, SY_ERR_IO, "bookmarks %s: cannot write %s: %s", path, tmp, strerror(errno));
        free(tmp);
        return r;
    }
    fprintf(f, "# sy bookmarks: N eye(x y z) target(x y z) up(x y z) [vertical field of view, degrees]; sy view saves with "
               "Ctrl+N, recalls with Shift+N\n");
    for (int i = 1; i <= SY_BOOKMARKS_MAX; ++i) {
        const sy_bookmark *b = &slots[i];
        if (!b->set) continue;
        fprintf(f, "%d %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g", i, (double)b->eye[0], (double)b->eye[1],
                (double)b->eye[2], (double)b->target[0], (double)b->target[1], (double)b->target[2], (double)b->up[0],
                (double)b->up[1], (double)b->up[2]);
        if (b->fov > 0.0f) fprintf(f, " %.9g", (double)b->fov * 180.0 / 3.14159265358979323846);
        fputc('\n', f);
    }
    bool bad = ferror(f) != 0;
    bad |= fclose(f) != 0;
    if (bad || rename(tmp, path) != 0) {
        sy_result r = sy_error_set(err, SY_ERR_IO, "bookmarks %s: cannot write: %s", path, strerror(errno));
        remove(tmp);
        free(tmp);
        return r;
    }
    free(tmp);
    return SY_OK;
}

sy_bookmark sy_bookmark_of_orbit(const sy_orbit *o)
{
    sy_mat4 m;
    sy_orbit_matrix(o, &m);
    sy_bookmark b = {.set = true, .eye = {m.m[12], m.m[13], m.m[14]}, .up = {0, 1, 0}};
    memcpy(b.target, o->target, sizeof b.target);
    return b;
}

sy_orbit sy_orbit_of_bookmark(const sy_bookmark *b)
{
    float d[3] = {b->eye[0] - b->target[0], b->eye[1] - b->target[1], b->eye[2] - b->target[2]};
    float dist = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    sy_orbit o = {.dist = dist > 1e-3f ? dist : 1e-3f};
    memcpy(o.target, b->target, sizeof o.target);
    float s = dist > 0.0f ? d[1] / dist : 0.0f;
    o.pitch = asinf(s < -1.0f ? -1.0f : s > 1.0f ? 1.0f : s);
    if (o.pitch > 1.55f) o.pitch = 1.55f;
    if (o.pitch < -1.55f) o.pitch = -1.55f;
    o.yaw = (d[0] == 0.0f && d[2] == 0.0f) ? 0.0f : atan2f(d[0], d[2]);
    return o;
}

bool sy_bookmark_matrix(const sy_bookmark *b, sy_mat4 *out)
{
    if (sy_bookmark_check(b, NULL) != SY_OK) return false;
    return sy_mat4_look_at(b->eye, b->target, b->up, out);
}
