/* sy_json.h — the JSON that sy prints (sy info, sy coverage, sy backends --json; sy_json.c): built
 * with cJSON and written in sy's layout (for people and grep: the top level's members one per
 * line, a short nested value on one line). Thread-safety: the main thread only. */
#ifndef SY_JSON_H
#define SY_JSON_H

#include <cJSON.h>

/* Adds item to an object (key) or an array (key NULL) and returns it; a failed allocation (item
 * NULL, or parent NULL) is remembered and reported by sy_json_print. */
cJSON *sy_json_add(cJSON *parent, const char *key, cJSON *item);
/* a float as its shortest decimal that reads back as the same float (not the double's 17 digits) */
cJSON *sy_json_float(double v);
/* a string; NULL as "" */
cJSON *sy_json_str(const char *s);
/* Writes doc to stdout and frees it; returns the exit status: 1 when something failed (out of
 * memory, named on stderr), else 0. */
int sy_json_print(cJSON *doc);

#endif /* SY_JSON_H */
