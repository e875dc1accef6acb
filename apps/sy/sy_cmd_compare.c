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
    static const struct option lo[] = {{"spp", required_argument, NULL, OPT_SPP},
                                       {"camera", required_argument, NULL, OPT_CAMERA},
                                       {"backends", required_argument, NULL, OPT_BACKENDS}, COMMON_OPTIONS};
    int c, status = 0;
    optind = 0;
    while ((c = sy_cli_next_sized_option("compare", argc, argv, SHORT_OPTIONS("w:h:o:"), lo, 1, &w, &h, &status)) != -1) {
        switch (c) {
        case OPT_STOP: return status;
        case OPT_SPP:
            if (!sy_cli_parse_u32(optarg, 1, 1u << 20, &spp)) return sy_cli_bad_value("--spp", optarg);
            break;
        case 'o': sheet = optarg; break;
        case OPT_CAMERA: camera = optarg; break;
        case OPT_BACKENDS: only = optarg; break;
        }
    }
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
