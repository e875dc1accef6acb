/* test_x3d_anim.c — X3D TimeSensors, Position- and OrientationInterpolators and ROUTEs played by the
 * scene clock (formats/sy_x3d_anim.c, issue 35): a file written here with known keys gives one clip
 * per sensor (DEF name, cycleInterval as its period, loop), node transforms at given times equal
 * the X3D interpolation computed here (key x cycleInterval, linear positions, orientations along
 * the shorter arc, looping sensors wrapping), equal keys jump, and what does not map is reported
 * naming the file and line: mismatched key / keyValue counts, decreasing keys, routes to undefined
 * nodes; Transforms with a center or scaleOrientation play (the children's world origin at two
 * times against X3D's T C R SR S -SR -C), a scale route under a scaleOrientation is warned. test_fields: Color- and ScalarInterpolators into Material,
 * PhysicalMaterial, light and Viewpoint fields, positions and orientations into a Viewpoint and
 * a light's direction, at two times against X3D's interpolation computed here (HSV colours,
 * 1 - transparency, intensities scaled as the loader scales the lights); routes whose types differ,
 * that close a loop or come from undefined nodes, and the interpolators whose targets are not
 * animated are warned about, naming the ROUTE's line; test_coordinates:
 * a CoordinateInterpolator becomes morph targets and weights on every node showing the mesh; the
 * shared sample HelloX3dTrademark.x3d (a spinning Earth) turns a quarter every 3 s; test_textures:
 * PositionInterpolator2D into TextureTransform translation and scale (about a center) and
 * CoordinateInterpolator2D into TextureCoordinate.point become texture coordinate morph targets
 * whose blend at three times is X3D's transformed coordinate; mismatched counts and values that
 * are not finite are refused, naming the interpolator's DEF, and points per key that do not match
 * the TextureCoordinate's, naming both lines.
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
        "<Transform DEF='Slider' center='0 1 0' translation='3 0 0' rotation='0 0 1 0.5'><Shape><Box/></Shape>"
        "</Transform>\n"                                                                                 /* 24 */
        "<ROUTE fromNode='Path' fromField='value_changed' toNode='Slider' toField='translation'/>\n"    /* 25 */
        "<Transform DEF='Squash' center='1 0 0' scaleOrientation='0 0 1 0.3'><Shape><Box/></Shape></Transform>\n" /* 26 */
        "<ROUTE fromNode='Path' fromField='value_changed' toNode='Squash' toField='scale'/>\n"         /* 27 */
        "<ROUTE fromNode='Turn' fromField='value_changed' toNode='Squash' toField='rotation'/>\n"      /* 28 */
        "</Scene></X3D>\n");
    if (!expect_loaded(&l, "anim.x3d")) return unload(&l);
    /* one clip: Clock (Once drives nothing playable: Short and Back are dropped, Tint not played) */
    EXPECT_MSG(sy_scene_count(l.scene, SY_TYPE_ANIMATION) == 1 && l.info.counts.animations == 1, "%u clips (want 1)",
               sy_scene_count(l.scene, SY_TYPE_ANIMATION));
    sy_animation clip = {sy_scene_next(l.scene, SY_TYPE_ANIMATION, 0)};
    const sy_animation_data *ad = sy_animation_get(l.scene, clip);
    uint32_t nch = 0;
    if (ad) sy_animation_channels(ad, &nch);
    /* Mover's translation and scale, Spinner's, Pivot's and Squash's rotations, Slider's translation */
    EXPECT_MSG(ad && ad->name && !strcmp(ad->name, "Clock") && ad->cycle == 4.0f && ad->loop == 1 && nch == 6,
               "clip Clock, period 4, loop, 6 channels: %s %g %u %u", ad && ad->name ? ad->name : "-",
               ad ? (double)ad->cycle : 0.0, ad ? ad->loop : 0, nch);
    EXPECT_MSG(has_warning(&l, "anim.x3d:8: PositionInterpolator: 2 keys and 1 key values", NULL), "Short's counts");
    EXPECT_MSG(has_warning(&l, "anim.x3d:9: PositionInterpolator: key 2 (0.5) is less than the key before it", NULL),
               "Back's keys");
    EXPECT_MSG(!has_warning(&l, "anim.x3d:16:", NULL), "Pivot's center: played, not warned");
    EXPECT_MSG(has_warning(&l, "anim.x3d:27: ROUTE to the scale of a Transform with a scaleOrientation", NULL),
               "a scale route under a scaleOrientation is not played (warned)");
    EXPECT_MSG(has_warning(&l, "anim.x3d:23: ROUTE to 'Nowhere'", "not DEFined"), "route to an undefined node");
    sy_node mover = node_named(&l, "Mover"), spinner = node_named(&l, "Spinner");
    /* Path: fraction f = (t mod 4) / 4; 0 -> (0,0,0), 0.5 -> (2,0,0) then the jump to (2,4,0) (one
     * float step after 2 s), 1 -> (2,4,8) */
    struct { double t; float x, y, z; } pt[] = {{0.0, 0, 0, 0}, {1.0, 1, 0, 0}, {2.0 - 1e-3, 1.999f, 0, 0}, {2.0 + 1e-4, 2, 4, 0},
                                               {3.0, 2, 4, 4}, {5.0, 1, 0, 0}, {-3.0, 1, 0, 0}};
    for (size_t i = 0; i < sizeof pt / sizeof pt[0]; ++i) {
        set_time(&l, pt[i].t);
        const float *p = pos(&l, mover), *sc = sy_node_get(l.scene, mover)->transform.scale;
        /* Path also drives Mover's scale (a later route in the file: both apply, in the clip's order) */
        EXPECT_MSG(fabsf(sc[0] - pt[i].x) < 2e-3f && fabsf(sc[1] - pt[i].y) < 2e-3f && fabsf(sc[2] - pt[i].z) < 2e-3f,
                   "Mover's scale at t = %g: (%g %g %g)", pt[i].t, (double)sc[0], (double)sc[1], (double)sc[2]);
        EXPECT_MSG(fabsf(p[0] - pt[i].x) < 2e-3f && fabsf(p[1] - pt[i].y) < 2e-3f && fabsf(p[2] - pt[i].z) < 2e-3f,
                   "Mover at t = %g: (%g %g %g), want (%g %g %g)", pt[i].t, (double)p[0], (double)p[1], (double)p[2],
                   (double)pt[i].x, (double)pt[i].y, (double)pt[i].z);
    }
    /* Turn: 0 to 3 rad about +y over 4 s (less than pi: the shorter arc is the key order's); its
     * translation stays the file's */
    set_time(&l, 2.0);
    EXPECT_MSG(fabsf(yaw(rot(&l, spinner)) - 1.5f) < 1e-4f && pos(&l, spinner)[0] == 5.0f, "Spinner at t = 2: yaw %g (want 1.5)",
               (double)yaw(rot(&l, spinner)));
    /* Transforms with a center (their node split in two at the first route, x3d_pivot): the world
     * matrix is X3D's T C R SR S -SR -C with the routed field at its value of the time; the
     * origin of the Transform's children lands at T + C + R SR S -SR (-C) */
    static const struct { const char *name; double t; float o[3]; } pv[] = {
        {"Pivot", 2.0, {1.0f - cosf(1.5f), 0.0f, sinf(1.5f)}},  /* C R(t) -C, R about y */
        {"Squash", 2.0, {1.0f - cosf(1.5f), 0.0f, sinf(1.5f)}}, /* the same: SR S -SR = 1 (scale not played) */
        {"Slider", 1.0, {1.0f + sinf(0.5f), 1.0f - cosf(0.5f), 0.0f}}, /* T(t) C R -C: T(1) = (1, 0, 0), R about z */
        {"Slider", 3.0, {2.0f + sinf(0.5f), 5.0f - cosf(0.5f), 4.0f}}, /* T(3) = (2, 4, 4) */
    };
    for (size_t i = 0; i < sizeof pv / sizeof pv[0]; ++i) {
        set_time(&l, pv[i].t);
        sy_error ce = {0};
        EXPECT_MSG(sy_scene_commit(l.scene, NULL, &ce) == SY_OK, "commit: %s", ce.message); /* world matrices */
        sy_node n = node_named(&l, pv[i].name);
        const sy_node_data *nd = sy_node_get(l.scene, n);
        uint32_t nk = 0;
        const uint32_t *kids = nd ? sy_node_children(nd, &nk) : NULL;
        sy_mat4 w = sy_mat4_identity();
        sy_error e = {0};
        bool ok = nk == 1 && sy_node_world_matrix(l.scene, (sy_node){kids[0]}, &w, &e) == SY_OK;
        EXPECT_MSG(ok && fabsf(w.m[12] - pv[i].o[0]) < 1e-4f && fabsf(w.m[13] - pv[i].o[1]) < 1e-4f &&
                       fabsf(w.m[14] - pv[i].o[2]) < 1e-4f,
                   "%s at t = %g: children's origin (%g %g %g), want (%g %g %g) (%u pivot children)", pv[i].name,
                   pv[i].t, (double)w.m[12], (double)w.m[13], (double)w.m[14], (double)pv[i].o[0], (double)pv[i].o[1],
                   (double)pv[i].o[2], nk);
    }
    unload(&l);
}

static const sy_material_data *material_named(const loaded *l, const char *name)
{
    for (uint32_t id = sy_scene_next(l->scene, SY_TYPE_MATERIAL, 0); id; id = sy_scene_next(l->scene, SY_TYPE_MATERIAL, id)) {
        const sy_material_data *m = sy_object_get(l->scene, SY_TYPE_MATERIAL, id);
        if (m->name && !strcmp(m->name, name)) return m;
    }
    return NULL;
}

/* X3D's HSV interpolation of red (hue 0) to blue (hue 240 degrees), the shorter way (through
 * magenta, 300): hue 360 - 120 u, full saturation and value */
static void red_to_blue(float u, float c[3])
{
    float h = 360.0f - 120.0f * u; /* in [240, 360]: from blue (240) through magenta (300) to red */
    if (h >= 300.0f) c[0] = 1.0f, c[1] = 0.0f, c[2] = (360.0f - h) / 60.0f;
    else c[0] = (h - 240.0f) / 60.0f, c[1] = 0.0f, c[2] = 1.0f;
}

static bool near3(const float *a, const float *b, float tol)
{
    return fabsf(a[0] - b[0]) < tol && fabsf(a[1] - b[1]) < tol && fabsf(a[2] - b[2]) < tol;
}

static void test_fields(void)
{
    loaded l = load_text("fields.x3d",
        "<X3D><Scene>\n"
        "<Viewpoint DEF='Cam' position='0 0 10'/>\n"                                                            /* 2 */
        "<PointLight DEF='Lamp' location='0 5 0' attenuation='0 0 2'/>\n"                                       /* 3 */
        "<DirectionalLight DEF='Sun' direction='0 0 -1' intensity='0.5'/>\n"                                    /* 4 */
        "<Shape><Appearance><Material DEF='Paint' diffuseColor='1 0 0'/></Appearance><Box/></Shape>\n"          /* 5 */
        "<Shape><Appearance><PhysicalMaterial DEF='Metal' baseColor='1 1 1'/></Appearance><Sphere/></Shape>\n"  /* 6 */
        "<Shape><IndexedFaceSet coordIndex='0 1 2'><Coordinate DEF='Pts' point='0 0 0 1 0 0 0 1 0'/></IndexedFaceSet></Shape>\n" /* 7 */
        "<TimeSensor DEF='Clock' cycleInterval='2'/>\n"                                                         /* 8 */
        "<ColorInterpolator DEF='Hue' key='0 1' keyValue='1 0 0 0 0 1'/>\n"                                     /* 9 */
        "<ScalarInterpolator DEF='Fade' key='0 1' keyValue='0 0.8'/>\n"                                         /* 10 */
        "<ScalarInterpolator DEF='Bright' key='0 1' keyValue='1 3'/>\n"                                         /* 11 */
        "<ScalarInterpolator DEF='Zoom' key='0 1' keyValue='0.5 1.0'/>\n"                                       /* 12 */
        "<PositionInterpolator DEF='Dolly' key='0 1' keyValue='0 0 10 0 0 20'/>\n"                              /* 13 */
        "<OrientationInterpolator DEF='Pan' key='0 1' keyValue='0 1 0 0 0 1 0 1'/>\n"                           /* 14 */
        "<PositionInterpolator DEF='Aim' key='0 1' keyValue='0 0 -1 1 0 0'/>\n"                                 /* 15 */
        "<ScalarInterpolator DEF='Rough' key='0 1' keyValue='0.2 0.6'/>\n"                                      /* 16 */
        "<CoordinateInterpolator DEF='Morph' key='0 1' keyValue='0 0 0 1 1 1'/>\n"                              /* 17 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Hue' toField='set_fraction'/>\n"          /* 18 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Fade' toField='set_fraction'/>\n"         /* 19 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Bright' toField='set_fraction'/>\n"       /* 20 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Zoom' toField='set_fraction'/>\n"         /* 21 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Dolly' toField='set_fraction'/>\n"        /* 22 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Pan' toField='set_fraction'/>\n"          /* 23 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Aim' toField='set_fraction'/>\n"          /* 24 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Rough' toField='set_fraction'/>\n"        /* 25 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Morph' toField='set_fraction'/>\n"        /* 26 */
        "<ROUTE fromNode='Hue' fromField='value_changed' toNode='Paint' toField='set_diffuseColor'/>\n"         /* 27 */
        "<ROUTE fromNode='Hue' fromField='value_changed' toNode='Lamp' toField='color'/>\n"                     /* 28 */
        "<ROUTE fromNode='Hue' fromField='value_changed' toNode='Metal' toField='emissiveColor'/>\n"            /* 29 */
        "<ROUTE fromNode='Fade' fromField='value_changed' toNode='Paint' toField='transparency'/>\n"            /* 30 */
        "<ROUTE fromNode='Bright' fromField='value_changed' toNode='Sun' toField='intensity'/>\n"               /* 31 */
        "<ROUTE fromNode='Bright' fromField='value_changed' toNode='Lamp' toField='intensity'/>\n"              /* 32 */
        "<ROUTE fromNode='Zoom' fromField='value_changed' toNode='Cam' toField='fieldOfView'/>\n"               /* 33 */
        "<ROUTE fromNode='Dolly' fromField='value_changed' toNode='Cam' toField='position'/>\n"                 /* 34 */
        "<ROUTE fromNode='Pan' fromField='value_changed' toNode='Cam' toField='orientation'/>\n"                /* 35 */
        "<ROUTE fromNode='Aim' fromField='value_changed' toNode='Sun' toField='direction'/>\n"                  /* 36 */
        "<ROUTE fromNode='Rough' fromField='value_changed' toNode='Metal' toField='roughness'/>\n"              /* 37 */
        "<ROUTE fromNode='Dolly' fromField='value_changed' toNode='Paint' toField='diffuseColor'/>\n"           /* 38 */
        "<ROUTE fromNode='Morph' fromField='value_changed' toNode='Pts' toField='point'/>\n"                    /* 39 */
        "<ROUTE fromNode='Clock' fromField='isActive' toNode='Clock' toField='enabled'/>\n"                     /* 40 */
        "<ROUTE fromNode='Ghost' fromField='value_changed' toNode='Cam' toField='position'/>\n"                 /* 41 */
        "<ROUTE fromNode='Fade' fromField='value_changed' toNode='Rough' toField='set_fraction'/>\n"            /* 42 */
        "<ROUTE fromNode='Rough' fromField='value_changed' toNode='Fade' toField='set_fraction'/>\n"            /* 43 */
        "</Scene></X3D>\n");
    if (!expect_loaded(&l, "fields.x3d")) return unload(&l);
    EXPECT_MSG(sy_scene_count(l.scene, SY_TYPE_ANIMATION) == 1, "%u clips (want 1)", sy_scene_count(l.scene, SY_TYPE_ANIMATION));
    EXPECT_MSG(has_warning(&l, "fields.x3d:38: ROUTE from PositionInterpolator.value_changed (SFVec3f) to "
                           "Material.diffuseColor (SFColor): the types differ; dropped", NULL), "types differ");
    EXPECT_MSG(has_warning(&l, "fields.x3d:7: CoordinateInterpolator (line 17): 1 points per key, the Coordinate (line 7) has 3",
                           NULL), "CoordinateInterpolator with too few points");
    EXPECT_MSG(has_warning(&l, "fields.x3d:39: ROUTE to Coordinate.point: no Shape shows that Coordinate", NULL),
               "its route not played");
    EXPECT_MSG(has_warning(&l, "fields.x3d:40: ROUTE from TimeSensor.isActive to TimeSensor.enabled closes a loop", NULL),
               "a route to its own node");
    EXPECT_MSG(has_warning(&l, "fields.x3d:42: ", "closes a loop") || has_warning(&l, "fields.x3d:43: ", "closes a loop"),
               "Fade <-> Rough");
    EXPECT_MSG(has_warning(&l, "fields.x3d:41: ROUTE from 'Ghost', which is not DEFined", NULL), "from an undefined node");
    const sy_material_data *paint = material_named(&l, "Paint"), *metal = material_named(&l, "Metal");
    sy_node cam = node_named(&l, "Cam"), lamp = node_named(&l, "Lamp"), sun = node_named(&l, "Sun");
    EXPECT_MSG(paint && metal && cam.id && lamp.id && sun.id, "objects: %p %p %u %u %u", (const void *)paint,
               (const void *)metal, cam.id, lamp.id, sun.id);
    if (!paint || !metal || !cam.id || !lamp.id || !sun.id) return unload(&l);
    const double times[2] = {0.5, 1.5}; /* fractions 0.25 and 0.75 (cycle 2 s, no loop) */
    for (int i = 0; i < 2; ++i) {
        float u = (float)times[i] / 2.0f, c[3];
        set_time(&l, times[i]);
        paint = material_named(&l, "Paint"), metal = material_named(&l, "Metal");
        red_to_blue(u, c);
        EXPECT_MSG(near3(paint->base_color, c, 1e-3f), "t %g: Paint diffuse (%g %g %g), want (%g %g %g)", times[i],
                   (double)paint->base_color[0], (double)paint->base_color[1], (double)paint->base_color[2], (double)c[0],
                   (double)c[1], (double)c[2]);
        EXPECT_MSG(fabsf(paint->base_color[3] - (1.0f - 0.8f * u)) < 1e-4f, "t %g: Paint alpha %g, want %g", times[i],
                   (double)paint->base_color[3], (double)(1.0f - 0.8f * u));
        EXPECT_MSG(near3(metal->emissive, c, 1e-3f) && fabsf(metal->roughness - (0.2f + 0.4f * u)) < 1e-4f,
                   "t %g: Metal emissive (%g %g %g), roughness %g", times[i], (double)metal->emissive[0],
                   (double)metal->emissive[1], (double)metal->emissive[2], (double)metal->roughness);
        const sy_light_data *ll = sy_light_get(l.scene, sy_node_get(l.scene, lamp)->light);
        const sy_light_data *sl = sy_light_get(l.scene, sy_node_get(l.scene, sun)->light);
        float bright = 1.0f + 2.0f * u;
        /* X3D intensity x pi; the point light with attenuation (0 0 2): / 2 as well (sy_x3d.h) */
        EXPECT_MSG(ll && near3(ll->color, c, 1e-3f) && fabsf(ll->intensity - bright * PI_F_TEST / 2.0f) < 1e-3f,
                   "t %g: Lamp colour (%g %g %g), intensity %g (want %g)", times[i], ll ? (double)ll->color[0] : -1.0,
                   ll ? (double)ll->color[1] : -1.0, ll ? (double)ll->color[2] : -1.0, ll ? (double)ll->intensity : -1.0,
                   (double)(bright * PI_F_TEST / 2.0f));
        EXPECT_MSG(sl && fabsf(sl->intensity - bright * PI_F_TEST) < 1e-3f, "t %g: Sun intensity %g (want %g)", times[i],
                   sl ? (double)sl->intensity : -1.0, (double)(bright * PI_F_TEST));
        /* the Sun's direction: X3D's (1 - u) (0 0 -1) + u (1 0 0), normalised, is where the node turns -Z */
        const float *q = rot(&l, sun);
        float dz[3] = {-(2 * (q[0] * q[2] + q[1] * q[3])), -(2 * (q[1] * q[2] - q[0] * q[3])),
                       -(1 - 2 * (q[0] * q[0] + q[1] * q[1]))}; /* R (0 0 -1) */
        float want[3] = {u, 0.0f, -(1.0f - u)}, n = sqrtf(want[0] * want[0] + want[2] * want[2]);
        want[0] /= n, want[2] /= n;
        EXPECT_MSG(near3(dz, want, 1e-3f), "t %g: Sun direction (%g %g %g), want (%g %g %g)", times[i], (double)dz[0],
                   (double)dz[1], (double)dz[2], (double)want[0], (double)want[1], (double)want[2]);
        /* fitting the cameras to a portrait image leaves the routed fieldOfView to the clock */
        sy_error fe = {0};
        EXPECT_MSG(sy_x3d_fit_cameras(l.scene, &l.info, 0.5f, &fe) == SY_OK, "fit cameras: %s", fe.message);
        const sy_camera_data *cd = sy_camera_get(l.scene, sy_node_get(l.scene, cam)->camera);
        EXPECT_MSG(cd && fabsf(cd->yfov - (0.5f + 0.5f * u)) < 1e-4f, "t %g: Cam yfov %g", times[i], cd ? (double)cd->yfov : -1.0);
        EXPECT_MSG(fabsf(pos(&l, cam)[2] - (10.0f + 10.0f * u)) < 1e-3f && fabsf(yaw(rot(&l, cam)) - u) < 1e-4f,
                   "t %g: Cam at z %g, yaw %g", times[i], (double)pos(&l, cam)[2], (double)yaw(rot(&l, cam)));
    }
    unload(&l);
}

/* CoordinateInterpolator -> Coordinate.point: the IndexedFaceSet's primitive gets one morph target
 * per key and every node showing it (two Shapes with the one IndexedFaceSet) a weights channel; base + weights x
 * targets at a time equals X3D's linear interpolation of the key points at each corner, and the
 * generated normals follow (the quad folds up, its normal turns); a NormalInterpolator into the
 * explicit normals of a triangle gives normal targets that blend to X3D's halfway normal. */
static void test_coordinates(void)
{
    loaded l = load_text("coords.x3d",
        "<X3D><Scene>\n"
        "<Transform DEF='A'><Shape><IndexedFaceSet DEF='Sheet' coordIndex='0 1 2 3 -1'>"
        "<Coordinate DEF='Pts' point='0 0 0 1 0 0 1 1 0 0 1 0'/></IndexedFaceSet></Shape></Transform>\n" /* 2 */
        "<Transform translation='3 0 0'><Shape><IndexedFaceSet USE='Sheet'/></Shape></Transform>\n"       /* 3 */
        "<TimeSensor DEF='Clock' cycleInterval='4'/>\n"                                                   /* 4 */
        "<CoordinateInterpolator DEF='Fold' key='0 0.5 1' keyValue='0 0 0 1 0 0 1 1 0 0 1 0  "
        "0 0 0 1 0 0 1 1 1 0 1 1  0 0 0 2 0 0 2 2 0 0 2 0'/>\n"                                          /* 5 */
        "<NormalInterpolator DEF='N' key='0 1' keyValue='0 0 1 0 1 0'/>\n"                                 /* 6 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Fold' toField='set_fraction'/>\n"   /* 7 */
        "<ROUTE fromNode='Fold' fromField='value_changed' toNode='Pts' toField='set_point'/>\n"           /* 8 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='N' toField='set_fraction'/>\n"      /* 9 */
        "</Scene></X3D>\n");
    if (!expect_loaded(&l, "coords.x3d")) return unload(&l);
    const float keys[3][12] = {{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, {0, 0, 0, 1, 0, 0, 1, 1, 1, 0, 1, 1},
                               {0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0}};
    sy_node nodes[2] = {{0}, {0}};
    uint32_t nn = 0;
    for (uint32_t id = sy_scene_next(l.scene, SY_TYPE_NODE, 0); id; id = sy_scene_next(l.scene, SY_TYPE_NODE, id))
        if (sy_node_get(l.scene, (sy_node){id})->mesh.id && nn < 2) nodes[nn++] = (sy_node){id};
    EXPECT_MSG(nn == 2, "%u nodes show the sheet (want 2)", nn);
    const sy_mesh_data *md = nn ? sy_mesh_get(l.scene, sy_node_get(l.scene, nodes[0])->mesh) : NULL;
    uint32_t np = 0;
    const sy_primitive *pr = md ? md->primitives.items : NULL;
    np = md ? md->primitives.count : 0;
    EXPECT_MSG(pr && np == 1 && pr->target_positions && pr->target_normals, "the sheet's primitive has morph targets");
    if (!pr || np != 1 || !pr->target_positions || !pr->target_normals || nn != 2) return unload(&l);
    size_t nv = sy_blob_size(pr->positions) / 12;
    EXPECT_MSG(sy_blob_size(pr->target_positions) == 3 * nv * 12, "3 targets of %zu vertices: %zu bytes", nv,
               sy_blob_size(pr->target_positions));
    const float *base = sy_blob_data(pr->positions), *tp = sy_blob_data(pr->target_positions);
    const float *bn = sy_blob_data(pr->normals), *tn = sy_blob_data(pr->target_normals);
    const double times[2] = {1.0, 3.0}; /* fractions 0.25 (keys 0 and 1, u 0.5) and 0.75 (keys 1 and 2, u 0.5) */
    for (int ti = 0; ti < 2; ++ti) {
        set_time(&l, times[ti]);
        int k0 = ti, k1 = ti + 1;
        for (uint32_t n = 0; n < 2; ++n) {
            const sy_node_data *nd = sy_node_get(l.scene, nodes[n]);
            uint32_t nw = nd->weights ? (uint32_t)(sy_blob_size(nd->weights) / 4) : 0;
            EXPECT_MSG(nw == 3, "t %g node %u: %u weights (want 3)", times[ti], n, nw);
            if (nw != 3) continue;
            const float *w = sy_blob_data(nd->weights);
            /* every corner: base + sum w_k target_k = X3D's (1 - u) key k0 + u key k1 at its point */
            for (size_t v = 0; v < nv; ++v) {
                float p[3], best = INFINITY;
                for (int a = 0; a < 3; ++a) {
                    p[a] = base[3 * v + a];
                    for (int k = 0; k < 3; ++k) p[a] += w[k] * tp[(size_t)k * nv * 3 + 3 * v + a];
                }
                for (int q = 0; q < 4; ++q) { /* the point this corner is: the nearest of the interpolated points */
                    float d = 0;
                    for (int a = 0; a < 3; ++a) {
                        float x = 0.5f * keys[k0][3 * q + a] + 0.5f * keys[k1][3 * q + a] - p[a];
                        d += x * x;
                    }
                    best = fminf(best, d);
                }
                EXPECT_MSG(best < 1e-10f, "t %g node %u corner %zu: (%g %g %g) is no interpolated point", times[ti], n, v,
                           (double)p[0], (double)p[1], (double)p[2]);
            }
            /* the normal at t = 1 (halfway to the fold) tilts from +z towards -y; at t = 3 it comes back */
            float nz = bn[2], ny = bn[1];
            for (int k = 0; k < 3; ++k) nz += w[k] * tn[(size_t)k * nv * 3 + 2], ny += w[k] * tn[(size_t)k * nv * 3 + 1];
            if (n == 0) printf("t %g: corner 0 normal y %.3f z %.3f\n", times[ti], (double)ny, (double)nz);
            EXPECT_MSG(ny < -0.05f && nz > 0.5f, "t %g node %u: corner 0's normal (y %g, z %g) did not tilt", times[ti], n,
                       (double)ny, (double)nz);
        }
    }
    unload(&l);
    /* NormalInterpolator -> Normal.vector of a triangle with explicit normals: normal deltas only;
     * halfway, the blended normal points along X3D's interpolation on the sphere, (0 1 1) / sqrt 2 */
    l = load_text("normals.x3d",
        "<X3D><Scene>\n"
        "<Shape><IndexedFaceSet coordIndex='0 1 2 -1' normalIndex='0 1 2 -1'>"
        "<Coordinate point='0 0 0 1 0 0 0 1 0'/><Normal DEF='Nr' vector='0 0 1 0 0 1 0 0 1'/></IndexedFaceSet></Shape>\n"
        "<TimeSensor DEF='Clock' cycleInterval='2'/>\n"
        "<NormalInterpolator DEF='N' key='0 1' keyValue='0 0 1 0 0 1 0 0 1  0 1 0 0 1 0 0 1 0'/>\n"
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='N' toField='set_fraction'/>\n"
        "<ROUTE fromNode='N' fromField='value_changed' toNode='Nr' toField='set_vector'/>\n"
        "</Scene></X3D>\n");
    EXPECT_MSG(l.r == SY_OK && sy_scene_count(l.scene, SY_TYPE_ANIMATION) == 1, "normals.x3d: %s", l.err.message);
    sy_node tri = {0};
    for (uint32_t id = sy_scene_next(l.scene, SY_TYPE_NODE, 0); l.r == SY_OK && id; id = sy_scene_next(l.scene, SY_TYPE_NODE, id))
        if (sy_node_get(l.scene, (sy_node){id})->mesh.id) tri = (sy_node){id};
    md = tri.id ? sy_mesh_get(l.scene, sy_node_get(l.scene, tri)->mesh) : NULL;
    pr = md && md->primitives.count == 1 ? md->primitives.items : NULL;
    EXPECT_MSG(pr && pr->target_normals && pr->target_positions, "the triangle has normal (and zero position) targets");
    if (pr && pr->target_normals) {
        set_time(&l, 1.0);
        const sy_node_data *nd = sy_node_get(l.scene, tri);
        const float *w = nd->weights && sy_blob_size(nd->weights) == 8 ? sy_blob_data(nd->weights) : NULL;
        EXPECT_MSG(w != NULL, "the triangle's node has 2 weights");
        const float *b0 = sy_blob_data(pr->normals), *t0 = sy_blob_data(pr->target_normals);
        nv = sy_blob_size(pr->normals) / 12;
        float n3[3];
        for (int a = 0; w && a < 3; ++a) n3[a] = b0[a] + w[0] * t0[a] + w[1] * t0[nv * 3 + a];
        float len = w ? sqrtf(n3[0] * n3[0] + n3[1] * n3[1] + n3[2] * n3[2]) : 0;
        EXPECT_MSG(w && len > 0 && fabsf(n3[0] / len) < 1e-5f && fabsf(n3[1] / len - 0.70710678f) < 1e-4f &&
                       fabsf(n3[2] / len - 0.70710678f) < 1e-4f,
                   "halfway normal (%g %g %g)", w ? (double)n3[0] : 0.0, w ? (double)n3[1] : 0.0, w ? (double)n3[2] : 0.0);
    }
    unload(&l);
}

/* the texture coordinates of the first primitive of node n at the scene's time: uv + sum w_t duv_t
 * (what the mirror hands every back-end, sy_deform_texcoords), corner v into uv[2] */
static bool morphed_uv(const loaded *l, sy_node n, size_t v, float uv[2])
{
    const sy_node_data *nd = sy_node_get(l->scene, n);
    const sy_mesh_data *md = nd && nd->mesh.id ? sy_mesh_get(l->scene, nd->mesh) : NULL;
    const sy_primitive *pr = md && md->primitives.count ? md->primitives.items : NULL;
    if (!pr || !pr->texcoords0 || !pr->target_texcoords0) return false;
    size_t nv = sy_blob_size(pr->texcoords0) / 8, nt = sy_blob_size(pr->target_texcoords0) / 8 / nv;
    const float *b = sy_blob_data(pr->texcoords0), *d = sy_blob_data(pr->target_texcoords0);
    const float *w = nd->weights ? sy_blob_data(nd->weights) : NULL;
    size_t nw = nd->weights ? sy_blob_size(nd->weights) / 4 : 0;
    uv[0] = b[2 * v], uv[1] = b[2 * v + 1];
    for (size_t t = 0; t < nt && t < nw; ++t) uv[0] += w[t] * d[t * nv * 2 + 2 * v], uv[1] += w[t] * d[t * nv * 2 + 2 * v + 1];
    return true;
}

/* PositionInterpolator2D -> TextureTransform.translation / .scale and CoordinateInterpolator2D ->
 * TextureCoordinate.point: texture coordinate morph targets (one per key) and weights, so that the
 * coordinates at a time are X3D's (u, 1 - t of the transformed point); bad interpolators are refused
 * with a warning naming the node */
static void test_textures(void)
{
    loaded l = load_text("tex.x3d",
        "<X3D><Scene>\n"
        "<Transform DEF='Slid'><Shape><Appearance><TextureTransform DEF='TT'/></Appearance>"                    /* 2 */
        "<IndexedFaceSet coordIndex='0 1 2 3 -1' texCoordIndex='0 1 2 3 -1'><Coordinate point='0 0 0 1 0 0 1 1 0 0 1 0'/>"
        "<TextureCoordinate point='0 0 1 0 1 1 0 1'/></IndexedFaceSet></Shape></Transform>\n"
        "<Transform DEF='Grown'><Shape><Appearance><TextureTransform DEF='TS' center='0.5 0.5'/></Appearance>"   /* 3 */
        "<IndexedFaceSet coordIndex='0 1 2 -1'><Coordinate point='0 0 0 1 0 0 1 1 0'/>"
        "<TextureCoordinate point='0 0 1 0 1 1'/></IndexedFaceSet></Shape></Transform>\n"
        "<Transform DEF='Waved'><Shape><IndexedFaceSet coordIndex='0 1 2 -1'><Coordinate point='0 0 0 1 0 0 1 1 0'/>" /* 4 */
        "<TextureCoordinate DEF='TC' point='0 0 1 0 1 1'/></IndexedFaceSet></Shape></Transform>\n"
        "<TimeSensor DEF='Clock' cycleInterval='2'/>\n"                                                        /* 5 */
        "<PositionInterpolator2D DEF='Slide' key='0 1' keyValue='0 0 0.5 0.25'/>\n"                           /* 6 */
        "<PositionInterpolator2D DEF='Grow' key='0 1' keyValue='1 1 3 2'/>\n"                                 /* 7 */
        "<CoordinateInterpolator2D DEF='Wave' key='0 0.5 1' keyValue='0 0 1 0 1 1  0 0 2 0 2 2  0 0 1 0 1 1'/>\n" /* 8 */
        "<PositionInterpolator2D DEF='Odd' key='0 1' keyValue='0 0'/>\n"                                      /* 9 */
        "<PositionInterpolator2D DEF='Huge' key='0 1' keyValue='0 0 1e39 0'/>"                                /* 10 */
        "<PositionInterpolator2D DEF='NaN' key='0 1' keyValue='0 0 nan 0'/>\n"
        "<Transform><Shape><Appearance><TextureTransform DEF='TO'/></Appearance><IndexedFaceSet coordIndex='0 1 2 -1'>" /* 11 */
        "<Coordinate point='0 0 0 1 0 0 1 1 0'/><TextureCoordinate point='0 0 1 0 1 1'/></IndexedFaceSet></Shape></Transform>\n"
        "<Transform><Shape><Appearance><TextureTransform DEF='TH'/></Appearance><IndexedFaceSet coordIndex='0 1 2 -1'>" /* 12 */
        "<Coordinate point='0 0 0 1 0 0 1 1 0'/><TextureCoordinate point='0 0 1 0 1 1'/></IndexedFaceSet></Shape></Transform>\n"
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Slide' toField='set_fraction'/>\n"       /* 13 */
        "<ROUTE fromNode='Slide' fromField='value_changed' toNode='TT' toField='set_translation'/>\n"          /* 14 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Grow' toField='set_fraction'/>\n"        /* 15 */
        "<ROUTE fromNode='Grow' fromField='value_changed' toNode='TS' toField='scale'/>\n"                     /* 16 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Wave' toField='set_fraction'/>\n"        /* 17 */
        "<ROUTE fromNode='Wave' fromField='value_changed' toNode='TC' toField='set_point'/>\n"                 /* 18 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Odd' toField='set_fraction'/>\n"         /* 19 */
        "<ROUTE fromNode='Odd' fromField='value_changed' toNode='TO' toField='translation'/>\n"                /* 20 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Huge' toField='set_fraction'/>\n"        /* 21 */
        "<ROUTE fromNode='Huge' fromField='value_changed' toNode='TH' toField='translation'/>\n"               /* 22 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='NaN' toField='set_fraction'/>\n"         /* 23 */
        "<ROUTE fromNode='NaN' fromField='value_changed' toNode='TH' toField='translation'/>\n"                /* 24 */
        "<Shape><IndexedFaceSet coordIndex='0 1 2 -1'><Coordinate point='0 0 0 1 0 0 1 1 0'/>"                /* 25 */
        "<TextureCoordinate DEF='TC2' point='0 0 1 0 1 1'/></IndexedFaceSet></Shape>\n"
        "<CoordinateInterpolator2D DEF='Short2' key='0 1' keyValue='0 0 1 0  0 0 2 0'/>\n"                  /* 26 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Short2' toField='set_fraction'/>\n"      /* 27 */
        "<ROUTE fromNode='Short2' fromField='value_changed' toNode='TC2' toField='point'/>\n"                  /* 28 */
        "</Scene></X3D>\n");
    if (!expect_loaded(&l, "tex.x3d")) return unload(&l);
    EXPECT_MSG(has_warning(&l, "tex.x3d:9: PositionInterpolator2D 'Odd': 2 keys and 1 key values", NULL), "Odd's counts");
    /* a value beyond a float (or NaN) is no number to the field parser: the values are refused, then the interpolator */
    EXPECT_MSG(has_warning(&l, "tex.x3d:10: PositionInterpolator2D.keyValue: not a list of numbers", NULL) &&
                   has_warning(&l, "tex.x3d:10: PositionInterpolator2D 'Huge': 2 keys and 0 key values", "not played"),
               "Huge's value");
    EXPECT_MSG(has_warning(&l, "tex.x3d:10: PositionInterpolator2D 'NaN'", "not played"), "NaN's value");
    EXPECT_MSG(has_warning(&l, "tex.x3d:25: CoordinateInterpolator2D (line 26): 2 points per key, the TextureCoordinate "
                               "(line 25) has 3; not played", NULL), "Short2's points");
    sy_node slid = node_named(&l, "Slid"), grown = node_named(&l, "Grown"), waved = node_named(&l, "Waved");
    /* Slid's shape is a child node of the Transform: the node showing the mesh */
    sy_node shows[3] = {{0}, {0}, {0}};
    const sy_node parents[3] = {slid, grown, waved};
    for (int k = 0; k < 3; ++k) { /* the Transform's node, or one of its children */
        const sy_node_data *pd = parents[k].id ? sy_node_get(l.scene, parents[k]) : NULL;
        if (!pd) continue;
        if (pd->mesh.id) shows[k] = parents[k];
        uint32_t nc = 0;
        const uint32_t *ch = sy_node_children(pd, &nc);
        for (uint32_t c = 0; c < nc && !shows[k].id; ++c)
            if (sy_node_get(l.scene, (sy_node){ch[c]})->mesh.id) shows[k] = (sy_node){ch[c]};
    }
    EXPECT_MSG(shows[0].id && shows[1].id && shows[2].id, "the three textured shapes");
    const double times[3] = {0.0, 1.0, 2.0};
    for (int ti = 0; ti < 3 && shows[0].id && shows[1].id && shows[2].id; ++ti) {
        set_time(&l, times[ti]);
        float f = (float)times[ti] / 2.0f, uv[2];
        /* Slide: T = (0.5 f, 0.25 f); corner 1 is (1, 0): (1 + 0.5 f, 1 - (0 + 0.25 f)) */
        bool ok = morphed_uv(&l, shows[0], 1, uv);
        EXPECT_MSG(ok && fabsf(uv[0] - (1.0f + 0.5f * f)) < 1e-5f && fabsf(uv[1] - (1.0f - 0.25f * f)) < 1e-5f,
                   "t %g: Slid corner 1 uv (%g %g), want (%g %g)", times[ti], (double)uv[0], (double)uv[1],
                   (double)(1.0f + 0.5f * f), (double)(1.0f - 0.25f * f));
        /* Grow: S = (1 + 2 f, 1 + f) about C = (0.5, 0.5); corner 1 (1, 0): s' = S (p - C)... X3D: -C S (p + C)
         * with T = 0: s' = S_x (1 + 0.5) - 0.5, t' = S_y (0 + 0.5) - 0.5 */
        float sx = 1.0f + 2.0f * f, sy = 1.0f + f;
        ok = morphed_uv(&l, shows[1], 1, uv);
        EXPECT_MSG(ok && fabsf(uv[0] - (sx * 1.5f - 0.5f)) < 1e-5f && fabsf(uv[1] - (1.0f - (sy * 0.5f - 0.5f))) < 1e-5f,
                   "t %g: Grown corner 1 uv (%g %g), want (%g %g)", times[ti], (double)uv[0], (double)uv[1],
                   (double)(sx * 1.5f - 0.5f), (double)(1.0f - (sy * 0.5f - 0.5f)));
        /* Wave: point 2 goes (1 1) -> (2 2) -> (1 1) at fractions 0, 0.5, 1 */
        float p = ti == 1 ? 2.0f : 1.0f;
        ok = morphed_uv(&l, shows[2], 2, uv);
        EXPECT_MSG(ok && fabsf(uv[0] - p) < 1e-5f && fabsf(uv[1] - (1.0f - p)) < 1e-5f, "t %g: Waved corner 2 uv (%g %g), want (%g %g)",
                   times[ti], (double)uv[0], (double)uv[1], (double)p, (double)(1.0f - p));
    }
    unload(&l);
}

/* the shared sample: OrbitalTimeInterval (12 s, loop) turns EarthCoordinateSystem 2 pi about +y in
 * four quarter keys */
/* ScalarInterpolator -> TextureTransform.rotation: the texture coordinates at a time are the file's
 * turned about the center by the interpolated angle (between the file's keys too: the keys made
 * dense, a blend of two is within 0.125 % of the radius; the two file keys alone would blend 0 and
 * pi into a point near the center); decreasing keys are refused naming the file's key, and 256 keys
 * leave no room for more */
static void test_texture_rotation(void)
{
    char many[256 * 2 * 12 + 200], *m = many;
    m += sprintf(m, "<ScalarInterpolator DEF='Many' key='");
    for (int k = 0; k < 256; ++k) m += sprintf(m, "%g ", k / 255.0);
    m += sprintf(m, "' keyValue='");
    for (int k = 0; k < 256; ++k) m += sprintf(m, "%d ", k);
    sprintf(m, "'/>\n");
    char text[16384];
    snprintf(text, sizeof text,
        "<X3D><Scene>\n"
        "<Transform DEF='Turned'><Shape><Appearance><TextureTransform DEF='TR' center='0.5 0.5'/></Appearance>"   /* 2 */
        "<IndexedFaceSet coordIndex='0 1 2 3 -1' texCoordIndex='0 1 2 3 -1'><Coordinate point='0 0 0 1 0 0 1 1 0 0 1 0'/>"
        "<TextureCoordinate point='0 0 1 0 1 1 0 1'/></IndexedFaceSet></Shape></Transform>\n"
        "<TimeSensor DEF='Clock' cycleInterval='2'/>\n"                                                        /* 3 */
        "<ScalarInterpolator DEF='Spin' key='0 1' keyValue='0 3.14159265'/>\n"                                /* 4 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Spin' toField='set_fraction'/>\n"
        "<ROUTE fromNode='Spin' fromField='value_changed' toNode='TR' toField='set_rotation'/>\n"
        "<Shape><Appearance><TextureTransform DEF='TD'/></Appearance><IndexedFaceSet coordIndex='0 1 2 -1'>"     /* 7 */
        "<Coordinate point='0 0 0 1 0 0 1 1 0'/><TextureCoordinate point='0 0 1 0 1 1'/></IndexedFaceSet></Shape>\n"
        "<ScalarInterpolator DEF='Down' key='0 0.6 0.3 1' keyValue='0 1 2 3'/>\n"                             /* 8 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Down' toField='set_fraction'/>\n"
        "<ROUTE fromNode='Down' fromField='value_changed' toNode='TD' toField='rotation'/>\n"
        "<Shape><Appearance><TextureTransform DEF='TM'/></Appearance><IndexedFaceSet coordIndex='0 1 2 -1'>"     /* 11 */
        "<Coordinate point='0 0 0 1 0 0 1 1 0'/><TextureCoordinate point='0 0 1 0 1 1'/></IndexedFaceSet></Shape>\n"
        "%s"                                                                                                     /* 12 */
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Many' toField='set_fraction'/>\n"
        "<ROUTE fromNode='Many' fromField='value_changed' toNode='TM' toField='rotation'/>\n"
        "</Scene></X3D>\n", many);
    loaded l = load_text("rot.x3d", text);
    if (!expect_loaded(&l, "rot.x3d")) return unload(&l);
    EXPECT_MSG(has_warning(&l, "rot.x3d:8: ScalarInterpolator: key 2 (0.3) is less than the key before it", "not played"),
               "Down's keys");
    EXPECT_MSG(has_warning(&l, "rot.x3d:12: ScalarInterpolator 'Many': 256 keys into a TextureTransform's rotation", "not played"),
               "Many's keys");
    sy_node turned = node_named(&l, "Turned"), shows = {0};
    const sy_node_data *pd = turned.id ? sy_node_get(l.scene, turned) : NULL;
    uint32_t nc = 0;
    const uint32_t *ch = pd ? sy_node_children(pd, &nc) : NULL;
    if (pd && pd->mesh.id) shows = turned;
    for (uint32_t c = 0; c < nc && !shows.id; ++c)
        if (sy_node_get(l.scene, (sy_node){ch[c]})->mesh.id) shows = (sy_node){ch[c]};
    EXPECT_MSG(shows.id, "the turned shape");
    const double times[4] = {0.0, 0.5, 1.0, 1.3};
    for (int ti = 0; ti < 4 && shows.id; ++ti) {
        set_time(&l, times[ti]);
        /* corner 1 (1, 0) about C (0.5, 0.5): p + C = (1.5, 0.5) turned by a, minus C; uv = (s', 1 - t') */
        double a = 3.14159265 * times[ti] / 2.0, s = 1.5 * cos(a) - 0.5 * sin(a) - 0.5, t = 1.5 * sin(a) + 0.5 * cos(a) - 0.5;
        float uv[2];
        bool ok = morphed_uv(&l, shows, 1, uv);
        EXPECT_MSG(ok && fabs(uv[0] - s) < 2.5e-3 && fabs(uv[1] - (1.0 - t)) < 2.5e-3, "t %g: corner 1 uv (%g %g), want (%g %g)",
                   times[ti], (double)uv[0], (double)uv[1], s, 1.0 - t);
    }
    unload(&l);
}

static void test_sample(const char *data)
{
    char p[2048];
    if (!sample_path(data, "x3d/assimp_debian_testmodels/HelloX3dTrademark.x3d", p, sizeof p)) return;
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

X3D_MAIN("x3d_anim", test_sample, test_routes, test_fields, test_coordinates, test_textures, test_texture_rotation)
