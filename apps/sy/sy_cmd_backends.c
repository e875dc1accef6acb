/* sy_cmd_backends.c — `sy backends [--params] [--json]`: the registered back-ends, their capabilities
 * and parameters. */
#include "sy_commands.h"
#include "sy_cli.h"
#include "sy_json.h"

#include "sy_mediators.h"
#include "sy_viewport.h"

#include <stdio.h>
#include <stdlib.h>

/* --params --json: a class's declared parameters (sy_params.h) */
static void jparams(cJSON *o, const sy_mediator_class *m)
{
    cJSON *a = sy_json_add(o, "params", cJSON_CreateArray());
    for (uint32_t i = 0; a && i < m->param_table.count; ++i) {
        const sy_param_decl *d = &m->param_table.decls[i];
        cJSON *p = sy_json_add(a, NULL, cJSON_CreateObject());
        if (!p) return;
        sy_json_add(p, "name", sy_json_str(d->name));
        sy_json_add(p, "type", sy_json_str(sy_param_type_name(d->type)));
        if (d->min != 0.0 || d->max != 0.0) sy_json_add(p, "min", cJSON_CreateNumber(d->min)), sy_json_add(p, "max", cJSON_CreateNumber(d->max));
        if (d->enum_values) sy_json_add(p, "values", sy_json_str(d->enum_values));
        sy_json_add(p, "default", d->default_value ? sy_json_str(d->default_value) : cJSON_CreateNull());
        sy_json_add(p, "help", sy_json_str(d->help));
    }
}

/* sy backends [--params] [--json]: one line per registered back-end, its name and capability words;
 * --params: then its parameter table (sy_mediator_class_format_params) (--json: an array of
 * {"name", "caps"[, "params"]}). */
int sy_cmd_backends(int argc, char **argv)
{
    bool json = false, params = false;
    const sy_cli_opt opts[] = {SY_CLI_OPT_FLAG("json", OPT_JSON, &json), SY_CLI_OPT_FLAG("params", OPT_PARAMS, &params)};
    sy_cli_parser p = {SY_CLI_ARGS("backends", argc, argv, opts)};
    if (sy_cli_parse(&p) != -1) return p.status;
    if (optind < argc) return sy_cli_usage_of("backends", "sy backends takes no operand");
    static const struct { uint32_t bit; const char *word; } caps[] = {
        {SY_CAP_DEPTH, "depth"}, {SY_CAP_PROGRESSIVE, "progressive"}, {SY_CAP_TILES, "tiles"},
        {SY_CAP_SAMPLE_RANGES, "sample-ranges"}, {SY_CAP_AOVS, "aovs"}, {SY_CAP_FILTERS, "filters"},
        {SY_CAP_ANALYSIS, "analysis"}, {SY_CAP_REMOTE, "remote"}, {SY_CAP_PREVIEW, "preview"},
        {SY_CAP_COVERAGE, "coverage"}, {SY_CAP_PICK, "pick"}, {SY_CAP_CLIP, "clip"}, {SY_CAP_MOTION, "motion"}};
    cJSON *doc = json ? cJSON_CreateArray() : NULL;
    for (uint32_t i = 0; i < sy_mediator_count(); ++i) {
        const sy_mediator_class *m = sy_mediator_at(i);
        cJSON *o = json ? sy_json_add(doc, NULL, cJSON_CreateObject()) : NULL, *cj = NULL;
        if (json) {
            sy_json_add(o, "name", sy_json_str(m->name));
            cj = sy_json_add(o, "caps", cJSON_CreateArray());
        } else {
            printf("%s", m->name);
        }
        for (size_t k = 0; k < sizeof caps / sizeof caps[0]; ++k) {
            if (!(m->caps & caps[k].bit)) continue;
            if (json) sy_json_add(cj, NULL, sy_json_str(caps[k].word));
            else printf(" %s", caps[k].word);
        }
        bool is_default = m == sy_mediator_default(); /* what sy render, view and web use without -b */
        if (json) sy_json_add(o, "default", cJSON_CreateBool(is_default));
        else printf(is_default ? "  (default)\n" : "\n");
        size_t n = params && !json ? sy_mediator_class_format_params(m, "  ", NULL, 0) : 0;
        char *t = n ? malloc(n + 1) : NULL; /* --params: the class's table, from the library */
        if (t) sy_mediator_class_format_params(m, "  ", t, n + 1), fputs(t, stdout), free(t);
        if (params && json) jparams(o, m);
    }
    return json ? sy_json_print(doc) : 0;
}
