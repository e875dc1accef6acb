/* test_assimp_corpus.c — the Assimp loader against Assimp itself over Assimp's own test models
 * (Debian assimp-testmodels, /usr/share/assimp/models, read in place): for every file of the OBJ,
 * STL, PLY, FBX, Collada, 3MF, 3DS and glTF (1.0) folders that Assimp's C API reads with the same
 * post-processing, sy_assimp_load must load it with the same number of drawable meshes (triangle,
 * line and point meshes) and the same number of triangles; files Assimp refuses must be refused
 * too. Prints a table per format (files, loaded, refused, mismatches). Exits 77 when the folder is
 * absent. */
#include "sy_assimp.h"
#include "sy_scene.h"

#include "../support/sy_check.h"

#include <assimp/cimport.h>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

/* what Assimp itself reports, with the loader's steps */
static bool assimp_counts(const char *path, unsigned *meshes, unsigned long *tris)
{
    struct aiPropertyStore *ps = aiCreatePropertyStore();
    aiSetImportPropertyInteger(ps, AI_CONFIG_PP_FD_REMOVE, 1);
    aiSetImportPropertyInteger(ps, AI_CONFIG_PP_FD_CHECKAREA, 0); /* as the loader: small triangles are kept */
    aiSetImportPropertyInteger(ps, AI_CONFIG_IMPORT_NO_SKELETON_MESHES, 1);
    const struct aiScene *s = aiImportFileExWithProperties(
        path, aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_FindDegenerates | aiProcess_JoinIdenticalVertices |
                  aiProcess_GenSmoothNormals | aiProcess_FindInvalidData | aiProcess_ValidateDataStructure |
                  aiProcess_SplitLargeMeshes,
        NULL, ps);
    aiReleasePropertyStore(ps);
    if (!s || !s->mRootNode) {
        if (s) aiReleaseImport(s);
        return false;
    }
    *meshes = 0;
    *tris = 0;
    for (unsigned i = 0; i < s->mNumMeshes; ++i) {
        const struct aiMesh *m = s->mMeshes[i];
        unsigned t = m->mPrimitiveTypes & ~(unsigned)aiPrimitiveType_NGONEncodingFlag;
        if (t != aiPrimitiveType_TRIANGLE && t != aiPrimitiveType_LINE && t != aiPrimitiveType_POINT) continue;
        if (!m->mNumVertices || !m->mNumFaces) continue;
        (*meshes)++;
        if (t == aiPrimitiveType_TRIANGLE) *tris += m->mNumFaces;
    }
    aiReleaseImport(s);
    return true;
}

int main(int argc, char **argv)
{
    const char *root = argc > 1 ? argv[1] : "/usr/share/assimp/models";
    struct stat st;
    if (stat(root, &st) != 0 || !S_ISDIR(st.st_mode)) {
        printf("SKIP: %s is absent (Debian package assimp-testmodels)\n", root);
        return 77;
    }
    static const char *const formats[] = {"OBJ", "STL", "PLY", "FBX", "Collada", "3MF", "3DS", "glTF"};
    unsigned total_loaded = 0;
    printf("%-8s %6s %7s %8s %10s\n", "format", "files", "loaded", "refused", "mismatches");
    for (size_t f = 0; f < sizeof formats / sizeof formats[0]; ++f) {
        char dir[512];
        snprintf(dir, sizeof dir, "%s/%s", root, formats[f]);
        /* the folder and one level of subfolders (glTF keeps one model per folder) */
        static char paths[256][2048];
        size_t np = 0;
        DIR *d = opendir(dir);
        if (!d) continue;
        struct dirent *de;
        while ((de = readdir(d)) && np < 256) {
            if (de->d_name[0] == '.') continue;
            char p[1024];
            snprintf(p, sizeof p, "%s/%s", dir, de->d_name);
            if (stat(p, &st) != 0) continue;
            if (S_ISDIR(st.st_mode)) {
                DIR *d2 = opendir(p);
                struct dirent *e2;
                while (d2 && (e2 = readdir(d2)) && np < 256) {
                    const char *x = strrchr(e2->d_name, '.');
                    if (e2->d_name[0] != '.' && x && (!strcasecmp(x, ".gltf") || !strcasecmp(x, ".glb")))
                        snprintf(paths[np++], sizeof paths[0], "%s/%s", p, e2->d_name);
                }
                if (d2) closedir(d2);
                continue;
            }
            const char *x = strrchr(de->d_name, '.');
            if (!x || !strcasecmp(x, ".jpg") || !strcasecmp(x, ".png") || !strcasecmp(x, ".mtl") || !strcasecmp(x, ".tga") ||
                !strcasecmp(x, ".txt") || !strcasecmp(x, ".bin") || !strcasecmp(x, ".bmp"))
                continue;
            snprintf(paths[np++], sizeof paths[0], "%s", p);
        }
        closedir(d);
        unsigned files = 0, loaded = 0, refused = 0, mismatches = 0;
        for (size_t i = 0; i < np; ++i) {
            unsigned am = 0;
            unsigned long at = 0;
            bool aok = assimp_counts(paths[i], &am, &at);
            files++;
            sy_scene *s = NULL;
            sy_error e = {0};
            sy_assimp_info info = {0};
            if (sy_scene_create(&s, &e) != SY_OK) return 1;
            sy_result r = sy_assimp_load(paths[i], s, NULL, &info, &e);
            if (r == SY_OK) {
                loaded++;
                bool same = aok && info.counts.meshes == am && info.counts.triangles == at;
                if (!same) {
                    mismatches++;
                    printf("  MISMATCH %s: sy %u meshes %u triangles, Assimp %s %u meshes %lu triangles\n", paths[i],
                           info.counts.meshes, info.counts.triangles, aok ? "" : "(refused)", am, at);
                }
            } else {
                refused++;
                printf("  refused %s: %s%s\n", paths[i], e.message, aok ? " (Assimp reads it)" : "");
                EXPECT_MSG(strstr(e.message, strrchr(paths[i], '/') + 1) != NULL, "the error names the file: %s", e.message);
                if (aok && r != SY_ERR_LIMIT) mismatches++; /* refused what Assimp reads (a limit or a refused path is ours) */
            }
            sy_assimp_info_free(&info);
            sy_scene_destroy(s);
        }
        printf("%-8s %6u %7u %8u %10u\n", formats[f], files, loaded, refused, mismatches);
        EXPECT_MSG(mismatches == 0, "%s: %u mismatches", formats[f], mismatches);
        total_loaded += loaded;
    }
    EXPECT_MSG(total_loaded >= 40, "only %u files loaded", total_loaded);
    return sy_check_finish("test_assimp_corpus");
}
