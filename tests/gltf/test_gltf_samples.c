/* test_gltf_samples.c — loads every glTF sample model of the shared test data and checks counts,
 * a few values read from the models' JSON, variant equality (glTF / glTF-Binary / glTF-Embedded
 * give deep-equal scenes), compressed variants (glTF-Draco, glTF-Quantized: same triangles, world
 * bounds within 1e-3 of the plain variant's diagonal) and the Cornell box.
 * Usage: test_gltf_samples TESTDATA_DIR.
 * Exits 77 (skipped) when the test data is absent. */
#include "../support/sy_check.h"
#include "gltf_files.h"
#include "sy_gltf.h"
#include "sy_graph.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static bool near(double a, double b, double eps) { return fabs(a - b) <= eps; }

typedef struct loaded {
    sy_scene *scene;
    sy_gltf_info info;
    sy_result r;
    sy_error err;
} loaded;

static loaded load(const char *path)
{
    loaded l;
    memset(&l, 0, sizeof l);
    if (sy_scene_create(&l.scene, &l.err) != SY_OK) {
        fprintf(stderr, "scene create: %s\n", l.err.message);
        exit(1);
    }
    l.r = sy_gltf_load(path, l.scene, NULL, &l.info, &l.err);
    if (l.r == SY_OK) {
        uint64_t frame;
        sy_error e = {0};
        if (sy_scene_commit(l.scene, &frame, &e) != SY_OK) {
            fprintf(stderr, "%s: commit failed: %s\n", path, e.message);
            l.r = e.code ? e.code : SY_ERR_INVALID_ARGUMENT;
        }
    }
    return l;
}

/* Texture names follow image names, and exporters name the images they embed in a GLB but not the
 * files a .gltf refers to (IridescenceSuzanne: "noise" against the uri noise.png): the variants are
 * compared without them. */
static void clear_texture_names(sy_scene *s)
{
    for (uint32_t id = sy_scene_next(s, SY_TYPE_TEXTURE, 0); id; id = sy_scene_next(s, SY_TYPE_TEXTURE, id))
        EXPECT(sy_object_set_field(s, SY_TYPE_TEXTURE, id, SY_FIELD_NAME, &(const char *){NULL}, NULL) == SY_OK);
}

static void unload(loaded *l)
{
    sy_gltf_info_free(&l->info);
    sy_scene_destroy(l->scene);
    l->scene = NULL;
}

static const sy_material_data *material_named(const sy_scene *s, const char *name)
{
    for (uint32_t id = sy_scene_next(s, SY_TYPE_MATERIAL, 0); id; id = sy_scene_next(s, SY_TYPE_MATERIAL, id)) {
        const sy_material_data *m = sy_material_get(s, (sy_material){id});
        if (m && m->name && !strcmp(m->name, name)) return m;
    }
    return NULL;
}

/* Generic checks for every loaded file: objects in the scene agree with the file's counts. */
static void check_generic(const char *path, loaded *l)
{
    const sy_gltf_counts *c = &l->info.counts;
    EXPECT_MSG(sy_scene_count(l->scene, SY_TYPE_MESH) == c->meshes, "%s: meshes %u vs %u", path,
               sy_scene_count(l->scene, SY_TYPE_MESH), c->meshes);
    EXPECT_MSG(sy_scene_count(l->scene, SY_TYPE_MATERIAL) == c->materials, "%s: materials", path);
    EXPECT_MSG(sy_scene_count(l->scene, SY_TYPE_CAMERA) == c->cameras, "%s: cameras", path);
    EXPECT_MSG(sy_scene_count(l->scene, SY_TYPE_LIGHT) == c->lights, "%s: lights", path);
    EXPECT_MSG(sy_scene_count(l->scene, SY_TYPE_TEXTURE) <= 2 * c->textures, "%s: textures", path);
    EXPECT_MSG(sy_node_get(l->scene, l->info.root) != NULL, "%s: root node", path);
    EXPECT_MSG(sy_scene_count(l->scene, SY_TYPE_NODE) >= 1, "%s: nodes", path);
    /* every node visible */
    for (uint32_t id = sy_scene_next(l->scene, SY_TYPE_NODE, 0); id; id = sy_scene_next(l->scene, SY_TYPE_NODE, id)) {
        const sy_node_data *n = sy_node_get(l->scene, (sy_node){id});
        EXPECT_MSG(n && (n->flags & SY_NODE_VISIBLE), "%s: node %u not visible", path, id);
    }
    /* triangles in the scene's meshes = reported triangles */
    uint64_t tris = 0;
    for (uint32_t id = sy_scene_next(l->scene, SY_TYPE_MESH, 0); id; id = sy_scene_next(l->scene, SY_TYPE_MESH, id)) {
        const sy_mesh_data *m = sy_mesh_get(l->scene, (sy_mesh){id});
        for (uint32_t p = 0; m && p < m->primitives.count; p++) tris += sy_primitive_triangle_count(&m->primitives.items[p]);
    }
    EXPECT_MSG(tris == c->triangles, "%s: triangles %llu vs %u", path, (unsigned long long)tris, c->triangles);
    sy_bounds b;
    sy_error e = {0};
    EXPECT_MSG(sy_node_world_bounds(l->scene, l->info.root, &b, &e) == SY_OK, "%s: bounds: %s", path, e.message);
}

/* Checks of values read from the models' JSON. */
static void check_specific(const char *model, const char *path, loaded *l)
{
    const sy_gltf_counts *c = &l->info.counts;
    sy_scene *s = l->scene;
    if (!strcmp(model, "Box")) {
        EXPECT_MSG(c->meshes == 1 && c->primitives == 1 && c->triangles == 12, "%s: counts %u/%u/%u", path, c->meshes,
                   c->primitives, c->triangles);
        sy_bounds b;
        sy_error e = {0};
        EXPECT_MSG(sy_node_world_bounds(s, l->info.root, &b, &e) == SY_OK, "%s", e.message);
        for (int k = 0; k < 3; k++)
            EXPECT_MSG(near(b.min[k], -0.5, 1e-5) && near(b.max[k], 0.5, 1e-5), "%s: bounds axis %d: %g..%g", path, k,
                       b.min[k], b.max[k]);
    } else if (!strcmp(model, "ClearCoatTest")) { /* KHR_materials_clearcoat factors */
        const sy_material_data *m = material_named(s, "Simple_Coated");
        EXPECT_MSG(m && near(m->clearcoat, 1, 1e-6) && near(m->clearcoat_roughness, 0.03, 1e-6), "%s: Simple_Coated", path);
    } else if (!strcmp(model, "SheenCloth")) { /* KHR_materials_sheen: factors and textures with their transform */
        const sy_material_data *m = material_named(s, "SheenClothMat");
        EXPECT_MSG(m && near(m->sheen_color[0], 1, 1e-6) && near(m->sheen_roughness, 1, 1e-6) &&
                       m->sheen_color_texture.texture.id && m->sheen_roughness_texture.texture.id &&
                       near(m->sheen_color_texture.uv_scale[1], -30, 1e-5),
                   "%s: SheenClothMat", path);
        /* one glTF texture in two roles: sRGB colour and linear roughness */
        EXPECT_MSG(m && m->sheen_color_texture.texture.id != m->sheen_roughness_texture.texture.id, "%s: sheen roles", path);
    } else if (!strcmp(model, "SpecularTest")) { /* KHR_materials_specular, HDR colour factor kept */
        const sy_material_data *a = material_named(s, "M1.3_specFac"), *b = material_named(s, "M7.3_HDR");
        const sy_material_data *t = material_named(s, "M4_whiteTex");
        EXPECT_MSG(a && near(a->specular, 0.212231, 1e-6) && near(a->specular_color[0], 1, 1e-6), "%s: M1.3_specFac", path);
        EXPECT_MSG(b && near(b->specular_color[1], 5.441, 1e-5) && near(b->specular, 1, 1e-6), "%s: M7.3_HDR", path);
        EXPECT_MSG(t && t->specular_color_texture.texture.id, "%s: M4_whiteTex", path);
    } else if (!strcmp(model, "AttenuationTest")) { /* KHR_materials_volume */
        const sy_material_data *m = material_named(s, "R5_Attenuation_0.50");
        EXPECT_MSG(m && near(m->thickness, 1, 1e-6) && near(m->attenuation_distance, 2, 1e-6) &&
                       near(m->attenuation_color[0], 0.1, 1e-6) && near(m->attenuation_color[2], 0.9, 1e-6) &&
                       near(m->transmission, 1, 1e-6),
                   "%s: R5_Attenuation_0.50", path);
        const sy_material_data *plain = material_named(s, "R1_Sample_1.5");
        EXPECT_MSG(plain && plain->thickness == 0 && plain->attenuation_distance == 0, "%s: R1_Sample_1.5", path);
    } else if (!strcmp(model, "IridescenceSuzanne")) { /* KHR_materials_iridescence with a thickness texture */
        uint32_t textured = 0;
        for (uint32_t id = sy_scene_next(s, SY_TYPE_MATERIAL, 0); id; id = sy_scene_next(s, SY_TYPE_MATERIAL, id)) {
            const sy_material_data *m = sy_material_get(s, (sy_material){id});
            EXPECT_MSG(near(m->iridescence, 1, 1e-6), "%s: iridescence factor", path);
            if (m->iridescence_thickness_texture.texture.id) {
                textured++;
                EXPECT_MSG(near(m->iridescence_ior, 1.8, 1e-6) && near(m->iridescence_thickness[0], 200, 1e-4) &&
                               near(m->iridescence_thickness[1], 600, 1e-4),
                           "%s: film of the textured material", path);
            } else {
                EXPECT_MSG(near(m->iridescence_thickness[0], 100, 1e-4), "%s: default film minimum", path);
            }
        }
        EXPECT_MSG(textured == 1, "%s: %u materials with a thickness texture", path, textured);
    } else if (!strcmp(model, "AnisotropyRotationTest")) { /* KHR_materials_anisotropy */
        const sy_material_data *m = material_named(s, "Aniso Tan + Rotation");
        EXPECT_MSG(m && near(m->anisotropy, 0.5, 1e-6) && near(m->anisotropy_rotation, 0.523598775598, 1e-6),
                   "%s: Aniso Tan + Rotation", path);
    } else if (!strcmp(model, "Cameras")) {
        EXPECT_MSG(c->cameras == 2 && l->info.camera_node_count == 2, "%s: cameras", path);
        if (l->info.camera_node_count == 2) {
            const sy_node_data *n0 = sy_node_get(s, l->info.camera_nodes[0]);
            const sy_node_data *n1 = sy_node_get(s, l->info.camera_nodes[1]);
            const sy_camera_data *c0 = n0 ? sy_camera_get(s, n0->camera) : NULL;
            const sy_camera_data *c1 = n1 ? sy_camera_get(s, n1->camera) : NULL;
            EXPECT_MSG(c0 && c0->projection == SY_PROJECTION_PERSPECTIVE && near(c0->yfov, 0.7, 1e-6) &&
                       near(c0->aspect, 1.0, 1e-6) && near(c0->znear, 0.01, 1e-6) && near(c0->zfar, 100, 1e-4),
                       "%s: camera 0", path);
            EXPECT_MSG(c1 && c1->projection == SY_PROJECTION_ORTHOGRAPHIC && near(c1->xmag, 1, 1e-6) && near(c1->ymag, 1, 1e-6),
                       "%s: camera 1", path);
        }
    } else if (!strcmp(model, "SimpleInstancing")) {
        EXPECT_MSG(c->meshes == 1 && sy_scene_count(s, SY_TYPE_MESH) == 1, "%s: one mesh", path);
        /* glTF node + 125 instances + root */
        EXPECT_MSG(sy_scene_count(s, SY_TYPE_NODE) == 127, "%s: nodes %u", path, sy_scene_count(s, SY_TYPE_NODE));
        uint32_t mesh_id = sy_scene_next(s, SY_TYPE_MESH, 0), users = 0;
        for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id; id = sy_scene_next(s, SY_TYPE_NODE, id)) {
            const sy_node_data *n = sy_node_get(s, (sy_node){id});
            if (n && n->mesh.id) {
                users++;
                EXPECT_MSG(n->mesh.id == mesh_id, "%s: shared mesh", path);
            }
        }
        EXPECT_MSG(users == 125, "%s: %u nodes use the mesh", path, users);
    } else if (!strcmp(model, "LightsPunctualLamp")) {
        EXPECT_MSG(c->lights == 5 && sy_scene_count(s, SY_TYPE_LIGHT) == 5, "%s: lights", path);
        bool found = false;
        for (uint32_t id = sy_scene_next(s, SY_TYPE_LIGHT, 0); id; id = sy_scene_next(s, SY_TYPE_LIGHT, id)) {
            const sy_light_data *ld = sy_light_get(s, (sy_light){id});
            if (ld && ld->name && !strcmp(ld->name, "Point")) {
                found = true;
                EXPECT_MSG(ld->type == SY_LIGHT_POINT && near(ld->intensity, 15, 1e-5) && near(ld->color[0], 1, 1e-6) &&
                           near(ld->color[1], 0.6318749785423279, 1e-6) && near(ld->color[2], 0.23909975588321689, 1e-6),
                           "%s: light Point", path);
            }
            if (ld && ld->name && !strcmp(ld->name, "Point.002"))
                EXPECT_MSG(near(ld->intensity, 1.5, 1e-6) && ld->color[0] == 1 && ld->color[1] == 1, "%s: default colour", path);
        }
        EXPECT_MSG(found, "%s: light 'Point'", path);
        /* KHR_materials_transmission is used by one material */
        bool transmissive = false;
        for (uint32_t id = sy_scene_next(s, SY_TYPE_MATERIAL, 0); id; id = sy_scene_next(s, SY_TYPE_MATERIAL, id)) {
            const sy_material_data *m = sy_material_get(s, (sy_material){id});
            transmissive = transmissive || (m && m->transmission > 0);
        }
        EXPECT_MSG(transmissive, "%s: transmission", path);
    } else if (!strcmp(model, "EmissiveStrengthTest")) {
        const char *names[] = {"Emit1", "Emit2", "Emit4", "Emit8", "Emit16"};
        const float strength[] = {1, 2, 4, 8, 16};
        for (int k = 0; k < 5; k++) {
            const sy_material_data *m = material_named(s, names[k]);
            EXPECT_MSG(m && near(m->emissive_strength, strength[k], 1e-6) && near(m->emissive[0], 0.1, 1e-6) &&
                       near(m->emissive[1], 0.5, 1e-6) && near(m->emissive[2], 0.9, 1e-6),
                       "%s: material %s", path, names[k]);
        }
    } else if (!strcmp(model, "MeshPrimitiveModes")) {
        /* 3 triangle primitives: 18 indices = 6, strip of 6 = 4, fan of 8 = 6; POINTS of 7 indices = 7
         * points; LINES of 12 indices = 6 segments, LINE_LOOP of 7 = 7, LINE_STRIP of 7 = 6 */
        EXPECT_MSG(c->primitives == 7 && c->skipped_primitives == 0 && c->triangles == 16 && c->points == 7 &&
                   c->line_segments == 6 + 7 + 6,
                   "%s: %u/%u/%u/%u/%u", path, c->primitives, c->skipped_primitives, c->triangles, c->points, c->line_segments);
        uint32_t kinds[SY_TOPOLOGY_COUNT] = {0}, elements[SY_TOPOLOGY_COUNT] = {0};
        for (uint32_t id = sy_scene_next(s, SY_TYPE_MESH, 0); id; id = sy_scene_next(s, SY_TYPE_MESH, id)) {
            const sy_mesh_data *m = sy_object_get(s, SY_TYPE_MESH, id);
            for (uint32_t k = 0; k < m->primitives.count; k++) {
                const sy_primitive *p = &m->primitives.items[k];
                kinds[p->topology]++;
                elements[p->topology] += sy_primitive_element_count(p);
            }
        }
        EXPECT_MSG(kinds[SY_TOPOLOGY_TRIANGLES] == 3 && kinds[SY_TOPOLOGY_LINES] == 3 && kinds[SY_TOPOLOGY_POINTS] == 1 &&
                   elements[SY_TOPOLOGY_LINES] == 19 && elements[SY_TOPOLOGY_POINTS] == 7,
                   "%s: primitives by topology %u/%u/%u, %u segments, %u points", path, kinds[0], kinds[1], kinds[2],
                   elements[1], elements[2]);
    } else if (!strcmp(model, "DamagedHelmet")) {
        EXPECT_MSG(sy_scene_count(s, SY_TYPE_TEXTURE) == 5, "%s: textures", path);
        const sy_material_data *m = sy_material_get(s, (sy_material){sy_scene_next(s, SY_TYPE_MATERIAL, 0)});
        const sy_texture_data *bc = m ? sy_texture_get(s, m->base_color_texture.texture) : NULL;
        const sy_texture_data *em = m ? sy_texture_get(s, m->emissive_texture.texture) : NULL;
        const sy_texture_data *nm = m ? sy_texture_get(s, m->normal_texture.texture) : NULL;
        const sy_texture_data *mr = m ? sy_texture_get(s, m->metallic_roughness_texture.texture) : NULL;
        const sy_texture_data *ao = m ? sy_texture_get(s, m->occlusion_texture.texture) : NULL;
        EXPECT_MSG(bc && bc->info.format == SY_PIXEL_U8_SRGB && em && em->info.format == SY_PIXEL_U8_SRGB, "%s: colour roles", path);
        EXPECT_MSG(nm && nm->info.format == SY_PIXEL_U8_LINEAR && mr && mr->info.format == SY_PIXEL_U8_LINEAR && ao &&
                   ao->info.format == SY_PIXEL_U8_LINEAR,
                   "%s: data roles", path);
        EXPECT_MSG(bc && bc->info.width == 2048 && bc->info.height == 2048 && bc->pixels, "%s: base colour size", path);
    } else if (!strcmp(model, "UnlitTest")) {
        uint32_t unlit = 0;
        for (uint32_t id = sy_scene_next(s, SY_TYPE_MATERIAL, 0); id; id = sy_scene_next(s, SY_TYPE_MATERIAL, id))
            unlit += sy_material_get(s, (sy_material){id})->unlit;
        EXPECT_MSG(unlit == 2, "%s: unlit materials %u", path, unlit);
    } else if (!strcmp(model, "TextureTransformTest")) {
        bool any = false;
        for (uint32_t id = sy_scene_next(s, SY_TYPE_MATERIAL, 0); id; id = sy_scene_next(s, SY_TYPE_MATERIAL, id)) {
            const sy_material_data *m = sy_material_get(s, (sy_material){id});
            any = any || m->base_color_texture.rotation != 0 || m->base_color_texture.offset[0] != 0 ||
                  m->base_color_texture.uv_scale[0] != 1;
        }
        EXPECT_MSG(any, "%s: KHR_texture_transform values", path);
    }
}

static bool ends_with(const char *s, const char *suffix)
{
    size_t a = strlen(s), b = strlen(suffix);
    return a >= b && !strcmp(s + a - b, suffix);
}

/* First file with the suffix in dir; returns false if none. */
static bool find_file(const char *dir, const char *suffix, char *out, size_t n)
{
    DIR *d = opendir(dir);
    if (!d) return false;
    struct dirent *e;
    bool found = false;
    while (!found && (e = readdir(d)))
        if (ends_with(e->d_name, suffix)) {
            int w = snprintf(out, n, "%s/%s", dir, e->d_name);
            found = w > 0 && (size_t)w < n;
        }
    closedir(d);
    return found;
}

/* A compressed variant (KHR_draco_mesh_compression, KHR_mesh_quantization) against the plain one:
 * it loads, has the same triangles and its world bounds agree within the quantization error (1e-3
 * of the diagonal; Draco's default 14 bits and 16-bit quantization are well inside it). */
static bool compare_compressed(const char *path, loaded *plain)
{
    loaded l = load(path);
    EXPECT_MSG(l.r == SY_OK, "%s: %s", path, l.err.message);
    bool ok = l.r == SY_OK;
    if (ok) {
        check_generic(path, &l);
        const sy_gltf_counts *c = &l.info.counts, *p = &plain->info.counts;
        EXPECT_MSG(c->triangles == p->triangles && c->primitives == p->primitives,
                   "%s: %u triangles in %u primitives, plain %u in %u", path, c->triangles, c->primitives, p->triangles,
                   p->primitives);
        sy_bounds a = sy_scene_world_bounds(plain->scene), b = sy_scene_world_bounds(l.scene);
        double diag = 0;
        for (int k = 0; k < 3; k++) diag += (double)(a.max[k] - a.min[k]) * (a.max[k] - a.min[k]);
        diag = sqrt(diag);
        double worst = 0;
        for (int k = 0; k < 3; k++) worst = fmax(worst, fmax(fabs(a.min[k] - b.min[k]), fabs(a.max[k] - b.max[k])));
        EXPECT_MSG(!sy_bounds_is_empty(&a) && diag > 0 && worst <= 1e-3 * diag, "%s: bounds differ by %g (diagonal %g)",
                   path, worst, diag);
        printf("ok %-70s tris %7u bounds within %.3g of diagonal %.4g\n", path, l.info.counts.triangles, worst, diag);
    }
    unload(&l);
    return ok;
}

static int cmp_str(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

static void test_cornell(const char *root)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/cornell/cornell_box.gltf", root);
    struct stat st;
    if (stat(path, &st) != 0) {
        printf("SKIP cornell: %s absent\n", path);
        return;
    }
    loaded l = load(path);
    EXPECT_MSG(l.r == SY_OK, "%s: %s", path, l.err.message);
    if (l.r == SY_OK) {
        check_generic(path, &l);
        EXPECT_MSG(l.info.counts.meshes == 8 && sy_scene_count(l.scene, SY_TYPE_MESH) == 8, "cornell: 8 meshes");
        const sy_material_data *m = material_named(l.scene, "light");
        EXPECT_MSG(m != NULL, "cornell: material 'light'");
        if (m) {
            const float want[3] = {17, 12, 4};
            for (int k = 0; k < 3; k++)
                EXPECT_MSG(near(m->emissive[k] * m->emissive_strength, want[k], 1e-4), "cornell: emission %d = %g", k,
                           m->emissive[k] * m->emissive_strength);
        }
        sy_node cam;
        sy_error e = {0};
        EXPECT_MSG(sy_gltf_find_camera(l.scene, &l.info, "camera", &cam, &e) == SY_OK, "cornell: camera: %s", e.message);
        const sy_node_data *nd = sy_node_get(l.scene, cam);
        const sy_camera_data *cd = nd ? sy_camera_get(l.scene, nd->camera) : NULL;
        EXPECT_MSG(nd && nd->name && !strcmp(nd->name, "camera"), "cornell: camera node name");
        EXPECT_MSG(cd && near(cd->yfov, 2 * atan(12.5 / 35), 1e-6), "cornell: yfov %g", cd ? cd->yfov : -1.0);
        sy_node cam0;
        EXPECT_MSG(sy_gltf_find_camera(l.scene, &l.info, "0", &cam0, &e) == SY_OK && cam0.id == cam.id, "cornell: index 0");
        EXPECT_MSG(sy_gltf_find_camera(l.scene, &l.info, "nope", &cam0, &e) == SY_ERR_NOT_FOUND &&
                   strstr(e.message, "camera") != NULL,
                   "cornell: unknown camera");
    }
    unload(&l);
}

int main(int argc, char **argv)
{
    const char *testdata = testdata_arg(argc, argv);
    char gdir[1024];
    snprintf(gdir, sizeof gdir, "%s/gltf", testdata);
    DIR *d = opendir(gdir);
    if (!d) {
        printf("SKIP: test data directory %s is absent\n", gdir);
        return 77;
    }
    char *models[256];
    size_t nmodels = 0;
    struct dirent *e;
    while ((e = readdir(d)) && nmodels < 256)
        if (e->d_name[0] != '.' && e->d_name[0] != '_') models[nmodels++] = strdup(e->d_name);
    closedir(d);
    qsort(models, nmodels, sizeof(char *), cmp_str);

    long blobs_before = sy_blob_live_count();
    unsigned files = 0, loaded_ok = 0, compared = 0, compressed_ok = 0;
    const char *variants[3][2] = {{"glTF", ".gltf"}, {"glTF-Binary", ".glb"}, {"glTF-Embedded", ".gltf"}};
    for (size_t m = 0; m < nmodels; m++) {
        loaded first;
        bool have_first = false;
        char first_path[1100] = "";
        for (int v = 0; v < 3; v++) {
            char dir[1024], path[1100];
            int w = snprintf(dir, sizeof dir, "%s/%s/%s", gdir, models[m], variants[v][0]);
            if (w < 0 || (size_t)w >= sizeof dir) continue;
            if (!find_file(dir, variants[v][1], path, sizeof path)) continue;
            files++;
            loaded l = load(path);
            /* files requiring an extension sy does not read are refused naming it (gltf_counts checks
             * each refusal against the file's own extensionsRequired) */
            bool refused = l.r == SY_ERR_UNSUPPORTED && strstr(l.err.message, "extensionsRequired: '");
            if (refused) printf("refused (unsupported required extension) %s: %s\n", path + strlen(gdir) + 1, l.err.message);
            EXPECT_MSG(l.r == SY_OK || refused, "%s: %s", path, l.err.message);
            if (l.r != SY_OK) {
                unload(&l);
                continue;
            }
            loaded_ok++;
            check_generic(path, &l);
            check_specific(models[m], path, &l);
            printf("ok %-70s nodes %3u meshes %3u prims %3u tris %7u mats %3u tex %2u img %2u lights %u cams %u warn %u\n",
                   path + strlen(gdir) + 1, l.info.counts.nodes, l.info.counts.meshes, l.info.counts.primitives,
                   l.info.counts.triangles, l.info.counts.materials, l.info.counts.textures, l.info.counts.images,
                   l.info.counts.lights, l.info.counts.cameras, l.info.warning_count);
            for (uint32_t w = 0; w < l.info.stored_warning_count; w++) printf("   warning: %s\n", l.info.warnings[w]);
            if (!have_first) {
                first = l;
                have_first = true;
                memcpy(first_path, path, sizeof path);
            } else {
                sy_error diff = {0};
                clear_texture_names(first.scene);
                clear_texture_names(l.scene);
                bool eq = sy_scene_equal(first.scene, l.scene, &diff);
                EXPECT_MSG(eq, "%s vs %s: %s", first_path, path, diff.message);
                compared++;
                unload(&l);
            }
        }
        const char *compressed[2] = {"glTF-Draco", "glTF-Quantized"};
        for (int v = 0; v < 2 && have_first; v++) {
            char dir[1024], path[1100];
            int w = snprintf(dir, sizeof dir, "%s/%s/%s", gdir, models[m], compressed[v]);
            if (w < 0 || (size_t)w >= sizeof dir || !find_file(dir, ".gltf", path, sizeof path)) continue;
            files++;
            loaded_ok += compare_compressed(path, &first);
            compressed_ok++;
        }
        if (have_first) unload(&first);
        free(models[m]);
    }
    test_cornell(testdata);
    EXPECT_MSG(sy_blob_live_count() == blobs_before, "blob leak: %ld live, %ld before", sy_blob_live_count(), blobs_before);
    EXPECT_MSG(files >= 30, "only %u sample files found", files);
    EXPECT_MSG(compressed_ok >= 2, "only %u compressed variants found", compressed_ok);
    printf("%u sample files, %u loaded, %u variant comparisons, %u compressed variants\n", files, loaded_ok, compared,
           compressed_ok);
    return sy_check_finish("gltf_samples");
}
