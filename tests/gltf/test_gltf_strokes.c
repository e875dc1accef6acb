/* test_gltf_strokes.c — the Khronos MeshPrimitiveModes sample (issue 15 part 4): POINTS / LINES /
 * LINE_LOOP / LINE_STRIP load as point and line primitives with the element counts of the file, and
 * the shared stroke tessellation (mediators/sy_strokes.c, compiled in) turns each into the expected
 * number of triangles (12 per non-degenerate segment + 20 per distinct vertex or point) whose bounds
 * lie within the positions grown by half the core width and reach at least 0.85 of it (the
 * icosahedron's extent). Usage: test_gltf_strokes TESTDATA_DIR (exit 77 when the sample is absent). */
#include "../support/sy_check.h"
#include "sy_gltf.h"
#include "sy_strokes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int main(int argc, char **argv)
{
    char path[2048];
    snprintf(path, sizeof path, "%s/gltf/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf", argc > 1 ? argv[1] : ".");
    if (access(path, R_OK) != 0) {
        printf("SKIP: %s absent\n", path);
        return 77;
    }
    sy_scene *s;
    sy_gltf_info info;
    sy_error e = {0};
    memset(&info, 0, sizeof info);
    if (sy_scene_create(&s, &e) != SY_OK || sy_gltf_load(path, s, NULL, &info, &e) != SY_OK) {
        fprintf(stderr, "load: %s\n", e.message);
        return 1;
    }
    /* the file: POINTS 7 indices, LINES 12 indices, LINE_LOOP 7, LINE_STRIP 7 */
    EXPECT_MSG(info.counts.points == 7 && info.counts.line_segments == 6 + 7 + 6 && info.counts.skipped_primitives == 0,
               "counts %u points %u segments %u skipped", info.counts.points, info.counts.line_segments,
               info.counts.skipped_primitives);
    uint32_t strokes = 0;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_MESH, 0); id; id = sy_scene_next(s, SY_TYPE_MESH, id)) {
        const sy_mesh_data *m = sy_object_get(s, SY_TYPE_MESH, id);
        for (uint32_t k = 0; k < m->primitives.count; k++) {
            const sy_primitive *p = &m->primitives.items[k];
            if (p->topology == SY_TOPOLOGY_TRIANGLES) continue;
            strokes++;
            /* expected triangles, counted here from the indices */
            uint32_t n = sy_primitive_element_count(p), per = p->topology == SY_TOPOLOGY_LINES ? 2 : 1;
            const uint32_t *ix = sy_blob_data(p->indices);
            const float *v = sy_blob_data(p->positions);
            uint32_t nv = sy_primitive_vertex_count(p);
            uint64_t want = 0;
            if (per == 1) {
                want = 20ull * n;
            } else {
                char *seen = calloc(nv, 1);
                for (uint32_t q = 0; q < n; q++) {
                    uint32_t a = ix ? ix[2 * q] : 2 * q, b = ix ? ix[2 * q + 1] : 2 * q + 1;
                    if (memcmp(v + 3 * a, v + 3 * b, 12)) want += 12;
                    if (!seen[a]) want += 20, seen[a] = 1;
                    if (!seen[b]) want += 20, seen[b] = 1;
                }
                free(seen);
            }
            EXPECT_MSG(sy_strokes_triangle_count(p) == want, "%s primitive %u: %llu triangles predicted, expected %llu",
                       m->name, k, (unsigned long long)sy_strokes_triangle_count(p), (unsigned long long)want);
            sy_bounds pb = sy_primitive_position_bounds(p);
            float w = sy_primitive_stroke_width(p, &pb), r = 0.5f * w;
            sy_primitive t;
            sy_result res = sy_strokes_tessellate(p, w, m->name, &t, &e);
            EXPECT_MSG(res == SY_OK, "%s: %s", m->name, e.message);
            if (res != SY_OK) continue;
            EXPECT_MSG(sy_primitive_triangle_count(&t) == want && t.normals && t.topology == SY_TOPOLOGY_TRIANGLES,
                       "%s: %u triangles, expected %llu", m->name, sy_primitive_triangle_count(&t), (unsigned long long)want);
            sy_bounds tb = sy_primitive_position_bounds(&t);
            for (int a = 0; a < 3; a++) {
                EXPECT_MSG(tb.min[a] >= pb.min[a] - r - 1e-5f && tb.max[a] <= pb.max[a] + r + 1e-5f &&
                           tb.min[a] <= pb.min[a] - 0.85f * r && tb.max[a] >= pb.max[a] + 0.85f * r,
                           "%s axis %d: tessellation [%g %g], positions [%g %g], r %g", m->name, a, (double)tb.min[a],
                           (double)tb.max[a], (double)pb.min[a], (double)pb.max[a], (double)r);
            }
            /* unit normals */
            const float *nn = sy_blob_data(t.normals);
            uint32_t off = 0;
            for (uint32_t q = 0; q < sy_primitive_vertex_count(&t); q++)
                if (fabsf(nn[3 * q] * nn[3 * q] + nn[3 * q + 1] * nn[3 * q + 1] + nn[3 * q + 2] * nn[3 * q + 2] - 1) > 1e-4f) off++;
            EXPECT_MSG(off == 0, "%s: %u normals not unit", m->name, off);
            printf("%s: %u elements, width %.4f -> %u triangles\n", m->name, n, (double)w, sy_primitive_triangle_count(&t));
            sy_primitive_release(&t);
        }
    }
    EXPECT_MSG(strokes == 4, "4 stroke primitives, got %u", strokes);
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
    return sy_check_finish("gltf_strokes");
}
