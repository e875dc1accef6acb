/* sy_cmd_demo.c — `sy demo [-o DIR]`: the built-in demo scene rendered with every back-end, a PNG and
 * an EXR each. */
#include "sy_commands.h"
#include "sy_cli.h"
#include "sy_load.h"
#include "sy_output.h"

#include "sy_mediators.h"
#include "sy_viewport.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

int sy_cmd_demo(int argc, char **argv)
{
    const char *dir = "out", *filter = "pixel";
    uint32_t w = 800, h = 450;
    const sy_cli_opt opts[] = {SY_CLI_OPT_TEXT(NULL, 'o', &dir), SY_CLI_OPT_TEXT("filter", OPT_FILTER, &filter)};
    sy_cli_parser p = {SY_CLI_ARGS("demo", argc, argv, opts), .w = &w, .h = &h, .min_size = 1};
    if (sy_cli_parse(&p) != -1) return p.status;
    if (optind < argc) return sy_cli_usage_of("demo", "sy demo takes no operand (-o DIR names the folder)");
    if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "sy: error: %s: cannot create directory: %s\n", dir, strerror(errno));
        return 2;
    }
    sy_error err = {0};
    loaded ld;
    if (sy_cli_load("demo", NULL, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
    sy_context_pool *pool = NULL;
    sy_result r = sy_context_pool_create(&pool, &err);
    printf("demo scene: %u nodes, %u meshes, %u materials, %ux%u\n", sy_scene_count(ld.scene, SY_TYPE_NODE),
           sy_scene_count(ld.scene, SY_TYPE_MESH), sy_scene_count(ld.scene, SY_TYPE_MATERIAL), w, h);
    for (uint32_t i = 0; i < sy_mediator_count() && r == SY_OK; ++i) {
        const char *name = sy_mediator_at(i)->name;
        sy_layer img = {0};
        double secs = 0;
        /* a progressive back-end gets 32 samples per pixel and its display filter (pixel filtering,
         * which also withholds fireflies; --filter none shows the raw samples): a clean image in a
         * few seconds */
        bool progressive = (sy_mediator_at(i)->caps & SY_CAP_PROGRESSIVE) != 0;
        if (sy_mediator_at(i)->caps & SY_CAP_ANALYSIS) continue;
        uint32_t spp = progressive ? 32 : 0;
        char params[64];
        snprintf(params, sizeof params, "filter=%s", filter);
        r = sy_cli_render_scene(&ld, name, progressive ? params : NULL, w, h, spp, pool, &img, &secs, &err);
        char png[1024], exr[1024];
        snprintf(png, sizeof png, "%s/demo_%s.png", dir, name);
        snprintf(exr, sizeof exr, "%s/demo_%s.exr", dir, name);
        out_opts oo = {.png = {.tonemap = SY_TONEMAP_DISPLAY}};
        if (r == SY_OK) r = sy_cli_write_image(png, &img, &oo, &err);
        if (r == SY_OK) r = sy_cli_write_image(exr, &img, &oo, &err);
        if (r == SY_OK && spp)
            printf("  %-12s %8.3f s  %s  %s  (%u samples per pixel, filter %s)\n", name, secs, png, exr, spp, filter);
        else if (r == SY_OK) printf("  %-12s %8.3f s  %s  %s\n", name, secs, png, exr);
        sy_layer_destroy(&img);
    }
    sy_context_pool_destroy(pool);
    sy_cli_loaded_free(&ld);
    return r == SY_OK ? 0 : sy_cli_fail(&err);
}
