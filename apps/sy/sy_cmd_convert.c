/* sy_cmd_convert.c — `sy convert SCENE -o OUT.glb|OUT.gltf`: any scene sy reads (glTF, X3D, the
 * Assimp formats, demo) written as glTF 2.0 (formats/sy_gltf_write.h: hierarchy, meshes, materials
 * with their extensions, PNG textures, cameras, lights). What glTF cannot hold is logged as a
 * warning naming the item. The file is written under a temporary name and renamed. */
#include "sy_commands.h"
#include "sy_cli.h"
#include "sy_load.h"

#include "sy_file.h"
#include "sy_gltf_write.h"
#include "sy_log.h"

#include <stdio.h>

int sy_cmd_convert(int argc, char **argv)
{
    const char *scene = NULL, *outp = NULL;
    const sy_cli_opt opts[] = {SY_CLI_OPT_TEXT(NULL, 'o', &outp)};
    sy_cli_parser p = {SY_CLI_ARGS("convert", argc, argv, opts)};
    if (sy_cli_parse(&p) != -1) return p.status;
    int status;
    if ((status = sy_cli_scene_operand("convert", argc, argv, &scene))) return status;
    if (!outp) return sy_cli_usage_of("convert", "-o OUT.glb or OUT.gltf is required");
    sy_error err = {0};
    if (!sy_cli_ends_with(outp, ".glb") && !sy_cli_ends_with(outp, ".gltf")) {
        sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "%s: output must end in .glb or .gltf", outp);
        return sy_cli_fail(&err);
    }
    /* the output's folder must take a file before anything is loaded (as sy render) */
    sy_atomic_file probe = {0};
    if (sy_atomic_file_begin(outp, &probe, &err) != SY_OK) return sy_cli_fail(&err);
    sy_atomic_file_abort(&probe);
    loaded ld;
    if (sy_cli_load(scene, NULL, false, &ld, &err) != SY_OK) return sy_cli_fail(&err);
    sy_gltf_write_options wo = {.generator = "Switchyard sy convert"};
    sy_result r = sy_gltf_write_scene_file(ld.scene, ld.root, &wo, outp, &err);
    sy_cli_loaded_free(&ld);
    if (r != SY_OK) return sy_cli_fail(&err);
    sy_log(SY_LOG_NOTE, "sy", NULL, "%s: written", outp);
    return 0;
}
