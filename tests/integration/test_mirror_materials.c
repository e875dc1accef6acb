/* test_mirror_materials.c — the mirror's material descriptions (mediators/sy_mirror.c,
 * sy_mirror_flat.c) for the glTF material extensions: every texture slot is resolved to the
 * back-end handle and a material is re-described when a texture it uses in any slot is remade (the
 * transmission texture was once missed), a partial material change merges into what the mirror
 * holds, and factors the specifications bound to [0, 1] reach the back-ends clamped. */
#include "../support/sy_check.h"
#include "sy_commit.h"
#include "sy_mirror.h"
#include "sy_scene.h"

#include <string.h>

typedef struct recorder {
    uint32_t next_handle;
    uint32_t material_sets;
    sy_mirror_flat_material last; /* the last material description */
} recorder;

static sy_result tex_set(void *user, const sy_mirror_texture_args *a, sy_error *err)
{
    (void)err;
    *a->handle = ++((recorder *)user)->next_handle;
    return SY_OK;
}
static sy_result mat_set(void *user, const sy_mirror_material_args *a, sy_error *err)
{
    (void)err;
    recorder *r = user;
    if (!*a->handle) *a->handle = ++r->next_handle;
    r->material_sets++;
    r->last = *a->flat;
    return SY_OK;
}
static sy_result prim_set(void *user, const sy_mirror_primitive_args *a, sy_error *err)
{
    (void)err;
    *a->handle = ++((recorder *)user)->next_handle;
    return SY_OK;
}
static sy_result inst_set(void *user, const sy_mirror_instance_args *a, sy_error *err)
{
    (void)err;
    if (!*a->handle) *a->handle = ++((recorder *)user)->next_handle;
    return SY_OK;
}
static void release(void *user, const sy_mirror_release_args *a) { (void)user, (void)a; }

static const sy_mirror_callbacks k_callbacks = {tex_set, mat_set, prim_set, inst_set, NULL, release, NULL, NULL};

/* a 1x1 RGBA texture with pixel value v */
static sy_texture make_texture(sy_scene *s, uint8_t v)
{
    sy_error e = {0};
    sy_texture t;
    EXPECT_MSG(sy_texture_create(s, NULL, &t, &e) == SY_OK, "%s", e.message);
    uint8_t px[4] = {v, v, v, 255};
    sy_blob *b = NULL;
    EXPECT(sy_blob_create_copy(px, 4, &b, &e) == SY_OK);
    sy_image_info info = {1, 1, 4, SY_PIXEL_U8_LINEAR};
    EXPECT_MSG(sy_texture_set_image(s, t, &info, b, &e) == SY_OK, "%s", e.message);
    sy_blob_release(b);
    return t;
}

static void sync(sy_scene *s, uint32_t consumer, sy_mirror *m)
{
    sy_error e = {0};
    sy_changes *c = NULL;
    EXPECT_MSG(sy_scene_commit(s, NULL, &e) == SY_OK, "%s", e.message);
    EXPECT_MSG(sy_scene_consumer_pull(s, consumer, &c, &e) == SY_OK, "%s", e.message);
    EXPECT_MSG(sy_mirror_sync(m, c, NULL, &e) == SY_OK, "%s", e.message);
    sy_changes_release(c);
}

int main(void)
{
    sy_error e = {0};
    sy_scene *s = NULL;
    EXPECT(sy_scene_create(&s, &e) == SY_OK);
    sy_texture coat_normal = make_texture(s, 128), transmission = make_texture(s, 200);
    sy_material mat;
    EXPECT(sy_material_create(s, "coated glass", &mat, &e) == SY_OK);
    sy_material_data d = *sy_material_get(s, mat);
    d.clearcoat = 0.5f;
    d.clearcoat_normal_texture.texture = coat_normal;
    d.clearcoat_normal_texture.scale = 0.25f;
    d.transmission = 1.0f;
    d.transmission_texture.texture = transmission;
    d.sheen_color[0] = 3.0f; /* core takes any non-negative factor; the specification bounds it to 1 */
    EXPECT_MSG(sy_material_set(s, mat, &d, &e) == SY_OK, "%s", e.message);

    recorder rec = {0};
    sy_mirror *m = NULL;
    sy_mirror_desc desc = {"test mirror", 0, &k_callbacks, &rec};
    EXPECT(sy_mirror_create(&desc, &m, &e) == SY_OK);
    uint32_t consumer;
    EXPECT(sy_scene_consumer_add(s, &consumer, &e) == SY_OK);
    sync(s, consumer, m);
    EXPECT_MSG(rec.material_sets >= 1, "the material was described");
    EXPECT_MSG(rec.last.clearcoat == 0.5f && rec.last.clearcoat_normal_scale == 0.25f &&
                   rec.last.clearcoat_normal_texture.handle == sy_mirror_texture_handle(m, coat_normal.id) &&
                   rec.last.clearcoat_normal_texture.handle != 0,
               "clearcoat: %g, normal handle %u", (double)rec.last.clearcoat, rec.last.clearcoat_normal_texture.handle);
    EXPECT_MSG(rec.last.transmission_texture.handle == sy_mirror_texture_handle(m, transmission.id) &&
                   rec.last.transmission_texture.handle != 0,
               "transmission texture handle %u", rec.last.transmission_texture.handle);
    EXPECT_MSG(rec.last.sheen_color[0] == 1.0f && rec.last.specular == 1.0f && rec.last.specular_color[2] == 1.0f &&
                   rec.last.iridescence_ior == 1.3f && rec.last.attenuation_color[1] == 1.0f,
               "clamped and default factors: sheen %g, specular %g", (double)rec.last.sheen_color[0],
               (double)rec.last.specular);

    /* a texture used only as the transmission texture is remade: the material gets its new handle */
    uint32_t sets = rec.material_sets, old = rec.last.transmission_texture.handle;
    uint8_t px[4] = {10, 20, 30, 255};
    sy_blob *b = NULL;
    EXPECT(sy_blob_create_copy(px, 4, &b, &e) == SY_OK);
    sy_image_info info = {1, 1, 4, SY_PIXEL_U8_LINEAR};
    EXPECT(sy_texture_set_image(s, transmission, &info, b, &e) == SY_OK);
    sy_blob_release(b);
    sync(s, consumer, m);
    EXPECT_MSG(rec.material_sets == sets + 1 && rec.last.transmission_texture.handle != old &&
                   rec.last.transmission_texture.handle == sy_mirror_texture_handle(m, transmission.id),
               "re-described after its transmission texture changed: %u sets, handle %u (was %u)", rec.material_sets,
               rec.last.transmission_texture.handle, old);

    /* a partial change (one field) merges: the other extension fields stay */
    float rough = 0.75f;
    EXPECT(sy_object_set_field(s, SY_TYPE_MATERIAL, mat.id, SY_MATERIAL_CLEARCOAT_ROUGHNESS, &rough, &e) == SY_OK);
    sync(s, consumer, m);
    EXPECT_MSG(rec.last.clearcoat_roughness == 0.75f && rec.last.clearcoat == 0.5f && rec.last.transmission == 1.0f &&
                   rec.last.clearcoat_normal_texture.handle != 0,
               "partial update merged: roughness %g, coat %g", (double)rec.last.clearcoat_roughness,
               (double)rec.last.clearcoat);

    sy_mirror_destroy(m);
    sy_scene_destroy(s);
    return sy_check_finish("integration_mirror_materials");
}
