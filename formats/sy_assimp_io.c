/* sy_assimp_io.c — the Assimp loader's ground floor: the rollback (errors and warnings: the macros
 * asp_fail / asp_warn of sy_assimp_internal.h over sy_loader_log.h); the file
 * system Assimp reads through (the model from memory, every other file confined to the model's
 * folder by sy_path_confine and read within the size limit); Assimp's log into sy_log; and the
 * checks of counts a file declares, made before Assimp allocates for them. */
#define _GNU_SOURCE /* memmem */
#include "sy_assimp_internal.h"

#include "sy_file.h"
#include "sy_loader_log.h"
#include "sy_sniff.h"

#include <assimp/cimport.h>

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* >>errors ------------------------------------------------------------------------------------ */

const char *asp_str(const struct aiString *s)
{
    if (!s || s->length == 0 || s->length >= MAXLEN) return "";
    return s->data; /* Assimp keeps it NUL-terminated within MAXLEN */
}

sy_result asp_new(asp_loader *L, sy_object_type t, const char *name, const char *what, uint32_t *id)
{
    if (!sy_array_reserve(&L->objs, L->obj_count, &L->obj_cap, sizeof *L->objs, 64))
        return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", what);
    sy_result r = sy_object_create(L->scene, t, name && name[0] ? name : NULL, id, &L->err);
    if (r) {
        sy_error_prefix(&L->err, "%s: %s", L->path, what);
        return r;
    }
    L->objs[L->obj_count++] = (asp_created){(uint32_t)t, *id};
    return SY_OK;
}

void asp_rollback(asp_loader *L)
{
    for (size_t k = L->obj_count; k-- > 0;) sy_object_destroy(L->scene, L->objs[k].type, L->objs[k].id, NULL);
    L->obj_count = 0;
}

/* >>files ------------------------------------------------------------------------------------- */

typedef struct asp_file {
    struct aiFile f;
    uint8_t *owned; /* a file read from disk (malloc()ed); NULL for the model in memory */
    const uint8_t *data;
    size_t size, pos;
} asp_file;

static size_t f_read(struct aiFile *f, char *buf, size_t size, size_t count)
{
    asp_file *a = (asp_file *)(void *)f->UserData;
    if (size == 0 || count == 0 || a->pos >= a->size) return 0;
    size_t items = (a->size - a->pos) / size;
    if (items > count) items = count;
    memcpy(buf, a->data + a->pos, items * size);
    a->pos += items * size;
    return items;
}

static size_t f_write(struct aiFile *f, const char *buf, size_t size, size_t count)
{
    (void)f, (void)buf, (void)size, (void)count;
    return 0; /* read-only */
}

static size_t f_tell(struct aiFile *f) { return ((asp_file *)(void *)f->UserData)->pos; }
static size_t f_size(struct aiFile *f) { return ((asp_file *)(void *)f->UserData)->size; }
static void f_flush(struct aiFile *f) { (void)f; }

static enum aiReturn f_seek(struct aiFile *f, size_t offset, enum aiOrigin origin)
{
    asp_file *a = (asp_file *)(void *)f->UserData;
    size_t base = origin == aiOrigin_SET ? 0 : origin == aiOrigin_CUR ? a->pos : a->size;
    size_t to = base + offset; /* a negative offset arrives wrapped: unsigned arithmetic undoes it */
    if (origin == aiOrigin_SET) to = offset;
    if (to > a->size) return aiReturn_FAILURE;
    a->pos = to;
    return aiReturn_SUCCESS;
}

static struct aiFile *serve(const uint8_t *data, size_t size, uint8_t *owned)
{
    asp_file *a = calloc(1, sizeof *a);
    if (!a) {
        free(owned);
        return NULL;
    }
    a->owned = owned;
    a->data = data;
    a->size = size;
    a->f = (struct aiFile){f_read, f_write, f_tell, f_size, f_seek, f_flush, (aiUserData)(void *)a};
    return &a->f;
}

/* The uri as the model names it: the path with the model's folder (which Assimp joined) taken off. */
static const char *uri_of(const asp_loader *L, const char *path)
{
    size_t n = strlen(L->model_dir);
    return n && !strncmp(path, L->model_dir, n) ? path + n : path;
}

sy_result asp_read_named(asp_loader *L, const char *uri, void **data, size_t *size, sy_error *err)
{
    *data = NULL;
    *size = 0;
    size_t n = strlen(L->model_dir) + strlen(uri) + 1;
    char *joined = malloc(n);
    if (!joined) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: '%s': out of memory", L->path, uri);
    snprintf(joined, n, "%s%s", uri[0] == '/' ? "" : L->model_dir, uri);
    char *real = NULL;
    sy_result r = sy_path_confine(L->path, uri, joined, L->model_dir, L->opt.allowed_roots, L->opt.allowed_root_count,
                                  &real, err);
    free(joined);
    if (r) return r;
    r = sy_file_read_all(real, L->opt.max_file_bytes, data, size, err);
    free(real);
    return r;
}

/* An MTL library the OBJ opened: its folder (as the model names it) kept once, for its textures. */
static void note_mtl_dir(asp_loader *L, const char *uri)
{
    const char *slash = strrchr(uri, '/');
    size_t n = slash ? (size_t)(slash - uri) + 1 : 0;
    for (size_t k = 0; k < L->mtl_dir_count; ++k)
        if (strlen(L->mtl_dirs[k]) == n && !strncmp(L->mtl_dirs[k], uri, n)) return;
    if (L->mtl_dir_count == SY_ASSIMP_MTL_DIRS) return; /* more folders: their textures fall back to the model's folder */
    char *d = malloc(n + 1);
    if (!d) return; /* the same fallback */
    memcpy(d, uri, n);
    d[n] = '\0';
    L->mtl_dirs[L->mtl_dir_count++] = d;
}

static struct aiFile *io_open(struct aiFileIO *io, const char *path, const char *mode)
{
    asp_loader *L = (asp_loader *)(void *)io->UserData;
    if (!path || !mode || strpbrk(mode, "wa+")) return NULL; /* nothing is written */
    if (!strcmp(path, L->main_name)) return serve(L->main_data, L->main_size, NULL);
    void *data = NULL;
    size_t size = 0;
    sy_error e = {0};
    sy_result r = asp_read_named(L, uri_of(L, path), &data, &size, &e);
    if (r == SY_ERR_NOT_FOUND) return NULL; /* Assimp looks for files that may not exist */
    if (r) {
        if (!L->io_result) {
            L->io_result = r;
            snprintf(L->io_message, sizeof L->io_message, "%s", e.message);
        }
        return NULL;
    }
    if (L->obj) note_mtl_dir(L, uri_of(L, path));
    return serve(data, size, data);
}

static void io_close(struct aiFileIO *io, struct aiFile *f)
{
    (void)io;
    if (!f) return;
    asp_file *a = (asp_file *)(void *)f->UserData;
    free(a->owned);
    free(a);
}

struct aiFileIO asp_file_io(asp_loader *L)
{
    return (struct aiFileIO){io_open, io_close, (aiUserData)(void *)L};
}

/* >>log --------------------------------------------------------------------------------------- */

static asp_loader *g_log_loader; /* the loader whose import runs (under sy_assimp.c's lock) */

void asp_note(asp_loader *L, sy_log_level level, const char *fmt, ...)
{
    if (!sy_log_enabled(level)) return; /* reads an atomic: no lock, also in the import process */
    char text[SY_ERROR_MESSAGE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    asp_notes *n = L->notes;
    if (!n) {
        sy_log(level, "assimp", L->path, "%s", text);
        return;
    }
    uint32_t len = (uint32_t)strlen(text);
    size_t need = n->len + 5 + len;
    if (need > SY_ASSIMP_NOTES_MAX) {
        n->dropped++;
        return;
    }
    if (need > n->cap) {
        size_t cap = n->cap ? n->cap : 4096;
        while (cap < need) cap *= 2;
        char *b = realloc(n->buf, cap);
        if (!b) {
            n->dropped++;
            return;
        }
        n->buf = b, n->cap = cap;
    }
    n->buf[n->len] = (char)level;
    memcpy(n->buf + n->len + 1, &len, 4);
    memcpy(n->buf + n->len + 5, text, len);
    n->len = need;
}

static void log_cb(const char *message, char *user)
{
    (void)user;
    asp_loader *L = g_log_loader;
    char line[SY_ERROR_MESSAGE_MAX];
    snprintf(line, sizeof line, "%s", message ? message : "");
    size_t n = strlen(line);
    while (n && (line[n - 1] == '\n' || line[n - 1] == '\r')) line[--n] = '\0';
    const char *text = strstr(line, ": ");
    text = text ? text + 2 : line; /* "Warn,  T0: text" */
    /* Assimp's own warnings and errors are notes (what its post-processing repaired, parts of a file
     * it ignores); they are not the loader's warnings, which name what the scene lacks (--strict) */
    bool loud = !strncmp(line, "Warn", 4) || !strncmp(line, "Error", 5);
    if (L) asp_note(L, loud ? SY_LOG_NOTE : SY_LOG_DEBUG, "%s", loud ? text : line);
}

static struct aiLogStream g_stream = {log_cb, NULL};

void asp_log_attach(asp_loader *L)
{
    g_log_loader = L;
    aiAttachLogStream(&g_stream);
}

void asp_log_detach(void)
{
    aiDetachLogStream(&g_stream);
    g_log_loader = NULL;
}

/* >>declared counts --------------------------------------------------------------------------- */

static uint64_t sat_add(uint64_t a, uint64_t b) { return a > UINT64_MAX - b ? UINT64_MAX : a + b; }
static uint64_t sat_mul(uint64_t a, uint64_t b) { return b && a > UINT64_MAX / b ? UINT64_MAX : a * b; }

static unsigned ply_type_size(const char *t)
{
    static const struct {
        const char *name;
        unsigned size;
    } types[] = {{"char", 1},   {"int8", 1},    {"uchar", 1},  {"uint8", 1},  {"short", 2},   {"int16", 2},
                 {"ushort", 2}, {"uint16", 2},  {"int", 4},    {"int32", 4},  {"uint", 4},    {"uint32", 4},
                 {"float", 4},  {"float32", 4}, {"double", 8}, {"float64", 8}};
    for (size_t k = 0; k < sizeof types / sizeof types[0]; ++k)
        if (!strcmp(t, types[k].name)) return types[k].size;
    return 1;
}

/* PLY: every element's count times the least bytes one instance takes (binary: its properties'
 * sizes, a list at least its count; ASCII: two characters per property), summed, must fit the
 * bytes after the header. */
static sy_result precheck_ply(asp_loader *L, const uint8_t *p, size_t n)
{
    size_t i = 0;
    bool ascii = true;
    uint64_t need = 0, count = 0, per = 0;
    char elem[64] = "", worst[64] = "", seen[1024] = " ";
    uint64_t worst_count = 0;
    while (i < n) {
        size_t s = i;
        while (i < n && p[i] != '\n') i++;
        char line[256];
        size_t len = i - s < sizeof line - 1 ? i - s : sizeof line - 1;
        memcpy(line, p + s, len);
        line[len] = '\0';
        if (i < n) i++;
        char a[64], b[64], c[64], d[64];
        int k = sscanf(line, "%63s %63s %63s %63s", a, b, c, d);
        /* the header ends where Assimp's parser sees it end: "end_header" at the start of a line and
         * followed by a space, tab, CR, form feed or the line's end (its TokenMatch). Another
         * character (a vertical tab: found by fuzz_assimp_ply) is no end for Assimp, which then
         * loops for ever at the end of the data, so it is none here either. */
        if (len >= 10 && !memcmp(line, "end_header", 10) && strchr(" \t\r\f", line[10])) break;
        if (k >= 2 && !strcmp(a, "format")) ascii = !strcmp(b, "ascii");
        if (k >= 3 && !strcmp(a, "element")) {
            /* an element declared twice: Assimp 5.2 fails an assertion in Triangulate and aborts the
             * process (Debian builds it with assertions; found by fuzz_assimp_ply) */
            if (strlen(seen) + strlen(b) + 2 < sizeof seen) {
                char key[80];
                snprintf(key, sizeof key, " %s ", b);
                if (strstr(seen, key))
                    return asp_fail(L, SY_ERR_PARSE, "PLY header declares element '%s' twice; refused before reading", b);
                strcat(seen, key + 1);
            }
            need = sat_add(need, sat_mul(count, per ? per : 1));
            snprintf(elem, sizeof elem, "%s", b);
            count = strtoull(c, NULL, 10);
            per = 0;
            if (count > worst_count) worst_count = count, snprintf(worst, sizeof worst, "%s", elem);
        }
        if (k >= 3 && !strcmp(a, "property")) {
            if (ascii) per += 2;
            else per += !strcmp(b, "list") ? ply_type_size(c) : ply_type_size(b);
        }
        if (i >= n) /* Assimp 5.2 loops for ever on some headers without end_header */
            return asp_fail(L, SY_ERR_PARSE, "PLY header has no end_header line; refused before reading");
    }
    need = sat_add(need, sat_mul(count, per ? per : 1));
    size_t body = n - i;
    if (need > body)
        return asp_fail(L, SY_ERR_PARSE,
                        "PLY header declares %llu instances of element '%s' (%s), needing at least %llu bytes, but "
                        "only %zu bytes follow the header; refused before reading",
                        (unsigned long long)worst_count, worst, ascii ? "ASCII" : "binary", (unsigned long long)need, body);
    return SY_OK;
}

/* Binary STL: 84 + 50 x facets bytes. Assimp computes it in 32 bits, so a count that wraps passes
 * its check and then allocates for 2^32 / 50 facets and reads past the file: refused here. */
static sy_result precheck_stl(asp_loader *L, const uint8_t *p, size_t n)
{
    if (n < 84) return SY_OK;
    uint32_t facets = (uint32_t)p[80] | (uint32_t)p[81] << 8 | (uint32_t)p[82] << 16 | (uint32_t)p[83] << 24;
    uint32_t wrapped = facets * 50u + 84u;
    uint64_t real = (uint64_t)facets * 50u + 84u;
    if (wrapped == (uint32_t)n && real != n)
        return asp_fail(L, SY_ERR_PARSE,
                        "binary STL header declares %u facets (%llu bytes), the file has %zu; refused before reading",
                        facets, (unsigned long long)real, n);
    return SY_OK;
}

static bool base64_char(uint8_t c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '+' || c == '/'; }

/* ASCII FBX: the quoted base64 strings of every "Content:" (embedded images) must be whole base64
 * (a multiple of 4 characters, '=' only as the last one or two). Assimp 5.2 decodes them into a
 * buffer sized from the characters, frees it when fewer bytes come out and frees it again in the
 * video's destructor (a double free, found by fuzz_assimp_fbx). */
static sy_result precheck_fbx_ascii(asp_loader *L, const uint8_t *p, size_t n)
{
    static const char key[] = "Content:";
    for (size_t i = 0; i + sizeof key - 1 <= n; ++i) {
        const uint8_t *hit = memmem(p + i, n - i, key, sizeof key - 1);
        if (!hit) break;
        i = (size_t)(hit - p);
        size_t j = i + sizeof key - 1, fragment = 0;
        for (;;) {
            while (j < n && (p[j] == ' ' || p[j] == '\t' || p[j] == '\r' || p[j] == '\n' || p[j] == ',')) j++;
            if (j >= n || p[j] != '"') break;
            size_t s = ++j, pad = 0;
            bool ok = true;
            while (j < n && p[j] != '"') {
                if (p[j] == '=') pad++;
                else if (!base64_char(p[j]) || pad) ok = false;
                j++;
            }
            size_t len = j - s;
            if (j < n) j++; /* the closing quote */
            if (!ok || pad > 2 || len % 4 != 0)
                return asp_fail(L, SY_ERR_PARSE,
                                "FBX embedded content (fragment %zu of the Content at byte %zu) is not whole base64 (%zu "
                                "characters); refused before reading",
                                fragment, i, len);
            fragment++;
        }
        i = j ? j - 1 : i;
    }
    return SY_OK;
}

/* COLLADA: the index lists (<p>, <vcount>, <v>, <h>, <int_array>) hold integers only. Assimp 5.2's
 * reader does not advance over another word in them and never returns (an "illum" in a <p> list,
 * found by fuzz_assimp_dae). */
static sy_result precheck_collada(asp_loader *L, const uint8_t *p, size_t n)
{
    static const char *const tags[] = {"<p>", "<p ", "<vcount>", "<vcount ", "<v>", "<v ", "<h>", "<h ", "<int_array "};
    for (size_t i = 0; i < n; ++i) {
        if (p[i] != '<') continue;
        const char *tag = NULL;
        for (size_t k = 0; k < sizeof tags / sizeof tags[0] && !tag; ++k)
            if (n - i >= strlen(tags[k]) && !memcmp(p + i, tags[k], strlen(tags[k]))) tag = tags[k];
        if (!tag) continue;
        size_t j = i + 1;
        while (j < n && p[j] != '>') j++;
        if (j < n && p[j - 1] == '/') continue; /* empty element */
        for (size_t k = j + 1; k < n && p[k] != '<'; ++k) {
            uint8_t c = p[k];
            if ((c >= '0' && c <= '9') || c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '-' || c == '+') continue;
            size_t tl = strcspn(tag + 1, " >");
            return asp_fail(L, SY_ERR_PARSE,
                            "COLLADA <%.*s> list at byte %zu holds '%c', not an integer; refused before reading", (int)tl,
                            tag + 1, k, c >= ' ' && c < 127 ? c : '?');
        }
        i = j;
    }
    return SY_OK;
}

sy_result asp_precheck(asp_loader *L)
{
    const uint8_t *p = L->main_data;
    size_t n = L->main_size;
    /* Assimp takes any file starting with "ply" in any case as PLY, whatever follows on the line */
    if (n >= 3 && (p[0] | 0x20) == 'p' && (p[1] | 0x20) == 'l' && (p[2] | 0x20) == 'y') return precheck_ply(L, p, n);
    sy_result r = precheck_stl(L, p, n);
    /* the content's kind (sy_sniff.h) names the importer Assimp is given (sy_assimp.c); the FBX
     * check walks the whole file, so it runs only where the content is not known as another
     * format (it took 5 % of loading a 10^6-triangle OBJ) */
    sy_file_format f = sy_sniff_bytes(p, n); /* as sy_assimp.c's extension_for */
    bool other = f != SY_FORMAT_UNKNOWN && f != SY_FORMAT_FBX && sy_file_format_is_assimp(f);
    if (r == SY_OK && !other && !(n >= 18 && !memcmp(p, "Kaydara FBX Binary", 18))) r = precheck_fbx_ascii(L, p, n);
    if (r == SY_OK && sy_sniff_bytes(p, n < 1024 ? n : 1024) == SY_FORMAT_COLLADA) r = precheck_collada(L, p, n);
    return r;
}
