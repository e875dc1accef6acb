/* test_x3d_strokes.c — X3D PointSet, IndexedLineSet, LineSet, Background gradients and Text
 * (issue 15 part 4): small files written by the test with known counts, bad input refused or
 * warned with file:line, and the shared sample files that contain these nodes (their counts
 * computed here from the file's own attributes). Usage: test_x3d_strokes [TESTDATA_DIR]. */
#include "sy_text.h"
#include "sy_world.h"
#include "x3d_loaded.h"

#include <math.h>

/* The primitive of the mesh whose node is named (DEF of the Shape). */
static const sy_primitive *prim_named(const loaded *l, const char *name)
{
    for (uint32_t id = sy_scene_next(l->scene, SY_TYPE_MESH, 0); id; id = sy_scene_next(l->scene, SY_TYPE_MESH, id)) {
        const sy_mesh_data *m = sy_object_get(l->scene, SY_TYPE_MESH, id);
        if (m->name && !strcmp(m->name, name) && m->primitives.count) return &m->primitives.items[0];
    }
    return NULL;
}

static const uint32_t *idx_of(const sy_primitive *p) { return sy_blob_data(p->indices); }
static const float *col_of(const sy_primitive *p, uint32_t v) { return (const float *)sy_blob_data(p->colors) + 4 * v; }

static void test_strokes(void)
{
    loaded l = load_text("strokes.x3d",
        "<X3D><Scene>\n"
        "<Shape DEF='P'><Appearance><Material emissiveColor='1 0 0'/></Appearance>\n"
        "  <PointSet><Coordinate point='0 0 0 1 0 0 2 0 0 3 0 0'/></PointSet></Shape>\n"
        "<Shape DEF='ILS'><IndexedLineSet coordIndex='0 1 2 -1 2 3 -1 3' colorPerVertex='false'>\n"
        "  <Coordinate point='0 1 0 1 1 0 2 1 0 3 1 0'/><Color color='1 0 0 0 1 0 0 0 1'/></IndexedLineSet></Shape>\n"
        "<Shape DEF='ILSV'><IndexedLineSet coordIndex='0 1 2' colorIndex='2 1 0'>\n"
        "  <Coordinate point='0 5 0 1 5 0 2 5 0'/><ColorRGBA color='1 0 0 1 0 1 0 1 0 0 1 0.5'/></IndexedLineSet></Shape>\n"
        "<Shape DEF='LS'><LineSet vertexCount='2 3'><Coordinate point='0 2 0 1 2 0 0 3 0 1 3 0 2 3 0'/></LineSet></Shape>\n"
        "</Scene></X3D>\n");
    expect_loaded(&l, "strokes");
    const sy_primitive *p = prim_named(&l, "P");
    EXPECT_MSG(p && p->topology == SY_TOPOLOGY_POINTS && sy_primitive_element_count(p) == 4 && !p->indices &&
               sy_primitive_triangle_count(p) == 0,
               "PointSet: 4 points");
    if (p) {
        const sy_material_data *md = sy_material_get(l.scene, p->material);
        EXPECT_MSG(md && md->unlit && md->base_color[0] == 1.0f && md->base_color[1] == 0.0f,
                   "PointSet: unlit, the Material's emissiveColor (X3D points are unlit)");
    }
    /* IndexedLineSet: polylines 0-1-2 and 2-3 (the lone "3" is no polyline): 3 segments, 5 vertices
     * (repeated per polyline), colours per polyline: red, green */
    p = prim_named(&l, "ILS");
    EXPECT_MSG(p && p->topology == SY_TOPOLOGY_LINES && sy_primitive_element_count(p) == 3 && sy_primitive_vertex_count(p) == 5,
               "IndexedLineSet: 3 segments over 5 vertices, got %u / %u", p ? sy_primitive_element_count(p) : 0,
               p ? sy_primitive_vertex_count(p) : 0);
    if (p && p->colors && p->indices) {
        const uint32_t *ix = idx_of(p);
        EXPECT_MSG(ix[0] == 0 && ix[1] == 1 && ix[2] == 1 && ix[3] == 2 && ix[4] == 3 && ix[5] == 4, "IndexedLineSet pairs");
        EXPECT_MSG(col_of(p, 0)[0] == 1.0f && col_of(p, 2)[0] == 1.0f && col_of(p, 3)[1] == 1.0f && col_of(p, 4)[1] == 1.0f,
                   "IndexedLineSet: colour per polyline");
    } else {
        EXPECT_MSG(false, "IndexedLineSet: colours and indices");
    }
    p = prim_named(&l, "ILSV");
    EXPECT_MSG(p && p->colors && sy_primitive_element_count(p) == 2 && col_of(p, 0)[2] == 1.0f && col_of(p, 0)[3] == 0.5f &&
               col_of(p, 2)[0] == 1.0f,
               "IndexedLineSet: colour per vertex through colorIndex (RGBA)");
    p = prim_named(&l, "LS");
    EXPECT_MSG(p && p->topology == SY_TOPOLOGY_LINES && sy_primitive_element_count(p) == 3 && sy_primitive_vertex_count(p) == 5,
               "LineSet vertexCount 2 3: 3 segments");
    if (p && p->indices) {
        const uint32_t *ix = idx_of(p);
        EXPECT_MSG(ix[0] == 0 && ix[1] == 1 && ix[2] == 2 && ix[3] == 3 && ix[4] == 3 && ix[5] == 4, "LineSet pairs");
    }
    EXPECT_MSG(l.info.counts.points == 4 && l.info.counts.line_segments == 3 + 2 + 3, "counts: %u points, %u segments",
               l.info.counts.points, l.info.counts.line_segments);
    /* mesh bounds include half the stroke width: LineSet spans 2 x 1, diagonal sqrt(5) */
    sy_bounds b;
    uint32_t mid = 0;
    for (uint32_t id = sy_scene_next(l.scene, SY_TYPE_MESH, 0); id; id = sy_scene_next(l.scene, SY_TYPE_MESH, id))
        if (prim_named(&l, "LS") == &((const sy_mesh_data *)sy_object_get(l.scene, SY_TYPE_MESH, id))->primitives.items[0]) mid = id;
    float half = 0.5f * SY_STROKE_LINE_FRACTION * sqrtf(5.0f);
    EXPECT_MSG(mid && sy_mesh_bounds(l.scene, (sy_mesh){mid}, &b, NULL) == SY_OK && fabsf(b.min[0] + half) < 1e-5f &&
               fabsf(b.max[0] - 2.0f - half) < 1e-5f && fabsf(b.max[2] - half) < 1e-5f,
               "LineSet bounds grown by half the width %g: [%g %g]", (double)half, (double)b.min[0], (double)b.max[0]);
    unload(&l);

    /* bad input: warned with file:line, geometry skipped, the rest loads */
    l = load_text("bad_strokes.x3d",
        "<X3D><Scene>\n"
        "<Shape><IndexedLineSet coordIndex='0 7'><Coordinate point='0 0 0 1 0 0'/></IndexedLineSet></Shape>\n"
        "<Shape><LineSet vertexCount='1'><Coordinate point='0 0 0 1 0 0'/></LineSet></Shape>\n"
        "<Shape><LineSet vertexCount='3'><Coordinate point='0 0 0 1 0 0'/></LineSet></Shape>\n"
        "<Shape><IndexedLineSet coordIndex='0 1' colorIndex='5'><Coordinate point='0 0 0 1 0 0'/><Color color='1 1 1'/></IndexedLineSet></Shape>\n"
        "<Shape><PointSet><Coordinate point='0 0 0 1 0 0'/><Color color='1 1 1'/></PointSet></Shape>\n"
        "</Scene></X3D>\n");
    EXPECT_MSG(l.r == SY_OK && sy_scene_count(l.scene, SY_TYPE_MESH) == 0 && l.info.counts.skipped_geometry == 5,
               "bad strokes skipped: %u meshes, %u skipped (%s)", sy_scene_count(l.scene, SY_TYPE_MESH),
               l.info.counts.skipped_geometry, l.err.message);
    EXPECT_MSG(has_warning(&l, "bad_strokes.x3d:2:", "coordIndex[1] = 7"), "out-of-range coordIndex named with file:line");
    EXPECT_MSG(has_warning(&l, "bad_strokes.x3d:3:", "less than 2"), "vertexCount 1 warned");
    EXPECT_MSG(has_warning(&l, "bad_strokes.x3d:4:", "more than the 2 points"), "vertexCount past the points warned");
    EXPECT_MSG(has_warning(&l, "bad_strokes.x3d:5:", "outside the 1 colours"), "bad colorIndex warned");
    EXPECT_MSG(has_warning(&l, "bad_strokes.x3d:6:", "1 colours for 2 vertices"), "too few PointSet colours warned");
    unload(&l);
}

static void test_background(void)
{
    loaded l = load_text("bg.x3d",
        "<X3D><Scene>\n"
        "<Background skyColor='0 0 1 0 1 0 1 0 0' skyAngle='0.8 1.6' groundColor='0.2 0.2 0.2 0.5 0.5 0.5'"
        " groundAngle='1.5708'/>\n"
        "</Scene></X3D>\n");
    expect_loaded(&l, "background");
    const sy_background_data *bd = sy_background_get(l.scene, l.info.background);
    EXPECT_MSG(bd && bd->color[3] == 0.0f && bd->gradient.sky_count == 3 && bd->gradient.ground_count == 2 &&
               bd->gradient.sky_angle[0] == 0.8f && bd->gradient.sky_angle[1] == 1.6f &&
               bd->gradient.sky_color[2][0] == 1.0f && bd->gradient.ground_color[1][0] == 0.5f &&
               fabsf(bd->gradient.ground_angle[0] - 1.5707964f) < 1e-7f,
               "gradient: 3 sky / 2 ground colours, 1.5708 taken as pi/2, colour transparent");
    EXPECT_MSG(l.info.warning_count == 0, "no warnings, got %u", l.info.warning_count);
    /* the user's --background replaces the file's gradient (sy_world_apply): a transparent background
     * for compositing showed the sky before */
    sy_world_options wo = {.has_background = true, .background = {0, 0, 0, 0}};
    sy_background world = l.info.background;
    sy_error we = {0};
    EXPECT_MSG(sy_world_apply(l.scene, &world, &wo, &we) == SY_OK, "world: %s", we.message);
    bd = sy_background_get(l.scene, world);
    EXPECT_MSG(world.id == l.info.background.id && bd && bd->gradient.sky_count == 0 && bd->gradient.ground_count == 0 &&
                   bd->color[3] == 0.0f,
               "--background: the gradient is gone (%u sky, %u ground colours)", bd ? bd->gradient.sky_count : 0,
               bd ? bd->gradient.ground_count : 0);
    unload(&l);

    /* angles out of order, too many colours */
    char big[2048] = "<X3D><Scene>\n<TextureBackground skyColor='";
    for (int k = 0; k < 10; k++) strcat(big, "0.1 0.1 0.1 ");
    strcat(big, "' skyAngle='0.1 0.2 0.3 0.4 0.5 0.6 0.7 0.8 0.9'\n groundColor='0 0 0 1 1 1 0 0 0' groundAngle='1.0 0.5'/>\n"
                "</Scene></X3D>\n");
    l = load_text("bg_bad.x3d", big);
    bd = sy_background_get(l.scene, l.info.background);
    EXPECT_MSG(l.r == SY_OK && bd && bd->gradient.sky_count == SY_GRADIENT_MAX && bd->gradient.ground_count == 1,
               "cut to %u sky colours, ground angles out of order -> one ground colour: %u / %u", SY_GRADIENT_MAX,
               bd ? bd->gradient.sky_count : 0, bd ? bd->gradient.ground_count : 0);
    EXPECT_MSG(has_warning(&l, "bg_bad.x3d:3:", "10 colours, only the first 8"), "too many colours warned with file:line");
    EXPECT_MSG(has_warning(&l, "bg_bad.x3d:3:", "groundAngle[1] = 0.5 must increase"), "angles out of order warned");
    for (uint32_t k = 0; k < l.info.stored_warning_count; k++) printf("  bg_bad warning: %s\n", l.info.warnings[k]);
    unload(&l);
}

static void test_text(void)
{
    const char *font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
    if (access(font, R_OK) != 0) {
        printf("SKIP text: %s absent (fonts-dejavu-core)\n", font);
        return;
    }
    /* the triangulation itself: a square with a square hole = 8 triangles, area 16 - 4 */
    double xy[] = {0, 0, 4, 0, 4, 4, 0, 4, 1, 1, 1, 3, 3, 3, 3, 1};
    size_t rs[] = {0, 4, 8};
    uint32_t tris[3 * SY_TEXT_TRIANGULATE_CAPACITY(8, 2)];
    size_t nt = sy_text_triangulate(xy, 8, rs, 2, tris);
    double area = 0;
    bool ccw = true;
    for (size_t t = 0; t < nt; t++) {
        const double *a = xy + 2 * tris[3 * t], *b = xy + 2 * tris[3 * t + 1], *c = xy + 2 * tris[3 * t + 2];
        double cr = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        ccw = ccw && cr > 0;
        area += cr / 2;
    }
    EXPECT_MSG(nt == 8 && fabs(area - 12.0) < 1e-9 && ccw, "square with hole: %zu triangles, area %g", nt, area);

    loaded l = load_text("text.x3d",
        "<X3D><Scene>\n"
        "<Shape DEF='T'><Appearance><Material diffuseColor='1 1 0'/></Appearance>\n"
        "  <Text string='\"Hello\" \"gO8\"'><FontStyle family='\"SANS\"' justify='\"MIDDLE\" \"MIDDLE\"' size='2' spacing='1.5'/></Text></Shape>\n"
        "<Shape DEF='O'><Text string='\"O\"'><FontStyle family='\"TYPEWRITER\"'/></Text></Shape>\n"
        "</Scene></X3D>\n");
    EXPECT_MSG(l.r == SY_OK && l.info.counts.texts == 2, "text: %s, %u texts", l.err.message, l.info.counts.texts);
    const sy_primitive *p = prim_named(&l, "T");
    EXPECT_MSG(p && p->topology == SY_TOPOLOGY_TRIANGLES && sy_primitive_triangle_count(p) > 100 && p->normals,
               "Text: triangles with normals, got %u", p ? sy_primitive_triangle_count(p) : 0);
    if (p) {
        sy_bounds b = sy_primitive_position_bounds(p);
        /* MIDDLE/MIDDLE: centred on x = 0; two lines of size 2 with spacing 1.5 (3 units apart):
         * the block is about 2 * ascender-ish high, centred near y = 0; flat in z = 0 */
        EXPECT_MSG(fabsf(b.min[0] + b.max[0]) < 0.2f && b.max[0] > 2.0f && b.max[0] < 6.0f && b.min[2] == 0.0f &&
                   b.max[2] == 0.0f && b.max[1] > 1.0f && b.min[1] < -1.5f && fabsf(b.max[1] + b.min[1]) < 1.0f,
                   "Text bounds [%g %g %g] [%g %g %g]", (double)b.min[0], (double)b.min[1], (double)b.min[2],
                   (double)b.max[0], (double)b.max[1], (double)b.max[2]);
        /* every triangle faces +Z */
        const float *v = sy_blob_data(p->positions);
        const uint32_t *ix = sy_blob_data(p->indices);
        uint32_t bad = 0;
        for (uint32_t t = 0; t < sy_primitive_triangle_count(p); t++) {
            const float *a = v + 3 * ix[3 * t], *bb = v + 3 * ix[3 * t + 1], *c = v + 3 * ix[3 * t + 2];
            if ((bb[0] - a[0]) * (c[1] - a[1]) - (bb[1] - a[1]) * (c[0] - a[0]) <= 0) bad++;
        }
        EXPECT_MSG(bad == 0, "%u triangles not facing +Z", bad);
    }
    /* "O" has a hole: its area is the ring's, well below the filled outline's box */
    p = prim_named(&l, "O");
    if (p) {
        const float *v = sy_blob_data(p->positions);
        const uint32_t *ix = sy_blob_data(p->indices);
        double a = 0;
        for (uint32_t t = 0; t < sy_primitive_triangle_count(p); t++) {
            const float *x = v + 3 * ix[3 * t], *y = v + 3 * ix[3 * t + 1], *z = v + 3 * ix[3 * t + 2];
            a += 0.5 * ((y[0] - x[0]) * (z[1] - x[1]) - (y[1] - x[1]) * (z[0] - x[0]));
        }
        sy_bounds b = sy_primitive_position_bounds(p);
        double box = (double)(b.max[0] - b.min[0]) * (b.max[1] - b.min[1]);
        EXPECT_MSG(a > 0.2 * box && a < 0.6 * box, "O: area %g of box %g (the hole is open)", a, box);
    } else {
        EXPECT_MSG(false, "O: no primitive");
    }
    unload(&l);

    /* a family we do not have falls back to SERIF; an unknown style letter is PLAIN; strings absent: nothing */
    l = load_text("text2.x3d", "<X3D><Scene><Shape><Text/></Shape></Scene></X3D>\n");
    EXPECT_MSG(l.r == SY_OK && sy_scene_count(l.scene, SY_TYPE_MESH) == 0, "Text without string: no mesh");
    unload(&l);
}

/* Shared sample files with these nodes: counts from the file's own attributes. */
static void test_samples(const char *data)
{
    char p[2048];
    if (!sample_path(data, "x3d/web3d/X3dForWebAuthors/Chapter02GeometryPrimitives/GeometryPrimitiveNodes.x3d", p, sizeof p))
        return;
    sy_scene *s;
    sy_x3d_info info;
    sy_error e;
    memset(&info, 0, sizeof info);
    if (sy_scene_create(&s, NULL) != SY_OK) exit(1);
    sy_result r = sy_x3d_load(p, s, NULL, &info, &e);
    EXPECT_MSG(r == SY_OK, "%s: %s", p, e.message);
    /* the file holds 3 Text nodes (one per label row) */
    EXPECT_MSG(info.counts.texts >= 1, "GeometryPrimitiveNodes: %u Text nodes loaded", info.counts.texts);
    printf("GeometryPrimitiveNodes.x3d: %u texts, %u meshes, %u triangles, %u warnings\n", info.counts.texts,
           info.counts.meshes, info.counts.triangles, info.warning_count);
    sy_x3d_info_free(&info);
    sy_scene_destroy(s);
}

X3D_MAIN("x3d_strokes", test_samples, test_strokes, test_background, test_text)
