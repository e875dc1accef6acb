/* sy_assimp.c — the formats read through Assimp (see sy_assimp.h), the load in one process: the
 * options, the import under the process-wide lock (Assimp's C API keeps its error string and
 * logger in globals), then the conversion in dependency order with rollback on failure; also
 * Assimp's reference import and export for benchmarks and tests. The loader's modules, bottom-up
 * (sy_assimp_internal.h): sy_assimp_io.c, sy_assimp_materials.c, sy_assimp_scene.c, this file,
 * sy_assimp_isolate.c (the public loads, in the import process). */
#include "sy_assimp_internal.h"

#include "sy_file.h"
#include "sy_log.h"
#include "sy_sniff.h"

#include <assimp/cimport.h>
#include <assimp/cexport.h>
#include <assimp/config.h>
#include <assimp/postprocess.h>

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* Assimp's C API is not reentrant (aiGetErrorString, the default logger): one import at a time. */
static pthread_mutex_t g_assimp_lock = PTHREAD_MUTEX_INITIALIZER;

/* The post-processing every file gets (sy_assimp.h). */
#define SY_ASSIMP_STEPS                                                                                              \
    (aiProcess_Triangulate | aiProcess_GenSmoothNormals | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType |  \
     aiProcess_FindInvalidData | aiProcess_TransformUVCoords | aiProcess_FlipUVs | aiProcess_ValidateDataStructure |      \
     aiProcess_SplitLargeMeshes)
/* SplitLargeMeshes (meshes of more than 10^6 triangles or vertices split, as `assimp info`'s preset
 * does) runs before JoinIdenticalVertices, whose working set on one mesh of a 10^6-triangle OBJ
 * (3 x 10^6 corner vertices) made Assimp's peak 643 MB against 429 MB split. */
/* FindDegenerates (degenerate triangles and segments removed) runs as a second pass over the
 * imported scene: in the same pass as Triangulate and SortByPType it crashes Assimp 5.2 (a bus
 * error on a wild pointer) on a PLY with a short vertex line (found by fuzz_assimp_ply). */

void sy_assimp_info_free(sy_assimp_info *info)
{
    if (!info) return;
    free(info->camera_nodes);
    sy_loader_warnings_free(asp_warnings(info));
    memset(info, 0, sizeof *info);
}

bool sy_assimp_reads_extension(const char *ext)
{
    if (!ext || !*ext) return false;
    char e[32];
    snprintf(e, sizeof e, "%s%s", ext[0] == '.' ? "" : ".", ext);
    return aiIsExtensionSupported(e) == AI_TRUE;
}

sy_assimp_options asp_resolve_options(const sy_assimp_options *o)
{
    sy_assimp_options r = o ? *o : (sy_assimp_options){0};
    if (!r.max_file_bytes) r.max_file_bytes = (size_t)1 << 30;
    if (!r.max_vertices) r.max_vertices = (size_t)1 << 28;
    if (!r.max_image_pixels) r.max_image_pixels = (uint64_t)1 << 26;
    if (!r.max_scene_bytes) r.max_scene_bytes = sy_budget_default_bytes();
    return r;
}

/* The extension Assimp should read content of this kind by ("" when the content does not say). */
static const char *extension_for(const void *data, size_t size)
{
    switch (sy_sniff_bytes(data, size)) {
    case SY_FORMAT_OBJ: return ".obj";
    case SY_FORMAT_PLY: return ".ply";
    case SY_FORMAT_STL: return ".stl";
    case SY_FORMAT_FBX: return ".fbx";
    case SY_FORMAT_COLLADA: return ".dae";
    case SY_FORMAT_3MF: return ".3mf";
    case SY_FORMAT_3DS: return ".3ds";
    case SY_FORMAT_GLTF1: return size >= 4 && !memcmp(data, "glTF", 4) ? ".glb" : ".gltf";
    default: return "";
    }
}

/* The name Assimp opens the model by: the model's folder and file name, with the extension its
 * content calls for appended where the name says otherwise (Assimp picks importers by extension). */
static sy_result main_name(asp_loader *L, const char *name)
{
    const char *slash = strrchr(name, '/');
    const char *base = slash ? slash + 1 : name;
    const char *ext = extension_for(L->main_data, L->main_size);
    size_t bl = strlen(base), el = strlen(ext);
    bool has = el && bl > el && !strcasecmp(base + bl - el, ext);
    if (!strcmp(ext, ".3ds") && bl > 4 && !strcasecmp(base + bl - 4, ".prj")) has = true;
    size_t n = strlen(L->model_dir) + bl + el + 1;
    if (!(L->main_name = malloc(n))) return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "out of memory");
    snprintf(L->main_name, n, "%s%s%s", L->model_dir, base, has ? "" : ext);
    n = strlen(L->main_name);
    L->obj = n > 4 && !strcasecmp(L->main_name + n - 4, ".obj");
    return SY_OK;
}

static const char *meta_string(const struct aiMetadata *md, const char *key)
{
    if (!md) return NULL;
    for (unsigned k = 0; k < md->mNumProperties; ++k)
        if (!strcmp(asp_str(&md->mKeys[k]), key) && md->mValues[k].mType == AI_AISTRING && md->mValues[k].mData)
            return asp_str((const struct aiString *)md->mValues[k].mData);
    return NULL;
}

/* false (the mesh in *bad) when a face of the scene has no vertex index. */
static bool faces_have_indices(const struct aiScene *s, unsigned *bad)
{
    for (unsigned i = 0; i < s->mNumMeshes; ++i)
        for (unsigned f = 0; f < s->mMeshes[i]->mNumFaces; ++f)
            if (s->mMeshes[i]->mFaces[f].mNumIndices == 0 || !s->mMeshes[i]->mFaces[f].mIndices) return *bad = i, false;
    return true;
}

/* Assimp reads the model (under the lock); L->ai on success, Assimp's reason on failure. */
static sy_result import(asp_loader *L)
{
    struct aiFileIO io = asp_file_io(L);
    struct aiPropertyStore *ps = aiCreatePropertyStore();
    if (!ps) return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "out of memory");
    aiSetImportPropertyFloat(ps, AI_CONFIG_PP_GSN_MAX_SMOOTHING_ANGLE, 80.0f);
    aiSetImportPropertyInteger(ps, AI_CONFIG_PP_FD_REMOVE, 1);
    /* only faces that repeat a vertex are degenerate: Assimp 5.2 also takes every triangle of area
     * under 1e-6 (in file units) for one unless told not to, which lost 1.1 % of a unit-sized
     * 10^6-triangle grid */
    aiSetImportPropertyInteger(ps, AI_CONFIG_PP_FD_CHECKAREA, 0);
    aiSetImportPropertyInteger(ps, AI_CONFIG_IMPORT_NO_SKELETON_MESHES, 1);
    bool lock = !L->notes; /* the import process has no other thread (and the lock may be a copy held at the fork) */
    if (lock) pthread_mutex_lock(&g_assimp_lock);
    asp_log_attach(L);
    /* Triangulate and SortByPType trust each face to have indices (Triangulate fails an assertion and
     * aborts the process on a PLY face list of count 0, which ValidateDataStructure lets through): they
     * run as a second pass once every face is checked; FindDegenerates as a third (see above) */
    const unsigned later = aiProcess_Triangulate | aiProcess_SortByPType;
    L->ai = aiImportFileExWithProperties(L->main_name, SY_ASSIMP_STEPS & ~later, &io, ps);
    unsigned empty_mesh = 0;
    bool empty = L->ai && !faces_have_indices(L->ai, &empty_mesh);
    if (L->ai && !empty) L->ai = aiApplyPostProcessing(L->ai, later); /* NULL: Assimp released it */
    if (L->ai && !empty) L->ai = aiApplyPostProcessing(L->ai, aiProcess_FindDegenerates);
    char why[SY_ERROR_MESSAGE_MAX];
    snprintf(why, sizeof why, "%s", L->ai ? "" : aiGetErrorString());
    asp_log_detach();
    if (lock) pthread_mutex_unlock(&g_assimp_lock);
    aiReleasePropertyStore(ps);
    if (L->io_result) return sy_error_set(&L->err, L->io_result, "%s", L->io_message); /* a refused file */
    if (empty) return asp_fail(L, SY_ERR_PARSE, "meshes[%u] has a face without vertex indices", empty_mesh);
    if (!L->ai) return asp_fail(L, SY_ERR_PARSE, "Assimp cannot read it: %s", why[0] ? why : "no reason given");
    if (!L->ai->mRootNode) return asp_fail(L, SY_ERR_PARSE, "Assimp read no scene (no root node)");
    if (L->ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE) /* no meshes (cameras, lights or animations only): loaded as it is */
        asp_warn(L, "Assimp marks the scene incomplete (%u meshes)", L->ai->mNumMeshes);
    const char *fmt = meta_string(L->ai->mMetaData, "SourceAsset_Format");
    snprintf(L->info->format, sizeof L->info->format, "%s", fmt ? fmt : "Assimp");
    return SY_OK;
}

static sy_result convert(asp_loader *L)
{
    const struct aiScene *s = L->ai;
    sy_assimp_counts *c = &L->info->counts;
    sy_result r = SY_OK;
    c->animations = s->mNumAnimations;
    c->embedded_textures = s->mNumTextures;
    if (!(L->materials = calloc((size_t)s->mNumMaterials + 1, sizeof *L->materials)) ||
        !(L->normal_mapped = calloc((size_t)s->mNumMaterials + 1, sizeof *L->normal_mapped)) ||
        !(L->meshes = calloc((size_t)s->mNumMeshes + 1, sizeof *L->meshes)) ||
        !(L->mesh_bounds = calloc((size_t)s->mNumMeshes + 1, sizeof *L->mesh_bounds)) ||
        !(L->mesh_skinned = calloc((size_t)s->mNumMeshes + 1, sizeof *L->mesh_skinned)) ||
        !(L->mesh_targets = calloc((size_t)s->mNumMeshes + 1, sizeof *L->mesh_targets)))
        return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "out of memory for %u meshes and %u materials", s->mNumMeshes, s->mNumMaterials);
    /* dependency order: textures (on demand) + materials, meshes, then nodes, cameras, lights */
    for (unsigned i = 0; i < s->mNumMaterials && r == SY_OK; ++i) r = asp_create_material(L, i);
    if (r == SY_OK) r = asp_charge(L);
    for (unsigned i = 0; i < s->mNumMeshes && r == SY_OK; ++i) r = asp_create_mesh(L, i);
    if (r == SY_OK) r = asp_create_nodes(L);
    /* then what needs the nodes by name: skins (joints), clips (channel targets) */
    if (r == SY_OK) r = asp_create_skins(L);
    if (r == SY_OK) r = asp_create_animations(L);
    return r;
}

sy_result asp_load_here(const char *path, const void *mem, size_t mem_size, const char *base_dir, sy_scene *scene,
                        const sy_assimp_options *opts, sy_assimp_info *info_out, asp_notes *notes, sy_error *err)
{
    sy_assimp_info local;
    sy_assimp_info *info = info_out ? info_out : &local;
    memset(info, 0, sizeof *info);
    asp_loader L;
    memset(&L, 0, sizeof L);
    L.path = path;
    L.scene = scene;
    L.opt = asp_resolve_options(opts);
    L.info = info;
    L.notes = notes;
    L.budget = sy_budget_make(path, L.opt.max_scene_bytes);
    info->unit_scale = 1.0f;
    info->up_axis = -1;
    void *bytes = NULL;
    sy_result r = SY_OK;
    /* the model's folder, '/'-terminated ("" = the working directory) */
    const char *slash = strrchr(path, '/');
    size_t dl = mem ? strlen(base_dir) : slash ? (size_t)(slash - path) + 1 : 0;
    bool add_slash = mem && dl && base_dir[dl - 1] != '/';
    if (!(L.model_dir = malloc(dl + 2))) {
        r = asp_fail(&L, SY_ERR_OUT_OF_MEMORY, "out of memory");
        goto out;
    }
    memcpy(L.model_dir, mem ? base_dir : path, dl);
    strcpy(L.model_dir + dl, add_slash ? "/" : "");
    const void *input = NULL;
    if ((r = sy_loader_input(path, mem, mem_size, L.opt.max_file_bytes, &bytes, &input, &L.main_size, &L.err))) goto out;
    L.main_data = input;
    if (L.main_size == 0) {
        r = asp_fail(&L, SY_ERR_PARSE, "empty file");
        goto out;
    }
    if ((r = asp_precheck(&L)) || (r = main_name(&L, path)) || (r = import(&L))) goto out;
    free(bytes); /* Assimp's scene holds what it read */
    bytes = NULL;
    if ((r = convert(&L))) asp_rollback(&L);
out:
    if (L.ai) aiReleaseImport(L.ai);
    asp_free_textures(&L);
    free(L.materials);
    free(L.normal_mapped);
    free(L.meshes);
    free(L.mesh_bounds);
    free(L.mesh_skinned);
    free(L.mesh_targets);
    free(L.named);
    free(L.placements);
    free(L.objs);
    free(L.main_name);
    for (size_t k = 0; k < L.mtl_dir_count; ++k) free(L.mtl_dirs[k]);
    free(L.model_dir);
    free(bytes);
    if (r) {
        sy_assimp_info_free(info);
        if (err) *err = L.err;
        return r;
    }
    if (!notes) sy_loader_warnings_log(asp_warnings(info), "assimp", path, path);
    if (!info_out) sy_assimp_info_free(&local);
    return SY_OK;
}

/* >>reference (sy bench load) ------------------------------------------------------------------ */

sy_result sy_assimp_reference_import(const char *path, sy_assimp_counts *counts_out, sy_error *err)
{
    if (counts_out) memset(counts_out, 0, sizeof *counts_out);
    if (!path) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_assimp_reference_import: path is required");
    pthread_mutex_lock(&g_assimp_lock);
    const struct aiScene *s = aiImportFile(path, aiProcessPreset_TargetRealtime_MaxQuality);
    char why[SY_ERROR_MESSAGE_MAX];
    snprintf(why, sizeof why, "%s", s ? "" : aiGetErrorString());
    pthread_mutex_unlock(&g_assimp_lock);
    if (!s) return sy_error_set(err, SY_ERR_PARSE, "%s: Assimp cannot read it: %s", path, why);
    if (counts_out) {
        counts_out->meshes = s->mNumMeshes;
        counts_out->materials = s->mNumMaterials;
        counts_out->embedded_textures = s->mNumTextures;
        for (unsigned i = 0; i < s->mNumMeshes; ++i)
            for (unsigned f = 0; f < s->mMeshes[i]->mNumFaces; ++f) counts_out->triangles += s->mMeshes[i]->mFaces[f].mNumIndices == 3;
    }
    aiReleaseImport(s);
    return SY_OK;
}

sy_result sy_assimp_export(const char *in, const char *format_id, const char *out, sy_error *err)
{
    if (!in || !format_id || !out)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_assimp_export: in, format_id and out are required");
    bool known = false;
    for (size_t k = 0, n = aiGetExportFormatCount(); k < n && !known; ++k) {
        const struct aiExportFormatDesc *d = aiGetExportFormatDescription(k);
        known = d && d->id && !strcmp(d->id, format_id);
        aiReleaseExportFormatDescription(d);
    }
    if (!known) return sy_error_set(err, SY_ERR_UNSUPPORTED, "%s: Assimp has no exporter '%s'", out, format_id);
    pthread_mutex_lock(&g_assimp_lock);
    const struct aiScene *s = aiImportFile(in, aiProcess_Triangulate);
    char why[SY_ERROR_MESSAGE_MAX] = "";
    sy_result r = SY_OK;
    if (!s) {
        snprintf(why, sizeof why, "%s", aiGetErrorString());
        r = SY_ERR_PARSE;
    } else if (aiExportScene(s, format_id, out, 0) != aiReturn_SUCCESS) { /* the C API keeps no reason */
        r = SY_ERR_IO;
    }
    if (s) aiReleaseImport(s);
    pthread_mutex_unlock(&g_assimp_lock);
    if (r == SY_ERR_PARSE) return sy_error_set(err, r, "%s: Assimp cannot read it: %s", in, why);
    if (r) return sy_error_set(err, r, "%s: Assimp's '%s' exporter failed (it gives no reason through its C API)", out, format_id);
    return SY_OK;
}
