/* sy_x3d_internal.h — internal to the X3D loader (not installed): the loader's state and the calls
 * between its modules. The modules, bottom-up (no module calls one above it; core_layers checks):
 *   sy_x3d_fields.c      warnings, created objects and the element cache; field values; DEF / USE
 *   sy_x3d_url.c         url fields: MFString, joining, confinement to the model's folder
 *   sy_x3d_appearance.c  Appearance -> sy_material (textures, the material nodes)
 *   sy_x3d_polygons.c    coordinate-based geometry -> triangle corners -> sy_primitive
 *   sy_x3d_geometry.c    one geometry node -> sy_primitive (primitives, points, lines, Text)
 *   sy_x3d_lights.c      lights, viewpoints (and the public camera calls), Background
 *   sy_x3d_nodes.c       the walk: files and Inline, grouping nodes, Transform, Shape
 *   sy_x3d_anim.c        TimeSensors, interpolators and ROUTEs -> animations (after each file's walk)
 *   sy_x3d.c             the public entry points (sy_x3d.h)
 * Every function here starts with x3d_ (types and constants never leave these files). */
#ifndef SY_X3D_INTERNAL_H
#define SY_X3D_INTERNAL_H

#include "sy_loader_log.h"
#include "sy_budget.h"
#include "sy_x3d.h"

#include <libxml/hash.h>
#include <libxml/tree.h>

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define PI_F 3.14159265358979323846f

/* >>state ------------------------------------------------------------------------------------- */

/* Objects created for one element (keyed by element address + variant in loader.cache). */
typedef struct created {
    uint32_t node;     /* sy_node id (grouping nodes, Shape, Inline, lights, viewpoints) */
    uint32_t mesh;     /* Shape */
    uint32_t material; /* Appearance variant */
    uint32_t texture;  /* ImageTexture (0 after a failed decode: no texture) */
    uint32_t tex_channels;
    bool done, in_progress;
} created;

typedef struct xfile {
    char *path;   /* for messages */
    char *dir;    /* base directory of relative URLs, "" = none, else ends with '/' */
    xmlHashTablePtr defs; /* DEF name -> xmlNode* (this file's namespace) */
    struct xfile *parent; /* the file that Inlines this one (cycle detection) */
    char *real;   /* realpath, NULL for memory input */
    uint32_t depth;
    uint32_t serial; /* distinct per loaded document: element addresses are reused after a free */
} xfile;

typedef struct pending_light {
    uint32_t light;
    float pos[3];
    float intensity; /* X3D intensity * pi */
    float a2;        /* quadratic attenuation */
    float mult;      /* what x3d_finish_lights multiplies intensity by (1 / a2, or the squared distance) */
} pending_light;

/* A routed intensity of a point or spot light (sy_x3d_anim.c): its sampler holds X3D intensity x pi
 * until x3d_fix_light_animations multiplies it by the light's mult. */
typedef struct intensity_fix {
    uint32_t animation, sampler, light;
} intensity_fix;

/* A Material element's sy_material (one per Appearance variant: solid, vertex colours, strokes)
 * and the animation paths its colour fields drive there (sy_anim_path, X3D_NO_PATH when that
 * field does not show in this variant): ROUTEs to a Material's fields (sy_x3d_anim.c). */
typedef struct mat_link {
    const xmlNode *mat;
    uint32_t serial, material;
    uint8_t diffuse, emissive; /* diffuseColor / baseColor, emissiveColor */
} mat_link;
#define X3D_NO_PATH 0xFFu

/* A Coordinate that a CoordinateInterpolator driven by a TimeSensor animates (found before the
 * walk, sy_x3d_anim.c): x3d_emit gives the primitives built on it one morph target per key (the
 * key's points, and normals generated again when the geometry generates them); the mesh is noted
 * for the weights channels (one-hot per key: linear weights blend consecutive keys exactly). */
/* What a morph source animates besides points and normals (morph_src.tex): texture coordinates,
 * through a CoordinateInterpolator2D into a TextureCoordinate's points or a PositionInterpolator2D
 * into a TextureTransform's translation, scale or center (the texture coordinates of every key are
 * the targets: X3D's transform is affine in each of those fields, so blending consecutive keys'
 * coordinates linearly is exactly the interpolated field's), or a ScalarInterpolator into its
 * rotation (not affine in the angle: x3d_scan_morphs adds keys between the file's, at most
 * X3D_TEX_ROTATION_STEP apart, so the blend of two keys' coordinates is within 1 - cos(step / 2)
 * of the rotated ones). */
enum { X3D_TEX_NONE = 0, X3D_TEX_POINT, X3D_TEX_TRANSLATION, X3D_TEX_SCALE, X3D_TEX_CENTER, X3D_TEX_ROTATION };
#define X3D_TEX_ROTATION_STEP 0.1f /* radians: a rotation's keys at most this far apart (0.125 % of a radius) */

typedef struct morph_src {
    const xmlNode *coord, *interp; /* coord: a Coordinate, or a Normal (normals: a NormalInterpolator), a
                                    * TextureCoordinate or TextureTransform (tex) */
    uint32_t serial;
    float *values;     /* keys x points x 3 (malloc()ed) */
    float *key;        /* the interpolator's keys (malloc()ed) */
    size_t keys, points;
    bool normals;      /* a NormalInterpolator into a Normal */
    bool merged;       /* normals played by the CoordinateInterpolator of the same geometry (same keys) */
    uint8_t tex;       /* X3D_TEX_*: texture coordinates (values: keys x points x 2; a TextureTransform's
                        * field: points 1, a rotation's angle as (angle, 0)) */
    uint32_t *meshes;  /* the meshes built on it (malloc()ed) */
    size_t mesh_count, mesh_cap;
} morph_src;

typedef struct loader {
    sy_scene *scene;
    sy_x3d_options opt;
    sy_budget budget; /* the load's, Inline files included (sy_budget.h) */
    sy_x3d_info *info;
    sy_error err;
    xmlHashTablePtr cache;      /* "%p:variant" -> created* */
    xmlHashTablePtr inline_roots; /* realpath -> created* (node of the Inline's scene) */
    xmlHashTablePtr warned;     /* node types already warned about */
    struct { uint32_t type, id; } *objs;
    size_t obj_count, obj_cap;
    pending_light *lights;
    size_t light_count, light_cap;
    mat_link *mat_links;
    size_t mat_link_count, mat_link_cap;
    intensity_fix *ifix;
    size_t ifix_count, ifix_cap;
    morph_src *morphs;
    size_t morph_count, morph_cap;
    size_t morph_pending; /* 1 + the morph_src x3d_emit just used for a primitive, 0 none (visit_shape notes the mesh) */
    sy_bounds bounds; /* world bounds of the shapes (first placement), for light intensities */
    bool have_background;
    uint32_t file_serial;
    size_t max_values;    /* numbers in one attribute: 4 * max_vertices (checked before allocating) */
    sy_result limit_r;    /* first attribute over max_values (the load fails with it) */
    sy_error limit_err;
    const char *model_dir; /* the top-level file's folder: urls must stay inside it (or allowed_roots) */
} loader;

/* What emit makes per vertex at most (position, normal, texcoord, colour): the budget's unit. */
#define X3D_VERTEX_BYTES 48u

static inline int x3d_line_of(const xmlNode *el) { return (int)xmlGetLineNo(el); }
static inline const char *x3d_ename(const xmlNode *el) { return (const char *)el->name; }

/* >>fields (sy_x3d_fields.c) ------------------------------------------------------------------ */

/* x3d_warn(L, fmt, ...): a warning into info->warnings (at most SY_X3D_MAX_WARNINGS stored, all
 * counted). */
#define x3d_warn(L, ...) sy_loader_warnf(x3d_warnings((L)->info), __VA_ARGS__)
/* x3d_warnings(info): the info struct's warnings (sy_loader_log.h). */
#define x3d_warnings(info) SY_LOADER_WARNINGS(info, SY_X3D_MAX_WARNINGS)
/* Creates a scene object and tracks it for the rollback. */
sy_result x3d_new_object(loader *L, sy_object_type t, const char *name, uint32_t *id);
/* The created objects of element el (+ variant) of file F; NULL when absent (create = false) or out
 * of memory. */
created *x3d_cache_get(loader *L, const xfile *F, const void *el, const char *variant, bool create);
/* xmlHashFree deallocators: free the payload / leave it. */
void x3d_free_created(void *payload, const xmlChar *name);
void x3d_free_none(void *payload, const xmlChar *name);

/* Attribute name of el (xmlFree it), NULL when absent. */
char *x3d_attr(const xmlNode *el, const char *name);
bool x3d_attr_present(const xmlNode *el, const char *name);
size_t x3d_get_floats(loader *L, xfile *F, const xmlNode *el, const char *name, float *out, size_t max);
float x3d_get_float(loader *L, xfile *F, const xmlNode *el, const char *name, float def);
bool x3d_get_bool(const xmlNode *el, const char *name, bool def);
bool x3d_get_float_array(loader *L, xfile *F, const xmlNode *el, const char *name, size_t group, float **out,
                         size_t *count);
bool x3d_get_int_array(loader *L, xfile *F, const xmlNode *el, const char *name, int32_t **out, size_t *count);
/* Whether name is one of the '|'-separated names of list. */
bool x3d_name_in(const char *name, const char *list);
/* Clamps n values to [0, 1]. */
void x3d_clamp01(float *v, int n);
/* SFRotation (axis, angle) -> unit quaternion (identity for a zero axis). */
void x3d_axis_angle_quat(const float aa[4], float q[4]);
/* A Transform's fields, X3D's defaults where absent; the rotations as unit quaternions. Its matrix
 * is T C R SR S -SR -C (x3d_transform_tail: the part after R). */
typedef struct x3d_transform {
    float t[3], r[4], s[3], c[3], so[4]; /* translation, rotation, scale, center, scaleOrientation */
} x3d_transform;
void x3d_read_transform(loader *L, xfile *F, const xmlNode *el, x3d_transform *out);
/* Whether the Transform has a center or a scaleOrientation (no TRS of its own). */
bool x3d_transform_pivoted(const x3d_transform *x);
/* SR S -SR -C, or with scale false SR -SR -C = -C (the scale left to the node's TRS). */
sy_mat4 x3d_transform_tail(const x3d_transform *x, bool scale);

/* DEF / USE: the DEF'd element of a USE (or el itself; NULL when undefined, warned), DEF registration,
 * and the child element of an SFNode field (USE resolved, DEFs registered). */
const xmlNode *x3d_resolve(loader *L, xfile *F, const xmlNode *el);
void x3d_define(loader *L, xfile *F, const xmlNode *el);
const xmlNode *x3d_field_child(loader *L, xfile *F, const xmlNode *el, const char *names, const char *field);

/* >>urls (sy_x3d_url.c) ----------------------------------------------------------------------- */

/* Next string of an MFString attribute; false at the end. */
bool x3d_next_mfstring(const char **p, char *out, size_t cap);
bool x3d_is_remote(const char *u);
/* Whether path is a regular file (why: the reason when not; may be NULL with cap 0). */
bool x3d_regular_file(const char *path, char *why, size_t cap);
bool x3d_resolve_url(const xfile *F, const char *u, char *out, size_t cap);
/* SY_OK with out = the real path, SY_ERR_NOT_FOUND (try the next url), or the refusal in L->err. */
sy_result x3d_confine_url(loader *L, const xfile *F, const xmlNode *el, const char *u, const char *path, char *out,
                          size_t cap);

/* >>appearance (sy_x3d_appearance.c) ---------------------------------------------------------- */

/* The material of (Appearance app, solid, vertex colours, points / lines); *normal_map: the
 * geometry needs tangents. */
sy_result x3d_get_material(loader *L, xfile *F, const xmlNode *app, bool solid, bool vcolors, bool stroke,
                           uint32_t *out, bool *normal_map);

/* >>polygons (sy_x3d_polygons.c) -------------------------------------------------------------- */

/* Corner-based geometry: every triangle corner refers to a coordinate and (optionally) to a
 * normal, texcoord and colour; output is non-indexed. */
typedef struct corners {
    uint32_t *coord;  /* 3 * tris */
    int32_t *normal;  /* index or -1 (generated) ; NULL: all generated */
    int32_t *tc;      /* index; NULL: generated / none */
    int32_t *color;   /* index; NULL: none */
    size_t tris;
} corners;

typedef struct geom_src {
    float *pts;  size_t npts;
    float *nrm;  size_t nnrm;
    float *tc;   size_t ntc;
    float *col;  size_t ncol; uint32_t col_comps;
    float crease;
    bool ccw, generate_tc;
    float tt[6]; /* texture transform (2x3 affine, X3D t-up space) */
    const xmlNode *coord_el; /* the Coordinate node the points come from (NULL: generated) */
    const xmlNode *normal_el; /* the Normal node of the normals (NULL: none) */
    const xmlNode *tc_el;     /* the TextureCoordinate of tc (NULL: none) */
    const xmlNode *tt_el;     /* the TextureTransform of tt (NULL: none) */
} geom_src;

/* X3D TextureTransform tt -> 2x3 affine matrix m (Tc' = -C x S x R x C x T x Tc), with field
 * `which` (X3D_TEX_TRANSLATION, _SCALE, _CENTER: value[0..1]; _ROTATION: value[0]; X3D_TEX_NONE:
 * none) taking the value instead of the file's (an animated key). tt NULL: the identity. */
void x3d_texture_transform(loader *L, xfile *F, const xmlNode *tt, int which, const float *value, float m[6]);


void x3d_corners_free(corners *c);
void x3d_geom_src_free(geom_src *g);
/* A blob that takes data (freed on failure). */
sy_result x3d_make_blob(loader *L, void *data, size_t bytes, sy_blob **out);
/* The budget for n vertices of geometry node el: charge = false checks where a generator sizes its
 * arrays (before it allocates them), charge = true charges once, in emit. */
sy_result x3d_budget_vertices(loader *L, const char *file, const xmlNode *el, uint64_t n, bool charge);
/* Texture coordinate morph targets of geometry node el from the morph source m: x3d_tex_targets_alloc
 * charges the load's budget for m->keys x nv (s, t) pairs and allocates them (*out; the caller owns
 * it); x3d_tex_targets_finish hands d (filled) to prim->target_texcoords0 (freed on failure) and
 * notes m in L->morph_pending. */
sy_result x3d_tex_targets_alloc(loader *L, xfile *F, const xmlNode *el, const morph_src *m, size_t nv, float **out);
sy_result x3d_tex_targets_finish(loader *L, const morph_src *m, float *d, size_t nv, sy_primitive *prim);
/* The corners of g as one non-indexed triangle primitive (new blobs in *prim). */
sy_result x3d_emit(loader *L, xfile *F, const xmlNode *el, const geom_src *g, corners *c, sy_primitive *prim);
/* Coordinate / Normal / TextureCoordinate / Color children of a geometry node; false: skip it. */
bool x3d_read_sources(loader *L, xfile *F, const xmlNode *el, geom_src *g);
/* The corner builders: *ok false (warned) when the node is skipped. */
sy_result x3d_build_faceset(loader *L, xfile *F, const xmlNode *el, geom_src *g, corners *c, bool *ok);
sy_result x3d_build_strip_fan_quad(loader *L, xfile *F, const xmlNode *el, geom_src *g, corners *c, bool *ok);
sy_result x3d_build_extrusion(loader *L, xfile *F, const xmlNode *el, geom_src *g, corners *c, bool *ok);
sy_result x3d_build_triset(loader *L, xfile *F, const xmlNode *el, geom_src *g, corners *c, bool indexed, bool *ok);

/* >>geometry (sy_x3d_geometry.c) -------------------------------------------------------------- */

/* The primitive of geometry node el with TextureTransform ttel (may be NULL); *ok false: skipped. */
sy_result x3d_build_geometry(loader *L, xfile *F, const xmlNode *el, const xmlNode *ttel, sy_primitive *prim,
                             bool *ok, bool *has_colors, bool *solid);

/* >>lights, viewpoints, background (sy_x3d_lights.c) ------------------------------------------ */

sy_result x3d_visit_light(loader *L, xfile *F, const xmlNode *el, const sy_mat4 *world, sy_node h);
/* Quaternion rotating -Z onto direction d (normalised; a zero d: identity). */
void x3d_quat_from_neg_z(const float d[3], float q[4]);
/* Point and spot light intensities from the scene's bounds (after the walk). */
void x3d_finish_lights(loader *L);
sy_result x3d_visit_viewpoint(loader *L, xfile *F, const xmlNode *el, sy_node h);
sy_result x3d_visit_background(loader *L, xfile *F, const xmlNode *el);

/* >>nodes (sy_x3d_nodes.c) -------------------------------------------------------------------- */

/* Loads one X3D document (the main file: parent NULL; an Inline: at / atF name the Inline element)
 * and returns the node of its Scene. */
/* A growing list of elements (sy_x3d_anim.c, sy_x3d_morphs.c). */
typedef struct x3d_elems {
    const xmlNode **items;
    size_t count, cap;
} x3d_elems;
/* Appends c; false when out of memory. */
bool x3d_elems_push(x3d_elems *rs, const xmlNode *c);
/* f without X3D's set_ prefix or _changed suffix equals name */
bool x3d_field_is(const char *f, const char *name);
/* qsort / bsearch over an array of element pointers (by address) */
int x3d_cmp_ptr_el(const void *a, const void *b);
/* The file's TimeSensors, interpolators and ROUTEs as animations (sy_x3d_anim.c); after the walk. */
sy_result x3d_load_animations(loader *L, xfile *F, const xmlNode *scene);
/* Before the walk of a file: its Coordinates that CoordinateInterpolators animate (L->morphs;
 * sy_x3d_morphs.c). */
sy_result x3d_scan_morphs(loader *L, xfile *F, const xmlNode *scene);
/* Frees L->morphs. */
void x3d_free_morphs(loader *L);
/* After x3d_finish_lights: routed point and spot light intensities scaled like their lights. */
sy_result x3d_fix_light_animations(loader *L);
sy_result x3d_load_file(loader *L, const char *path, const void *mem, size_t mem_size, const char *base_dir,
                        xfile *parent, sy_node *root_out, const xmlNode *at, xfile *atF);

#endif /* SY_X3D_INTERNAL_H */
