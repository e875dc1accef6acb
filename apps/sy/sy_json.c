/* sy_json.c — the JSON that sy prints (sy info, sy coverage, sy backends --json): built with cJSON,
 * written in sy's layout (sy_json.h). */
#include "sy_json.h"

#include "sy_log.h"

#include <stdio.h>
#include <stdlib.h>

/* >>json: the JSON that commands print is built and written by cJSON. jadd adds an item to an object
 * (key) or an array (key NULL); a failed allocation is remembered and reported by print_json. */
static bool g_json_failed;

cJSON *sy_json_add(cJSON *parent, const char *key, cJSON *item)
{
    if (item && parent && (key ? cJSON_AddItemToObject(parent, key, item) : cJSON_AddItemToArray(parent, item)))
        return item;
    cJSON_Delete(item);
    g_json_failed = true;
    return NULL;
}

/* a float as its shortest decimal that reads back as the same float (not the double's 17 digits) */
cJSON *sy_json_float(double v)
{
    char t[32];
    snprintf(t, sizeof t, "%.9g", v);
    return cJSON_CreateNumber(strtod(t, NULL));
}

cJSON *sy_json_str(const char *s) { return cJSON_CreateString(s ? s : ""); }

/* The layout of sy's JSON (for people and grep; cJSON writes every key and value): the top level's
 * members one per line, a nested value on one line ("key": value, ", " between items) unless it
 * holds objects or is longer than JSON_LINE characters; then its members one per line. */
#define JSON_LINE 160

static bool json_write(FILE *f, const cJSON *v, int depth);

static bool json_leaf(FILE *f, const cJSON *v) /* a string, number, bool or null: cJSON's text */
{
    char *t = cJSON_PrintUnformatted(v);
    if (!t) return false;
    fputs(t, f);
    cJSON_free(t);
    return true;
}

static bool json_members(FILE *f, const cJSON *v, int depth, bool broken)
{
    bool obj = cJSON_IsObject(v), ok = true;
    fputc(obj ? '{' : '[', f);
    for (const cJSON *c = v->child; c && ok; c = c->next) {
        if (broken) fprintf(f, "%s\n%*s", c == v->child ? "" : ",", 2 * (depth + 1), "");
        else if (c != v->child) fputs(", ", f);
        if (obj) {
            cJSON *key = cJSON_CreateString(c->string);
            ok = key && json_leaf(f, key);
            cJSON_Delete(key);
            fputs(": ", f);
        }
        ok = ok && json_write(f, c, depth + 1);
    }
    if (broken && v->child) fprintf(f, "\n%*s", 2 * depth, "");
    fputc(obj ? '}' : ']', f);
    return ok;
}

static bool json_write(FILE *f, const cJSON *v, int depth)
{
    if (!cJSON_IsObject(v) && !cJSON_IsArray(v)) return json_leaf(f, v);
    bool broken = depth == 0;
    for (const cJSON *c = v->child; c && !broken; c = c->next) broken = cJSON_IsObject(c);
    if (!broken) { /* one line if it is short */
        char *line = NULL;
        size_t len = 0;
        FILE *m = open_memstream(&line, &len);
        bool ok = m && json_members(m, v, depth, false);
        if (m) fclose(m);
        if (ok && len <= JSON_LINE) fputs(line, f);
        free(line);
        if (!ok) return false;
        if (len <= JSON_LINE) return true;
    }
    return json_members(f, v, depth, true);
}

/* Writes doc to stdout and frees it; 1 when something failed (out of memory). */
int sy_json_print(cJSON *doc)
{
    bool ok = doc && !g_json_failed && json_write(stdout, doc, 0);
    cJSON_Delete(doc);
    if (!ok) {
        sy_log(SY_LOG_ERROR, "sy", NULL, "out of memory while writing JSON");
        return 1;
    }
    fputc('\n', stdout);
    return 0;
}
