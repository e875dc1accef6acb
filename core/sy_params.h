/** @file
 * sy_params.h — back-end parameters: the "k=v,k=v" list a viewport or context gives its back-end
 * (sy_params), and the typed declaration table every mediator class publishes for it
 * (sy_param_decl: name, type, range or values, default, one-line help).
 *
 * The table is the single source of a back-end's parameter names, ranges, defaults and help:
 *   - core validates given parameters against it (sy_params_check; sy_mediator_class_check_params
 *     runs it before a class's create and wherever parameters change later): an unknown name is an
 *     error that lists the valid ones, a malformed value, one outside [min, max] or not among the
 *     enum's values is an error naming the key, the value and what is allowed;
 *   - mediators read values through it (sy_param_int, sy_param_float, ...: the given value, else the
 *     declared default), never with their own parsing;
 *   - `sy backends --params` and embedders list it (sy_param_table_format).
 *
 * Ownership: sy_params is a plain value (fixed-size, copy it freely). Declaration tables are static
 * storage of their mediator; strings returned by the getters are borrowed from the sy_params or the
 * table. Thread-safety: everything here is pure or works on caller-owned memory. */
#ifndef SY_PARAMS_H
#define SY_PARAMS_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- parameter lists: "key=value" pairs given to a back-end ---- */
#define SY_PARAMS_MAX 16 /**< most pairs in a sy_params */
/** A parameter list: up to SY_PARAMS_MAX "key=value" pairs (copied text). */
typedef struct sy_params {
    uint32_t count; /**< pairs used */
    struct {
        char key[32];
        char value[96];
    } items[SY_PARAMS_MAX]; /**< the pairs */
} sy_params;

/** Parses "k=v,k=v" (NULL or "" = empty). Errors name the offending item; a key given twice
 * ("spp=1,spp=2") is an error naming the key (SY_ERR_INVALID_ARGUMENT). */
sy_result sy_params_parse(const char *text, sy_params *out, sy_error *err);
/** Sets key to value (replacing an existing value); fails on a bad key, a value too long or a full list. */
sy_result sy_params_set(sy_params *p, const char *key, const char *value, sy_error *err);
const char *sy_params_get(const sy_params *p, const char *key); /**< NULL when absent (or p NULL) */
/** Untyped getters for parameters outside any table (application options): default when absent;
 * SY_ERR_INVALID_ARGUMENT naming the key when malformed or outside [min, max]. Mediators use the
 * table getters below instead. */
sy_result sy_params_get_int(const sy_params *p, const char *key, long def, long min, long max, long *out,
                            sy_error *err);
/** As sy_params_get_int, for a finite number. */
sy_result sy_params_get_float(const sy_params *p, const char *key, double def, double min, double max,
                              double *out, sy_error *err);
/** true when both lists hold the same pairs. */
bool sy_params_equal(const sy_params *a, const sy_params *b);

/* ---- declarations ---- */
/** Value types of a declared parameter. */
typedef enum sy_param_type {
    SY_PARAM_BOOL,   /**< 0|1 (also false|true, no|yes, off|on) */
    SY_PARAM_INT,    /**< decimal integer in [min, max] */
    SY_PARAM_FLOAT,  /**< finite number in [min, max] */
    SY_PARAM_ENUM,   /**< one of enum_values ("a|b|c") */
    SY_PARAM_STRING, /**< any text (the mediator checks what it means) */
} sy_param_type;

/** sy_param_decl.flags */
enum {
    SY_PARAM_LIVE = 1u << 0, /**< may change after creation: a display-filter option (sy_context_set_filter) */
};

/** One declared parameter of a class: name, type, range or values, default, help. */
typedef struct sy_param_decl {
    const char *name;          /**< key, [a-z0-9_-], shorter than sy_params' 32-byte keys */
    sy_param_type type; /**< the value's type */
    /** @{ INT, FLOAT: inclusive range; both 0 = unbounded */
    double min, max; /** @} */
    const char *default_value; /**< as it would be given ("8", "0.01", "osmesa"); NULL = none: absent keys
                                  leave the getter's *out as the caller set it (e.g. a required key) */
    const char *enum_values;   /**< ENUM: the values joined by '|' */
    const char *help;          /**< one line */
    uint32_t flags;            /**< SY_PARAM_LIVE, ... */
} sy_param_decl;

/** A class's table: count declarations at decls (count 0: it accepts no parameter). */
typedef struct sy_param_table {
    const sy_param_decl *decls; /**< the declarations */
    uint32_t count; /**< number of declarations */
} sy_param_table;
/** Initialiser for a table from a static array: .param_table = SY_PARAM_TABLE(my_decls). */
#define SY_PARAM_TABLE(array) {(array), (uint32_t)(sizeof(array) / sizeof((array)[0]))}

const sy_param_decl *sy_param_find(const sy_param_table *t, const char *name); /**< NULL when undeclared */
const char *sy_param_type_name(sy_param_type type); /**< "bool", "int", "float", "enum", "string" */
/** Index of value among an ENUM's values, -1 when it is not one. */
int sy_param_enum_index(const sy_param_decl *d, const char *value);

/** Checks one value against its declaration; the error names the key, the value and what is allowed,
 * then the help ("parameter max_depth=99 for back-end 'whitted': expected an integer in [1, 64]
 * (longest ray path ...)"). owner (may be NULL) names what the parameter belongs to:
 * "back-end 'whitted'". */
sy_result sy_param_check_value(const sy_param_decl *d, const char *value, const char *owner, sy_error *err);

/** Checks every key of p against t: a declared key's value with sy_param_check_value; a declared key
 * whose flags lack need_flags is an error that lists the keys that have them; an undeclared key is
 * an error naming it and listing the valid names ("unknown parameter 'max_detph' for back-end
 * 'whitted' (did you mean 'max_depth'?); valid: spp, max_depth, ...") unless undeclared is not
 * NULL: it then receives the undeclared pairs (cleared first) for the caller to check. */
sy_result sy_params_check(const sy_param_table *t, const sy_params *p, uint32_t need_flags, const char *owner,
                          sy_params *undeclared, sy_error *err);

/* ---- typed getters through a table: the value given in p (NULL = none given), else the declared
 * default; an undeclared key is SY_ERR_NOT_FOUND (a mistake in the mediator), a value that does not
 * fit its declaration SY_ERR_INVALID_ARGUMENT as sy_param_check_value. When neither a value nor a
 * default exists, *out is left as it was. A key of another type than the getter's is
 * SY_ERR_INVALID_ARGUMENT (BOOL reads also as INT 0/1; INT also as FLOAT). ---- */
/** BOOL (see above). */
sy_result sy_param_bool(const sy_param_table *t, const sy_params *p, const char *key, bool *out, sy_error *err);
/** INT (see above). */
sy_result sy_param_int(const sy_param_table *t, const sy_params *p, const char *key, long *out, sy_error *err);
/** FLOAT (see above). */
sy_result sy_param_float(const sy_param_table *t, const sy_params *p, const char *key, double *out, sy_error *err);
/** ENUM: the index of the value among enum_values. */
sy_result sy_param_enum(const sy_param_table *t, const sy_params *p, const char *key, uint32_t *out, sy_error *err);
/** Any type, as text: the given value or the default (borrowed). */
sy_result sy_param_string(const sy_param_table *t, const sy_params *p, const char *key, const char **out,
                          sy_error *err);

/** Writes a header line and one line per declaration, each starting with indent (NULL = ""), in
 * aligned columns name, type, range (or enum values, "0|1", "text"), default ("-": none), help
 * ("[live]" appended for SY_PARAM_LIVE):
 *   "  max_depth      int    1..64     8        longest ray path: ..."
 * (an empty table: indent + "(no parameters)"). Returns the length of the whole text, like
 * snprintf: call with (NULL, 0) to size a buffer; the text is cut to len - 1 characters. */
size_t sy_param_table_format(const sy_param_table *t, const char *indent, char *buf, size_t len);

#ifdef __cplusplus
}
#endif
#endif /* SY_PARAMS_H */
