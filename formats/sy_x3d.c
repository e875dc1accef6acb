/* sy_x3d.c — X3D (XML encoding) loader on libxml2: element tree -> sy_scene objects
 * (see sy_x3d.h for the supported nodes and the documented mappings). */
#define _DEFAULT_SOURCE /* realpath */
#include "sy_x3d.h"
#include "sy_budget.h"

#include "sy_file.h"
#include "sy_log.h"
#include "sy_mesh_util.h"
#include "sy_text.h"

#include <libxml/hash.h>
#include <libxml/parser.h>
#include <libxml/tree.h>
#include <libxml/xmlerror.h>
#include <stb_image.h>

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define PI_F 3.14159265358979323846f

/* >>state ------------------------------------------------------------------------------------- */

/* Objects created for one element (keyed by element address + variant in loader.cache). */
typedef struct created {
    uint32_t node;     /* sy_node id (grouping nodes, Shape, Inline, lights, viewpoints) */
    uint32_t mesh;     /* Shape */
    uint32_t material; /* Appearance variant */
    uint32_t texture;  /* ImageTexture (0 after a failed decode: no texture) */
    uint32_t tex_channels;
    bool done, in_progress;
} created;

typedef struct xfile {
    char *path;   /* for messages */
    char *dir;    /* base directory of relative URLs, "" = none, else ends with '/' */
    xmlHashTablePtr defs; /* DEF name -> xmlNode* (this file's namespace) */
    struct xfile *parent; /* the file that Inlines this one (cycle detection) */
    char *real;   /* realpath, NULL for memory input */
    uint32_t depth;
    uint32_t serial; /* distinct per loaded document: element addresses are reused after a free */
} xfile;

typedef struct pending_light {
    uint32_t light;
    float pos[3];
    float intensity; /* X3D intensity * pi */
    float a2;        /* quadratic attenuation */
} pending_light;

typedef struct loader {
    sy_scene *scene;
    sy_x3d_options opt;
    sy_budget budget; /* the load's, Inline files included (sy_budget.h) */
    sy_x3d_info *info;
    sy_error err;
    xmlHashTablePtr cache;      /* "%p:variant" -> created* */
    xmlHashTablePtr inline_roots; /* realpath -> created* (node of the Inline's scene) */
    xmlHashTablePtr warned;     /* node types already warned about */
    struct { uint32_t type, id; } *objs;
    size_t obj_count, obj_cap;
    pending_light *lights;
    size_t light_count, light_cap;
    sy_bounds bounds; /* world bounds of the shapes (first placement), for light intensities */
    bool have_background;
    uint32_t file_serial;
    size_t max_values;    /* numbers in one attribute: 4 * max_vertices (checked before allocating) */
    sy_result limit_r;    /* first attribute over max_values (the load fails with it) */
    sy_error limit_err;
    const char *model_dir; /* the top-level file's folder: urls must stay inside it (or allowed_roots) */
} loader;

/* What emit makes per vertex at most (position, normal, texcoord, colour): the budget's unit. */
#define X3D_VERTEX_BYTES 48u

/* The budget for n vertices of geometry node el: charge = false checks where a generator sizes its
 * arrays (before it allocates them), charge = true charges once, in emit. */
static sy_result budget_vertices(loader *L, const char *file, const xmlNode *el, uint64_t n, bool charge);


static void warn(loader *L, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void warn(loader *L, const char *fmt, ...)
{
    sy_x3d_info *I = L->info;
    I->warning_count++;
    if (I->stored_warning_count >= SY_X3D_MAX_WARNINGS) return;
    char buf[SY_ERROR_MESSAGE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (!I->warnings) {
        I->warnings = calloc(SY_X3D_MAX_WARNINGS, sizeof(char *));
        if (!I->warnings) return;
    }
    char *s = strdup(buf);
    if (s) I->warnings[I->stored_warning_count++] = s;
}

static int line_of(const xmlNode *el) { return (int)xmlGetLineNo(el); }
static const char *ename(const xmlNode *el) { return (const char *)el->name; }

static sy_result track(loader *L, sy_object_type t, uint32_t id)
{
    if (L->obj_count == L->obj_cap) {
        size_t cap = L->obj_cap ? L->obj_cap * 2 : 64;
        void *p = realloc(L->objs, cap * sizeof *L->objs);
        if (!p) {
            sy_object_destroy(L->scene, t, id, NULL);
            return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        }
        L->objs = p;
        L->obj_cap = cap;
    }
    L->objs[L->obj_count].type = t;
    L->objs[L->obj_count++].id = id;
    return SY_OK;
}

static sy_result new_object(loader *L, sy_object_type t, const char *name, uint32_t *id)
{
    sy_result r = sy_object_create(L->scene, t, name, id, &L->err);
    if (r) return r;
    return track(L, t, *id);
}

static void free_created(void *payload, const xmlChar *name)
{
    (void)name;
    free(payload);
}

static created *cache_get(loader *L, const xfile *F, const void *el, const char *variant, bool create)
{
    char key[112];
    snprintf(key, sizeof key, "%u:%p:%s", (unsigned)F->serial, el, variant);
    created *c = xmlHashLookup(L->cache, (const xmlChar *)key);
    if (c || !create) return c;
    c = calloc(1, sizeof *c);
    if (!c) return NULL;
    if (xmlHashAddEntry(L->cache, (const xmlChar *)key, c) != 0) {
        free(c);
        return NULL;
    }
    return c;
}

/* >>fields ------------------------------------------------------------------------------------ */

static char *attr(const xmlNode *el, const char *name)
{
    return (char *)xmlGetNoNsProp(el, (const xmlChar *)name);
}

static bool attr_present(const xmlNode *el, const char *name)
{
    return xmlHasProp(el, (const xmlChar *)name) != NULL;
}

static bool is_sep(char c) { return c == ' ' || c == ',' || c == '\t' || c == '\n' || c == '\r'; }

/* strtod for the common case, exactly: at most 15 significant decimal digits and a decimal
 * exponent within +-22 make both the mantissa and the power of ten exact doubles, so one multiply
 * or divide rounds correctly (Clinger's fast path), as strtod does. Anything else goes to strtod. */
static double parse_double(const char *p, char **end)
{
    static const double pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                     1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    const char *s = p;
    bool neg = *s == '-';
    if (*s == '-' || *s == '+') s++;
    uint64_t m = 0;
    int sig = 0, e10 = 0;
    bool any = false;
    for (; *s >= '0' && *s <= '9'; s++) {
        any = true;
        if (m || *s != '0') {
            if (++sig > 15) return strtod(p, end);
            m = m * 10 + (uint64_t)(*s - '0');
        }
    }
    if (*s == '.')
        for (s++; *s >= '0' && *s <= '9'; s++) {
            any = true;
            if (m || *s != '0') {
                if (++sig > 15) return strtod(p, end);
                m = m * 10 + (uint64_t)(*s - '0');
            }
            e10--;
        }
    if (!any) return strtod(p, end);
    if (*s == 'e' || *s == 'E') {
        const char *t = s + 1;
        bool eneg = *t == '-';
        if (*t == '-' || *t == '+') t++;
        if (!(*t >= '0' && *t <= '9')) return strtod(p, end);
        int x = 0;
        for (; *t >= '0' && *t <= '9'; t++) {
            if (x > 1000) return strtod(p, end);
            x = x * 10 + (*t - '0');
        }
        e10 += eneg ? -x : x;
        s = t;
    }
    if (e10 < -22 || e10 > 22) return strtod(p, end);
    double v = e10 < 0 ? (double)m / pow10[-e10] : (double)m * pow10[e10];
    *end = (char *)s;
    return neg ? -v : v;
}

/* Parses whitespace / comma separated numbers. The tokens are counted first and checked against
 * max before the array is allocated (once). Returns 1 on success, 0 on a bad token, -1 when there
 * are more than max numbers (*n = the count) or memory runs out; arrays are malloc()ed (NULL when
 * empty). */
static int parse_numbers(const char *s, size_t max, double **out, size_t *n)
{
    *out = NULL;
    *n = 0;
    size_t tokens = 0;
    for (const char *p = s; *p;) {
        while (is_sep(*p)) p++;
        if (!*p) break;
        tokens++;
        while (*p && !is_sep(*p)) p++;
    }
    if (tokens > max) {
        *n = tokens;
        return -1;
    }
    if (!tokens) return 1;
    size_t cap = tokens;
    double *a = malloc(cap * sizeof *a);
    if (!a) return -1;
    const char *p = s;
    for (;;) {
        while (is_sep(*p)) p++;
        if (!*p) break;
        char *end;
        errno = 0;
        double v = parse_double(p, &end);
        if (end == p || !isfinite(v) || fabs(v) > 3.0e38) { /* must fit a float */
            free(a);
            return 0;
        }
        if (*n == cap) { /* "1-2" is one token and two numbers */
            if (cap >= max) {
                free(a);
                *n = cap + 1;
                return -1;
            }
            cap = cap > max / 2 ? max : cap * 2;
            double *q = realloc(a, cap * sizeof *a);
            if (!q) {
                free(a);
                return -1;
            }
            a = q;
        }
        a[(*n)++] = v;
        p = end;
    }
    *out = a;
    return 1;
}

/* Attribute `name` of el as a list of numbers into *v (malloc()ed, NULL when empty). Returns 1 when
 * present, 0 when absent, -1 (warned as "not a list of <what>; <then>") when malformed. More than
 * L->max_values numbers also give -1 and make the load fail (SY_ERR_LIMIT, file:line). */
static int attr_numbers(loader *L, xfile *F, const xmlNode *el, const char *name, const char *what, const char *then,
                        double **v, size_t *n)
{
    *v = NULL;
    *n = 0;
    char *s = attr(el, name);
    if (!s) return 0;
    int ok = parse_numbers(s, L->max_values, v, n);
    xmlFree(s);
    if (ok == 1) return 1;
    if (ok < 0) {
        size_t count = *n;
        *n = 0;
        if (!L->limit_r)
            L->limit_r = count ? sy_error_set(&L->limit_err, SY_ERR_LIMIT, "%s:%d: %s.%s: %zu values exceed the limit of %zu (4 x max_vertices)",
                                              F->path, line_of(el), ename(el), name, count, L->max_values)
                               : sy_error_set(&L->limit_err, SY_ERR_OUT_OF_MEMORY, "%s:%d: %s.%s: out of memory",
                                              F->path, line_of(el), ename(el), name);
        return -1;
    }
    warn(L, "%s:%d: %s.%s: not a list of %s; %s", F->path, line_of(el), ename(el), name, what, then);
    return -1;
}

/* Numeric attribute: fills up to max values into out (defaults kept otherwise); returns the
 * number of values in the attribute (0 when absent or bad: warned). */
static size_t get_floats(loader *L, xfile *F, const xmlNode *el, const char *name, float *out, size_t max)
{
    double *v;
    size_t n;
    if (attr_numbers(L, F, el, name, "numbers", "ignored", &v, &n) <= 0) return 0;
    for (size_t k = 0; k < n && k < max; k++) out[k] = (float)v[k];
    free(v);
    return n;
}

static float get_float(loader *L, xfile *F, const xmlNode *el, const char *name, float def)
{
    float v = def;
    get_floats(L, F, el, name, &v, 1);
    return v;
}

static bool get_bool(const xmlNode *el, const char *name, bool def)
{
    char *s = attr(el, name);
    if (!s) return def;
    bool v = def;
    if (!strcmp(s, "true") || !strcmp(s, "TRUE")) v = true;
    else if (!strcmp(s, "false") || !strcmp(s, "FALSE")) v = false;
    xmlFree(s);
    return v;
}

/* Whole float array attribute (MFFloat / MFVec*): *out malloc()ed float array. */
static bool get_float_array(loader *L, xfile *F, const xmlNode *el, const char *name, size_t group, float **out,
                            size_t *count)
{
    *out = NULL;
    *count = 0;
    double *v;
    size_t n;
    int present = attr_numbers(L, F, el, name, "numbers", "geometry skipped", &v, &n);
    if (present <= 0) return present == 0;
    if (n % group)
        warn(L, "%s:%d: %s.%s: %zu values are not a multiple of %zu; the rest is ignored", F->path, line_of(el),
             ename(el), name, n, group);
    n -= n % group;
    float *f = malloc((n ? n : 1) * sizeof *f);
    if (!f) {
        free(v);
        return false;
    }
    for (size_t k = 0; k < n; k++) f[k] = (float)v[k];
    free(v);
    *out = f;
    *count = n / group;
    return true;
}

static bool get_int_array(loader *L, xfile *F, const xmlNode *el, const char *name, int32_t **out, size_t *count)
{
    *out = NULL;
    *count = 0;
    double *v;
    size_t n;
    int present = attr_numbers(L, F, el, name, "integers", "geometry skipped", &v, &n);
    if (present <= 0) return present == 0;
    int32_t *a = malloc((n ? n : 1) * sizeof *a);
    if (!a) {
        free(v);
        return false;
    }
    for (size_t k = 0; k < n; k++) {
        if (v[k] != floor(v[k]) || v[k] < -1.0 || v[k] > (double)INT32_MAX) {
            warn(L, "%s:%d: %s.%s[%zu]: %g is not a valid index; geometry skipped", F->path, line_of(el), ename(el),
                 name, k, v[k]);
            free(v);
            free(a);
            return false;
        }
        a[k] = (int32_t)v[k];
    }
    free(v);
    *out = a;
    *count = n;
    return true;
}

/* First element child with the given name (or any of the names separated by '|') and, when
 * `field` is given, a matching containerField (or none). */
static bool name_in(const char *name, const char *list)
{
    size_t n = strlen(name);
    for (const char *p = list; *p;) {
        const char *e = strchr(p, '|');
        size_t k = e ? (size_t)(e - p) : strlen(p);
        if (k == n && !strncmp(p, name, n)) return true;
        if (!e) break;
        p = e + 1;
    }
    return false;
}

/* >>DEF/USE ----------------------------------------------------------------------------------- */

/* Resolves USE: returns the DEF'd element (or el itself), NULL when undefined (warned). */
static const xmlNode *resolve(loader *L, xfile *F, const xmlNode *el)
{
    char *use = attr(el, "USE");
    if (!use) return el;
    const xmlNode *t = xmlHashLookup(F->defs, (const xmlChar *)use);
    if (!t) warn(L, "%s:%d: USE '%s' of an undefined DEF; %s skipped", F->path, line_of(el), use, ename(el));
    else if (strcmp(ename(t), ename(el)) != 0)
        warn(L, "%s:%d: USE '%s' names a %s (line %d), used as %s", F->path, line_of(el), use, ename(t), line_of(t),
             ename(el));
    xmlFree(use);
    return t;
}

/* DEF registration happens in document order during the walk (X3D: DEF precedes USE). */
static void define(loader *L, xfile *F, const xmlNode *el)
{
    char *def = attr(el, "DEF");
    if (!def) return;
    if (xmlHashLookup(F->defs, (const xmlChar *)def))
        warn(L, "%s:%d: DEF '%s' defined again; later USEs refer to this one", F->path, line_of(el), def);
    xmlHashUpdateEntry(F->defs, (const xmlChar *)def, (void *)el, NULL);
    xmlFree(def);
}

/* Finds the child element for an SFNode field: a child whose containerField equals field, else the
 * first child whose element name is in `names`. USE is resolved (and DEFs registered). */
static const xmlNode *field_child(loader *L, xfile *F, const xmlNode *el, const char *names, const char *field)
{
    const xmlNode *fallback = NULL;
    for (const xmlNode *c = el->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE) continue;
        char *cf = attr(c, "containerField");
        bool match_field = field && cf && !strcmp(cf, field);
        bool other_field = cf && (!field || strcmp(cf, field) != 0);
        xmlFree(cf);
        if (match_field || (!other_field && !fallback && name_in(ename(c), names))) {
            define(L, F, c);
            const xmlNode *t = resolve(L, F, c);
            if (match_field) return t;
            if (!fallback && t) fallback = t;
        }
    }
    return fallback;
}

/* >>textures ---------------------------------------------------------------------------------- */

/* Next string of an MFString attribute ('"a" "b"' or a bare word); returns false at the end. */
static bool next_mfstring(const char **p, char *out, size_t cap)
{
    const char *s = *p;
    while (*s == ' ' || *s == '\t' || *s == '\n' || *s == '\r' || *s == ',') s++;
    if (!*s) return false;
    size_t n = 0;
    if (*s == '"') {
        s++;
        while (*s && *s != '"') {
            if (*s == '\\' && s[1]) s++;
            if (n + 1 < cap) out[n++] = *s;
            s++;
        }
        if (*s == '"') s++;
    } else {
        while (*s && *s != ' ' && *s != '\t' && *s != '\n' && *s != '\r') {
            if (n + 1 < cap) out[n++] = *s;
            s++;
        }
    }
    out[n] = '\0';
    *p = s;
    return true;
}

static bool is_remote(const char *u) { return strstr(u, "://") != NULL; }

/* URLs in a file are untrusted: only regular files are read (no devices, FIFOs, directories),
 * so a reference cannot block the load or feed it endless data. */
static bool regular_file(const char *path, char *why, size_t cap)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        snprintf(why, cap, "%.400s: cannot open: %s", path, strerror(errno));
        return false;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(why, cap, "%.400s: not a regular file", path);
        return false;
    }
    return true;
}

/* Resolves a relative URL against F->dir (percent-escapes and fragments are not interpreted). */
static bool resolve_url(const xfile *F, const char *u, char *out, size_t cap)
{
    if (u[0] == '/' || !F->dir[0]) return (size_t)snprintf(out, cap, "%s", u) < cap;
    return (size_t)snprintf(out, cap, "%s%s", F->dir, u) < cap;
}

/* Model files stay in their folder: the file that url u (joined: path) names must lie in the
 * top-level model's folder or in allowed_roots (sy_path_confine). Returns SY_OK with out = the real
 * path to read, SY_ERR_NOT_FOUND (the caller tries the next url), or the refusal in L->err (the
 * load fails: a file outside the tree is never read). */
static sy_result confine_url(loader *L, const xfile *F, const xmlNode *el, const char *u, const char *path, char *out,
                             size_t cap)
{
    char *real = NULL;
    sy_error e = {0};
    sy_result r = sy_path_confine("url", u, path, L->model_dir, L->opt.allowed_roots, L->opt.allowed_root_count,
                                  &real, &e);
    if (r == SY_OK && strlen(real) >= cap) r = SY_ERR_NOT_FOUND;
    if (r == SY_OK) memcpy(out, real, strlen(real) + 1);
    free(real);
    if (r != SY_OK && r != SY_ERR_NOT_FOUND) {
        L->err = e;
        sy_error_prefix(&L->err, "%s:%d: %s", F->path, line_of(el), ename(el));
    }
    return r;
}

static uint32_t map_filter(const char *s)
{
    if (!s) return SY_FILTER_LINEAR;
    if (!strncmp(s, "NEAREST", 7)) return SY_FILTER_NEAREST;
    return SY_FILTER_LINEAR;
}

static uint32_t map_boundary(const char *s, bool repeat)
{
    if (!s) return repeat ? SY_WRAP_REPEAT : SY_WRAP_CLAMP;
    if (!strcmp(s, "MIRRORED_REPEAT")) return SY_WRAP_MIRROR;
    if (!strcmp(s, "REPEAT")) return SY_WRAP_REPEAT;
    return SY_WRAP_CLAMP;
}

/* Decodes the first readable URL of an ImageTexture. Returns the texture id (0 = none, warned). */
static sy_result load_texture(loader *L, xfile *F, const xmlNode *el, bool srgb, uint32_t *tex_out,
                              uint32_t *channels_out)
{
    *tex_out = 0;
    *channels_out = 0;
    if (!el) return SY_OK;
    if (strcmp(ename(el), "ImageTexture") != 0) {
        warn(L, "%s:%d: texture node %s not supported; no texture", F->path, line_of(el), ename(el));
        return SY_OK;
    }
    created *c = cache_get(L, F, el, srgb ? "srgb" : "lin", true);
    if (!c) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    if (c->done) {
        *tex_out = c->texture;
        *channels_out = c->tex_channels;
        return SY_OK;
    }
    c->done = true;
    char *urls = attr(el, "url");
    if (!urls) {
        warn(L, "%s:%d: ImageTexture without url; no texture", F->path, line_of(el));
        return SY_OK;
    }
    const char *p = urls;
    char u[2048], path[4096], why[SY_ERROR_MESSAGE_MAX] = "no usable url";
    uint8_t *pixels = NULL;
    int w = 0, h = 0, comp = 0;
    while (!pixels && next_mfstring(&p, u, sizeof u)) {
        if (!u[0] || is_remote(u)) continue;
        if (!strncmp(u, "data:", 5)) {
            snprintf(why, sizeof why, "data: URLs are not supported");
            continue;
        }
        char joined[4096];
        if (!resolve_url(F, u, joined, sizeof joined)) continue;
        sy_result cr = confine_url(L, F, el, u, joined, path, sizeof path);
        if (cr == SY_ERR_NOT_FOUND) {
            snprintf(why, sizeof why, "%.400s: not found", joined);
            continue;
        }
        if (cr != SY_OK) {
            xmlFree(urls);
            return cr;
        }
        if (!regular_file(path, why, sizeof why)) continue;
        void *bytes;
        size_t size;
        sy_error ferr = {0};
        if (sy_file_read_all(path, L->opt.max_file_bytes, &bytes, &size, &ferr)) {
            snprintf(why, sizeof why, "%s", ferr.message);
            continue;
        }
        if (size > INT_MAX || !stbi_info_from_memory(bytes, (int)size, &w, &h, &comp) || w < 1 || h < 1 ||
            comp < 1 || comp > 4) {
            snprintf(why, sizeof why, "%.400s: cannot decode (%s)", path, size > INT_MAX ? "too large" : stbi_failure_reason());
        } else if ((uint64_t)w * (uint64_t)h > L->opt.max_image_pixels) {
            snprintf(why, sizeof why, "%.400s: %dx%d pixels exceed the limit", path, w, h);
        } else if (!sy_budget_fits(&L->budget, (uint64_t)w * (uint64_t)h, (uint64_t)comp)) {
            snprintf(why, sizeof why, "%.400s: %dx%d pixels exceed what is left of the scene budget (%.0f MiB)", path, w,
                     h, (double)(L->budget.limit - L->budget.used) / (1024.0 * 1024.0));
        } else {
            int w2, h2, c2;
            pixels = stbi_load_from_memory(bytes, (int)size, &w2, &h2, &c2, comp);
            if (pixels && (w2 != w || h2 != h)) {
                stbi_image_free(pixels);
                pixels = NULL;
            }
            if (!pixels) snprintf(why, sizeof why, "%.400s: cannot decode (%s)", path, stbi_failure_reason());
        }
        free(bytes);
    }
    xmlFree(urls);
    if (!pixels) {
        warn(L, "%s:%d: ImageTexture: %s; no texture", F->path, line_of(el), why);
        return SY_OK;
    }
    (void)sy_budget_charge(&L->budget, (uint64_t)w * (uint64_t)h, (uint64_t)comp, &L->err, "ImageTexture"); /* fits */
    sy_result r;
    sy_blob *blob = NULL;
    size_t bytes = (size_t)w * (size_t)h * (size_t)comp;
    if ((r = sy_blob_create_copy(pixels, bytes, &blob, &L->err))) {
        stbi_image_free(pixels);
        return r;
    }
    stbi_image_free(pixels);
    char *def = attr(el, "DEF");
    uint32_t id;
    r = new_object(L, SY_TYPE_TEXTURE, def ? def : u, &id);
    xmlFree(def);
    sy_image_info ii = {(uint32_t)w, (uint32_t)h, (uint32_t)comp, srgb ? SY_PIXEL_U8_SRGB : SY_PIXEL_U8_LINEAR};
    if (!r) r = sy_texture_set_image(L->scene, (sy_texture){id}, &ii, blob, &L->err);
    sy_blob_release(blob);
    if (r) return r;
    sy_sampler smp = {SY_WRAP_REPEAT, SY_WRAP_REPEAT, SY_FILTER_LINEAR, SY_FILTER_LINEAR};
    bool rs = get_bool(el, "repeatS", true), rt = get_bool(el, "repeatT", true);
    smp.wrap_s = rs ? SY_WRAP_REPEAT : SY_WRAP_CLAMP;
    smp.wrap_t = rt ? SY_WRAP_REPEAT : SY_WRAP_CLAMP;
    const xmlNode *tp = field_child(L, F, el, "TextureProperties", "textureProperties");
    if (tp) {
        char *mag = attr(tp, "magnificationFilter"), *min = attr(tp, "minificationFilter");
        char *bs = attr(tp, "boundaryModeS"), *bt = attr(tp, "boundaryModeT");
        smp.mag_filter = map_filter(mag);
        smp.min_filter = map_filter(min);
        if (bs) smp.wrap_s = map_boundary(bs, rs);
        if (bt) smp.wrap_t = map_boundary(bt, rt);
        xmlFree(mag); xmlFree(min); xmlFree(bs); xmlFree(bt);
    }
    if ((r = sy_texture_set_sampler(L->scene, (sy_texture){id}, &smp, &L->err))) return r;
    L->info->counts.textures++;
    c->texture = id;
    c->tex_channels = (uint32_t)comp;
    *tex_out = id;
    *channels_out = (uint32_t)comp;
    return SY_OK;
}

/* An ImageTexture or a SurfaceShaderTexture wrapping one (CommonSurfaceShader). */
static const xmlNode *texture_field(loader *L, xfile *F, const xmlNode *el, const char *field)
{
    const xmlNode *t = NULL;
    for (const xmlNode *c = el->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE) continue;
        char *cf = attr(c, "containerField");
        bool m = cf && !strcmp(cf, field);
        xmlFree(cf);
        if (!m) continue;
        define(L, F, c);
        t = resolve(L, F, c);
        break;
    }
    if (t && !strcmp(ename(t), "SurfaceShaderTexture")) t = field_child(L, F, t, "ImageTexture", "texture");
    return t;
}

/* >>materials --------------------------------------------------------------------------------- */

static float shininess_to_roughness(float shininess, float specular_max)
{
    if (!(specular_max > 0.0f)) return 1.0f;
    float n = 128.0f * fmaxf(0.0f, fminf(1.0f, shininess));
    float alpha = sqrtf(2.0f / (n + 2.0f));
    return fminf(1.0f, sqrtf(alpha));
}

static float max3(const float *v) { return fmaxf(v[0], fmaxf(v[1], v[2])); }

static void clamp01(float *v, int n)
{
    for (int k = 0; k < n; k++) v[k] = fmaxf(0.0f, fminf(1.0f, v[k]));
}

static void set_tex(sy_texture_ref *ref, uint32_t id)
{
    ref->texture.id = id;
    ref->scale = 1.0f;
    ref->uv_scale[0] = ref->uv_scale[1] = 1.0f;
}

/* Material for (Appearance, solid, vertex colours). 0 = the default material (never: X3D needs
 * an explicit one); *normal_map tells the geometry to generate tangents. */
static sy_result get_material(loader *L, xfile *F, const xmlNode *app, bool solid, bool vcolors, bool stroke,
                              uint32_t *out, bool *normal_map)
{
    char variant[16];
    snprintf(variant, sizeof variant, "m%d%d%d", solid, vcolors, stroke);
    created *c = cache_get(L, F, app ? (const void *)app : (const void *)F, variant, true);
    if (!c) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    if (c->done) {
        *out = c->material;
        *normal_map = c->tex_channels != 0;
        return SY_OK;
    }
    sy_material_data md = *(const sy_material_data *)sy_object_defaults(SY_TYPE_MATERIAL);
    md.double_sided = !solid;
    md.metallic = 0.0f;
    sy_result r;
    uint32_t tex, ch, alpha_channels = 0;
    const xmlNode *mat = app ? field_child(L, F, app, "Material|PhysicalMaterial|UnlitMaterial|TwoSidedMaterial", "material") : NULL;
    const xmlNode *css = NULL;
    if (app) {
        for (const xmlNode *k = app->children; k; k = k->next) {
            if (k->type != XML_ELEMENT_NODE) continue;
            if (!strcmp(ename(k), "CommonSurfaceShader")) {
                define(L, F, k);
                css = resolve(L, F, k);
            } else if (!strcmp(ename(k), "ComposedShader") || !strcmp(ename(k), "PackagedShader") ||
                       !strcmp(ename(k), "ProgramShader")) {
                warn(L, "%s:%d: %s not supported; the Material is used", F->path, line_of(k), ename(k));
            }
        }
    }
    if (css) {
        float diffuse[3] = {0.8f, 0.8f, 0.8f}, spec[3] = {0, 0, 0}, emis[3] = {0, 0, 0}, refl[3] = {0, 0, 0};
        float trans[3] = {0, 0, 0};
        get_floats(L, F, css, "diffuseFactor", diffuse, 3);
        get_floats(L, F, css, "specularFactor", spec, 3);
        get_floats(L, F, css, "emissiveFactor", emis, 3);
        get_floats(L, F, css, "reflectionFactor", refl, 3);
        get_floats(L, F, css, "transmissionFactor", trans, 3);
        float shin = get_float(L, F, css, "shininessFactor", 0.2f);
        float alpha = get_float(L, F, css, "alphaFactor", 1.0f);
        float rior = get_float(L, F, css, "relativeIndexOfRefraction", 1.0f);
        clamp01(diffuse, 3); clamp01(spec, 3); clamp01(refl, 3); clamp01(trans, 3);
        float metal = max3(refl);
        for (int k = 0; k < 3; k++) md.base_color[k] = metal > 0 ? diffuse[k] * (1 - metal) + refl[k] : diffuse[k];
        clamp01(md.base_color, 3);
        md.base_color[3] = fmaxf(0.0f, fminf(1.0f, alpha));
        md.metallic = metal;
        md.roughness = metal > 0 || max3(trans) > 0 ? shininess_to_roughness(shin, 1.0f) : shininess_to_roughness(shin, max3(spec));
        for (int k = 0; k < 3; k++) md.emissive[k] = fmaxf(0.0f, emis[k]);
        md.transmission = max3(trans);
        if (rior > 0.0f && isfinite(rior)) md.ior = rior >= 1.0f ? rior : 1.0f / rior;
        if ((r = load_texture(L, F, texture_field(L, F, css, "diffuseTexture"), true, &tex, &ch))) return r;
        if (tex) set_tex(&md.base_color_texture, tex), alpha_channels = (ch == 2 || ch == 4);
        if ((r = load_texture(L, F, texture_field(L, F, css, "emissiveTexture"), true, &tex, &ch))) return r;
        if (tex) set_tex(&md.emissive_texture, tex);
        if ((r = load_texture(L, F, texture_field(L, F, css, "normalTexture"), false, &tex, &ch))) return r;
        if (tex) {
            set_tex(&md.normal_texture, tex);
            float ns[3] = {2, 2, 2}, nb[3] = {-1, -1, -1};
            get_floats(L, F, css, "normalScale", ns, 3);
            get_floats(L, F, css, "normalBias", nb, 3);
            char *fmt = attr(css, "normalFormat"), *space = attr(css, "normalSpace");
            if (ns[0] != 2 || nb[0] != -1 || (fmt && strcmp(fmt, "UNORM")) || (space && strcmp(space, "TANGENT")))
                warn(L, "%s:%d: CommonSurfaceShader: only UNORM tangent-space normal maps with scale 2 and bias -1 are "
                     "supported; the normal map is read as such", F->path, line_of(css));
            xmlFree(fmt);
            xmlFree(space);
        }
    } else if (mat && !strcmp(ename(mat), "PhysicalMaterial")) {
        float base[3] = {1, 1, 1}, emis[3] = {0, 0, 0};
        get_floats(L, F, mat, "baseColor", base, 3);
        get_floats(L, F, mat, "emissiveColor", emis, 3);
        clamp01(base, 3);
        memcpy(md.base_color, base, sizeof base);
        md.base_color[3] = 1.0f - fmaxf(0.0f, fminf(1.0f, get_float(L, F, mat, "transparency", 0.0f)));
        md.metallic = fmaxf(0.0f, fminf(1.0f, get_float(L, F, mat, "metallic", 1.0f)));
        md.roughness = fmaxf(0.0f, fminf(1.0f, get_float(L, F, mat, "roughness", 1.0f)));
        for (int k = 0; k < 3; k++) md.emissive[k] = fmaxf(0.0f, emis[k]);
        if ((r = load_texture(L, F, texture_field(L, F, mat, "baseTexture"), true, &tex, &ch))) return r;
        if (tex) set_tex(&md.base_color_texture, tex), alpha_channels = (ch == 2 || ch == 4);
        if ((r = load_texture(L, F, texture_field(L, F, mat, "metallicRoughnessTexture"), false, &tex, &ch))) return r;
        if (tex) set_tex(&md.metallic_roughness_texture, tex);
        if ((r = load_texture(L, F, texture_field(L, F, mat, "emissiveTexture"), true, &tex, &ch))) return r;
        if (tex) set_tex(&md.emissive_texture, tex);
        if ((r = load_texture(L, F, texture_field(L, F, mat, "occlusionTexture"), false, &tex, &ch))) return r;
        if (tex) set_tex(&md.occlusion_texture, tex);
        if ((r = load_texture(L, F, texture_field(L, F, mat, "normalTexture"), false, &tex, &ch))) return r;
        if (tex) set_tex(&md.normal_texture, tex);
    } else if (mat) { /* Material (X3D 3 / 4), UnlitMaterial, TwoSidedMaterial (front side) */
        bool unlit = !strcmp(ename(mat), "UnlitMaterial");
        float diffuse[3] = {0.8f, 0.8f, 0.8f}, spec[3] = {0, 0, 0}, emis[3] = {0, 0, 0};
        if (unlit) diffuse[0] = diffuse[1] = diffuse[2] = 0;
        get_floats(L, F, mat, "diffuseColor", diffuse, 3);
        get_floats(L, F, mat, "specularColor", spec, 3);
        get_floats(L, F, mat, "emissiveColor", emis, 3);
        if (unlit) {
            float e[3] = {1, 1, 1};
            get_floats(L, F, mat, "emissiveColor", e, 3);
            memcpy(diffuse, e, sizeof e);
            md.unlit = 1;
        }
        clamp01(diffuse, 3);
        clamp01(spec, 3);
        memcpy(md.base_color, diffuse, sizeof diffuse);
        md.base_color[3] = 1.0f - fmaxf(0.0f, fminf(1.0f, get_float(L, F, mat, "transparency", 0.0f)));
        md.roughness = shininess_to_roughness(get_float(L, F, mat, "shininess", 0.2f), max3(spec));
        if (!unlit) for (int k = 0; k < 3; k++) md.emissive[k] = fmaxf(0.0f, emis[k]);
        if ((r = load_texture(L, F, texture_field(L, F, mat, unlit ? "emissiveTexture" : "diffuseTexture"), true, &tex, &ch))) return r;
        if (tex) set_tex(&md.base_color_texture, tex), alpha_channels = (ch == 2 || ch == 4);
        if (!unlit) {
            if ((r = load_texture(L, F, texture_field(L, F, mat, "emissiveTexture"), true, &tex, &ch))) return r;
            if (tex) set_tex(&md.emissive_texture, tex);
            if ((r = load_texture(L, F, texture_field(L, F, mat, "normalTexture"), false, &tex, &ch))) return r;
            if (tex) set_tex(&md.normal_texture, tex);
        }
    } else {
        /* no Material: lighting off, unlit white (X3D) */
        md.unlit = 1;
        md.base_color[0] = md.base_color[1] = md.base_color[2] = 1.0f;
        md.roughness = 1.0f;
    }
    /* Appearance-level texture (X3D 3: replaces the diffuse colour for RGB textures) */
    if (app && !md.base_color_texture.texture.id) {
        const xmlNode *t = field_child(L, F, app, "ImageTexture|MultiTexture|MovieTexture|PixelTexture", "texture");
        if ((r = load_texture(L, F, t, true, &tex, &ch))) return r;
        if (tex) {
            set_tex(&md.base_color_texture, tex);
            alpha_channels = (ch == 2 || ch == 4);
            if (mat && strcmp(ename(mat), "PhysicalMaterial") != 0 && !css) {
                /* X3D lighting model: an RGB texture replaces the diffuse colour, grey modulates it */
                if (ch >= 3) md.base_color[0] = md.base_color[1] = md.base_color[2] = 1.0f;
            } else if (!mat && !css) {
                md.base_color[0] = md.base_color[1] = md.base_color[2] = 1.0f;
            }
        }
    }
    if (vcolors && !css && !(mat && !strcmp(ename(mat), "PhysicalMaterial")))
        md.base_color[0] = md.base_color[1] = md.base_color[2] = 1.0f; /* X3D: Color replaces diffuseColor */
    if (stroke && !css) {
        /* X3D points and lines are unlit: the Material's emissiveColor (UnlitMaterial: its colour;
         * no Material: white), replaced by the Color node's colours when present */
        if (mat && strcmp(ename(mat), "UnlitMaterial") != 0) {
            float e[3] = {0, 0, 0};
            get_floats(L, F, mat, "emissiveColor", e, 3);
            clamp01(e, 3);
            memcpy(md.base_color, e, sizeof e);
        }
        if (vcolors) md.base_color[0] = md.base_color[1] = md.base_color[2] = 1.0f;
        md.unlit = 1;
        md.emissive[0] = md.emissive[1] = md.emissive[2] = 0.0f;
        memset(&md.normal_texture, 0, sizeof md.normal_texture);
        memset(&md.emissive_texture, 0, sizeof md.emissive_texture);
        md.double_sided = 0;
    }
    /* alpha mode: Appearance.alphaMode (X3D 4) or AUTO */
    char *am = app ? attr(app, "alphaMode") : NULL;
    if (am && !strcmp(am, "OPAQUE")) md.alpha_mode = SY_ALPHA_OPAQUE;
    else if (am && !strcmp(am, "MASK")) md.alpha_mode = SY_ALPHA_MASK;
    else if (am && !strcmp(am, "BLEND")) md.alpha_mode = SY_ALPHA_BLEND;
    else md.alpha_mode = (md.base_color[3] < 1.0f || alpha_channels) ? SY_ALPHA_BLEND : SY_ALPHA_OPAQUE;
    xmlFree(am);
    if (app) md.alpha_cutoff = get_float(L, F, app, "alphaCutoff", 0.5f);
    if (md.ior < 1.0f) md.ior = 1.0f;
    char *def = app ? attr(app, "DEF") : NULL;
    if (!def && mat) def = attr(mat, "DEF");
    uint32_t id;
    r = new_object(L, SY_TYPE_MATERIAL, def, &id);
    xmlFree(def);
    md.name = NULL;
    if (!r) {
        const sy_material_data *cur = sy_material_get(L->scene, (sy_material){id});
        md.name = cur ? cur->name : NULL;
        r = sy_material_set(L->scene, (sy_material){id}, &md, &L->err);
    }
    if (r) {
        sy_error_prefix(&L->err, "%s:%d: material", F->path, app ? line_of(app) : 0);
        return r;
    }
    L->info->counts.materials++;
    c->done = true;
    c->material = id;
    c->tex_channels = md.normal_texture.texture.id != 0;
    *out = id;
    *normal_map = c->tex_channels != 0;
    return SY_OK;
}

/* >>geometry ---------------------------------------------------------------------------------- */

static void axis_angle_quat(const float aa[4], float q[4]);

/* Corner-based geometry: every triangle corner refers to a coordinate and (optionally) to a
 * normal, texcoord and colour; output is non-indexed. */
typedef struct corners {
    uint32_t *coord;  /* 3 * tris */
    int32_t *normal;  /* index or -1 (generated) ; NULL: all generated */
    int32_t *tc;      /* index; NULL: generated / none */
    int32_t *color;   /* index; NULL: none */
    size_t tris;
} corners;

typedef struct geom_src {
    float *pts;  size_t npts;
    float *nrm;  size_t nnrm;
    float *tc;   size_t ntc;
    float *col;  size_t ncol; uint32_t col_comps;
    float crease;
    bool ccw, generate_tc;
    float tt[6]; /* texture transform (2x3 affine, X3D t-up space) */
} geom_src;

static void corners_free(corners *c)
{
    free(c->coord); free(c->normal); free(c->tc); free(c->color);
    memset(c, 0, sizeof *c);
}

static void geom_src_free(geom_src *g)
{
    free(g->pts); free(g->nrm); free(g->tc); free(g->col);
}

static sy_result make_blob(loader *L, void *data, size_t bytes, sy_blob **out)
{
    sy_result r = sy_blob_create_take(data, bytes, out, &L->err);
    if (r) free(data);
    return r;
}

/* Emits the primitive. Takes ownership of nothing; *prim gets new blobs. */
static sy_result budget_vertices(loader *L, const char *file, const xmlNode *el, uint64_t n, bool charge)
{
    if (!charge && sy_budget_fits(&L->budget, n, X3D_VERTEX_BYTES)) return SY_OK;
    return sy_budget_charge(&L->budget, n, X3D_VERTEX_BYTES, &L->err, "%s:%d: %s: %llu vertices", file, line_of(el),
                            ename(el), (unsigned long long)n);
}

static sy_result emit(loader *L, xfile *F, const xmlNode *el, const geom_src *g, corners *c, sy_primitive *prim)
{
    size_t nv = c->tris * 3;
    memset(prim, 0, sizeof *prim);
    if (nv > L->opt.max_vertices)
        return sy_error_set(&L->err, SY_ERR_LIMIT, "%s:%d: %s: %zu vertices exceed the limit of %zu", F->path,
                            line_of(el), ename(el), nv, L->opt.max_vertices);
    sy_result br = budget_vertices(L, F->path, el, nv, true);
    if (br) return br;
    if (!g->ccw)
        for (size_t t = 0; t < c->tris; t++) {
            uint32_t a = c->coord[3 * t + 1];
            c->coord[3 * t + 1] = c->coord[3 * t + 2];
            c->coord[3 * t + 2] = a;
            if (c->normal) { int32_t b = c->normal[3 * t + 1]; c->normal[3 * t + 1] = c->normal[3 * t + 2]; c->normal[3 * t + 2] = b; }
            if (c->tc) { int32_t b = c->tc[3 * t + 1]; c->tc[3 * t + 1] = c->tc[3 * t + 2]; c->tc[3 * t + 2] = b; }
            if (c->color) { int32_t b = c->color[3 * t + 1]; c->color[3 * t + 1] = c->color[3 * t + 2]; c->color[3 * t + 2] = b; }
        }
    float *pos = malloc(nv * 12), *nrm = NULL, *uv = NULL, *col = NULL, *gen = NULL;
    if (!pos) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    for (size_t k = 0; k < nv; k++) memcpy(pos + 3 * k, g->pts + 3 * (size_t)c->coord[k], 12);
    sy_result r = SY_OK;
    bool need_gen = !c->normal || !g->nrm;
    if (!need_gen)
        for (size_t k = 0; k < nv && !need_gen; k++) need_gen = c->normal[k] < 0;
    if (need_gen && (r = sy_corner_normals(g->pts, g->npts, c->coord, c->tris, g->crease, &gen, &L->err))) goto fail;
    nrm = malloc(nv * 12);
    if (!nrm) goto oom;
    for (size_t k = 0; k < nv; k++) {
        if (c->normal && g->nrm && c->normal[k] >= 0) {
            float *n = nrm + 3 * k;
            memcpy(n, g->nrm + 3 * (size_t)c->normal[k], 12);
            float l = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            if (l > 0) { n[0] /= l; n[1] /= l; n[2] /= l; }
            else { n[0] = 0; n[1] = 0; n[2] = 1; }
        } else {
            memcpy(nrm + 3 * k, gen + 3 * k, 12);
        }
    }
    free(gen);
    gen = NULL;
    if ((c->tc && g->tc) || g->generate_tc) {
        uv = malloc(nv * 8);
        if (!uv) goto oom;
        float bmin[3] = {INFINITY, INFINITY, INFINITY}, bmax[3] = {-INFINITY, -INFINITY, -INFINITY};
        int sa = 0, ta = 1;
        float ssize = 1;
        if (!(c->tc && g->tc)) { /* X3D default: bounding box, longest side S, second T */
            for (size_t k = 0; k < g->npts; k++)
                for (int a = 0; a < 3; a++) {
                    bmin[a] = fminf(bmin[a], g->pts[3 * k + a]);
                    bmax[a] = fmaxf(bmax[a], g->pts[3 * k + a]);
                }
            float ext[3] = {bmax[0] - bmin[0], bmax[1] - bmin[1], bmax[2] - bmin[2]};
            int order[3] = {0, 1, 2};
            for (int i = 0; i < 3; i++)
                for (int j = i + 1; j < 3; j++)
                    if (ext[order[j]] > ext[order[i]]) { int t = order[i]; order[i] = order[j]; order[j] = t; }
            sa = order[0];
            ta = order[1];
            ssize = ext[sa] > 0 ? ext[sa] : 1;
        }
        for (size_t k = 0; k < nv; k++) {
            float s, t;
            if (c->tc && g->tc) {
                s = g->tc[2 * (size_t)c->tc[k]];
                t = g->tc[2 * (size_t)c->tc[k] + 1];
            } else {
                s = (pos[3 * k + sa] - bmin[sa]) / ssize;
                t = (pos[3 * k + ta] - bmin[ta]) / ssize;
            }
            float s2 = g->tt[0] * s + g->tt[1] * t + g->tt[2], t2 = g->tt[3] * s + g->tt[4] * t + g->tt[5];
            uv[2 * k] = s2;
            uv[2 * k + 1] = 1.0f - t2;
        }
    }
    if (c->color && g->col) {
        col = malloc(nv * 16);
        if (!col) goto oom;
        for (size_t k = 0; k < nv; k++) {
            const float *s = g->col + (size_t)g->col_comps * (size_t)c->color[k];
            col[4 * k] = s[0]; col[4 * k + 1] = s[1]; col[4 * k + 2] = s[2];
            col[4 * k + 3] = g->col_comps == 4 ? s[3] : 1.0f;
        }
    }
    r = make_blob(L, pos, nv * 12, &prim->positions);
    pos = NULL;
    if (!r) r = make_blob(L, nrm, nv * 12, &prim->normals);
    nrm = NULL;
    if (!r && uv) r = make_blob(L, uv, nv * 8, &prim->texcoords0);
    uv = NULL;
    if (!r && col) r = make_blob(L, col, nv * 16, &prim->colors);
    col = NULL;
    if (r) goto fail;
    return SY_OK;
oom:
    r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
fail:
    free(pos); free(nrm); free(uv); free(col); free(gen);
    sy_blob_release(prim->positions); sy_blob_release(prim->normals);
    sy_blob_release(prim->texcoords0); sy_blob_release(prim->colors);
    memset(prim, 0, sizeof *prim);
    return r;
}

/* Reads Coordinate / Normal / TextureCoordinate / Color children of a geometry node. */
static bool read_sources(loader *L, xfile *F, const xmlNode *el, geom_src *g)
{
    const xmlNode *n;
    if ((n = field_child(L, F, el, "Coordinate|CoordinateDouble", "coord")) &&
        !get_float_array(L, F, n, "point", 3, &g->pts, &g->npts))
        return false;
    if ((n = field_child(L, F, el, "Normal", "normal")) && !get_float_array(L, F, n, "vector", 3, &g->nrm, &g->nnrm))
        return false;
    n = field_child(L, F, el, "TextureCoordinate|MultiTextureCoordinate|TextureCoordinateGenerator", "texCoord");
    if (n && !strcmp(ename(n), "MultiTextureCoordinate")) n = field_child(L, F, n, "TextureCoordinate", "texCoord");
    if (n && !strcmp(ename(n), "TextureCoordinate") && !get_float_array(L, F, n, "point", 2, &g->tc, &g->ntc))
        return false;
    if ((n = field_child(L, F, el, "Color|ColorRGBA", "color"))) {
        g->col_comps = !strcmp(ename(n), "ColorRGBA") ? 4 : 3;
        if (!get_float_array(L, F, n, "color", g->col_comps, &g->col, &g->ncol)) return false;
        for (size_t k = 0; k < g->ncol * g->col_comps; k++) g->col[k] = fmaxf(0.0f, fminf(1.0f, g->col[k]));
    }
    g->ccw = get_bool(el, "ccw", true);
    g->crease = get_float(L, F, el, "creaseAngle", 0.0f);
    return true;
}

static bool check_range(loader *L, xfile *F, const xmlNode *el, const char *what, const int32_t *idx, size_t n,
                        size_t limit)
{
    for (size_t k = 0; k < n; k++)
        if (idx[k] < 0 || (size_t)idx[k] >= limit) {
            warn(L, "%s:%d: %s: %s[%zu] = %d is outside the %zu entries of its list; geometry skipped", F->path,
                 line_of(el), ename(el), what, k, (int)idx[k], limit);
            return false;
        }
    return true;
}

/* Per-corner index of an attribute: explicit index list (parallel to the corner's source
 * position in coordIndex / per face) or implicit. */
typedef struct face_lists {
    const int32_t *ci, *ni, *ti, *coi; /* coordIndex, normalIndex, texCoordIndex, colorIndex */
    size_t nci, nni, nti, ncoi;
    bool npv, cpv;                     /* normalPerVertex, colorPerVertex */
} face_lists;

/* Triangulates the -1-separated polygons of an IndexedFaceSet (or an Extrusion's generated
 * faces) into corners. Bad indices are warned and leave *ok false. */
static sy_result build_faces(loader *L, xfile *F, const xmlNode *el, geom_src *g, corners *c, const face_lists *fl,
                             bool *ok)
{
    *ok = false;
    const int32_t *ci = fl->ci, *ni = fl->ni, *ti = fl->ti, *coi = fl->coi;
    size_t nci = fl->nci, nni = fl->nni, nti = fl->nti, ncoi = fl->ncoi;
    bool npv = fl->npv, cpv = fl->cpv;
    sy_result r = SY_OK;
    uint32_t *local = NULL, *tris = NULL;
    float *fpts = NULL;
    void *scratch = NULL;
    /* faces: count corners and triangles */
    size_t faces = 0, total_tris = 0, maxk = 0, k0 = 0;
    for (size_t k = 0; k <= nci; k++) {
        if (k == nci || ci[k] == -1) {
            size_t n = k - k0;
            if (n >= 3) total_tris += n - 2;
            if (n > maxk) maxk = n;
            if (k < nci || n > 0) faces++;
            k0 = k + 1;
        } else if (ci[k] < 0 || (size_t)ci[k] >= g->npts) {
            warn(L, "%s:%d: %s: coordIndex[%zu] = %d is outside the %zu points of its Coordinate; geometry skipped",
                 F->path, line_of(el), ename(el), k, (int)ci[k], g->npts);
            goto done;
        }
    }
    if (total_tris == 0) {
        warn(L, "%s:%d: %s has no polygon with 3 or more vertices; skipped", F->path, line_of(el), ename(el));
        goto done;
    }
    if (total_tris > L->opt.max_vertices / 3) {
        r = sy_error_set(&L->err, SY_ERR_LIMIT, "%s:%d: %s: %zu triangles exceed the vertex limit of %zu", F->path,
                         line_of(el), ename(el), total_tris, L->opt.max_vertices);
        goto done;
    }
    if ((r = budget_vertices(L, F->path, el, (uint64_t)total_tris * 3u, false))) goto done;
    c->tris = total_tris;
    c->coord = malloc(total_tris * 3 * sizeof(uint32_t));
    size_t *src = malloc(total_tris * 3 * sizeof(size_t)); /* position in coordIndex */
    size_t *face = malloc(total_tris * 3 * sizeof(size_t));
    local = malloc(maxk * sizeof(uint32_t));
    tris = malloc(maxk * 3 * sizeof(uint32_t));
    fpts = malloc(maxk * 12);
    scratch = malloc(SY_TRIANGULATE_SCRATCH(maxk));
    if (!c->coord || !src || !face || !local || !tris || !fpts || !scratch) {
        free(src); free(face);
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    size_t out = 0, f = 0;
    k0 = 0;
    for (size_t k = 0; k <= nci; k++) {
        if (k < nci && ci[k] != -1) continue;
        size_t n = k - k0;
        if (n >= 3) {
            for (size_t q = 0; q < n; q++) {
                memcpy(fpts + 3 * q, g->pts + 3 * (size_t)ci[k0 + q], 12);
                local[q] = (uint32_t)q;
            }
            size_t nt = sy_triangulate_polygon(fpts, local, n, tris, scratch);
            for (size_t q = 0; q < nt * 3; q++) {
                src[out] = k0 + tris[q];
                face[out] = f;
                c->coord[out] = (uint32_t)ci[k0 + tris[q]];
                out++;
            }
        }
        if (k < nci || n > 0) f++;
        k0 = k + 1;
    }
    c->tris = out / 3;
    size_t nv = out;
    bool bad = false;
    if (g->nrm) {
        c->normal = malloc(nv * sizeof(int32_t));
        if (!c->normal) bad = true;
        for (size_t q = 0; !bad && q < nv; q++) {
            size_t at = npv ? src[q] : face[q];
            int32_t idx = npv ? (nni ? (at < nni ? ni[at] : -2) : ci[at]) : (nni ? (at < nni ? ni[at] : -2) : (int32_t)at);
            c->normal[q] = idx;
        }
        if (!bad && !check_range(L, F, el, npv ? "normal of corner" : "normal of face", c->normal, nv, g->nnrm)) goto fail_local;
    }
    if (g->tc) {
        c->tc = malloc(nv * sizeof(int32_t));
        if (!c->tc) bad = true;
        for (size_t q = 0; !bad && q < nv; q++) c->tc[q] = nti ? (src[q] < nti ? ti[src[q]] : -2) : ci[src[q]];
        if (!bad && !check_range(L, F, el, "texCoord of corner", c->tc, nv, g->ntc)) goto fail_local;
    } else {
        g->generate_tc = true;
    }
    if (g->col) {
        c->color = malloc(nv * sizeof(int32_t));
        if (!c->color) bad = true;
        for (size_t q = 0; !bad && q < nv; q++) {
            size_t at = cpv ? src[q] : face[q];
            c->color[q] = cpv ? (ncoi ? (at < ncoi ? coi[at] : -2) : ci[at]) : (ncoi ? (at < ncoi ? coi[at] : -2) : (int32_t)at);
        }
        if (!bad && !check_range(L, F, el, cpv ? "color of corner" : "color of face", c->color, nv, g->ncol)) goto fail_local;
    }
    if (!npv && !g->nrm) g->crease = 0.0f;
    free(src);
    free(face);
    if (bad) r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    else *ok = true;
    goto done;
fail_local:
    free(src);
    free(face);
done:
    free(local); free(tris); free(fpts); free(scratch);
    return r;
}

static sy_result build_faceset(loader *L, xfile *F, const xmlNode *el, geom_src *g, corners *c, bool *ok)
{
    *ok = false;
    int32_t *ci = NULL, *ni = NULL, *ti = NULL, *coi = NULL;
    face_lists fl = {0};
    sy_result r = SY_OK;
    if (get_int_array(L, F, el, "coordIndex", &ci, &fl.nci) && get_int_array(L, F, el, "normalIndex", &ni, &fl.nni) &&
        get_int_array(L, F, el, "texCoordIndex", &ti, &fl.nti) && get_int_array(L, F, el, "colorIndex", &coi, &fl.ncoi)) {
        fl.ci = ci; fl.ni = ni; fl.ti = ti; fl.coi = coi;
        fl.npv = get_bool(el, "normalPerVertex", true);
        fl.cpv = get_bool(el, "colorPerVertex", true);
        r = build_faces(L, F, el, g, c, &fl, ok);
    }
    free(ci); free(ni); free(ti); free(coi);
    return r;
}

/* Strip, fan and quad sets (X3D Rendering component): converted to 3- or 4-vertex faces with
 * coordinate indices, then the IndexedFaceSet path (per-vertex attributes follow the coordinate
 * index; per-face attributes are not supported for these and are warned about). */
static sy_result build_strip_fan_quad(loader *L, xfile *F, const xmlNode *el, geom_src *g, corners *c, bool *ok)
{
    *ok = false;
    const char *n = ename(el);
    bool indexed = !strncmp(n, "Indexed", 7);
    bool strip = strstr(n, "Strip") != NULL, fan = strstr(n, "Fan") != NULL, quad = strstr(n, "Quad") != NULL;
    int32_t *ix = NULL, *counts = NULL, *ci = NULL;
    size_t nix = 0, ncounts = 0, nci = 0, cap = 0;
    sy_result r = SY_OK;
    if (indexed && !get_int_array(L, F, el, "index", &ix, &nix)) goto done;
    if (!indexed && !quad &&
        !get_int_array(L, F, el, strip ? "stripCount" : "fanCount", &counts, &ncounts))
        goto done;
    if (!get_bool(el, "normalPerVertex", true) || !get_bool(el, "colorPerVertex", true))
        warn(L, "%s:%d: %s: per-face normals / colours are not supported; per-vertex used", F->path, line_of(el), n);
    /* runs of vertices: [start, end) positions in the sequence */
    size_t total = indexed ? nix : g->npts;
    cap = total * 4 + 16;
    ci = malloc(cap * sizeof(int32_t));
    if (!ci) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    size_t pos = 0, run = 0;
    while (pos < total) {
        size_t end;
        if (quad) {
            end = pos + 4 <= total ? pos + 4 : total;
        } else if (indexed) {
            end = pos;
            while (end < total && ix[end] != -1) end++;
        } else {
            if (run >= ncounts) break;
            int32_t k = counts[run++];
            end = k > 0 && (size_t)k <= total - pos ? pos + (size_t)k : total;
        }
        size_t m = end - pos;
        #define SEQ(q) (indexed ? ix[pos + (q)] : (int32_t)(pos + (q)))
        if (quad && m == 4) {
            for (size_t q = 0; q < 4; q++) ci[nci++] = SEQ(q);
            ci[nci++] = -1;
        } else if (!quad) {
            for (size_t k = 0; k + 2 < m; k++) {
                if (nci + 4 > cap) break;
                if (fan) { ci[nci++] = SEQ(0); ci[nci++] = SEQ(k + 1); ci[nci++] = SEQ(k + 2); }
                else if (k % 2 == 0) { ci[nci++] = SEQ(k); ci[nci++] = SEQ(k + 1); ci[nci++] = SEQ(k + 2); }
                else { ci[nci++] = SEQ(k + 1); ci[nci++] = SEQ(k); ci[nci++] = SEQ(k + 2); }
                ci[nci++] = -1;
            }
        }
        #undef SEQ
        pos = (indexed && !quad) ? end + 1 : end;
    }
    if (nci == 0) {
        warn(L, "%s:%d: %s has no complete triangle; skipped", F->path, line_of(el), n);
        goto done;
    }
    face_lists fl = {.ci = ci, .nci = nci, .npv = true, .cpv = true};
    r = build_faces(L, F, el, g, c, &fl, ok);
    g->crease = 0.0f;
done:
    free(ix); free(counts); free(ci);
    return r;
}

/* Extrusion (X3D 13.3.5): the cross-section swept along the spine in each spine point's
 * spine-aligned cross-section plane, scaled and oriented per point; side quads plus the caps as
 * polygons, then the IndexedFaceSet path (creaseAngle normals, ear-clipped caps). Texture
 * coordinates: s along the cross-section, t along the spine (X3D), caps by the bounding box. */
static sy_result build_extrusion(loader *L, xfile *F, const xmlNode *el, geom_src *g, corners *c, bool *ok)
{
    *ok = false;
    float *cs = NULL, *sp = NULL, *sc = NULL, *orr = NULL;
    size_t ncs = 0, nsp = 0, nsc = 0, nor = 0;
    int32_t *ci = NULL;
    sy_result r = SY_OK;
    static const float def_cs[10] = {1, 1, 1, -1, -1, -1, -1, 1, 1, 1}, def_sp[6] = {0, 0, 0, 0, 1, 0};
    if (!get_float_array(L, F, el, "crossSection", 2, &cs, &ncs) || !get_float_array(L, F, el, "spine", 3, &sp, &nsp) ||
        !get_float_array(L, F, el, "scale", 2, &sc, &nsc) || !get_float_array(L, F, el, "orientation", 4, &orr, &nor))
        goto done;
    const float *CS = cs ? cs : def_cs, *SP = sp ? sp : def_sp;
    if (!cs) ncs = 5;
    if (!sp) nsp = 2;
    if (ncs < 2 || nsp < 2) {
        warn(L, "%s:%d: Extrusion needs 2 or more crossSection and spine points; skipped", F->path, line_of(el));
        goto done;
    }
    if (ncs > L->opt.max_vertices / nsp) {
        r = sy_error_set(&L->err, SY_ERR_LIMIT, "%s:%d: Extrusion: %zu x %zu points exceed the limit", F->path,
                         line_of(el), ncs, nsp);
        goto done;
    }
    /* two triangles per quad of the swept surface (caps come on top, charged in emit) */
    if ((r = budget_vertices(L, F->path, el, 6u * (uint64_t)(ncs - 1) * (nsp - 1), false))) goto done;
    bool closed_spine = SP[0] == SP[3 * (nsp - 1)] && SP[1] == SP[3 * (nsp - 1) + 1] && SP[2] == SP[3 * (nsp - 1) + 2];
    bool closed_cs = CS[0] == CS[2 * (ncs - 1)] && CS[1] == CS[2 * (ncs - 1) + 1];
    g->npts = ncs * nsp;
    g->pts = malloc(g->npts * 12);
    g->tc = malloc(g->npts * 8);
    g->ntc = g->npts;
    size_t quads = (ncs - 1) * (nsp - 1);
    size_t cap_n = closed_cs ? ncs - 1 : ncs;
    ci = malloc((quads * 5 + 2 * (cap_n + 1)) * sizeof(int32_t));
    if (!g->pts || !g->tc || !ci) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    float prevz[3] = {0, 0, 1};
    bool have_z = false;
    double cs_len = 0, sp_len = 0;
    for (size_t j = 1; j < ncs; j++) cs_len += hypot(CS[2 * j] - CS[2 * j - 2], CS[2 * j + 1] - CS[2 * j - 1]);
    for (size_t i = 1; i < nsp; i++)
        sp_len += sqrt(pow(SP[3 * i] - SP[3 * i - 3], 2) + pow(SP[3 * i + 1] - SP[3 * i - 2], 2) + pow(SP[3 * i + 2] - SP[3 * i - 1], 2));
    double t_acc = 0;
    for (size_t i = 0; i < nsp; i++) {
        const float *p = SP + 3 * i;
        const float *pn = SP + 3 * (i + 1 < nsp ? i + 1 : (closed_spine ? 1 : i));
        const float *pp = SP + 3 * (i > 0 ? i - 1 : (closed_spine ? nsp - 2 : i));
        float Y[3] = {pn[0] - pp[0], pn[1] - pp[1], pn[2] - pp[2]};
        float ly = sqrtf(Y[0] * Y[0] + Y[1] * Y[1] + Y[2] * Y[2]);
        if (ly > 0) { Y[0] /= ly; Y[1] /= ly; Y[2] /= ly; }
        else { Y[0] = 0; Y[1] = 1; Y[2] = 0; }
        float a[3] = {pn[0] - p[0], pn[1] - p[1], pn[2] - p[2]}, b[3] = {pp[0] - p[0], pp[1] - p[1], pp[2] - p[2]};
        float Z[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
        float lz = sqrtf(Z[0] * Z[0] + Z[1] * Z[1] + Z[2] * Z[2]);
        if (lz > 1e-12f) {
            Z[0] /= lz; Z[1] /= lz; Z[2] /= lz;
            if (have_z && Z[0] * prevz[0] + Z[1] * prevz[1] + Z[2] * prevz[2] < 0) { Z[0] = -Z[0]; Z[1] = -Z[1]; Z[2] = -Z[2]; }
        } else if (have_z) {
            memcpy(Z, prevz, sizeof Z);
        } else { /* straight spine: the plane perpendicular to Y nearest to the XZ plane */
            float up[3] = {0, 1, 0};
            float ax[3] = {up[1] * Y[2] - up[2] * Y[1], up[2] * Y[0] - up[0] * Y[2], up[0] * Y[1] - up[1] * Y[0]};
            float la = sqrtf(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
            if (la < 1e-6f) { Z[0] = 0; Z[1] = 0; Z[2] = Y[1] >= 0 ? 1.0f : -1.0f; }
            else { /* rotate +Z by the rotation taking +Y to Y */
                float ang = acosf(fmaxf(-1.0f, fminf(1.0f, Y[1])));
                float k[3] = {ax[0] / la, ax[1] / la, ax[2] / la}, z0[3] = {0, 0, 1};
                float kz[3] = {k[1] * z0[2] - k[2] * z0[1], k[2] * z0[0] - k[0] * z0[2], k[0] * z0[1] - k[1] * z0[0]};
                float kd = k[2];
                for (int m = 0; m < 3; m++) Z[m] = z0[m] * cosf(ang) + kz[m] * sinf(ang) + k[m] * kd * (1 - cosf(ang));
            }
        }
        memcpy(prevz, Z, sizeof Z);
        have_z = true;
        float X[3] = {Y[1] * Z[2] - Y[2] * Z[1], Y[2] * Z[0] - Y[0] * Z[2], Y[0] * Z[1] - Y[1] * Z[0]};
        float s2[2] = {1, 1};
        if (nsc) { size_t k = i < nsc ? i : nsc - 1; s2[0] = sc[2 * k]; s2[1] = sc[2 * k + 1]; }
        float q[4] = {0, 0, 0, 1};
        if (nor) { size_t k = i < nor ? i : nor - 1; axis_angle_quat(orr + 4 * k, q); }
        sy_mat4 R = sy_mat4_from_trs((const float[3]){0, 0, 0}, q, (const float[3]){1, 1, 1});
        if (i > 0)
            t_acc += sqrt(pow(SP[3 * i] - SP[3 * i - 3], 2) + pow(SP[3 * i + 1] - SP[3 * i - 2], 2) +
                          pow(SP[3 * i + 2] - SP[3 * i - 1], 2));
        double s_acc = 0;
        for (size_t j = 0; j < ncs; j++) {
            if (j > 0) s_acc += hypot(CS[2 * j] - CS[2 * j - 2], CS[2 * j + 1] - CS[2 * j - 1]);
            float lx = CS[2 * j] * s2[0], lz2 = CS[2 * j + 1] * s2[1];
            float v[3] = {X[0] * lx + Z[0] * lz2, X[1] * lx + Z[1] * lz2, X[2] * lx + Z[2] * lz2}, o[3];
            sy_mat4_transform_dir(&R, v, o);
            float *dst = g->pts + 3 * (i * ncs + j);
            dst[0] = p[0] + o[0]; dst[1] = p[1] + o[1]; dst[2] = p[2] + o[2];
            g->tc[2 * (i * ncs + j)] = cs_len > 0 ? (float)(s_acc / cs_len) : 0.0f;
            g->tc[2 * (i * ncs + j) + 1] = sp_len > 0 ? (float)(t_acc / sp_len) : 0.0f;
        }
    }
    size_t n = 0;
    for (size_t i = 0; i + 1 < nsp; i++)
        for (size_t j = 0; j + 1 < ncs; j++) {
            ci[n++] = (int32_t)(i * ncs + j); ci[n++] = (int32_t)(i * ncs + j + 1);
            ci[n++] = (int32_t)((i + 1) * ncs + j + 1); ci[n++] = (int32_t)((i + 1) * ncs + j); ci[n++] = -1;
        }
    /* caps use the generated texture coordinates of their ring (not the X3D cap mapping) */
    if (get_bool(el, "beginCap", true) && cap_n >= 3) {
        for (size_t j = cap_n; j-- > 0;) ci[n++] = (int32_t)j;
        ci[n++] = -1;
    }
    if (get_bool(el, "endCap", true) && cap_n >= 3) {
        for (size_t j = 0; j < cap_n; j++) ci[n++] = (int32_t)((nsp - 1) * ncs + j);
        ci[n++] = -1;
    }
    face_lists fl = {.ci = ci, .nci = n, .npv = true, .cpv = true};
    r = build_faces(L, F, el, g, c, &fl, ok);
done:
    free(cs); free(sp); free(sc); free(orr); free(ci);
    return r;
}

/* IndexedTriangleSet (index given) and TriangleSet (implicit 0..n-1). */
static sy_result build_triset(loader *L, xfile *F, const xmlNode *el, geom_src *g, corners *c, bool indexed, bool *ok)
{
    *ok = false;
    int32_t *ix = NULL;
    size_t n = 0;
    if (indexed) {
        if (!get_int_array(L, F, el, "index", &ix, &n)) return SY_OK;
        if (!check_range(L, F, el, "index", ix, n, g->npts)) {
            free(ix);
            return SY_OK;
        }
    } else {
        n = g->npts;
    }
    if (n % 3) warn(L, "%s:%d: %s: %zu vertices are not a multiple of 3; the last %zu ignored", F->path, line_of(el),
                    ename(el), n, n % 3);
    n -= n % 3;
    if (n == 0) {
        free(ix);
        warn(L, "%s:%d: %s has no triangle; skipped", F->path, line_of(el), ename(el));
        return SY_OK;
    }
    if (n > L->opt.max_vertices) {
        free(ix);
        return sy_error_set(&L->err, SY_ERR_LIMIT, "%s:%d: %s: %zu vertices exceed the limit of %zu", F->path,
                            line_of(el), ename(el), n, L->opt.max_vertices);
    }
    sy_result br = budget_vertices(L, F->path, el, n, false);
    if (br) {
        free(ix);
        return br;
    }
    bool npv = get_bool(el, "normalPerVertex", true), cpv = get_bool(el, "colorPerVertex", true);
    c->tris = n / 3;
    c->coord = malloc(n * sizeof(uint32_t));
    c->normal = g->nrm ? malloc(n * sizeof(int32_t)) : NULL;
    c->tc = g->tc ? malloc(n * sizeof(int32_t)) : NULL;
    c->color = g->col ? malloc(n * sizeof(int32_t)) : NULL;
    if (!c->coord || (g->nrm && !c->normal) || (g->tc && !c->tc) || (g->col && !c->color)) {
        free(ix);
        return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    }
    for (size_t k = 0; k < n; k++) {
        int32_t v = ix ? ix[k] : (int32_t)k;
        c->coord[k] = (uint32_t)v;
        if (c->normal) c->normal[k] = npv ? v : (int32_t)(k / 3);
        if (c->tc) c->tc[k] = v;
        if (c->color) c->color[k] = cpv ? v : (int32_t)(k / 3);
    }
    free(ix);
    if (c->normal && !check_range(L, F, el, "normal", c->normal, n, g->nnrm)) return SY_OK;
    if (c->tc && !check_range(L, F, el, "texCoord", c->tc, n, g->ntc)) return SY_OK;
    if (c->color && !check_range(L, F, el, "color", c->color, n, g->ncol)) return SY_OK;
    g->crease = 0.0f; /* no creaseAngle field: generated normals are flat */
    *ok = true;
    return SY_OK;
}

/* X3D TextureTransform -> 2x3 affine matrix: Tc' = -C x S x R x C x T x Tc. */
static void texture_transform(loader *L, xfile *F, const xmlNode *tt, float m[6])
{
    m[0] = 1; m[1] = 0; m[2] = 0; m[3] = 0; m[4] = 1; m[5] = 0;
    if (!tt) return;
    float c[2] = {0, 0}, s[2] = {1, 1}, t[2] = {0, 0};
    get_floats(L, F, tt, "center", c, 2);
    get_floats(L, F, tt, "scale", s, 2);
    get_floats(L, F, tt, "translation", t, 2);
    float rot = get_float(L, F, tt, "rotation", 0.0f), cr = cosf(rot), sr = sinf(rot);
    /* p -> p + T + C -> R -> S -> -C */
    float a = s[0] * cr, b = -s[0] * sr, d = s[1] * sr, e = s[1] * cr;
    float ox = t[0] + c[0], oy = t[1] + c[1];
    m[0] = a; m[1] = b; m[2] = a * ox + b * oy - c[0];
    m[3] = d; m[4] = e; m[5] = d * ox + e * oy - c[1];
}

static void bounds_add_prim(loader *L, const sy_primitive *p, const sy_mat4 *world)
{
    if (!p->positions) return;
    const float *v = sy_blob_data(p->positions);
    size_t n = sy_blob_size(p->positions) / 12;
    sy_bounds b = sy_bounds_empty();
    for (size_t k = 0; k < n; k++) sy_bounds_add_point(&b, v + 3 * k);
    sy_bounds w = sy_bounds_transform(&b, world);
    sy_bounds_add_bounds(&L->bounds, &w);
}

/* Output of a stroke geometry node: vertices (positions, optional RGBA colours) and, for lines,
 * index pairs. */
typedef struct stroke_out {
    float *pos, *col;
    uint32_t *pairs;
    size_t nv, npairs, cap_v;
} stroke_out;

static void stroke_out_free(stroke_out *o)
{
    free(o->pos); free(o->col); free(o->pairs);
    memset(o, 0, sizeof *o);
}

/* Colour k of a Color / ColorRGBA source as RGBA. */
static void src_color(const geom_src *g, size_t k, float *out)
{
    const float *c = g->col + (size_t)g->col_comps * k;
    out[0] = c[0]; out[1] = c[1]; out[2] = c[2];
    out[3] = g->col_comps == 4 ? c[3] : 1.0f;
}

/* PointSet, LineSet, IndexedLineSet: SY_TOPOLOGY_POINTS / SY_TOPOLOGY_LINES primitives (width 0:
 * core's rule; every back-end draws them as tubes and balls). Polylines become index pairs;
 * IndexedLineSet vertices are repeated per polyline so per-polyline colours stay exact. Colours: per
 * vertex (PointSet, LineSet; IndexedLineSet with colorPerVertex, through colorIndex or coordIndex)
 * or per polyline (IndexedLineSet colorPerVertex false, through colorIndex or the polyline number).
 * Bad indices or counts are warned (file:line) and skip the geometry. */
static sy_result build_strokes(loader *L, xfile *F, const xmlNode *el, const geom_src *g, stroke_out *o, bool *ok)
{
    *ok = false;
    const char *n = ename(el);
    sy_result r = SY_OK;
    int32_t *ci = NULL, *coi = NULL, *vc = NULL;
    size_t nci = 0, ncoi = 0, nvc = 0;
    if (!strcmp(n, "PointSet")) {
        o->nv = g->npts;
        if (o->nv == 0) {
            warn(L, "%s:%d: PointSet without points; skipped", F->path, line_of(el));
            return SY_OK;
        }
    } else if (!strcmp(n, "LineSet")) {
        if (!get_int_array(L, F, el, "vertexCount", &vc, &nvc)) return SY_OK;
        size_t used = 0;
        for (size_t k = 0; k < nvc; k++) {
            if (vc[k] < 2) {
                warn(L, "%s:%d: LineSet.vertexCount[%zu] = %d is less than 2; geometry skipped", F->path, line_of(el), k,
                     (int)vc[k]);
                goto done;
            }
            if ((size_t)vc[k] > g->npts - used) {
                warn(L, "%s:%d: LineSet.vertexCount needs more than the %zu points of its Coordinate; geometry skipped",
                     F->path, line_of(el), g->npts);
                goto done;
            }
            used += (size_t)vc[k];
            o->npairs += (size_t)vc[k] - 1;
        }
        o->nv = used;
    } else { /* IndexedLineSet */
        if (!get_int_array(L, F, el, "coordIndex", &ci, &nci) || !get_int_array(L, F, el, "colorIndex", &coi, &ncoi))
            goto done;
        for (size_t k = 0, k0 = 0; k <= nci; k++) {
            if (k < nci && ci[k] != -1) {
                if (ci[k] < 0 || (size_t)ci[k] >= g->npts) {
                    warn(L, "%s:%d: IndexedLineSet: coordIndex[%zu] = %d is outside the %zu points of its Coordinate; "
                         "geometry skipped", F->path, line_of(el), k, (int)ci[k], g->npts);
                    goto done;
                }
                continue;
            }
            if (k - k0 >= 2) {
                o->nv += k - k0;
                o->npairs += k - k0 - 1;
            }
            k0 = k + 1;
        }
    }
    if (o->nv > L->opt.max_vertices) {
        r = sy_error_set(&L->err, SY_ERR_LIMIT, "%s:%d: %s: %zu vertices exceed the limit of %zu", F->path, line_of(el),
                         n, o->nv, L->opt.max_vertices);
        goto done;
    }
    if ((r = budget_vertices(L, F->path, el, o->nv, true))) goto done; /* strokes do not go through emit */
    if (o->nv == 0 || (strcmp(n, "PointSet") && o->npairs == 0)) {
        warn(L, "%s:%d: %s has no polyline with 2 or more vertices; skipped", F->path, line_of(el), n);
        goto done;
    }
    o->pos = malloc(o->nv * 12);
    o->col = g->col ? malloc(o->nv * 16) : NULL;
    o->pairs = o->npairs ? malloc(o->npairs * 2 * sizeof(uint32_t)) : NULL;
    if (!o->pos || (g->col && !o->col) || (o->npairs && !o->pairs)) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    size_t v = 0, pr = 0;
    if (strcmp(n, "IndexedLineSet")) { /* PointSet, LineSet: the first nv points, in order */
        if (g->col && g->ncol < o->nv) {
            warn(L, "%s:%d: %s: %zu colours for %zu vertices; geometry skipped", F->path, line_of(el), n, g->ncol, o->nv);
            goto done;
        }
        memcpy(o->pos, g->pts, o->nv * 12);
        for (size_t k = 0; o->col && k < o->nv; k++) src_color(g, k, o->col + 4 * k);
        for (size_t k = 0, start = 0; k < nvc; start += (size_t)vc[k], k++)
            for (size_t j = 0; j + 1 < (size_t)vc[k]; j++, pr++) {
                o->pairs[2 * pr] = (uint32_t)(start + j);
                o->pairs[2 * pr + 1] = (uint32_t)(start + j + 1);
            }
    } else {
        bool cpv = get_bool(el, "colorPerVertex", true);
        size_t line = 0;
        for (size_t k = 0, k0 = 0; k <= nci; k++) {
            if (k < nci && ci[k] != -1) continue;
            size_t cnt = k - k0;
            if (cnt >= 2) {
                for (size_t j = 0; j < cnt; j++) {
                    memcpy(o->pos + 3 * (v + j), g->pts + 3 * (size_t)ci[k0 + j], 12);
                    if (o->col) {
                        size_t at = cpv ? k0 + j : line;
                        int64_t c = ncoi ? (at < ncoi ? coi[at] : -2) : cpv ? ci[at] : (int64_t)at;
                        if (c < 0 || (size_t)c >= g->ncol) {
                            warn(L, "%s:%d: IndexedLineSet: colour %lld of %s %zu is outside the %zu colours; geometry "
                                 "skipped", F->path, line_of(el), (long long)c, cpv ? "vertex" : "polyline",
                                 cpv ? k0 + j : line, g->ncol);
                            goto done;
                        }
                        src_color(g, (size_t)c, o->col + 4 * (v + j));
                    }
                    if (j + 1 < cnt) {
                        o->pairs[2 * pr] = (uint32_t)(v + j);
                        o->pairs[2 * pr + 1] = (uint32_t)(v + j + 1);
                        pr++;
                    }
                }
                v += cnt;
            }
            if (k < nci || cnt > 0) line++;
            k0 = k + 1;
        }
    }
    *ok = true;
done:
    free(ci); free(coi); free(vc);
    return r;
}

/* Text: the strings as flat geometry (sy_text.h) with the FontStyle's font (family SANS / SERIF
 * (the default) / TYPEWRITER -> DejaVu Sans / Serif / Sans Mono under SY_X3D_FONT_DIR, style PLAIN /
 * BOLD / ITALIC / BOLDITALIC), size, spacing and justify (major, minor). A missing font is a
 * warning and the text is skipped; length, maxExtent and vertical / right-to-left layouts are not
 * supported (warned). */
#ifndef SY_X3D_FONT_DIR
#define SY_X3D_FONT_DIR "/usr/share/fonts/truetype/dejavu/"
#endif
static uint32_t justify_of(const char *s, bool major)
{
    if (!strcmp(s, "BEGIN")) return SY_TEXT_BEGIN;
    if (!strcmp(s, "MIDDLE")) return SY_TEXT_MIDDLE;
    if (!strcmp(s, "END")) return SY_TEXT_END;
    return major ? SY_TEXT_BEGIN : SY_TEXT_FIRST; /* FIRST (and anything else) */
}

static sy_result build_text(loader *L, xfile *F, const xmlNode *el, sy_primitive *prim, bool *ok)
{
    *ok = false;
    sy_result r = SY_OK;
    char *strs = attr(el, "string");
    if (!strs) return SY_OK; /* no string: nothing to draw */
    size_t cap = strlen(strs) + 1, nl = 0, lcap = 0;
    char **lines = NULL, *buf = NULL;
    for (const char *p = strs;;) {
        if (!buf && !(buf = malloc(cap))) goto oom;
        if (!next_mfstring(&p, buf, cap)) break;
        if (nl == lcap) {
            lcap = lcap ? lcap * 2 : 4;
            char **q = realloc(lines, lcap * sizeof *q);
            if (!q) goto oom;
            lines = q;
        }
        lines[nl++] = buf;
        buf = NULL;
    }
    const xmlNode *fs = field_child(L, F, el, "FontStyle|ScreenFontStyle", "fontStyle");
    const char *family = "DejaVuSerif", *style_sfx = "";
    float size = 1.0f, spacing = 1.0f;
    uint32_t major = SY_TEXT_BEGIN, minor = SY_TEXT_FIRST;
    if (fs) {
        char *fam = attr(fs, "family"), tok[64];
        const char *p = fam;
        while (p && next_mfstring(&p, tok, sizeof tok)) {
            if (!strcmp(tok, "SANS")) { family = "DejaVuSans"; break; }
            if (!strcmp(tok, "SERIF")) { family = "DejaVuSerif"; break; }
            if (!strcmp(tok, "TYPEWRITER")) { family = "DejaVuSansMono"; break; }
        }
        xmlFree(fam);
        char *st = attr(fs, "style");
        bool bold = st && strstr(st, "BOLD"), italic = st && strstr(st, "ITALIC");
        xmlFree(st);
        bool serif = !strcmp(family, "DejaVuSerif");
        style_sfx = bold && italic ? (serif ? "-BoldItalic" : "-BoldOblique") : bold ? "-Bold"
                    : italic ? (serif ? "-Italic" : "-Oblique") : "";
        size = get_float(L, F, fs, "size", 1.0f);
        spacing = get_float(L, F, fs, "spacing", 1.0f);
        char *j = attr(fs, "justify");
        p = j;
        if (p && next_mfstring(&p, tok, sizeof tok)) {
            major = justify_of(tok, true);
            if (next_mfstring(&p, tok, sizeof tok)) minor = justify_of(tok, false);
        }
        xmlFree(j);
        if (!get_bool(fs, "horizontal", true) || !get_bool(fs, "leftToRight", true) || !get_bool(fs, "topToBottom", true))
            warn(L, "%s:%d: FontStyle: only horizontal, left-to-right, top-to-bottom text is supported", F->path,
                 line_of(fs));
    }
    if (!(size > 0) || !(spacing >= 0)) {
        warn(L, "%s:%d: Text: FontStyle size %g / spacing %g out of range; skipped", F->path, line_of(el), (double)size,
             (double)spacing);
        goto done;
    }
    if (attr_present(el, "length") || attr_present(el, "maxExtent"))
        warn(L, "%s:%d: Text: length and maxExtent are not supported; ignored", F->path, line_of(el));
    char font[512];
    snprintf(font, sizeof font, "%s%s%s.ttf", SY_X3D_FONT_DIR, family, style_sfx);
    if (!regular_file(font, NULL, 0)) {
        warn(L, "%s:%d: Text: font '%s' not found (install fonts-dejavu-core); text skipped", F->path, line_of(el), font);
        goto done;
    }
    sy_text_desc td = {.lines = (const char *const *)lines, .line_count = nl, .font_path = font, .size = size,
                       .spacing = spacing, .major = major, .minor = minor, .max_triangles = L->opt.max_vertices / 3};
    sy_text_stats ts;
    r = sy_text_build(&td, prim, &ts, &L->err);
    if (r == SY_ERR_NOT_FOUND) {
        warn(L, "%s:%d: Text: %s; text skipped", F->path, line_of(el), L->err.message);
        r = SY_OK;
    } else if (r) {
        sy_error_prefix(&L->err, "%s:%d: Text", F->path, line_of(el));
    } else if (!prim->positions) {
        warn(L, "%s:%d: Text has no visible glyph; skipped", F->path, line_of(el));
    } else {
        *ok = true;
    }
    goto done;
oom:
    r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
done:
    for (size_t k = 0; k < nl; k++) free(lines[k]);
    free(lines);
    free(buf);
    xmlFree(strs);
    return r;
}

/* Builds the primitive of a geometry node (cached per geometry element and texture transform). */
static sy_result build_geometry(loader *L, xfile *F, const xmlNode *el, const xmlNode *ttel, sy_primitive *prim,
                                bool *ok, bool *has_colors, bool *solid)
{
    *ok = false;
    memset(prim, 0, sizeof *prim);
    const char *n = ename(el);
    sy_result r = SY_OK;
    *solid = get_bool(el, "solid", true);
    *has_colors = false;
    if (!strcmp(n, "Box")) {
        float size[3] = {2, 2, 2};
        get_floats(L, F, el, "size", size, 3);
        if (!(size[0] > 0 && size[1] > 0 && size[2] > 0)) goto bad_size;
        r = sy_tess_box(size, prim, &L->err);
    } else if (!strcmp(n, "Sphere")) {
        float rad = get_float(L, F, el, "radius", 1.0f);
        if (!(rad > 0)) goto bad_size;
        r = sy_tess_sphere(rad, NULL, prim, &L->err);
    } else if (!strcmp(n, "Cone")) {
        float rad = get_float(L, F, el, "bottomRadius", 1.0f), h = get_float(L, F, el, "height", 2.0f);
        if (!(rad > 0 && h > 0)) goto bad_size;
        bool side = get_bool(el, "side", true), bottom = get_bool(el, "bottom", true);
        if (!side && !bottom) goto empty;
        r = sy_tess_cone(rad, h, side, bottom, NULL, prim, &L->err);
    } else if (!strcmp(n, "Text")) {
        *solid = get_bool(el, "solid", false); /* X3D: Text is not solid by default */
        bool built = false;
        r = build_text(L, F, el, prim, &built);
        if (r || !built) return r;
    } else if (!strcmp(n, "Cylinder")) {
        float rad = get_float(L, F, el, "radius", 1.0f), h = get_float(L, F, el, "height", 2.0f);
        if (!(rad > 0 && h > 0)) goto bad_size;
        bool side = get_bool(el, "side", true), top = get_bool(el, "top", true), bottom = get_bool(el, "bottom", true);
        if (!side && !top && !bottom) goto empty;
        r = sy_tess_cylinder(rad, h, side, top, bottom, NULL, prim, &L->err);
    } else {
        geom_src g = {0};
        corners c = {0};
        bool built = false;
        texture_transform(L, F, ttel, g.tt);
        if (!read_sources(L, F, el, &g)) {
            geom_src_free(&g);
            if (L->limit_r) L->err = L->limit_err;
            return L->limit_r;
        }
        if (!strcmp(n, "Extrusion")) {
            geom_src_free(&g); /* an Extrusion has no Coordinate etc.: its fields build the sources */
            memset(&g, 0, sizeof g);
            texture_transform(L, F, ttel, g.tt);
            g.ccw = get_bool(el, "ccw", true);
            g.crease = get_float(L, F, el, "creaseAngle", 0.0f);
            r = build_extrusion(L, F, el, &g, &c, &built);
        } else if (!g.pts) {
            warn(L, "%s:%d: %s without Coordinate points; skipped", F->path, line_of(el), n);
        } else if (name_in(n, "PointSet|LineSet|IndexedLineSet")) {
            stroke_out so = {0};
            r = build_strokes(L, F, el, &g, &so, &built);
            if (!r && L->limit_r) {
                r = L->limit_r;
                L->err = L->limit_err;
            }
            if (!r && built) {
                r = make_blob(L, so.pos, so.nv * 12, &prim->positions);
                so.pos = NULL;
                if (!r && so.col) r = make_blob(L, so.col, so.nv * 16, &prim->colors);
                so.col = NULL;
                if (!r && so.pairs) r = make_blob(L, so.pairs, so.npairs * 8, &prim->indices);
                so.pairs = NULL;
                if (r) sy_primitive_release(prim);
                else prim->topology = so.npairs ? SY_TOPOLOGY_LINES : SY_TOPOLOGY_POINTS;
                *ok = !r;
                *has_colors = !r && prim->colors != NULL;
                *solid = false;
            }
            stroke_out_free(&so);
            geom_src_free(&g);
            return r;
        } else if (!strcmp(n, "IndexedFaceSet")) {
            r = build_faceset(L, F, el, &g, &c, &built);
        } else if (!strcmp(n, "IndexedTriangleSet")) {
            r = build_triset(L, F, el, &g, &c, true, &built);
        } else if (strstr(n, "Strip") || strstr(n, "Fan") || strstr(n, "Quad")) {
            r = build_strip_fan_quad(L, F, el, &g, &c, &built);

        } else {
            r = build_triset(L, F, el, &g, &c, false, &built);
        }
        if (!r && L->limit_r) { /* an attribute over the value limit: the load fails */
            r = L->limit_r;
            L->err = L->limit_err;
        }
        if (!r && built) {
            r = emit(L, F, el, &g, &c, prim);
            if (!r) {
                *ok = true;
                *has_colors = prim->colors != NULL;
            }
        }
        corners_free(&c);
        geom_src_free(&g);
        return r;
    }
    if (r) {
        sy_error_prefix(&L->err, "%s:%d: %s", F->path, line_of(el), n);
        return r;
    }
    if (ttel && prim->texcoords0) { /* apply the texture transform to the tessellated coordinates */
        float m[6];
        texture_transform(L, F, ttel, m);
        size_t nv = sy_blob_size(prim->texcoords0) / 8;
        float *uv = malloc(nv * 8);
        if (!uv) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        const float *src = sy_blob_data(prim->texcoords0);
        for (size_t k = 0; k < nv; k++) {
            float s = src[2 * k], t = 1.0f - src[2 * k + 1];
            uv[2 * k] = m[0] * s + m[1] * t + m[2];
            uv[2 * k + 1] = 1.0f - (m[3] * s + m[4] * t + m[5]);
        }
        sy_blob *b;
        if ((r = make_blob(L, uv, nv * 8, &b))) return r;
        sy_blob_release(prim->texcoords0);
        prim->texcoords0 = b;
    }
    *ok = true;
    return SY_OK;
bad_size:
    warn(L, "%s:%d: %s with a non-positive size; skipped", F->path, line_of(el), n);
    return SY_OK;
empty:
    return SY_OK;
}

/* >>nodes ------------------------------------------------------------------------------------- */

static sy_result visit(loader *L, xfile *F, const xmlNode *el, const sy_mat4 *world, sy_node *out);

static bool warn_type_once(loader *L, const char *type)
{
    if (xmlHashLookup(L->warned, (const xmlChar *)type)) return false;
    xmlHashAddEntry(L->warned, (const xmlChar *)type, (void *)1);
    return true;
}

static bool silent_node(const char *n)
{
    return name_in(n, "WorldInfo|NavigationInfo|ROUTE|EXPORT|IMPORT|meta|head|component|unit|MetadataString|"
                      "MetadataFloat|MetadataDouble|MetadataInteger|MetadataBoolean|MetadataSet|IS|connect|field|"
                      "fieldValue|ProtoDeclare|ExternProtoDeclare|Script");
}

static sy_result children_of(loader *L, xfile *F, const xmlNode *el, const sy_mat4 *world, sy_node node,
                             const char *only_nth)
{
    sy_result r = SY_OK;
    sy_node *kids = NULL;
    size_t nk = 0, cap = 0;
    long which = only_nth ? strtol(only_nth, NULL, 10) : -2, idx = 0;
    for (const xmlNode *c = el->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE) continue;
        if (only_nth) {
            if (idx++ != which) continue;
        }
        sy_node k = {0};
        if ((r = visit(L, F, c, world, &k))) break;
        if (!k.id) continue;
        bool dup = false;
        for (size_t q = 0; q < nk; q++) dup |= kids[q].id == k.id;
        if (dup) continue; /* the same USEd node twice under one parent adds nothing */
        if (nk == cap) {
            cap = cap ? cap * 2 : 8;
            sy_node *p = realloc(kids, cap * sizeof *p);
            if (!p) {
                r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
                break;
            }
            kids = p;
        }
        kids[nk++] = k;
    }
    if (!r && nk) {
        r = sy_node_set_children(L->scene, node, kids, (uint32_t)nk, &L->err);
        if (r) sy_error_prefix(&L->err, "%s:%d: %s", F->path, line_of(el), ename(el));
    }
    free(kids);
    return r;
}

static void axis_angle_quat(const float aa[4], float q[4])
{
    float l = sqrtf(aa[0] * aa[0] + aa[1] * aa[1] + aa[2] * aa[2]);
    if (!(l > 0) || !isfinite(aa[3])) {
        q[0] = q[1] = q[2] = 0;
        q[3] = 1;
        return;
    }
    float s = sinf(aa[3] * 0.5f) / l;
    q[0] = aa[0] * s; q[1] = aa[1] * s; q[2] = aa[2] * s; q[3] = cosf(aa[3] * 0.5f);
}

static sy_result set_transform(loader *L, xfile *F, const xmlNode *el, sy_node h, sy_mat4 *local)
{
    float t[3] = {0, 0, 0}, rot[4] = {0, 0, 1, 0}, s[3] = {1, 1, 1}, c[3] = {0, 0, 0}, so[4] = {0, 0, 1, 0};
    get_floats(L, F, el, "translation", t, 3);
    get_floats(L, F, el, "rotation", rot, 4);
    get_floats(L, F, el, "scale", s, 3);
    get_floats(L, F, el, "center", c, 3);
    get_floats(L, F, el, "scaleOrientation", so, 4);
    float q[4], sq[4], one[3] = {1, 1, 1}, zero[3] = {0, 0, 0}, idq[4] = {0, 0, 0, 1};
    axis_angle_quat(rot, q);
    axis_angle_quat(so, sq);
    sy_result r;
    if (c[0] == 0 && c[1] == 0 && c[2] == 0 && sq[3] == 1) {
        *local = sy_mat4_from_trs(t, q, s);
        r = sy_node_set_trs(L->scene, h, t, q, s, &L->err);
    } else { /* T C R SR S -SR -C */
        float nc[3] = {-c[0], -c[1], -c[2]}, nsq[4] = {-sq[0], -sq[1], -sq[2], sq[3]};
        sy_mat4 T = sy_mat4_from_trs(t, idq, one), C = sy_mat4_from_trs(c, idq, one), R = sy_mat4_from_trs(zero, q, one);
        sy_mat4 SR = sy_mat4_from_trs(zero, sq, one), S = sy_mat4_from_trs(zero, idq, s);
        sy_mat4 NSR = sy_mat4_from_trs(zero, nsq, one), NC = sy_mat4_from_trs(nc, idq, one);
        sy_mat4 m = sy_mat4_mul(&T, &C);
        m = sy_mat4_mul(&m, &R);
        m = sy_mat4_mul(&m, &SR);
        m = sy_mat4_mul(&m, &S);
        m = sy_mat4_mul(&m, &NSR);
        m = sy_mat4_mul(&m, &NC);
        *local = m;
        r = sy_node_set_matrix(L->scene, h, &m, &L->err);
    }
    if (r) sy_error_prefix(&L->err, "%s:%d: Transform", F->path, line_of(el));
    return r;
}

/* Creates the node for an element (DEF name as node name) and marks it in progress. */
static sy_result begin_node(loader *L, xfile *F, const xmlNode *el, created *c, sy_node *h)
{
    char *def = attr(el, "DEF");
    char *desc = def ? NULL : attr(el, "description");
    sy_result r = new_object(L, SY_TYPE_NODE, def ? def : desc, &h->id);
    xmlFree(def);
    xmlFree(desc);
    if (r) {
        sy_error_prefix(&L->err, "%s:%d: %s", F->path, line_of(el), ename(el));
        return r;
    }
    L->info->counts.nodes++;
    c->node = h->id;
    c->in_progress = true;
    return SY_OK;
}

static sy_result visit_shape(loader *L, xfile *F, const xmlNode *el, const sy_mat4 *world, sy_node h)
{
    created *c = cache_get(L, F, el, "mesh", true);
    if (!c) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    sy_result r;
    if (!c->done) {
        c->done = true;
        const xmlNode *app = field_child(L, F, el, "Appearance", "appearance");
        const xmlNode *geo = NULL;
        for (const xmlNode *k = el->children; k; k = k->next) {
            if (k->type != XML_ELEMENT_NODE || !strcmp(ename(k), "Appearance") || silent_node(ename(k))) continue;
            char *cf = attr(k, "containerField");
            bool other = cf && strcmp(cf, "geometry") != 0;
            xmlFree(cf);
            if (other) continue;
            define(L, F, k);
            geo = resolve(L, F, k);
            break;
        }
        if (!geo) return SY_OK;
        if (!name_in(ename(geo), "IndexedFaceSet|IndexedTriangleSet|TriangleSet|IndexedTriangleStripSet|IndexedTriangleFanSet|"
                           "TriangleStripSet|TriangleFanSet|IndexedQuadSet|QuadSet|Extrusion|Box|Sphere|Cone|Cylinder|"
                           "PointSet|LineSet|IndexedLineSet|Text")) {
            L->info->counts.skipped_geometry++;
            if (warn_type_once(L, ename(geo)))
                warn(L, "%s:%d: geometry %s not supported; skipped (reported once per type)", F->path, line_of(geo),
                     ename(geo));
            return SY_OK;
        }
        const xmlNode *tt = app ? field_child(L, F, app, "TextureTransform", "textureTransform") : NULL;
        sy_primitive prim;
        bool ok, colors, solid;
        if ((r = build_geometry(L, F, geo, tt, &prim, &ok, &colors, &solid))) return r;
        if (!ok) {
            L->info->counts.skipped_geometry++;
            return SY_OK;
        }
        uint32_t mat = 0;
        bool normal_map = false;
        r = get_material(L, F, app, solid, colors, prim.topology != SY_TOPOLOGY_TRIANGLES, &mat, &normal_map);
        if (!r && normal_map && prim.texcoords0 && prim.normals) r = sy_prim_generate_tangents(&prim, 0, &L->err);
        prim.material.id = mat;
        char *def = attr(el, "DEF");
        if (!def) def = attr(geo, "DEF");
        uint32_t mid = 0;
        if (!r) r = new_object(L, SY_TYPE_MESH, def, &mid);
        xmlFree(def);
        if (!r) r = sy_mesh_set_primitives(L->scene, (sy_mesh){mid}, &prim, 1, &L->err);
        if (!r) {
            L->info->counts.meshes++;
            L->info->counts.primitives++;
            L->info->counts.triangles += sy_primitive_triangle_count(&prim);
            if (prim.topology == SY_TOPOLOGY_LINES) L->info->counts.line_segments += sy_primitive_element_count(&prim);
            if (prim.topology == SY_TOPOLOGY_POINTS) L->info->counts.points += sy_primitive_element_count(&prim);
            if (!strcmp(ename(geo), "Text")) L->info->counts.texts++;
            c->mesh = mid;
            bounds_add_prim(L, &prim, world);
        } else {
            sy_error_prefix(&L->err, "%s:%d: Shape", F->path, line_of(el));
        }
        sy_primitive_release(&prim);
        if (r) return r;
    }
    if (c->mesh && (r = sy_node_set_mesh(L->scene, h, (sy_mesh){c->mesh}, &L->err))) return r;
    return SY_OK;
}

/* Quaternion rotating -Z onto d (unit). */
static void quat_from_neg_z(const float d_in[3], float q[4])
{
    float d[3] = {d_in[0], d_in[1], d_in[2]};
    float l = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(l > 0)) { d[0] = 0; d[1] = 0; d[2] = -1; }
    else { d[0] /= l; d[1] /= l; d[2] /= l; }
    float a[3] = {0, 0, -1};
    float cx = a[1] * d[2] - a[2] * d[1], cy = a[2] * d[0] - a[0] * d[2], cz = a[0] * d[1] - a[1] * d[0];
    float dot = -d[2];
    if (dot < -0.999999f) { q[0] = 0; q[1] = 1; q[2] = 0; q[3] = 0; return; }
    q[0] = cx; q[1] = cy; q[2] = cz; q[3] = 1.0f + dot;
    float n = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int k = 0; k < 4; k++) q[k] /= n;
}

static sy_result visit_light(loader *L, xfile *F, const xmlNode *el, const sy_mat4 *world, sy_node h)
{
    if (!get_bool(el, "on", true)) return SY_OK;
    sy_light_data ld = *(const sy_light_data *)sy_object_defaults(SY_TYPE_LIGHT);
    float color[3] = {1, 1, 1}, dir[3] = {0, 0, -1}, loc[3] = {0, 0, 0}, att[3] = {1, 0, 0};
    get_floats(L, F, el, "color", color, 3);
    clamp01(color, 3);
    memcpy(ld.color, color, sizeof color);
    float inten = fmaxf(0.0f, get_float(L, F, el, "intensity", 1.0f));
    get_floats(L, F, el, "direction", dir, 3);
    get_floats(L, F, el, "location", loc, 3);
    get_floats(L, F, el, "attenuation", att, 3);
    const char *n = ename(el);
    float q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
    if (!strcmp(n, "DirectionalLight")) {
        ld.type = SY_LIGHT_DIRECTIONAL;
        ld.intensity = inten * PI_F;
        quat_from_neg_z(dir, q);
        loc[0] = loc[1] = loc[2] = 0;
    } else if (!strcmp(n, "PointLight")) {
        ld.type = SY_LIGHT_POINT;
        ld.range = fmaxf(0.0f, get_float(L, F, el, "radius", 100.0f));
    } else {
        ld.type = SY_LIGHT_SPOT;
        ld.range = fmaxf(0.0f, get_float(L, F, el, "radius", 100.0f));
        float cut = get_float(L, F, el, "cutOffAngle", PI_F / 4), beam = get_float(L, F, el, "beamWidth", PI_F / 4);
        cut = fmaxf(1e-4f, fminf(PI_F / 2, cut));
        ld.outer_cone = cut;
        ld.inner_cone = fmaxf(0.0f, fminf(beam, cut * 0.999f));
        quat_from_neg_z(dir, q);
    }
    sy_result r;
    char *def = attr(el, "DEF");
    uint32_t lid;
    r = new_object(L, SY_TYPE_LIGHT, def, &lid);
    xmlFree(def);
    if (!r) r = sy_light_set(L->scene, (sy_light){lid}, &ld, &L->err);
    if (!r) r = sy_node_set_trs(L->scene, h, loc, q, one, &L->err);
    if (!r) r = sy_node_set_light(L->scene, h, (sy_light){lid}, &L->err);
    if (r) {
        sy_error_prefix(&L->err, "%s:%d: %s", F->path, line_of(el), n);
        return r;
    }
    L->info->counts.lights++;
    if (ld.type != SY_LIGHT_DIRECTIONAL) {
        if (L->light_count == L->light_cap) {
            size_t cap = L->light_cap ? L->light_cap * 2 : 8;
            pending_light *p = realloc(L->lights, cap * sizeof *p);
            if (!p) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
            L->lights = p;
            L->light_cap = cap;
        }
        pending_light *pl = &L->lights[L->light_count++];
        pl->light = lid;
        sy_mat4_transform_point(world, loc, pl->pos);
        pl->intensity = inten * PI_F;
        pl->a2 = att[2] > 0 && isfinite(att[2]) ? att[2] : 0.0f;
    }
    return SY_OK;
}

static sy_result visit_viewpoint(loader *L, xfile *F, const xmlNode *el, sy_node h)
{
    float pos[3] = {0, 0, 10}, ori[4] = {0, 0, 1, 0}, q[4], one[3] = {1, 1, 1};
    get_floats(L, F, el, "position", pos, 3);
    get_floats(L, F, el, "orientation", ori, 4);
    axis_angle_quat(ori, q);
    sy_camera_data cd = *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
    float fov = PI_F / 4;
    if (!strcmp(ename(el), "OrthoViewpoint")) {
        float fw[4] = {-1, -1, 1, 1};
        get_floats(L, F, el, "fieldOfView", fw, 4);
        cd.projection = SY_PROJECTION_ORTHOGRAPHIC;
        cd.xmag = fmaxf(1e-6f, 0.5f * fabsf(fw[2] - fw[0]));
        cd.ymag = fmaxf(1e-6f, 0.5f * fabsf(fw[3] - fw[1]));
        fov = 0;
    } else {
        fov = get_float(L, F, el, "fieldOfView", PI_F / 4);
        if (!(fov > 0 && fov < PI_F)) {
            warn(L, "%s:%d: Viewpoint fieldOfView %g outside (0, pi); using pi/4", F->path, line_of(el), (double)fov);
            fov = PI_F / 4;
        }
        cd.projection = SY_PROJECTION_PERSPECTIVE;
        cd.yfov = fov;
    }
    char *desc = attr(el, "description");
    char *def = attr(el, "DEF");
    uint32_t cid;
    sy_result r = new_object(L, SY_TYPE_CAMERA, desc ? desc : def, &cid);
    xmlFree(desc);
    xmlFree(def);
    if (!r) {
        cd.name = (char *)sy_camera_get(L->scene, (sy_camera){cid})->name;
        r = sy_camera_set(L->scene, (sy_camera){cid}, &cd, &L->err);
    }
    if (!r) r = sy_node_set_trs(L->scene, h, pos, q, one, &L->err);
    if (!r) r = sy_node_set_camera(L->scene, h, (sy_camera){cid}, &L->err);
    if (r) {
        sy_error_prefix(&L->err, "%s:%d: %s", F->path, line_of(el), ename(el));
        return r;
    }
    sy_x3d_info *I = L->info;
    void *a = realloc(I->camera_nodes, (I->camera_node_count + 1) * sizeof(sy_node));
    if (!a) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    I->camera_nodes = a;
    void *b = realloc(I->camera_fovs, (I->camera_node_count + 1) * sizeof(float));
    if (!b) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    I->camera_fovs = b;
    I->camera_nodes[I->camera_node_count] = h;
    I->camera_fovs[I->camera_node_count++] = fov;
    I->counts.cameras++;
    return SY_OK;
}

/* One part of an X3D Background gradient (sky or ground) into colours[]/angles[]: at most
 * SY_GRADIENT_MAX colours (more are cut, warned), one angle fewer than colours (a mismatch is
 * warned and the shorter list wins), angles increasing within (0, limit] as core's check_gradient
 * requires (angles up to 1e-3 past the limit are taken as the limit; otherwise warned and only the
 * first colour is used). Returns the colour count (0: none). */
static uint32_t gradient_part(loader *L, xfile *F, const xmlNode *el, const char *cname, const char *aname,
                              float limit, float (*colours)[3], float *angles)
{
    float *c = NULL, *a = NULL;
    size_t nc = 0, na = 0;
    if (!get_float_array(L, F, el, cname, 3, &c, &nc) || !get_float_array(L, F, el, aname, 1, &a, &na)) {
        free(c);
        free(a);
        return 0;
    }
    size_t given = nc;
    if (nc > SY_GRADIENT_MAX) {
        warn(L, "%s:%d: %s.%s: %zu colours, only the first %u are used", F->path, line_of(el), ename(el), cname, nc,
             (unsigned)SY_GRADIENT_MAX);
        nc = SY_GRADIENT_MAX;
    }
    if (nc && na != nc - 1) {
        size_t keep = na < nc - 1 ? na + 1 : nc;
        if (na != given - 1)
            warn(L, "%s:%d: %s: %zu %s for %zu %s (expected one fewer angle than colours); %zu colour(s) used", F->path,
                 line_of(el), ename(el), na, aname, nc, cname, keep);
        nc = keep;
    }
    float prev = 0.0f;
    for (size_t k = 0; k + 1 < nc; k++) {
        if (a[k] > limit && a[k] <= limit + 1e-3f) a[k] = limit; /* "1.5708", "3.1416" */
        if (!(a[k] > prev && a[k] <= limit)) {
            warn(L, "%s:%d: %s.%s[%zu] = %g must increase within (0, %g]; only the first %s used", F->path,
                 line_of(el), ename(el), aname, k, (double)a[k], (double)limit, cname);
            nc = 1; /* one colour needs no angle */
            break;
        }
        prev = a[k];
    }
    for (size_t k = 0; k < nc; k++) {
        for (int j = 0; j < 3; j++) colours[k][j] = fmaxf(0.0f, fminf(1.0f, c[3 * k + j]));
        if (k + 1 < nc) angles[k] = a[k];
    }
    free(c);
    free(a);
    return (uint32_t)nc;
}

/* Background / TextureBackground: skyColor / skyAngle / groundColor / groundAngle become the
 * world's gradient (SY_BACKGROUND_GRADIENT), shown where nothing is hit; the world's colour is
 * transparent (alpha 0) and nothing of it lights the scene. No skyColor: X3D's default black sky.
 * transparency is not supported with a gradient (warned). Textures of the panorama are ignored. */
static sy_result visit_background(loader *L, xfile *F, const xmlNode *el)
{
    if (L->have_background) return SY_OK; /* the first one is bound */
    L->have_background = true;
    sy_background_data bd = *(const sy_background_data *)sy_object_defaults(SY_TYPE_BACKGROUND);
    memset(bd.color, 0, sizeof bd.color);
    sy_gradient *g = &bd.gradient;
    memset(g, 0, sizeof *g);
    char *sky = attr(el, "skyColor");
    bool has_sky = sky != NULL;
    xmlFree(sky);
    if (has_sky) g->sky_count = gradient_part(L, F, el, "skyColor", "skyAngle", 3.1415927f, g->sky_color, g->sky_angle);
    else g->sky_count = 1; /* X3D default: skyColor 0 0 0 */
    if (g->sky_count)
        g->ground_count = gradient_part(L, F, el, "groundColor", "groundAngle", 1.5707964f, g->ground_color, g->ground_angle);
    if (get_float(L, F, el, "transparency", 0.0f) > 0.0f)
        warn(L, "%s:%d: %s.transparency is not supported; the background is opaque", F->path, line_of(el), ename(el));
    char *def = attr(el, "DEF");
    uint32_t id;
    sy_result r = new_object(L, SY_TYPE_BACKGROUND, def ? def : "Background", &id);
    xmlFree(def);
    if (!r) {
        bd.name = (char *)sy_background_get(L->scene, (sy_background){id})->name;
        r = sy_background_set(L->scene, (sy_background){id}, &bd, &L->err);
    }
    if (r) {
        sy_error_prefix(&L->err, "%s:%d: Background", F->path, line_of(el));
        return r;
    }
    L->info->background.id = id;
    return SY_OK;
}

static sy_result load_file(loader *L, const char *path, const void *mem, size_t mem_size, const char *base_dir,
                           xfile *parent, sy_node *root_out, const xmlNode *at, xfile *atF);

static sy_result visit_inline(loader *L, xfile *F, const xmlNode *el, sy_node h)
{
    if (!get_bool(el, "load", true)) return SY_OK;
    char *urls = attr(el, "url");
    if (!urls) {
        warn(L, "%s:%d: Inline without url; ignored", F->path, line_of(el));
        return SY_OK;
    }
    const char *p = urls;
    char u[2048], path[4096];
    sy_result r = SY_OK;
    bool loaded = false;
    while (!loaded && next_mfstring(&p, u, sizeof u)) {
        if (!u[0] || is_remote(u)) continue;
        char *hash = strchr(u, '#');
        if (hash) *hash = '\0';
        char joined[4096];
        if (!resolve_url(F, u, joined, sizeof joined)) continue;
        r = confine_url(L, F, el, u, joined, path, sizeof path);
        if (r == SY_ERR_NOT_FOUND) {
            r = SY_OK;
            warn(L, "%s:%d: Inline '%s': not found", F->path, line_of(el), joined);
            continue;
        }
        if (r) break;
        sy_node sub = {0};
        r = load_file(L, path, NULL, 0, NULL, F, &sub, el, F);
        if (r) break;
        if (sub.id) {
            loaded = true;
            r = sy_node_set_children(L->scene, h, &sub, 1, &L->err);
            if (r) sy_error_prefix(&L->err, "%s:%d: Inline", F->path, line_of(el));
        }
    }
    xmlFree(urls);
    return r;
}

static sy_result visit(loader *L, xfile *F, const xmlNode *el_in, const sy_mat4 *world, sy_node *out)
{
    out->id = 0;
    const char *n = ename(el_in);
    if (silent_node(n)) return SY_OK;
    define(L, F, el_in);
    const xmlNode *el = resolve(L, F, el_in);
    if (!el) return SY_OK;
    n = ename(el);
    if (!strcmp(n, "Background") || !strcmp(n, "TextureBackground")) return visit_background(L, F, el);
    bool group = name_in(n, "Transform|Group|StaticGroup|Collision|Anchor|Billboard|Switch|LOD|CADAssembly|CADLayer|CADPart|CADFace|HAnimHumanoid|HAnimJoint|HAnimSegment|HAnimSite|ScreenGroup|LayoutGroup");
    bool leaf = name_in(n, "Shape|DirectionalLight|PointLight|SpotLight|Viewpoint|OrthoViewpoint|Inline");
    if (!group && !leaf) {
        if (warn_type_once(L, n))
            warn(L, "%s:%d: node type %s not supported; skipped (reported once per type)", F->path, line_of(el), n);
        return SY_OK;
    }
    created *c = cache_get(L, F, el, "node", true);
    if (!c) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    if (c->in_progress) {
        warn(L, "%s:%d: USE of '%s' inside its own definition (line %d): cycle; skipped", F->path, line_of(el_in),
             n, line_of(el));
        return SY_OK;
    }
    if (c->done) {
        out->id = c->node;
        return SY_OK;
    }
    sy_node h;
    sy_result r;
    if ((r = begin_node(L, F, el, c, &h))) return r;
    sy_mat4 local = sy_mat4_identity();
    if (!strcmp(n, "Transform") || !strcmp(n, "HAnimJoint") || !strcmp(n, "HAnimHumanoid") || !strcmp(n, "CADPart"))
        r = set_transform(L, F, el, h, &local);
    sy_mat4 w = sy_mat4_mul(world, &local);
    if (!r) {
        if (!strcmp(n, "Shape")) r = visit_shape(L, F, el, &w, h);
        else if (name_in(n, "DirectionalLight|PointLight|SpotLight")) r = visit_light(L, F, el, &w, h);
        else if (!strcmp(n, "Viewpoint") || !strcmp(n, "OrthoViewpoint")) r = visit_viewpoint(L, F, el, h);
        else if (!strcmp(n, "Inline")) r = visit_inline(L, F, el, h);
        else if (!strcmp(n, "Switch")) {
            char *wc = attr(el, "whichChoice");
            r = children_of(L, F, el, &w, h, wc ? wc : "-1");
            xmlFree(wc);
        } else if (!strcmp(n, "LOD")) r = children_of(L, F, el, &w, h, "0");
        else r = children_of(L, F, el, &w, h, NULL);
    }
    if (!r && (r = sy_node_set_flags(L->scene, h, SY_NODE_VISIBLE, &L->err)))
        sy_error_prefix(&L->err, "%s:%d: %s", F->path, line_of(el), n);
    c->in_progress = false;
    c->done = true;
    if (!r) *out = h;
    return r;
}

/* >>files ------------------------------------------------------------------------------------- */

static void free_none(void *payload, const xmlChar *name)
{
    (void)payload;
    (void)name;
}

static char *dir_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    size_t n = slash ? (size_t)(slash - path) + 1 : 0;
    char *d = malloc(n + 1);
    if (!d) return NULL;
    memcpy(d, path, n);
    d[n] = '\0';
    return d;
}

/* Loads one X3D document (the main file or an Inline) and returns the node for its Scene. For an
 * Inline (at != NULL) problems are warnings (the Inline stays empty); for the main file errors. */
static sy_result load_file(loader *L, const char *path, const void *mem, size_t mem_size, const char *base_dir,
                           xfile *parent, sy_node *root_out, const xmlNode *at, xfile *atF)
{
    root_out->id = 0;
    xfile F = {0};
    sy_result r = SY_OK;
    void *bytes = NULL;
    size_t size = 0;
    xmlDocPtr doc = NULL;
    created *ic = NULL;
    if (parent) {
        if (parent->depth + 1 > L->opt.max_inline_depth) {
            warn(L, "%s:%d: Inline nesting deeper than %u; ignored", atF->path, line_of(at), L->opt.max_inline_depth);
            return SY_OK;
        }
        char why[SY_ERROR_MESSAGE_MAX];
        if (!regular_file(path, why, sizeof why)) {
            warn(L, "%s:%d: Inline: %s; ignored", atF->path, line_of(at), why);
            return SY_OK;
        }
        char *real = realpath(path, NULL);
        if (!real) {
            warn(L, "%s:%d: Inline '%s': %s; ignored", atF->path, line_of(at), path, strerror(errno));
            return SY_OK;
        }
        for (xfile *p = parent; p; p = p->parent)
            if (p->real && !strcmp(p->real, real)) {
                warn(L, "%s:%d: Inline '%s' includes itself (cycle); ignored", atF->path, line_of(at), path);
                free(real);
                return SY_OK;
            }
        ic = xmlHashLookup(L->inline_roots, (const xmlChar *)real);
        if (ic) { /* loaded before: share its node */
            free(real);
            root_out->id = ic->node;
            return SY_OK;
        }
        F.real = real;
        F.depth = parent->depth + 1;
    } else if (!mem) {
        F.real = realpath(path, NULL);
    }
    F.parent = parent;
    F.serial = ++L->file_serial;
    F.path = strdup(path);
    F.dir = mem ? strdup(base_dir ? base_dir : "") : dir_of(path);
    F.defs = xmlHashCreate(64);
    if (!F.path || !F.dir || !F.defs) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        goto done;
    }
    if (F.dir[0] && F.dir[strlen(F.dir) - 1] != '/' && mem) {
        char *d = malloc(strlen(F.dir) + 2);
        if (!d) {
            r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
            goto done;
        }
        sprintf(d, "%s/", F.dir);
        free(F.dir);
        F.dir = d;
    }
    if (!mem) {
        sy_error ferr = {0};
        if ((r = sy_file_read_all(path, L->opt.max_file_bytes, &bytes, &size, &ferr))) {
            if (parent) {
                warn(L, "%s:%d: Inline: %s; ignored", atF->path, line_of(at), ferr.message);
                r = SY_OK;
            } else {
                L->err = ferr;
            }
            goto done;
        }
        mem = bytes;
        mem_size = size;
    }
    if (mem_size > INT_MAX) {
        r = sy_error_set(&L->err, SY_ERR_LIMIT, "%s: too large for the XML parser", path);
        goto done;
    }
    xmlParserCtxtPtr ctxt = xmlNewParserCtxt();
    if (!ctxt) {
        r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
        goto done;
    }
    doc = xmlCtxtReadMemory(ctxt, mem, (int)mem_size, path, NULL,
                            XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING | XML_PARSE_NOCDATA);
    if (!doc) {
        const xmlError *e = xmlCtxtGetLastError(ctxt);
        char msg[256] = "not well-formed XML";
        if (e && e->message) {
            snprintf(msg, sizeof msg, "%s", e->message);
            size_t k = strlen(msg);
            while (k && (msg[k - 1] == '\n' || msg[k - 1] == ' ')) msg[--k] = '\0';
        }
        int line = e ? e->line : 0;
        xmlFreeParserCtxt(ctxt);
        if (parent) {
            warn(L, "%s:%d: Inline '%s': line %d: %s; ignored", atF->path, line_of(at), path, line, msg);
        } else {
            r = sy_error_set(&L->err, SY_ERR_PARSE, "%s:%d: malformed XML: %s", path, line, msg);
        }
        goto done;
    }
    xmlFreeParserCtxt(ctxt);
    const xmlNode *x3d = xmlDocGetRootElement(doc), *scene = NULL;
    if (x3d && !strcmp(ename(x3d), "X3D")) {
        for (const xmlNode *c = x3d->children; c; c = c->next)
            if (c->type == XML_ELEMENT_NODE && !strcmp(ename(c), "Scene")) scene = c;
    } else if (x3d && !strcmp(ename(x3d), "Scene")) {
        scene = x3d;
    }
    if (!scene) {
        if (parent) warn(L, "%s:%d: Inline '%s': no X3D Scene element; ignored", atF->path, line_of(at), path);
        else r = sy_error_set(&L->err, SY_ERR_PARSE, "%s:%d: not an X3D file (root element <%s>, expected <X3D> with a <Scene>)",
                              path, x3d ? line_of(x3d) : 1, x3d ? ename(x3d) : "none");
        goto done;
    }
    sy_node h;
    if ((r = new_object(L, SY_TYPE_NODE, parent ? path : "Scene", &h.id))) goto done;
    L->info->counts.nodes++;
    if (parent) {
        L->info->counts.inlines++;
        ic = calloc(1, sizeof *ic);
        if (!ic || xmlHashAddEntry(L->inline_roots, (const xmlChar *)F.real, ic) != 0) {
            free(ic);
            r = sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
            goto done;
        }
        ic->node = h.id;
    }
    sy_mat4 id = sy_mat4_identity();
    if ((r = children_of(L, &F, scene, &id, h, NULL))) goto done;
    if ((r = sy_node_set_flags(L->scene, h, SY_NODE_VISIBLE, &L->err))) goto done;
    *root_out = h;
done:
    if (doc) xmlFreeDoc(doc);
    free(bytes);
    if (F.defs) xmlHashFree(F.defs, free_none);
    free(F.path);
    free(F.dir);
    free(F.real);
    return r;
}

/* >>public ------------------------------------------------------------------------------------ */

void sy_x3d_info_free(sy_x3d_info *info)
{
    if (!info) return;
    for (uint32_t k = 0; k < info->stored_warning_count; k++) free(info->warnings[k]);
    free(info->warnings);
    free(info->camera_nodes);
    free(info->camera_fovs);
    memset(info, 0, sizeof *info);
}

static void finish_lights(loader *L)
{
    float centre[3] = {0, 0, 0}, diag = 1.0f;
    if (!sy_bounds_is_empty(&L->bounds)) {
        for (int k = 0; k < 3; k++) centre[k] = 0.5f * (L->bounds.min[k] + L->bounds.max[k]);
        float d[3] = {L->bounds.max[0] - L->bounds.min[0], L->bounds.max[1] - L->bounds.min[1], L->bounds.max[2] - L->bounds.min[2]};
        diag = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(diag > 0)) diag = 1.0f;
    }
    for (size_t k = 0; k < L->light_count; k++) {
        pending_light *pl = &L->lights[k];
        const sy_light_data *cur = sy_light_get(L->scene, (sy_light){pl->light});
        if (!cur) continue;
        sy_light_data ld = *cur;
        if (pl->a2 > 0) {
            ld.intensity = pl->intensity / pl->a2;
        } else {
            float d[3] = {pl->pos[0] - centre[0], pl->pos[1] - centre[1], pl->pos[2] - centre[2]};
            float dist = fmaxf(sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), 0.05f * diag);
            ld.intensity = pl->intensity * dist * dist;
        }
        sy_light_set(L->scene, (sy_light){pl->light}, &ld, NULL);
    }
}

/* What a successful load skipped or repaired, on the log (sy_log.h; module "x3d"): the stored
 * warnings (each names its file and line, so the item is NULL), then how many more there were. They
 * stay in info->warnings as well. */
static void log_warnings(const char *path, const sy_x3d_info *info)
{
    for (uint32_t i = 0; i < info->stored_warning_count; i++) sy_log(SY_LOG_WARNING, "x3d", NULL, "%s", info->warnings[i]);
    if (info->warning_count > info->stored_warning_count)
        sy_log(SY_LOG_WARNING, "x3d", path, "%u more warnings not shown", info->warning_count - info->stored_warning_count);
}

static sy_result load_common(const char *path, const void *mem, size_t size, const char *base_dir, sy_scene *scene,
                             const sy_x3d_options *opts, sy_x3d_info *info_out, sy_error *err)
{
    sy_x3d_info local_info;
    sy_x3d_info *info = info_out ? info_out : &local_info;
    memset(info, 0, sizeof *info);
    if (!path || !scene) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_x3d_load: path and scene are required");
    loader L = {0};
    L.scene = scene;
    L.info = info;
    if (opts) L.opt = *opts;
    if (!L.opt.max_file_bytes) L.opt.max_file_bytes = (size_t)1 << 30;
    if (!L.opt.max_vertices) L.opt.max_vertices = (size_t)1 << 27;
    if (!L.opt.max_image_pixels) L.opt.max_image_pixels = (uint64_t)1 << 26;
    if (!L.opt.max_inline_depth) L.opt.max_inline_depth = 16;
    L.budget = sy_budget_make(path, L.opt.max_scene_bytes);
    L.max_values = L.opt.max_vertices > SIZE_MAX / 4 ? SIZE_MAX : L.opt.max_vertices * 4;
    L.bounds = sy_bounds_empty();
    xmlInitParser();
    L.cache = xmlHashCreate(256);
    L.inline_roots = xmlHashCreate(16);
    L.warned = xmlHashCreate(16);
    sy_result r = SY_OK;
    if (!L.cache || !L.inline_roots || !L.warned) r = sy_error_set(&L.err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    sy_node root = {0};
    char *model_dir = NULL;
    if (mem) {
        model_dir = strdup(base_dir ? base_dir : "");
    } else {
        const char *slash = strrchr(path, '/');
        size_t n = slash ? (size_t)(slash - path) + 1 : 0;
        if ((model_dir = malloc(n + 1))) {
            memcpy(model_dir, path, n);
            model_dir[n] = '\0';
        }
    }
    L.model_dir = model_dir;
    if (!model_dir && !r) r = sy_error_set(&L.err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    if (!r) r = load_file(&L, path, mem, size, base_dir, NULL, &root, NULL, NULL);
    free(model_dir);
    L.model_dir = NULL;
    if (!r && L.limit_r) {
        r = L.limit_r;
        L.err = L.limit_err;
    }
    /* USE and Inline fan-out: what the mirror and the back-ends will hold, once per path */
    if (!r) r = sy_budget_charge_placements(&L.budget, scene, root, &L.err);
    /* a message without a place (out of memory) names the file at least */
    if (r && strncmp(L.err.message, path, strlen(path)) != 0) sy_error_prefix(&L.err, "%s", path);
    if (!r) {
        finish_lights(&L);
        info->root = root;
    }
    if (L.cache) xmlHashFree(L.cache, free_created);
    if (L.inline_roots) xmlHashFree(L.inline_roots, free_created);
    if (L.warned) xmlHashFree(L.warned, free_none);
    free(L.lights);
    if (r) {
        for (size_t k = L.obj_count; k-- > 0;) sy_object_destroy(scene, L.objs[k].type, L.objs[k].id, NULL);
        free(L.objs);
        if (err) *err = L.err;
        sy_x3d_info_free(info);
        return r;
    }
    free(L.objs);
    log_warnings(path, info);
    if (info == &local_info) sy_x3d_info_free(info);
    return SY_OK;
}

sy_result sy_x3d_load(const char *path, sy_scene *scene, const sy_x3d_options *opts, sy_x3d_info *info_out,
                      sy_error *err)
{
    return load_common(path, NULL, 0, NULL, scene, opts, info_out, err);
}

sy_result sy_x3d_load_memory(const void *data, size_t size, const char *name, const char *base_dir,
                             sy_scene *scene, const sy_x3d_options *opts, sy_x3d_info *info_out, sy_error *err)
{
    if (!data && size) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_x3d_load_memory: no data");
    static const char empty[1] = "";
    return load_common(name ? name : "(memory)", data ? data : empty, size, base_dir, scene, opts, info_out, err);
}

float sy_x3d_yfov(float fov, float aspect)
{
    if (!(aspect > 0) || aspect >= 1.0f) return fov;
    return 2.0f * atanf(tanf(0.5f * fov) / aspect);
}

sy_result sy_x3d_fit_cameras(sy_scene *scene, const sy_x3d_info *info, float aspect, sy_error *err)
{
    for (uint32_t k = 0; k < info->camera_node_count; k++) {
        if (!(info->camera_fovs[k] > 0)) continue;
        const sy_node_data *nd = sy_node_get(scene, info->camera_nodes[k]);
        if (!nd) continue;
        const sy_camera_data *cd = sy_camera_get(scene, nd->camera);
        if (!cd) continue;
        sy_camera_data c = *cd;
        c.yfov = fminf(sy_x3d_yfov(info->camera_fovs[k], aspect), 3.1f);
        sy_result r = sy_camera_set(scene, nd->camera, &c, err);
        if (r) return r;
    }
    return SY_OK;
}

sy_result sy_x3d_find_camera(const sy_scene *scene, const sy_x3d_info *info, const char *selector, sy_node *out,
                             sy_error *err)
{
    char *end;
    unsigned long idx = strtoul(selector, &end, 10);
    if (*selector && !*end) {
        if (idx < info->camera_node_count) {
            *out = info->camera_nodes[idx];
            return SY_OK;
        }
    } else {
        for (uint32_t k = 0; k < info->camera_node_count; k++) {
            const sy_node_data *nd = sy_node_get(scene, info->camera_nodes[k]);
            const sy_camera_data *cd = nd ? sy_camera_get(scene, nd->camera) : NULL;
            if ((nd && nd->name && !strcmp(nd->name, selector)) || (cd && cd->name && !strcmp(cd->name, selector))) {
                *out = info->camera_nodes[k];
                return SY_OK;
            }
        }
    }
    char list[256] = "";
    size_t used = 0;
    for (uint32_t k = 0; k < info->camera_node_count && used + 1 < sizeof list; k++) {
        const sy_node_data *nd = sy_node_get(scene, info->camera_nodes[k]);
        int w = snprintf(list + used, sizeof list - used, "%s%u \"%s\"", k ? ", " : "", (unsigned)k,
                         nd && nd->name ? nd->name : "");
        if (w < 0) break;
        used += (size_t)w;
        if (used >= sizeof list) used = sizeof list - 1;
    }
    return sy_error_set(err, SY_ERR_NOT_FOUND, "no viewpoint '%s' (available: %s)", selector,
                        info->camera_node_count ? list : "none");
}
