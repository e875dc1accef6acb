/* sy_cmd_compare.c — `sy compare SCENE`: every picture back-end side by side, a contact sheet and a
 * table (the comparison itself: sy_compare.h). */
#include "sy_commands.h"
#include "sy_cli.h"
#include "sy_compare.h"
#include "sy_load.h"

#include <stdio.h>

/* sy compare SCENE [-w W] [-h H] [--spp N] [-o SHEET.png] [--camera C] [--backends a,b]:
 * every picture back-end side by side (sy_compare.h). */
int sy_cmd_compare(int argc, char **argv)
{
    const char *scene = NULL, *camera = NULL, *sheet = "compare.png", *only = NULL;
    uint32_t w = 200, h = 150, spp = 256;
    const sy_cli_opt opts[] = {SY_CLI_OPT_UINT("spp", OPT_SPP, &spp, 1, 1u << 20), SY_CLI_OPT_TEXT(NULL, 'o', &sheet),
                               SY_CLI_OPT_TEXT("camera", OPT_CAMERA, &camera),
                               SY_CLI_OPT_TEXT("backends", OPT_BACKENDS, &only)};
    sy_cli_parser p = {SY_CLI_ARGS("compare", argc, argv, opts), .w = &w, .h = &h, .min_size = 1};
    if (sy_cli_parse(&p) != -1) return p.status;
    int status;
    if ((status = sy_cli_scene_operand("compare", argc, argv, &scene))) return status;
    if (!sy_cli_ends_with(sheet, ".png")) {
        fprintf(stderr, "sy compare: %s: the contact sheet must end in .png\n", sheet);
        return 2;
    }
    sy_error err = {0};
    loaded ld;
    if (sy_cli_load(scene, camera, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
    if (ld.is_x3d) sy_cli_fit_x3d_cameras(&ld, w, h);
    sy_context_pool *pool = NULL;
    sy_result r = sy_context_pool_create(&pool, &err);
    sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .background = ld.background};
    sy_compare_opts co = {.width = w, .height = h, .spp = spp, .sheet_path = sheet, .title = scene, .only = only};
    sy_compare_row rows[16];
    uint32_t n = 0;
    printf("%s, %ux%u\n", scene, w, h);
    if (r == SY_OK) r = sy_compare_run(ld.scene, &vd, &co, pool, stdout, rows, 16, &n, &err);
    if (r == SY_OK) printf("contact sheet: %s\n", sheet);
    sy_context_pool_destroy(pool);
    sy_cli_loaded_free(&ld);
    return r == SY_OK ? 0 : sy_cli_fail(&err);
}
