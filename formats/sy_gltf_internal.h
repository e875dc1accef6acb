/* sy_gltf_internal.h — internal to the glTF loader (not installed): the loader's state and the calls
 * between its modules. The modules, bottom-up (no module calls one above it; core_layers checks):
 *   sy_gltf_errors.c     errors, warnings, created objects (rollback), checked allocation
 *   sy_gltf_validate.c   GLB container, JSON depth, the one validation pass over the document
 *   sy_gltf_accessors.c  reading accessors (components, strides, sparse substitution)
 *   sy_gltf_materials.c  materials, textures, samplers
 *   sy_gltf_meshes.c     the meshes' budget, primitives (triangles, points, lines) -> sy_meshes
 *   sy_gltf_nodes.c      cameras, lights, the node graph of one scene, instancing
 *   sy_gltf_animations.c every animation into a core animation object (after the nodes)
 *   sy_gltf.c            the public entry points (sy_gltf.h): options, the order of the load
 * Every function here starts with gltf_ (types and constants never leave these files). */
#ifndef SY_GLTF_INTERNAL_H
#define SY_GLTF_INTERNAL_H

#include "sy_budget.h"
#include "sy_loader_log.h"
#include "sy_gltf.h"
#include "sy_gltf_shim.h"

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define GLTF_POINTS 0
#define GLTF_LINES 1
#define GLTF_LINE_LOOP 2
#define GLTF_LINE_STRIP 3
#define GLTF_TRIANGLES 4
#define GLTF_TRIANGLE_STRIP 5
#define GLTF_TRIANGLE_FAN 6

#define CT_BYTE 5120
#define CT_UBYTE 5121
#define CT_SHORT 5122
#define CT_USHORT 5123
#define CT_UINT 5125
#define CT_FLOAT 5126

typedef struct created_obj {
    uint32_t type, id;
} created_obj;

typedef struct loader {
    const char *path;
    sy_scene *scene;
    sy_gltf_options opt;
    const sy_gltf_doc *doc;
    sy_error err; /* local; copied to the caller's at the end */
    sy_gltf_info *info;
    created_obj *objs;
    size_t obj_count, obj_cap;
    /* glTF index -> created handle (0 = not created) */
    sy_material *materials;
    sy_mesh *meshes;
    sy_camera *cameras;
    sy_light *lights;
    sy_node *nodes;
    sy_texture *textures; /* 2 per glTF texture: colour, data */
    sy_blob **image_blobs;
    int32_t *parent;      /* per glTF node: parent index, -1 none */
    uint8_t *reached;     /* per glTF node: part of the loaded scene */
    uint32_t *mesh_triangles;
    uint32_t *mesh_joints; /* per glTF mesh: 1 + its largest JOINTS_n index (0: not skinned) */
    sy_budget budget; /* the file's (sy_budget.h) */
    bool warned_skin, warned_morph, warned_anim;
    uint32_t pointers_dropped; /* KHR_animation_pointer channels dropped: the first is named, the rest counted */
    size_t variant_cursor;     /* next doc->variant_uses entry (meshes are created in order) */
    uint32_t variant_uses_done; /* info->variant_uses entries whose mesh is set */
} loader;

/* Extensions the loader supports (NULL-terminated; sy_gltf_supported_extensions returns it). */
extern const char *const gltf_supported[];

/* >>errors (sy_gltf_errors.c) ----------------------------------------------------------------- */

/* gltf_fail(L, code, fmt, ...): sets L->err to "<path>: <message>" and returns code. */
#define gltf_fail(L, code, ...) sy_loader_failf(&(L)->err, (L)->path, (code), __VA_ARGS__)
/* gltf_warnings(info): the info struct's warnings (sy_loader_log.h). */
#define gltf_warnings(info) SY_LOADER_WARNINGS(info, SY_GLTF_MAX_WARNINGS)
/* gltf_warn(L, fmt, ...): a warning into info->warnings (at most SY_GLTF_MAX_WARNINGS stored, all
 * counted). */
#define gltf_warn(L, ...) sy_loader_warnf(gltf_warnings((L)->info), __VA_ARGS__)
/* Adds context to an error that a core call left in L->err. */
sy_result gltf_context(loader *L, sy_result r, const char *what);
/* Creates an object of the type, named name (NULL: unnamed), recorded for the rollback; an error
 * names where. */
sy_result gltf_create(loader *L, sy_object_type type, const char *name, const char *where, uint32_t *id);
/* Destroys every tracked object, newest first. */
void gltf_rollback(loader *L);
/* calloc of n x size bytes, overflow-checked; NULL with *r set (and L->err) on failure. */
void *gltf_xcalloc(loader *L, size_t n, size_t size, sy_result *r);

static inline bool gltf_to_float(double d, float *out)
{
    if (!isfinite(d) || d > 3.4e38 || d < -3.4e38) return false;
    *out = (float)d;
    return true;
}

static inline const char *gltf_nonempty(const char *s) { return (s && s[0]) ? s : NULL; }

/* >>material tables (sy_gltf_materials.c) ---------------------------------------------------- */

/* A material's texture slot: where the shim holds it, where core takes it, the colour role (sRGB
 * texture) or data, and its name in the file. One table drives validation and loading. */
typedef struct gltf_texture_slot {
    size_t shim;    /* offsetof(sy_gltf_shim_material, ...) of a sy_gltf_shim_texinfo */
    size_t core;    /* offsetof(sy_material_data, ...) of a sy_texture_ref */
    bool color;     /* sRGB colour (else linear data) */
    const char *name; /* e.g. "KHR_materials_clearcoat.clearcoatTexture" */
} gltf_texture_slot;
extern const gltf_texture_slot gltf_texture_slots[];
extern const size_t gltf_texture_slot_count;

/* >>validation (sy_gltf_validate.c) ----------------------------------------------------------- */

/* The GLB header and chunk table of b (size bytes); *json / *json_len: the JSON chunk. */
sy_result gltf_check_glb(loader *L, const uint8_t *b, size_t size, const uint8_t **json, size_t *json_len);
/* Refuses JSON nested deeper than opt.max_json_depth. */
sy_result gltf_check_json_depth(loader *L, const uint8_t *s, size_t n);
/* The one validation pass over L->doc (fills L->parent). */
sy_result gltf_validate_doc(loader *L);
/* Bytes of a component type (0: not a glTF type), of one element (matrix columns 4-byte aligned),
 * and between elements. */
size_t gltf_component_size(int32_t ct);
size_t gltf_element_size(const sy_gltf_shim_accessor *a);
size_t gltf_accessor_stride(const sy_gltf_doc *d, const sy_gltf_shim_accessor *a);

/* >>accessors (sy_gltf_accessors.c) ----------------------------------------------------------- */

/* Accessor ai as out_comps floats per element (missing components 0, a 4th 1); *out malloc()ed. */
sy_result gltf_read_floats(loader *L, size_t ai, size_t out_comps, float **out);
/* Element i of accessor ai as out_comps floats; allocates nothing. */
sy_result gltf_read_element(loader *L, size_t ai, size_t i, size_t out_comps, float *dst);
/* Accessor ai as unsigned integers; *out malloc()ed. */
sy_result gltf_read_uints(loader *L, size_t ai, uint32_t **out);

/* >>materials (sy_gltf_materials.c) ----------------------------------------------------------- */

/* Material i (and the textures it uses) into L->materials[i]. */
sy_result gltf_create_material(loader *L, size_t i);

/* >>meshes (sy_gltf_meshes.c) ----------------------------------------------------------------- */

/* The budget for every primitive of every mesh, before any is decoded. */
sy_result gltf_charge_meshes(loader *L);
/* Mesh m into L->meshes[m] (L->mesh_triangles[m]: its triangles). */
sy_result gltf_create_mesh(loader *L, size_t m);
/* Morph weights (a glTF weights array) into mesh or node id; unusable ones warned about and left. */
sy_result gltf_set_weights(loader *L, const double *w, size_t count, uint32_t id, sy_object_type type, const char *where);

/* >>cameras, lights, nodes (sy_gltf_nodes.c) -------------------------------------------------- */

sy_result gltf_create_camera(loader *L, size_t i);
sy_result gltf_create_light(loader *L, size_t i);
/* The nodes reachable from roots and a new root node named root_name (L->info->root, camera nodes). */
sy_result gltf_create_nodes(loader *L, const int32_t *roots, size_t root_count, const char *root_name);

/* >>animations (sy_gltf_animations.c) -------------------------------------------------------- */

/* Every animation of the file into L->info->animations (after gltf_create_nodes). */
sy_result gltf_create_animations(loader *L);

#endif /* SY_GLTF_INTERNAL_H */
