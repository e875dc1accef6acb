/* test_params.c — typed, validated back-end parameters (core/sy_params.h and
 * sy_mediator_class_check_params): unknown keys name the valid ones, ranges, enums, booleans and
 * malformed values are refused naming key and value, getters return the declared defaults, the
 * listing shows every declaration, and a context is never created with parameters its class did
 * not declare (the class's create is not even called). */
#include "../support/sy_check.h"
#include "sy_mediator.h"

#include <string.h>

static const sy_param_decl decls[] = {
    {"spp", SY_PARAM_INT, 1, 256, "4", NULL, "camera rays per pixel", 0},
    {"max_depth", SY_PARAM_INT, 1, 64, "8", NULL, "longest ray path", 0},
    {"specular", SY_PARAM_FLOAT, 0, 1, "1", NULL, "specular factor", 0},
    {"filter", SY_PARAM_ENUM, 0, 0, "none", "none|pixel|atrous", "display filter", SY_PARAM_LIVE},
    {"indirect", SY_PARAM_BOOL, 0, 0, "1", NULL, "indirect light", 0},
    {"backend", SY_PARAM_STRING, 0, 0, NULL, NULL, "the servers' back-end", 0},
    {"offset", SY_PARAM_FLOAT, 0, 0, "-2.5", NULL, "unbounded", 0},
};
static const sy_param_table table = SY_PARAM_TABLE(decls);

static sy_result check(const char *text, sy_error *e)
{
    sy_params p;
    sy_result r = sy_params_parse(text, &p, e);
    return r != SY_OK ? r : sy_params_check(&table, &p, 0, "back-end 'demo'", NULL, e);
}

static int test_validation(void)
{
    sy_error e = {0};
    CHECK_OK(check("", &e), e);
    CHECK_OK(check("spp=1,max_depth=64,specular=0.5,filter=atrous,indirect=off,backend=x,offset=-1e9", &e), e);
    /* unknown key: named, a near miss suggested, every valid name listed */
    CHECK(check("max_detph=8", &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "unknown parameter 'max_detph' for back-end 'demo'");
    CHECK_SAYS(e, "did you mean 'max_depth'?");
    CHECK_SAYS(e, "valid: spp, max_depth, specular, filter, indirect, backend, offset");
    CHECK(check("zzzzzzzz=1", &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK(strstr(e.message, "did you mean") == NULL);
    /* range, type, enum, bool */
    CHECK(check("max_depth=65", &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "parameter max_depth=65 for back-end 'demo': expected an integer in [1, 64]");
    CHECK(check("max_depth=0", &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK(check("max_depth=3.5", &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "max_depth=3.5");
    CHECK(check("spp=", &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK(check("spp=99999999999999999999999", &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK(check("specular=1.5", &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "expected a number in [0, 1]");
    CHECK(check("specular=nan", &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK(check("specular=abc", &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK(check("filter=bogus", &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "filter=bogus");
    CHECK_SAYS(e, "expected one of none, pixel, atrous (display filter)");
    CHECK(check("filter=pix", &e) == SY_ERR_INVALID_ARGUMENT); /* a prefix is not a value */
    CHECK(check("indirect=2", &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "expected 0 or 1");
    CHECK_OK(check("indirect=true", &e), e);
    CHECK_OK(check("offset=123456789", &e), e); /* both bounds 0: unbounded */
    /* need_flags: only SY_PARAM_LIVE keys may change later */
    sy_params p;
    CHECK_OK(sy_params_parse("filter=pixel", &p, &e), e);
    CHECK_OK(sy_params_check(&table, &p, SY_PARAM_LIVE, "back-end 'demo'", NULL, &e), e);
    CHECK_OK(sy_params_parse("filter=pixel,spp=2", &p, &e), e);
    CHECK(sy_params_check(&table, &p, SY_PARAM_LIVE, "back-end 'demo'", NULL, &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "'spp'");
    CHECK_SAYS(e, "these can change: filter");
    /* undeclared keys collected instead of refused (a class with check_params) */
    sy_params rest;
    CHECK_OK(sy_params_parse("spp=2,foo=1,bar=x", &p, &e), e);
    CHECK_OK(sy_params_check(&table, &p, 0, NULL, &rest, &e), e);
    CHECK(rest.count == 2 && !strcmp(sy_params_get(&rest, "foo"), "1") && !strcmp(sy_params_get(&rest, "bar"), "x"));
    /* declared keys are still checked then */
    CHECK_OK(sy_params_parse("spp=0,foo=1", &p, &e), e);
    CHECK(sy_params_check(&table, &p, 0, NULL, &rest, &e) == SY_ERR_INVALID_ARGUMENT);
    /* a key given twice is refused, named (issue 32: "spp=1,spp=2" was taken as spp=2) */
    CHECK(sy_params_parse("spp=1,filter=pixel,spp=2", &p, &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "parameters: 'spp' is given twice in 'spp=1,filter=pixel,spp=2'");
    CHECK(sy_params_parse("spp=1,spp=1", &p, &e) == SY_ERR_INVALID_ARGUMENT);
    /* an empty table accepts nothing */
    sy_param_table none = {NULL, 0};
    CHECK_OK(sy_params_parse("spp=4", &p, &e), e);
    CHECK(sy_params_check(&none, &p, 0, "back-end 'normals'", NULL, &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "unknown parameter 'spp' for back-end 'normals': it takes no parameters");
    return 0;
}

static int test_getters(void)
{
    sy_error e = {0};
    sy_params p = {0};
    long l = -1;
    double d = -1;
    bool b = false;
    uint32_t k = 99;
    const char *s = "unchanged";
    /* defaults from the table */
    CHECK_OK(sy_param_int(&table, &p, "spp", &l, &e), e);
    CHECK(l == 4);
    CHECK_OK(sy_param_int(&table, NULL, "max_depth", &l, &e), e);
    CHECK(l == 8);
    CHECK_OK(sy_param_float(&table, &p, "specular", &d, &e), e);
    CHECK(d == 1.0);
    CHECK_OK(sy_param_float(&table, &p, "offset", &d, &e), e);
    CHECK(d == -2.5);
    CHECK_OK(sy_param_bool(&table, &p, "indirect", &b, &e), e);
    CHECK(b);
    CHECK_OK(sy_param_enum(&table, &p, "filter", &k, &e), e);
    CHECK(k == 0);
    CHECK_OK(sy_param_string(&table, &p, "backend", &s, &e), e); /* no default: untouched */
    CHECK(!strcmp(s, "unchanged"));
    CHECK_OK(sy_param_string(&table, &p, "filter", &s, &e), e);
    CHECK(!strcmp(s, "none"));
    /* given values */
    CHECK_OK(sy_params_parse("spp=16,specular=0.25,indirect=no,filter=atrous,backend=whitted", &p, &e), e);
    CHECK_OK(sy_param_int(&table, &p, "spp", &l, &e), e);
    CHECK(l == 16);
    CHECK_OK(sy_param_float(&table, &p, "specular", &d, &e), e);
    CHECK(d == 0.25);
    CHECK_OK(sy_param_float(&table, &p, "spp", &d, &e), e); /* an int reads as a float too */
    CHECK(d == 16.0);
    CHECK_OK(sy_param_bool(&table, &p, "indirect", &b, &e), e);
    CHECK(!b);
    CHECK_OK(sy_param_enum(&table, &p, "filter", &k, &e), e);
    CHECK(k == 2);
    CHECK_OK(sy_param_string(&table, &p, "backend", &s, &e), e);
    CHECK(!strcmp(s, "whitted"));
    /* a bad value, an undeclared key, a wrong type */
    CHECK_OK(sy_params_parse("spp=1000", &p, &e), e);
    CHECK(sy_param_int(&table, &p, "spp", &l, &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "spp=1000");
    CHECK(sy_param_int(&table, &p, "nope", &l, &e) == SY_ERR_NOT_FOUND);
    CHECK(sy_param_int(&table, &p, "specular", &l, &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK(sy_param_enum(&table, &p, "spp", &k, &e) == SY_ERR_INVALID_ARGUMENT);
    /* every declared default is valid for its own declaration */
    for (uint32_t i = 0; i < table.count; ++i)
        if (decls[i].default_value) CHECK_OK(sy_param_check_value(&decls[i], decls[i].default_value, NULL, &e), e);
    CHECK(sy_param_enum_index(&decls[3], "pixel") == 1 && sy_param_enum_index(&decls[3], "x") == -1);
    return 0;
}

static int test_listing(void)
{
    size_t n = sy_param_table_format(&table, "  ", NULL, 0);
    CHECK(n > 0);
    char buf[2048];
    CHECK(sy_param_table_format(&table, "  ", buf, sizeof buf) == n && strlen(buf) == n);
    CHECK(strstr(buf, "max_depth") && strstr(buf, "1..64") && strstr(buf, "longest ray path"));
    CHECK(strstr(buf, "none|pixel|atrous") && strstr(buf, "[live]") && strstr(buf, "0|1"));
    /* one header line plus one per declaration, each indented */
    uint32_t lines = 0;
    for (const char *c = buf; *c; ++c) lines += *c == '\n';
    CHECK(lines == table.count + 1);
    CHECK(!strncmp(buf, "  name", 6));
    /* truncation reports the whole length, like snprintf */
    char small[16];
    CHECK(sy_param_table_format(&table, "  ", small, sizeof small) == n && strlen(small) == sizeof small - 1);
    sy_param_table none = {NULL, 0};
    CHECK(sy_param_table_format(&none, "  ", buf, sizeof buf) > 0 && !strcmp(buf, "  (no parameters)\n"));
    return 0;
}

/* A class with the table: create counts its calls and records what it read. */
static int g_creates;
static long g_spp;
static sy_result demo_create(const sy_mediator_create_args *a, void **state, sy_error *err)
{
    g_creates++;
    *state = &g_creates;
    return sy_param_int(&table, a->params, "spp", &g_spp, err);
}
static void demo_destroy(void *s) { (void)s; }
static sy_result demo_sync(void *s, const sy_changes *c, sy_error *e) { return (void)s, (void)c, (void)e, SY_OK; }
static sy_result demo_render(void *s, const sy_render_request *r, sy_layer *l, sy_error *e)
{
    return (void)s, (void)r, (void)l, (void)e, SY_OK;
}
static sy_result demo_set_filter(void *s, const char *n, const sy_params *o, sy_error *e)
{
    return (void)s, (void)n, (void)o, (void)e, SY_OK;
}
static int g_forwarded;
static sy_result demo_forward(const sy_params *all, const sy_params *undeclared, const void *user, sy_error *err)
{
    (void)all, (void)user;
    g_forwarded += (int)undeclared->count;
    return sy_params_get(undeclared, "bad") ? sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "forwarded 'bad' refused")
                                            : SY_OK;
}
static const sy_mediator_class demo_class = {.name = "params_demo", .caps = SY_CAP_FILTERS, .create = demo_create,
                                             .destroy = demo_destroy, .sync = demo_sync, .render = demo_render,
                                             .set_filter = demo_set_filter, .param_table = SY_PARAM_TABLE(decls)};
static const sy_mediator_class fwd_class = {.name = "params_forward", .create = demo_create, .destroy = demo_destroy,
                                            .sync = demo_sync, .render = demo_render,
                                            .param_table = SY_PARAM_TABLE(decls), .check_params = demo_forward};

static int test_contexts(void)
{
    sy_error e = {0};
    sy_scene *scene = NULL;
    CHECK_OK(sy_scene_create(&scene, &e), e);
    CHECK_OK(sy_mediator_register(&demo_class, &e), e);
    CHECK_OK(sy_mediator_register(&fwd_class, &e), e);
    sy_params p;
    sy_context *c = NULL;
    CHECK_OK(sy_params_parse("max_detph=8", &p, &e), e);
    CHECK(sy_context_create(scene, "params_demo", &p, 0, &c, &e) == SY_ERR_INVALID_ARGUMENT && !c);
    CHECK_SAYS(e, "unknown parameter 'max_detph' for back-end 'params_demo'");
    CHECK_SAYS(e, "valid: spp, max_depth");
    CHECK_OK(sy_params_parse("spp=300", &p, &e), e);
    CHECK(sy_context_create(scene, "params_demo", &p, 0, &c, &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "spp=300 for back-end 'params_demo': expected an integer in [1, 256]");
    CHECK(g_creates == 0); /* refused before the class saw them */
    CHECK(sy_mediator_class_check_params(&demo_class, &p, &e) == SY_ERR_INVALID_ARGUMENT);
    /* valid parameters reach create; absent ones read as the declared defaults */
    CHECK_OK(sy_context_create(scene, "params_demo", NULL, 0, &c, &e), e);
    CHECK(g_creates == 1 && g_spp == 4);
    /* filter options: only live keys */
    CHECK_OK(sy_params_parse("filter=pixel", &p, &e), e);
    CHECK_OK(sy_context_set_filter(c, "pixel", &p, &e), e);
    CHECK_OK(sy_params_parse("max_depth=3", &p, &e), e);
    CHECK(sy_context_set_filter(c, "pixel", &p, &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "fixed when the back-end is created");
    CHECK_OK(sy_params_parse("filter=sharpen", &p, &e), e);
    CHECK(sy_context_set_filter(c, "pixel", &p, &e) == SY_ERR_INVALID_ARGUMENT);
    sy_context_release(c);
    /* the pool validates through sy_context_create too */
    sy_context_pool *pool = NULL;
    CHECK_OK(sy_context_pool_create(&pool, &e), e);
    CHECK_OK(sy_params_parse("specular=2", &p, &e), e);
    CHECK(sy_context_pool_get(pool, scene, "params_demo", &p, 0, &c, &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK(sy_context_pool_size(pool) == 0);
    sy_context_pool_destroy(pool);
    /* a class with check_params sees the undeclared keys only, and may refuse them */
    CHECK_OK(sy_params_parse("spp=2,foo=1,bar=2", &p, &e), e);
    CHECK_OK(sy_context_create(scene, "params_forward", &p, 0, &c, &e), e);
    CHECK(g_forwarded == 2 && g_spp == 2);
    sy_context_release(c);
    CHECK_OK(sy_params_parse("bad=1", &p, &e), e);
    CHECK(sy_context_create(scene, "params_forward", &p, 0, &c, &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "forwarded 'bad' refused");
    CHECK_OK(sy_params_parse("spp=0,bad=1", &p, &e), e); /* declared keys first */
    CHECK(sy_context_create(scene, "params_forward", &p, 0, &c, &e) == SY_ERR_INVALID_ARGUMENT);
    CHECK_SAYS(e, "spp=0");
    /* the class's listing */
    char buf[2048];
    CHECK(sy_mediator_class_format_params(&demo_class, "", buf, sizeof buf) > 0 && strstr(buf, "max_depth"));
    sy_scene_destroy(scene);
    return 0;
}

SY_CHECK_MAIN("core_params", SY_TEST(test_validation), SY_TEST(test_getters), SY_TEST(test_listing),
              SY_TEST(test_contexts))
