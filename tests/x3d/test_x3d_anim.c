/* test_x3d_anim.c — X3D TimeSensors, Position- and OrientationInterpolators and ROUTEs played by the
 * scene clock (formats/sy_x3d_anim.c, issue 35): a file written here with known keys gives one clip
 * per sensor (DEF name, cycleInterval as its period, loop), node transforms at given times equal
 * the X3D interpolation computed here (key x cycleInterval, linear positions, orientations along
 * the shorter arc, looping sensors wrapping), equal keys jump, and what does not map is reported
 * naming the file and line: mismatched key / keyValue counts, decreasing keys, other
 * interpolators, routes to other fields or undefined nodes, Transforms with a center; the
 * shared sample HelloX3dTrademark.x3d (a spinning Earth) turns a quarter every 3 s.
 * Usage: test_x3d_anim [TESTDATA_DIR]. */
#include "sy_anim.h"
#include "x3d_loaded.h"

#include <math.h>

#define PI_F_TEST 3.14159265f

static sy_node node_named(const loaded *l, const char *name)
{
    for (uint32_t id = sy_scene_next(l->scene, SY_TYPE_NODE, 0); id; id = sy_scene_next(l->scene, SY_TYPE_NODE, id)) {
        const sy_node_data *n = sy_object_get(l->scene, SY_TYPE_NODE, id);
        if (n->name && !strcmp(n->name, name)) return (sy_node){id};
    }
    return (sy_node){0};
}

static const float *pos(const loaded *l, sy_node n) { return sy_node_get(l->scene, n)->transform.translation; }
static const float *rot(const loaded *l, sy_node n) { return sy_node_get(l->scene, n)->transform.rotation; }

/* the angle of quaternion q about +y (q = (0, sin a/2, 0, cos a/2)), in (-pi, pi] */
static float yaw(const float q[4]) { return 2.0f * atan2f(q[1], q[3]); }

static void set_time(const loaded *l, double t)
{
    sy_error e = {0};
    EXPECT_MSG(sy_scene_set_time(l->scene, (sy_animation){0}, t, &e) == SY_OK, "set_time %g: %s", t, e.message);
}

static void test_routes(void)
{
    loaded l = load_text("anim.x3d",
        "<X3D><Scene>\n"
        "<Transform DEF='Mover'><Shape><Box/></Shape></Transform>\n"                                   /* 2 */
        "<Transform DEF='Spinner' translation='5 0 0'><Shape><Sphere/></Shape></Transform>\n"          /* 3 */
        "<Transform DEF='Pivot' center='1 0 0'><Shape><Box/></Shape></Transform>\n"                    /* 4 */
        "<TimeSensor DEF='Clock' cycleInterval='4' loop='true'/>\n"                                    /* 5 */
        "<PositionInterpolator DEF='Path' key='0 0.5 0.5 1' keyValue='0 0 0 2 0 0 2 4 0 2 4 8'/>\n"  /* 6 */
        "<OrientationInterpolator DEF='Turn' key='0 1' keyValue='0 1 0 0 0 1 0 3'/>\n"                 /* 7 */
        "<PositionInterpolator DEF='Short' key='0 1' keyValue='0 0 0'/>\n"                             /* 8 */
        "<PositionInterpolator DEF='Back' key='0 1 0.5' keyValue='0 0 0 1 1 1 2 2 2'/>\n"              /* 9 */
        "<ColorInterpolator DEF='Tint' key='0 1' keyValue='1 0 0 0 0 1'/>\n"                           /* 10 */
        "<TimeSensor DEF='Once' cycleInterval='2'/>\n"                                                 /* 11 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Path' toField='set_fraction'/>\n" /* 12 */
        "<ROUTE fromNode='Path' fromField='value_changed' toNode='Mover' toField='set_translation'/>\n" /* 13 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Turn' toField='set_fraction'/>\n" /* 14 */
        "<ROUTE fromNode='Turn' fromField='value_changed' toNode='Spinner' toField='rotation'/>\n"      /* 15 */
        "<ROUTE fromNode='Turn' fromField='value_changed' toNode='Pivot' toField='rotation'/>\n"        /* 16 */
        "<ROUTE fromNode='Once' fromField='fraction_changed' toNode='Short' toField='set_fraction'/>\n" /* 17 */
        "<ROUTE fromNode='Short' fromField='value_changed' toNode='Mover' toField='translation'/>\n"    /* 18 */
        "<ROUTE fromNode='Once' fromField='fraction_changed' toNode='Back' toField='set_fraction'/>\n"  /* 19 */
        "<ROUTE fromNode='Back' fromField='value_changed' toNode='Mover' toField='translation'/>\n"     /* 20 */
        "<ROUTE fromNode='Once' fromField='fraction_changed' toNode='Tint' toField='set_fraction'/>\n"  /* 21 */
        "<ROUTE fromNode='Path' fromField='value_changed' toNode='Mover' toField='scale'/>\n"           /* 22 */
        "<ROUTE fromNode='Path' fromField='value_changed' toNode='Nowhere' toField='translation'/>\n"   /* 23 */
        "</Scene></X3D>\n");
    EXPECT_MSG(l.r == SY_OK, "anim.x3d: %s", l.err.message);
    if (l.r != SY_OK) return unload(&l);
    /* one clip: Clock (Once drives nothing playable: Short and Back are dropped, Tint not played) */
    EXPECT_MSG(sy_scene_count(l.scene, SY_TYPE_ANIMATION) == 1 && l.info.counts.animations == 1, "%u clips (want 1)",
               sy_scene_count(l.scene, SY_TYPE_ANIMATION));
    sy_animation clip = {sy_scene_next(l.scene, SY_TYPE_ANIMATION, 0)};
    const sy_animation_data *ad = sy_animation_get(l.scene, clip);
    uint32_t nch = 0;
    if (ad) sy_animation_channels(ad, &nch);
    EXPECT_MSG(ad && ad->name && !strcmp(ad->name, "Clock") && ad->cycle == 4.0f && ad->loop == 1 && nch == 2,
               "clip Clock, period 4, loop, 2 channels: %s %g %u %u", ad && ad->name ? ad->name : "-",
               ad ? (double)ad->cycle : 0.0, ad ? ad->loop : 0, nch);
    EXPECT_MSG(has_warning(&l, "anim.x3d:8: PositionInterpolator: 2 keys and 1 key values", NULL), "Short's counts");
    EXPECT_MSG(has_warning(&l, "anim.x3d:9: PositionInterpolator: key 2 (0.5) is less than the key before it", NULL),
               "Back's keys");
    EXPECT_MSG(has_warning(&l, "anim.x3d:10: ColorInterpolator: not played", NULL), "ColorInterpolator");
    EXPECT_MSG(has_warning(&l, "anim.x3d:16:", "center or scaleOrientation"), "Pivot has a center");
    EXPECT_MSG(has_warning(&l, "anim.x3d:22: ROUTE from a PositionInterpolator to Transform.scale: not played", NULL),
               "route to scale");
    EXPECT_MSG(has_warning(&l, "anim.x3d:23: ROUTE to 'Nowhere'", "not DEFined"), "route to an undefined node");
    sy_node mover = node_named(&l, "Mover"), spinner = node_named(&l, "Spinner");
    /* Path: fraction f = (t mod 4) / 4; 0 -> (0,0,0), 0.5 -> (2,0,0) then the jump to (2,4,0) (one
     * float step after 2 s), 1 -> (2,4,8) */
    struct { double t; float x, y, z; } pt[] = {{0.0, 0, 0, 0}, {1.0, 1, 0, 0}, {2.0 - 1e-3, 1.999f, 0, 0}, {2.0 + 1e-4, 2, 4, 0},
                                               {3.0, 2, 4, 4}, {5.0, 1, 0, 0}, {-3.0, 1, 0, 0}};
    for (size_t i = 0; i < sizeof pt / sizeof pt[0]; ++i) {
        set_time(&l, pt[i].t);
        const float *p = pos(&l, mover);
        EXPECT_MSG(fabsf(p[0] - pt[i].x) < 2e-3f && fabsf(p[1] - pt[i].y) < 2e-3f && fabsf(p[2] - pt[i].z) < 2e-3f,
                   "Mover at t = %g: (%g %g %g), want (%g %g %g)", pt[i].t, (double)p[0], (double)p[1], (double)p[2],
                   (double)pt[i].x, (double)pt[i].y, (double)pt[i].z);
    }
    /* Turn: 0 to 3 rad about +y over 4 s (less than pi: the shorter arc is the key order's); its
     * translation stays the file's */
    set_time(&l, 2.0);
    EXPECT_MSG(fabsf(yaw(rot(&l, spinner)) - 1.5f) < 1e-4f && pos(&l, spinner)[0] == 5.0f, "Spinner at t = 2: yaw %g (want 1.5)",
               (double)yaw(rot(&l, spinner)));
    unload(&l);
}

/* the shared sample: OrbitalTimeInterval (12 s, loop) turns EarthCoordinateSystem 2 pi about +y in
 * four quarter keys */
static void test_sample(const char *data)
{
    if (!data) {
        printf("skip: HelloX3dTrademark.x3d: no TESTDATA_DIR given\n");
        return;
    }
    char p[2048];
    PATHF(p, "%s/x3d/assimp_debian_testmodels/HelloX3dTrademark.x3d", data);
    FILE *f = fopen(p, "rb");
    if (!f) {
        printf("skip: %s is absent\n", p);
        return;
    }
    fclose(f);
    loaded l = load_path(p);
    EXPECT_MSG(l.r == SY_OK && sy_scene_count(l.scene, SY_TYPE_ANIMATION) == 1, "HelloX3dTrademark: %s, %u clips", l.err.message,
               sy_scene_count(l.scene, SY_TYPE_ANIMATION));
    sy_node earth = node_named(&l, "EarthCoordinateSystem");
    const double t[4] = {1.5, 3.0, 4.5, 13.5}; /* 13.5 wraps to 1.5 */
    const float want[4] = {0.25f * PI_F_TEST, 0.5f * PI_F_TEST, 0.75f * PI_F_TEST, 0.25f * PI_F_TEST};
    for (int i = 0; l.r == SY_OK && earth.id && i < 4; ++i) {
        set_time(&l, t[i]);
        EXPECT_MSG(fabsf(yaw(rot(&l, earth)) - want[i]) < 1e-3f, "Earth at t = %g: yaw %g (want %g)", t[i],
                   (double)yaw(rot(&l, earth)), (double)want[i]);
    }
    EXPECT_MSG(earth.id != 0, "EarthCoordinateSystem node");
    unload(&l);
}

int main(int argc, char **argv)
{
    make_scratch_dir(g_dir, sizeof g_dir, "x3d_anim");
    test_routes();
    test_sample(argc > 1 ? argv[1] : NULL);
    remove_scratch_dir(g_dir);
    return sy_check_finish("x3d_anim");
}
