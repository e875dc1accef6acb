/* sy_x3d_fields.c — the X3D loader's ground floor: the objects it creates (tracked
 * for the rollback, cached per element), the reading of field values from XML attributes (numbers
 * counted against the value limit before anything is allocated, booleans, arrays, SFRotation) and
 * DEF / USE (names per file, resolved in document order). Everything else in the loader builds on
 * this file and on its warning macro x3d_warn (sy_x3d_internal.h, over sy_loader_log.h). */
#include "sy_x3d_internal.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>state ------------------------------------------------------------------------------------- */

static sy_result track(loader *L, sy_object_type t, uint32_t id)
{
    if (!sy_array_reserve(&L->objs, L->obj_count, &L->obj_cap, sizeof *L->objs, 64)) {
        sy_object_destroy(L->scene, t, id, NULL);
        return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    }
    L->objs[L->obj_count].type = t;
    L->objs[L->obj_count++].id = id;
    return SY_OK;
}

sy_result x3d_new_object(loader *L, sy_object_type t, const char *name, uint32_t *id)
{
    sy_result r = sy_object_create(L->scene, t, name, id, &L->err);
    if (r) return r;
    return track(L, t, *id);
}

void x3d_free_created(void *payload, const xmlChar *name)
{
    (void)name;
    free(payload);
}

created *x3d_cache_get(loader *L, const xfile *F, const void *el, const char *variant, bool create)
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

void x3d_free_none(void *payload, const xmlChar *name)
{
    (void)payload;
    (void)name;
}

/* >>fields ------------------------------------------------------------------------------------ */

char *x3d_attr(const xmlNode *el, const char *name)
{
    return (char *)xmlGetNoNsProp(el, (const xmlChar *)name);
}

bool x3d_attr_present(const xmlNode *el, const char *name)
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
    char *s = x3d_attr(el, name);
    if (!s) return 0;
    int ok = parse_numbers(s, L->max_values, v, n);
    xmlFree(s);
    if (ok == 1) return 1;
    if (ok < 0) {
        size_t count = *n;
        *n = 0;
        if (!L->limit_r)
            L->limit_r = count ? sy_error_set(&L->limit_err, SY_ERR_LIMIT, "%s:%d: %s.%s: %zu values exceed the limit of %zu (4 x max_vertices)",
                                              F->path, x3d_line_of(el), x3d_ename(el), name, count, L->max_values)
                               : sy_error_set(&L->limit_err, SY_ERR_OUT_OF_MEMORY, "%s:%d: %s.%s: out of memory",
                                              F->path, x3d_line_of(el), x3d_ename(el), name);
        return -1;
    }
    x3d_warn(L, "%s:%d: %s.%s: not a list of %s; %s", F->path, x3d_line_of(el), x3d_ename(el), name, what, then);
    return -1;
}

/* Numeric attribute: fills up to max values into out (defaults kept otherwise); returns the
 * number of values in the attribute (0 when absent or bad: warned). */
size_t x3d_get_floats(loader *L, xfile *F, const xmlNode *el, const char *name, float *out, size_t max)
{
    double *v;
    size_t n;
    if (attr_numbers(L, F, el, name, "numbers", "ignored", &v, &n) <= 0) return 0;
    for (size_t k = 0; k < n && k < max; k++) out[k] = (float)v[k];
    free(v);
    return n;
}

float x3d_get_float(loader *L, xfile *F, const xmlNode *el, const char *name, float def)
{
    float v = def;
    x3d_get_floats(L, F, el, name, &v, 1);
    return v;
}

bool x3d_get_bool(const xmlNode *el, const char *name, bool def)
{
    char *s = x3d_attr(el, name);
    if (!s) return def;
    bool v = def;
    if (!strcmp(s, "true") || !strcmp(s, "TRUE")) v = true;
    else if (!strcmp(s, "false") || !strcmp(s, "FALSE")) v = false;
    xmlFree(s);
    return v;
}

/* Whole float array attribute (MFFloat / MFVec*): *out malloc()ed float array. */
bool x3d_get_float_array(loader *L, xfile *F, const xmlNode *el, const char *name, size_t group, float **out,
                         size_t *count)
{
    *out = NULL;
    *count = 0;
    double *v;
    size_t n;
    int present = attr_numbers(L, F, el, name, "numbers", "geometry skipped", &v, &n);
    if (present <= 0) return present == 0;
    if (n % group)
        x3d_warn(L, "%s:%d: %s.%s: %zu values are not a multiple of %zu; the rest is ignored", F->path, x3d_line_of(el),
                 x3d_ename(el), name, n, group);
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

bool x3d_get_int_array(loader *L, xfile *F, const xmlNode *el, const char *name, int32_t **out, size_t *count)
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
            x3d_warn(L, "%s:%d: %s.%s[%zu]: %g is not a valid index; geometry skipped", F->path, x3d_line_of(el), x3d_ename(el),
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

/* Whether name is one of the '|'-separated names of list (sy_name_in_list). */
bool x3d_name_in(const char *name, const char *list) { return sy_name_in_list(name, list, '|'); }

void x3d_clamp01(float *v, int n)
{
    for (int k = 0; k < n; k++) v[k] = fmaxf(0.0f, fminf(1.0f, v[k]));
}

void x3d_axis_angle_quat(const float aa[4], float q[4])
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

void x3d_read_transform(loader *L, xfile *F, const xmlNode *el, x3d_transform *out)
{
    float rot[4] = {0, 0, 1, 0}, so[4] = {0, 0, 1, 0};
    *out = (x3d_transform){.s = {1, 1, 1}};
    x3d_get_floats(L, F, el, "translation", out->t, 3);
    x3d_get_floats(L, F, el, "rotation", rot, 4);
    x3d_get_floats(L, F, el, "scale", out->s, 3);
    x3d_get_floats(L, F, el, "center", out->c, 3);
    x3d_get_floats(L, F, el, "scaleOrientation", so, 4);
    x3d_axis_angle_quat(rot, out->r);
    x3d_axis_angle_quat(so, out->so);
}

bool x3d_transform_pivoted(const x3d_transform *x)
{
    return x->c[0] != 0.0f || x->c[1] != 0.0f || x->c[2] != 0.0f || x->so[3] != 1.0f;
}

sy_mat4 x3d_transform_tail(const x3d_transform *x, bool scale)
{
    float one[3] = {1, 1, 1}, zero[3] = {0, 0, 0}, idq[4] = {0, 0, 0, 1};
    float nc[3] = {-x->c[0], -x->c[1], -x->c[2]}, nsq[4] = {-x->so[0], -x->so[1], -x->so[2], x->so[3]};
    sy_mat4 SR = sy_mat4_from_trs(zero, x->so, one), S = sy_mat4_from_trs(zero, idq, scale ? x->s : one);
    sy_mat4 NSR = sy_mat4_from_trs(zero, nsq, one), NC = sy_mat4_from_trs(nc, idq, one);
    sy_mat4 m = sy_mat4_mul(&SR, &S);
    m = sy_mat4_mul(&m, &NSR);
    return sy_mat4_mul(&m, &NC);
}

/* >>DEF/USE ----------------------------------------------------------------------------------- */

/* Resolves USE: returns the DEF'd element (or el itself), NULL when undefined (warned). */
const xmlNode *x3d_resolve(loader *L, xfile *F, const xmlNode *el)
{
    char *use = x3d_attr(el, "USE");
    if (!use) return el;
    const xmlNode *t = xmlHashLookup(F->defs, (const xmlChar *)use);
    if (!t) x3d_warn(L, "%s:%d: USE '%s' of an undefined DEF; %s skipped", F->path, x3d_line_of(el), use, x3d_ename(el));
    else if (strcmp(x3d_ename(t), x3d_ename(el)) != 0)
        x3d_warn(L, "%s:%d: USE '%s' names a %s (line %d), used as %s", F->path, x3d_line_of(el), use, x3d_ename(t), x3d_line_of(t),
                 x3d_ename(el));
    xmlFree(use);
    return t;
}

/* DEF registration happens in document order during the walk (X3D: DEF precedes USE). */
void x3d_define(loader *L, xfile *F, const xmlNode *el)
{
    char *def = x3d_attr(el, "DEF");
    if (!def) return;
    if (xmlHashLookup(F->defs, (const xmlChar *)def))
        x3d_warn(L, "%s:%d: DEF '%s' defined again; later USEs refer to this one", F->path, x3d_line_of(el), def);
    xmlHashUpdateEntry(F->defs, (const xmlChar *)def, (void *)el, NULL);
    xmlFree(def);
}

/* Finds the child element for an SFNode field: a child whose containerField equals field, else the
 * first child whose element name is in `names`. USE is resolved (and DEFs registered). */
const xmlNode *x3d_field_child(loader *L, xfile *F, const xmlNode *el, const char *names, const char *field)
{
    const xmlNode *fallback = NULL;
    for (const xmlNode *c = el->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE) continue;
        char *cf = x3d_attr(c, "containerField");
        bool match_field = field && cf && !strcmp(cf, field);
        bool other_field = cf && (!field || strcmp(cf, field) != 0);
        xmlFree(cf);
        if (match_field || (!other_field && !fallback && x3d_name_in(x3d_ename(c), names))) {
            x3d_define(L, F, c);
            const xmlNode *t = x3d_resolve(L, F, c);
            if (match_field) return t;
            if (!fallback && t) fallback = t;
        }
    }
    return fallback;
}
