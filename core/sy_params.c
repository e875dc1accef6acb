/* sy_params.c — back-end parameter lists and their declaration tables: parsing, validation against
 * a table, typed getters and the listing (see sy_params.h). */
#include "sy_params.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>lists */
sy_result sy_params_set(sy_params *p, const char *key, const char *value, sy_error *err)
{
    if (!key[0] || strlen(key) >= sizeof p->items[0].key)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "parameter '%s': bad key", key);
    if (strlen(value) >= sizeof p->items[0].value)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "parameter '%s': value too long", key);
    uint32_t i = 0;
    while (i < p->count && strcmp(p->items[i].key, key) != 0) i++;
    if (i == p->count) {
        if (p->count == SY_PARAMS_MAX)
            return sy_error_set(err, SY_ERR_LIMIT, "parameter '%s': more than %d parameters", key, SY_PARAMS_MAX);
        p->count++;
        strcpy(p->items[i].key, key);
    }
    strcpy(p->items[i].value, value);
    return SY_OK;
}

sy_result sy_params_parse(const char *text, sy_params *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    if (!text) return SY_OK;
    const char *p = text;
    while (*p) {
        const char *end = strchr(p, ',');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        char item[160];
        if (len >= sizeof item) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "parameters: item too long in '%s'", text);
        memcpy(item, p, len);
        item[len] = '\0';
        if (len) {
            char *eq = strchr(item, '=');
            if (!eq || eq == item)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "parameters: '%s' is not key=value", item);
            *eq = '\0';
            if (sy_params_get(out, item)) /* "spp=1,spp=2": which one was meant is not ours to guess */
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "parameters: '%s' is given twice in '%s'", item, text);
            sy_result r = sy_params_set(out, item, eq + 1, err);
            if (r != SY_OK) return r;
        }
        p += len;
        if (*p == ',') p++;
    }
    return SY_OK;
}

const char *sy_params_get(const sy_params *p, const char *key)
{
    if (!p) return NULL;
    for (uint32_t i = 0; i < p->count; ++i)
        if (strcmp(p->items[i].key, key) == 0) return p->items[i].value;
    return NULL;
}

sy_result sy_params_get_int(const sy_params *p, const char *key, long def, long min, long max, long *out, sy_error *err)
{
    const char *v = sy_params_get(p, key);
    *out = def;
    if (!v) return SY_OK;
    char *end;
    errno = 0;
    long x = strtol(v, &end, 10);
    if (errno || end == v || *end || x < min || x > max)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "parameter %s=%s: expected an integer in [%ld, %ld]", key, v,
                            min, max);
    *out = x;
    return SY_OK;
}

sy_result sy_params_get_float(const sy_params *p, const char *key, double def, double min, double max, double *out,
                              sy_error *err)
{
    const char *v = sy_params_get(p, key);
    *out = def;
    if (!v) return SY_OK;
    char *end;
    double x = strtod(v, &end);
    if (end == v || *end || !isfinite(x) || x < min || x > max)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "parameter %s=%s: expected a number in [%g, %g]", key, v, min,
                            max);
    *out = x;
    return SY_OK;
}

bool sy_params_equal(const sy_params *a, const sy_params *b)
{
    if (a->count != b->count) return false;
    for (uint32_t i = 0; i < a->count; ++i) {
        const char *v = sy_params_get(b, a->items[i].key);
        if (!v || strcmp(v, a->items[i].value) != 0) return false;
    }
    return true;
}

/* >>declarations */
const sy_param_decl *sy_param_find(const sy_param_table *t, const char *name)
{
    if (!t || !name) return NULL;
    for (uint32_t i = 0; i < t->count; ++i)
        if (t->decls[i].name && strcmp(t->decls[i].name, name) == 0) return &t->decls[i];
    return NULL;
}

const char *sy_param_type_name(sy_param_type type)
{
    switch (type) {
    case SY_PARAM_BOOL: return "bool";
    case SY_PARAM_INT: return "int";
    case SY_PARAM_FLOAT: return "float";
    case SY_PARAM_ENUM: return "enum";
    case SY_PARAM_STRING: return "string";
    }
    return "?";
}

int sy_param_enum_index(const sy_param_decl *d, const char *value)
{
    if (!d || !d->enum_values || !value) return -1;
    size_t n = strlen(value);
    int i = 0;
    for (const char *s = d->enum_values;; ++i) {
        const char *bar = strchr(s, '|');
        size_t l = bar ? (size_t)(bar - s) : strlen(s);
        if (l == n && strncmp(s, value, n) == 0) return i;
        if (!bar) return -1;
        s = bar + 1;
    }
}

static bool ranged(const sy_param_decl *d) { return !(d->min == 0.0 && d->max == 0.0); }

/* Parses value as d's type; *num gets the number (BOOL 0/1, INT, FLOAT, ENUM index). */
static bool parse_value(const sy_param_decl *d, const char *v, double *num)
{
    char *end;
    *num = 0.0;
    switch (d->type) {
    case SY_PARAM_BOOL: {
        static const char *const words[][2] = {{"0", "1"}, {"false", "true"}, {"no", "yes"}, {"off", "on"}};
        for (size_t i = 0; i < sizeof words / sizeof words[0]; ++i)
            for (int b = 0; b < 2; ++b)
                if (!strcmp(v, words[i][b])) {
                    *num = b;
                    return true;
                }
        return false;
    }
    case SY_PARAM_INT: {
        errno = 0;
        long x = strtol(v, &end, 10);
        if (errno || end == v || *end) return false;
        *num = (double)x;
        return !ranged(d) || (*num >= d->min && *num <= d->max);
    }
    case SY_PARAM_FLOAT: {
        double x = strtod(v, &end);
        if (end == v || *end || !isfinite(x)) return false;
        *num = x;
        return !ranged(d) || (x >= d->min && x <= d->max);
    }
    case SY_PARAM_ENUM: {
        int i = sy_param_enum_index(d, v);
        *num = i;
        return i >= 0;
    }
    case SY_PARAM_STRING: return true;
    }
    return false;
}

/* snprintf-style appending: *used grows by what the whole text needs, buf holds what fits. */
static void append(char *buf, size_t len, size_t *used, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
static void append(char *buf, size_t len, size_t *used, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf && *used < len ? buf + *used : NULL, buf && *used < len ? len - *used : 0, fmt, ap);
    va_end(ap);
    if (n > 0) *used += (size_t)n;
}

/* enum_values with sep between the values */
static void append_values(char *buf, size_t len, size_t *used, const char *values, const char *sep)
{
    for (const char *s = values; s && *s;) {
        const char *bar = strchr(s, '|');
        int l = bar ? (int)(bar - s) : (int)strlen(s);
        append(buf, len, used, "%s%.*s", s == values ? "" : sep, l, s);
        s = bar ? bar + 1 : NULL;
    }
}

/* What d accepts, as "an integer in [1, 64]" (expected = true) or "1..64" (for listings). */
static void describe(const sy_param_decl *d, bool expected, char *buf, size_t len)
{
    size_t used = 0;
    buf[0] = '\0';
    switch (d->type) {
    case SY_PARAM_BOOL: append(buf, len, &used, "%s", expected ? "0 or 1 (or false/true, no/yes, off/on)" : "0|1"); break;
    case SY_PARAM_INT:
    case SY_PARAM_FLOAT:
        if (expected) append(buf, len, &used, "%s", d->type == SY_PARAM_INT ? "an integer" : "a number");
        if (ranged(d)) append(buf, len, &used, expected ? " in [%.15g, %.15g]" : "%.15g..%.15g", d->min, d->max);
        else if (!expected) append(buf, len, &used, "any");
        break;
    case SY_PARAM_ENUM:
        if (expected) append(buf, len, &used, "one of ");
        append_values(buf, len, &used, d->enum_values, expected ? ", " : "|");
        break;
    case SY_PARAM_STRING: append(buf, len, &used, "text"); break;
    }
}

sy_result sy_param_check_value(const sy_param_decl *d, const char *value, const char *owner, sy_error *err)
{
    double num;
    if (parse_value(d, value, &num)) return SY_OK;
    char what[256];
    describe(d, true, what, sizeof what);
    bool help = d->help && d->help[0];
    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "parameter %s=%s%s%s: expected %s%s%s%s", d->name, value,
                        owner ? " for " : "", owner ? owner : "", what, help ? " (" : "", help ? d->help : "",
                        help ? ")" : "");
}

/* Edit distance of two short keys (for "did you mean"), capped at 9. */
static int distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    if (la > 40 || lb > 40) return 9;
    int row[41];
    for (size_t j = 0; j <= lb; ++j) row[j] = (int)j;
    for (size_t i = 1; i <= la; ++i) {
        int diag = row[0];
        row[0] = (int)i;
        for (size_t j = 1; j <= lb; ++j) {
            int up = row[j];
            int best = diag + (a[i - 1] != b[j - 1]);
            if (row[j] + 1 < best) best = row[j] + 1;
            if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
            row[j] = best;
            diag = up;
        }
    }
    return row[lb] > 9 ? 9 : row[lb];
}

/* The declared names (with all of need_flags), joined by ", ". */
static void names_of(const sy_param_table *t, uint32_t need_flags, char *buf, size_t len)
{
    size_t used = 0;
    buf[0] = '\0';
    for (uint32_t i = 0; i < t->count; ++i)
        if ((t->decls[i].flags & need_flags) == need_flags)
            append(buf, len, &used, "%s%s", used ? ", " : "", t->decls[i].name);
}

static sy_result unknown_key(const sy_param_table *t, const char *key, const char *owner, sy_error *err)
{
    const char *of = owner ? " for " : "", *who = owner ? owner : "";
    if (!t || !t->count)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "unknown parameter '%s'%s%s: it takes no parameters", key, of,
                            who);
    const char *near = NULL;
    int best = 3; /* suggest within two edits */
    for (uint32_t i = 0; i < t->count; ++i) {
        int d = distance(key, t->decls[i].name);
        if (d < best) best = d, near = t->decls[i].name;
    }
    char names[SY_ERROR_MESSAGE_MAX];
    names_of(t, 0, names, sizeof names);
    char hint[64] = "";
    if (near) snprintf(hint, sizeof hint, " (did you mean '%s'?)", near);
    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "unknown parameter '%s'%s%s%s; valid: %s", key, of, who, hint,
                        names);
}

sy_result sy_params_check(const sy_param_table *t, const sy_params *p, uint32_t need_flags, const char *owner,
                          sy_params *undeclared, sy_error *err)
{
    if (undeclared) memset(undeclared, 0, sizeof *undeclared);
    if (!p) return SY_OK;
    for (uint32_t i = 0; i < p->count; ++i) {
        const char *key = p->items[i].key, *value = p->items[i].value;
        const sy_param_decl *d = sy_param_find(t, key);
        if (!d) {
            if (!undeclared) return unknown_key(t, key, owner, err);
            sy_params_set(undeclared, key, value, NULL); /* fits: p held it */
            continue;
        }
        sy_result r = sy_param_check_value(d, value, owner, err);
        if (r != SY_OK) return r;
        if ((d->flags & need_flags) != need_flags) {
            char names[SY_ERROR_MESSAGE_MAX];
            names_of(t, need_flags, names, sizeof names);
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "parameter '%s'%s%s is fixed when the back-end is created; these can change: %s", key,
                                owner ? " for " : "", owner ? owner : "", names[0] ? names : "none");
        }
    }
    return SY_OK;
}

/* >>typed getters */
/* The text to read for key (given value or default; NULL = neither) and its declaration. */
static sy_result lookup(const sy_param_table *t, const sy_params *p, const char *key, const sy_param_decl **d_out,
                        const char **text, sy_error *err)
{
    const sy_param_decl *d = sy_param_find(t, key);
    *d_out = d;
    *text = NULL;
    if (!d) return sy_error_set(err, SY_ERR_NOT_FOUND, "parameter '%s' is not declared by its back-end", key);
    const char *v = sy_params_get(p, key);
    *text = v ? v : d->default_value;
    return SY_OK;
}

static sy_result read_number(const sy_param_table *t, const sy_params *p, const char *key, bool int_ok, bool float_ok,
                             bool bool_ok, double *num, bool *have, sy_error *err)
{
    const sy_param_decl *d;
    const char *v;
    *have = false;
    sy_result r = lookup(t, p, key, &d, &v, err);
    if (r != SY_OK) return r;
    bool typed = (d->type == SY_PARAM_INT && int_ok) || (d->type == SY_PARAM_FLOAT && float_ok) ||
                 (d->type == SY_PARAM_BOOL && bool_ok);
    if (!typed)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "parameter '%s' is declared as %s, read as another type", key,
                            sy_param_type_name(d->type));
    if (!v) return SY_OK;
    if (!parse_value(d, v, num)) return sy_param_check_value(d, v, NULL, err);
    *have = true;
    return SY_OK;
}

sy_result sy_param_bool(const sy_param_table *t, const sy_params *p, const char *key, bool *out, sy_error *err)
{
    double x;
    bool have;
    sy_result r = read_number(t, p, key, false, false, true, &x, &have, err);
    if (r == SY_OK && have) *out = x != 0.0;
    return r;
}

sy_result sy_param_int(const sy_param_table *t, const sy_params *p, const char *key, long *out, sy_error *err)
{
    double x;
    bool have;
    sy_result r = read_number(t, p, key, true, false, true, &x, &have, err);
    if (r == SY_OK && have) *out = (long)x;
    return r;
}

sy_result sy_param_float(const sy_param_table *t, const sy_params *p, const char *key, double *out, sy_error *err)
{
    double x;
    bool have;
    sy_result r = read_number(t, p, key, true, true, false, &x, &have, err);
    if (r == SY_OK && have) *out = x;
    return r;
}

sy_result sy_param_enum(const sy_param_table *t, const sy_params *p, const char *key, uint32_t *out, sy_error *err)
{
    const sy_param_decl *d;
    const char *v;
    sy_result r = lookup(t, p, key, &d, &v, err);
    if (r != SY_OK) return r;
    if (d->type != SY_PARAM_ENUM)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "parameter '%s' is declared as %s, read as an enum", key,
                            sy_param_type_name(d->type));
    if (!v) return SY_OK;
    int i = sy_param_enum_index(d, v);
    if (i < 0) return sy_param_check_value(d, v, NULL, err);
    *out = (uint32_t)i;
    return SY_OK;
}

sy_result sy_param_string(const sy_param_table *t, const sy_params *p, const char *key, const char **out,
                          sy_error *err)
{
    const sy_param_decl *d;
    const char *v;
    sy_result r = lookup(t, p, key, &d, &v, err);
    if (r != SY_OK) return r;
    if (v && (r = sy_param_check_value(d, v, NULL, err)) != SY_OK) return r;
    if (v) *out = v;
    return SY_OK;
}

/* >>listing */
size_t sy_param_table_format(const sy_param_table *t, const char *indent, char *buf, size_t len)
{
    size_t used = 0;
    if (buf && len) buf[0] = '\0';
    if (!indent) indent = "";
    if (!t || !t->count) {
        append(buf, len, &used, "%s(no parameters)\n", indent);
        return used;
    }
    int wn = 4, wt = 4, wr = 5, wd = 7;
    char range[256], def[128];
    for (uint32_t i = 0; i < t->count; ++i) {
        const sy_param_decl *d = &t->decls[i];
        describe(d, false, range, sizeof range);
        snprintf(def, sizeof def, "%s", d->default_value ? d->default_value : "-");
        int n = (int)strlen(d->name), ty = (int)strlen(sy_param_type_name(d->type)), r = (int)strlen(range),
            df = (int)strlen(def);
        wn = n > wn ? n : wn, wt = ty > wt ? ty : wt, wr = r > wr ? r : wr, wd = df > wd ? df : wd;
    }
    if (wr > 40) wr = 40; /* long enum lists run into the next column rather than widen every row */
    append(buf, len, &used, "%s%-*s  %-*s  %-*s  %-*s  %s\n", indent, wn, "name", wt, "type", wr, "range", wd,
           "default", "description");
    for (uint32_t i = 0; i < t->count; ++i) {
        const sy_param_decl *d = &t->decls[i];
        describe(d, false, range, sizeof range);
        append(buf, len, &used, "%s%-*s  %-*s  %-*s  %-*s  %s%s\n", indent, wn, d->name, wt, sy_param_type_name(d->type),
               wr, range, wd, d->default_value ? d->default_value : "-", d->help ? d->help : "",
               (d->flags & SY_PARAM_LIVE) ? " [live]" : "");
    }
    return used;
}
