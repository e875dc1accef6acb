/* test_rt_api.c — validation and lifetime rules of the backends/rt API: rejected mesh, material,
 * light and camera descs come back with a result and a message; stale handles are detected;
 * rendering needs a commit; meshes outlive their handle while instances use them; shared meshes
 * (a release callback) are not copied and are given back once. */
#include "rt_test.h"

static void test_mesh_validation(sy_rt_device *dev)
{
    sy_rt_mesh m;
    const float pos[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const uint32_t bad_idx[] = {0, 1, 3};
    sy_rt_mesh_desc d = {.positions = pos, .indices = bad_idx, .vertex_count = 3, .triangle_count = 1};
    EXPECT_MSG(sy_rt_mesh_create(dev, &d, &m) == SY_RT_ERROR_INVALID_ARGUMENT, "index past vertex count accepted");
    EXPECT_MSG(strstr(sy_rt_device_error(dev), "indices[2] = 3") != NULL, "message was '%s'", sy_rt_device_error(dev));
    EXPECT_MSG(m.id == 0, "failed create left a handle");

    float nan_pos[] = {0, 0, 0, 1, NAN, 0, 0, 1, 0};
    sy_rt_mesh_desc dn = {.positions = nan_pos, .vertex_count = 3, .triangle_count = 1};
    EXPECT_MSG(sy_rt_mesh_create(dev, &dn, &m) == SY_RT_ERROR_INVALID_ARGUMENT, "NaN position accepted");
    EXPECT_MSG(strstr(sy_rt_device_error(dev), "vertex 1") != NULL && strstr(sy_rt_device_error(dev), "not finite") != NULL, "message was '%s'", sy_rt_device_error(dev));

    sy_rt_mesh_desc dc = {.positions = pos, .vertex_count = 3, .triangle_count = 2};
    EXPECT_MSG(sy_rt_mesh_create(dev, &dc, &m) == SY_RT_ERROR_INVALID_ARGUMENT, "inconsistent counts accepted");
    EXPECT_MSG(strstr(sy_rt_device_error(dev), "3 * triangle_count") != NULL, "message was '%s'", sy_rt_device_error(dev));

    sy_rt_mesh_desc dz = {.positions = NULL, .vertex_count = 3, .triangle_count = 1};
    EXPECT_MSG(sy_rt_mesh_create(dev, &dz, &m) == SY_RT_ERROR_INVALID_ARGUMENT, "NULL positions accepted");

    float inf_nrm[] = {0, 0, 1, 0, 0, INFINITY, 0, 0, 1};
    sy_rt_mesh_desc dnn = {.positions = pos, .normals = inf_nrm, .vertex_count = 3, .triangle_count = 1};
    EXPECT_MSG(sy_rt_mesh_create(dev, &dnn, &m) == SY_RT_ERROR_INVALID_ARGUMENT, "infinite normal accepted");

    sy_rt_mesh_desc ok = {.positions = pos, .vertex_count = 3, .triangle_count = 1};
    EXPECT_MSG(sy_rt_mesh_create(dev, &ok, &m) == SY_RT_OK, "valid non-indexed mesh rejected: %s", sy_rt_device_error(dev));
    EXPECT_MSG(sy_rt_mesh_destroy(dev, m) == SY_RT_OK, "destroy failed: %s", sy_rt_device_error(dev));
    EXPECT_MSG(sy_rt_mesh_destroy(dev, m) == SY_RT_ERROR_INVALID_HANDLE, "double destroy not detected");
}

static void test_other_validation(sy_rt_device *dev)
{
    sy_rt_material_desc md;
    sy_rt_material_desc_init(&md);
    md.roughness = 1.5f;
    sy_rt_material mat;
    EXPECT_MSG(sy_rt_material_create(dev, &md, &mat) == SY_RT_ERROR_INVALID_ARGUMENT, "roughness 1.5 accepted");
    EXPECT_MSG(strstr(sy_rt_device_error(dev), "roughness") != NULL, "message was '%s'", sy_rt_device_error(dev));
    sy_rt_material_desc_init(&md);
    md.base_color_texture.texture.id = 0x00400001u; /* never issued */
    EXPECT_MSG(sy_rt_material_create(dev, &md, &mat) == SY_RT_ERROR_INVALID_HANDLE, "stale texture accepted");

    sy_rt_light_desc ld = {.type = SY_RT_LIGHT_SPOT, .color = {1, 1, 1}, .intensity = 1, .direction = {0, 0, -1},
                           .inner_cone_angle = 0.8f, .outer_cone_angle = 0.4f};
    sy_rt_light light;
    EXPECT_MSG(sy_rt_light_create(dev, &ld, &light) == SY_RT_ERROR_INVALID_ARGUMENT, "inner > outer accepted");
    EXPECT_MSG(strstr(sy_rt_device_error(dev), "cone") != NULL, "message was '%s'", sy_rt_device_error(dev));

    uint8_t px[4] = {0};
    sy_rt_texture_desc td = {.width = 1, .height = 1, .channels = 5, .format = SY_RT_TEXEL_UNORM8, .pixels = px};
    sy_rt_texture tex;
    EXPECT_MSG(sy_rt_texture_create(dev, &td, &tex) == SY_RT_ERROR_INVALID_ARGUMENT, "5 channels accepted");

    sy_rt_mesh q = rt_quad(dev, 1.0f);
    float singular[16] = {0};
    sy_rt_instance_desc id = {.mesh = q};
    memcpy(id.transform, singular, sizeof singular);
    sy_rt_instance inst;
    EXPECT_MSG(sy_rt_instance_create(dev, &id, &inst) == SY_RT_ERROR_INVALID_ARGUMENT, "singular transform accepted");
    EXPECT_MSG(strstr(sy_rt_device_error(dev), "singular") != NULL, "message was '%s'", sy_rt_device_error(dev));
    MUST(sy_rt_mesh_destroy(dev, q));
    EXPECT_MSG(sy_rt_instance_create(dev, &id, &inst) == SY_RT_ERROR_INVALID_HANDLE, "stale mesh accepted");
}

static void test_lifetime_and_commit(sy_rt_device *dev)
{
    sy_rt_mesh q = rt_quad(dev, 1.0f);
    sy_rt_material em = rt_emitter(dev, 1, 2, 3);
    float xf[16];
    rt_identity(xf);
    sy_rt_instance inst = rt_place(dev, q, xf, em, 0);
    /* The mesh handle goes first; the instance keeps the geometry alive. */
    MUST(sy_rt_mesh_destroy(dev, q));

    sy_rt_camera cam = rt_camera(5.0f, 0.5f);
    sy_rt_render_desc rd = rt_desc(SY_RT_INTEGRATOR_WHITTED, 9, 9);
    float rgba[9 * 9 * 4];
    EXPECT_MSG(sy_rt_render(dev, &cam, &rd, rgba, NULL) == SY_RT_ERROR_INVALID_OPERATION,
               "render with uncommitted changes accepted");
    EXPECT_MSG(strstr(sy_rt_device_error(dev), "sy_rt_commit") != NULL, "message was '%s'", sy_rt_device_error(dev));
    MUST(sy_rt_commit(dev));
    MUST(sy_rt_render(dev, &cam, &rd, rgba, NULL));
    const float *c = rgba + 4 * (4 * 9 + 4);
    EXPECT_MSG(c[0] == 1.0f && c[1] == 2.0f && c[2] == 3.0f && c[3] == 1.0f, "centre %g %g %g %g", c[0], c[1], c[2], c[3]);

    sy_rt_stats st;
    sy_rt_device_stats(dev, &st);
    EXPECT_MSG(st.meshes == 0 && st.instances == 1 && st.area_light_triangles == 2, "stats %u %u %u", st.meshes, st.instances,
               st.area_light_triangles);

    rd.integrator = (sy_rt_integrator)99; /* 3 is the path tracer, 4 reserved */
    EXPECT_MSG(sy_rt_render(dev, &cam, &rd, rgba, NULL) == SY_RT_ERROR_UNSUPPORTED, "unknown integrator accepted");
    rd.integrator = SY_RT_INTEGRATOR_WHITTED;
    rd.x = 5;
    rd.width = 5;
    EXPECT_MSG(sy_rt_render(dev, &cam, &rd, rgba, NULL) == SY_RT_ERROR_INVALID_ARGUMENT, "rectangle outside accepted");
    rd.x = 0;
    rd.width = 9;
    sy_rt_camera bad = cam;
    bad.window[0] = bad.window[1];
    EXPECT_MSG(sy_rt_render(dev, &bad, &rd, rgba, NULL) == SY_RT_ERROR_INVALID_ARGUMENT, "empty window accepted");

    MUST(sy_rt_instance_destroy(dev, inst));
    EXPECT_MSG(sy_rt_instance_set_transform(dev, inst, xf) == SY_RT_ERROR_INVALID_HANDLE, "stale instance accepted");
    MUST(sy_rt_material_destroy(dev, em));
    MUST(sy_rt_commit(dev));
    sy_rt_device_stats(dev, &st);
    EXPECT_MSG(st.instances == 0 && st.materials == 0 && st.area_light_triangles == 0, "stats after destroy %u %u %u",
               st.instances, st.materials, st.area_light_triangles);

    /* Cancellation through the progress callback. */
    MUST(sy_rt_render(dev, &cam, &rd, rgba, NULL));
}

static bool cancel_cb(const sy_rt_progress *p, void *user)
{
    int *calls = user;
    ++*calls;
    return p->tiles_done < 1;
}

static void test_progress(sy_rt_device *dev)
{
    sy_rt_camera cam = rt_camera(5.0f, 0.5f);
    sy_rt_render_desc rd = rt_desc(SY_RT_INTEGRATOR_PRIMARY, 64, 64);
    int calls = 0;
    rd.progress = cancel_cb;
    rd.progress_user_data = &calls;
    float *rgba = malloc(64 * 64 * 4 * sizeof(float));
    EXPECT_MSG(sy_rt_render(dev, &cam, &rd, rgba, NULL) == SY_RT_ERROR_CANCELLED, "cancel ignored");
    EXPECT_MSG(calls >= 1 && calls < 16, "progress called %d times for 16 tiles with cancel after the first", calls);
    free(rgba);
}

static void count_release(void *user) { ++*(int *)user; }

/* Shared meshes (sy_rt_mesh_desc.release): nothing is copied, the pixels equal a copied mesh's,
 * release comes exactly once after the handle and the last instance are gone, and never for a
 * create that failed. */
static void test_shared_mesh(void)
{
    /* positions padded by one float (Embree reads 16 bytes at the last vertex) */
    const float pos[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0, 0};
    const float nrm[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const float uv[] = {0, 1, 1, 1, 1, 0, 0, 0};
    const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
    float *img[2] = {NULL, NULL};
    for (int shared = 0; shared < 2; ++shared) {
        sy_rt_device *dev = rt_device();
        int released = 0;
        sy_rt_mesh_desc d = {.positions = pos, .normals = nrm, .uv = {uv, NULL}, .indices = idx, .vertex_count = 4,
                             .triangle_count = 2, .release = shared ? count_release : NULL, .release_user = &released};
        sy_rt_mesh m;
        MUST(sy_rt_mesh_create(dev, &d, &m));
        sy_rt_stats st;
        sy_rt_device_stats(dev, &st);
        if (shared)
            EXPECT_MSG(st.mesh_bytes == 0 && st.shared_bytes == sizeof pos - 4 + sizeof nrm + sizeof uv + sizeof idx,
                       "shared mesh: %llu bytes copied, %llu shared", (unsigned long long)st.mesh_bytes,
                       (unsigned long long)st.shared_bytes);
        else
            EXPECT_MSG(st.mesh_bytes == sizeof nrm + sizeof uv && st.shared_bytes == 0, "copied mesh: %llu bytes copied",
                       (unsigned long long)st.mesh_bytes);
        sy_rt_material mat = rt_emitter(dev, 0.25f, 0.5f, 1.0f);
        sy_rt_instance inst = rt_place(dev, m, NULL, mat, 0);
        MUST(sy_rt_mesh_destroy(dev, m));
        EXPECT_MSG(released == 0, "released while an instance uses the mesh");
        MUST(sy_rt_commit(dev));
        sy_rt_camera cam = rt_camera(5.0f, 0.5f);
        sy_rt_render_desc rd = rt_desc(SY_RT_INTEGRATOR_WHITTED, 16, 16);
        float *depth = NULL;
        rt_render(dev, &cam, &rd, &img[shared], &depth);
        free(depth);
        MUST(sy_rt_instance_destroy(dev, inst));
        EXPECT_MSG(released == shared, "release called %d times after the last instance went (expected %d)", released, shared);
        /* a failed create leaves the arrays with the caller */
        const uint32_t bad[] = {0, 1, 7};
        sy_rt_mesh_desc db = d;
        db.indices = bad;
        db.triangle_count = 1;
        EXPECT_MSG(sy_rt_mesh_create(dev, &db, &m) == SY_RT_ERROR_INVALID_ARGUMENT, "bad index accepted");
        sy_rt_device_destroy(dev);
        EXPECT_MSG(released == shared, "release called %d times in all (expected %d)", released, shared);
    }
    EXPECT_MSG(memcmp(img[0], img[1], 16 * 16 * 4 * sizeof(float)) == 0, "shared and copied meshes render differently");
    free(img[0]);
    free(img[1]);
}

/* Scenes too big for the device's memory limit are refused with the size needed and the size
 * available, before Embree builds anything. */
static void test_memory_limit(void)
{
    sy_rt_device_desc dd = {.max_memory_bytes = 1u << 20};
    sy_rt_device *dev = NULL;
    MUST(sy_rt_device_create(&dd, &dev));
    enum { G = 100 }; /* 2 G^2 = 20000 triangles: about 2.4 MB of BVH */
    float *pos = malloc((G + 1) * (G + 1) * 3 * sizeof(float));
    uint32_t *idx = malloc(G * G * 6 * sizeof(uint32_t));
    for (uint32_t z = 0, v = 0; z <= G; ++z)
        for (uint32_t x = 0; x <= G; ++x, ++v) pos[3 * v] = (float)x, pos[3 * v + 1] = 0, pos[3 * v + 2] = (float)z;
    for (uint32_t z = 0, k = 0; z < G; ++z)
        for (uint32_t x = 0; x < G; ++x) {
            uint32_t a = z * (G + 1) + x, b = a + G + 1;
            idx[k++] = a, idx[k++] = b, idx[k++] = a + 1, idx[k++] = a + 1, idx[k++] = b, idx[k++] = b + 1;
        }
    sy_rt_mesh_desc d = {.positions = pos, .indices = idx, .vertex_count = (G + 1) * (G + 1), .triangle_count = 2 * G * G};
    sy_rt_mesh m;
    MUST(sy_rt_mesh_create(dev, &d, &m));
    float xf[16];
    rt_identity(xf);
    sy_rt_instance_desc id = {.mesh = m};
    memcpy(id.transform, xf, sizeof xf);
    sy_rt_instance inst;
    EXPECT_MSG(sy_rt_instance_create(dev, &id, &inst) == SY_RT_ERROR_OUT_OF_MEMORY,
               "a BVH over the device's memory limit was built");
    EXPECT_MSG(strstr(sy_rt_device_error(dev), "20000 triangles needs about 2.4 MB") && strstr(sy_rt_device_error(dev), "MB left under the device's memory limit"),
               "message was '%s'", sy_rt_device_error(dev));
    sy_rt_device_destroy(dev);
    /* without a limit of its own the device builds it */
    MUST(sy_rt_device_create(NULL, &dev));
    MUST(sy_rt_mesh_create(dev, &d, &m));
    id.mesh = m;
    MUST(sy_rt_instance_create(dev, &id, &inst));
    MUST(sy_rt_commit(dev));
    sy_rt_device_destroy(dev);
    free(pos);
    free(idx);
}

/* The error report: the desc's callback receives each failure once, with the code the call returns
 * and the message sy_rt_device_error keeps; sy_rt_device_create's own failures reach it too. */
typedef struct report_log {
    int calls;
    sy_rt_result code;
    char message[512];
} report_log;
static void on_error(void *user, sy_rt_result code, const char *message)
{
    report_log *l = user;
    l->calls++;
    l->code = code;
    snprintf(l->message, sizeof l->message, "%s", message);
}

static void test_error_report(void)
{
    report_log log = {0};
    sy_rt_device_desc dd = {.error = on_error, .error_user = &log};
    EXPECT_MSG(sy_rt_device_create(&dd, NULL) == SY_RT_ERROR_INVALID_ARGUMENT && log.calls == 1 &&
                   log.code == SY_RT_ERROR_INVALID_ARGUMENT && strstr(log.message, "out is NULL"),
               "device create: %d calls, code %d, '%s'", log.calls, (int)log.code, log.message);
    sy_rt_device *dev = NULL;
    MUST(sy_rt_device_create(&dd, &dev));
    EXPECT_MSG(log.calls == 1 && strcmp(sy_rt_device_error(dev), "") == 0, "a new device reports '%s'",
               sy_rt_device_error(dev));
    sy_rt_material_desc md;
    sy_rt_material_desc_init(&md);
    md.roughness = -1.0f;
    sy_rt_material mat;
    EXPECT(sy_rt_material_create(dev, &md, &mat) == SY_RT_ERROR_INVALID_ARGUMENT);
    EXPECT_MSG(log.calls == 2 && log.code == SY_RT_ERROR_INVALID_ARGUMENT && strstr(log.message, "roughness") &&
                   strcmp(log.message, sy_rt_device_error(dev)) == 0,
               "material: %d calls, code %d, '%s' / '%s'", log.calls, (int)log.code, log.message, sy_rt_device_error(dev));
    sy_rt_accum *acc = NULL;
    EXPECT(sy_rt_accum_create(dev, 0, 4, &acc) == SY_RT_ERROR_INVALID_ARGUMENT && log.calls == 3 && acc == NULL);
    MUST(sy_rt_commit(dev));
    EXPECT_MSG(log.calls == 3, "a call that succeeded reported (%d calls)", log.calls);
    sy_rt_device_destroy(dev);
    EXPECT(sy_rt_accum_create(NULL, 0, 4, &acc) == SY_RT_ERROR_INVALID_ARGUMENT); /* no device: the code only */
    EXPECT(strcmp(sy_rt_device_error(NULL), "") == 0);
}

int main(void)
{
    test_error_report();
    sy_rt_device *dev = rt_device();
    test_mesh_validation(dev);
    test_other_validation(dev);
    test_lifetime_and_commit(dev);
    test_progress(dev);
    sy_rt_device_destroy(dev);
    test_shared_mesh();
    test_memory_limit();
    return sy_check_finish("test_rt_api");
}
