/* sy_assimp_internal.h — internal to the Assimp loader (not installed): the loader's state and the
 * calls between its modules. The modules, bottom-up (no module calls one above it):
 *   sy_assimp_io.c         warnings, rollback, the confined aiFileIO (the model from memory, every
 *                          other file through sy_path_confine), Assimp's log into sy_log, the
 *                          checks made before Assimp reads a file (PLY counts and end_header,
 *                          binary STL's facet count, ASCII FBX's embedded base64, COLLADA's
 *                          integer lists)
 *   sy_assimp_materials.c  textures (files and embedded) and materials
 *   sy_assimp_scene.c      meshes, cameras, lights, the node tree, units and up axis
 *   sy_assimp_anim.c       bones (skin attributes and node skins), anim meshes (morph targets) and
 *                          animations (clips with node TRS and morph weight channels)
 *   sy_assimp.c            options, the import, the conversion in order (the load in one process)
 *   sy_assimp_isolate.c    the public entry points (sy_assimp.h): the load in a child process (the
 *                          import process) whose scene changes come back as a change list
 * Every function here starts with asp_. */
#ifndef SY_ASSIMP_INTERNAL_H
#define SY_ASSIMP_INTERNAL_H

#include "sy_assimp.h"
#include "sy_budget.h"
#include "sy_loader_log.h"
#include "sy_log.h"

#include <assimp/cfileio.h>
#include <assimp/scene.h>

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define SY_ASSIMP_MTL_DIRS 8 /* MTL folders kept (an OBJ names its texture relative to its MTL) */

typedef struct asp_created {
    uint32_t type, id;
} asp_created;

typedef struct asp_texture {
    char *key;       /* the material's texture path */
    bool srgb;       /* colour role */
    sy_texture tex;  /* {0}: failed (warned once) */
    uint32_t channels;
    unsigned mr_used; /* a combined metallic-roughness texture: 1 metalness map used, 2 roughness map used */
} asp_texture;

/* Log lines kept for the parent when the load runs in the import process (sy_assimp_isolate.c),
 * which must not call sy_log (another thread of the parent may have held its lock at the fork):
 * records of [level u8][length u32][text], at most SY_ASSIMP_NOTES_MAX bytes, the rest counted. */
#define SY_ASSIMP_NOTES_MAX (64u << 10)
typedef struct asp_notes {
    char *buf;
    size_t len, cap;
    uint32_t dropped;
} asp_notes;

/* A node of the file's tree by name (the tree's nodes sorted by name, then by breadth-first order). */
typedef struct asp_named {
    const struct aiNode *ai;
    sy_node node;
    uint32_t walk; /* its breadth-first index */
    bool trs;      /* its transform was turned into TRS for an animation channel */
} asp_named;

/* A node that draws a mesh: the tree node itself (one mesh) or a child made for each of its meshes. */
typedef struct asp_placement {
    uint32_t walk; /* the tree node's breadth-first index */
    unsigned mesh; /* the aiMesh */
    sy_node node;  /* the node holding the mesh */
} asp_placement;

typedef struct asp_loader {
    const char *path;      /* names the file in messages */
    char *model_dir;       /* the model's folder ("" = the working directory), '/'-terminated or "" */
    sy_scene *scene;
    sy_assimp_options opt;
    sy_assimp_info *info;
    sy_error err;
    sy_budget budget;
    const struct aiScene *ai;
    asp_created *objs;
    size_t obj_count, obj_cap;
    sy_material *materials;      /* per aiMaterial */
    bool *normal_mapped;         /* per aiMaterial: has a normal texture */
    sy_mesh *meshes;             /* per aiMesh; {0}: skipped */
    sy_bounds *mesh_bounds;      /* per aiMesh: its positions' bounds */
    bool *mesh_skinned;          /* per aiMesh: its primitive has joints and weights */
    uint32_t *mesh_targets;      /* per aiMesh: morph targets its primitive has */
    asp_named *named;            /* the tree's nodes by name (asp_create_nodes) */
    size_t named_count;
    asp_placement *placements;   /* every node that draws a mesh, in creation order */
    size_t placement_count, placement_cap;
    bool anim_states_warned;     /* a channel's pre / post state the clock cannot follow: warned once */
    asp_texture *textures;
    size_t texture_count, texture_cap;
    /* the confined file system */
    const uint8_t *main_data;
    size_t main_size;
    char *main_name;        /* the name Assimp opens the model by */
    bool obj;               /* the model is Wavefront OBJ: the other files Assimp opens are MTL libraries */
    char *mtl_dirs[SY_ASSIMP_MTL_DIRS]; /* their folders relative to the model's ("" = the same; '/'-terminated) */
    size_t mtl_dir_count;
    asp_notes *notes;       /* NULL: log lines go to sy_log; else kept here (the import process) */
    sy_result io_result;    /* the first refused or failed file (fails the load) */
    char io_message[SY_ERROR_MESSAGE_MAX];
} asp_loader;

/* >>io (sy_assimp_io.c) ------------------------------------------------------------------------ */

/* asp_fail(L, code, fmt, ...): sets L->err to "<path>: <message>" and returns code. */
#define asp_fail(L, code, ...) sy_loader_failf(&(L)->err, (L)->path, (code), __VA_ARGS__)
/* asp_warnings(info): the info struct's warnings (sy_loader_log.h). */
#define asp_warnings(info) SY_LOADER_WARNINGS(info, SY_ASSIMP_MAX_WARNINGS)
/* asp_warn(L, fmt, ...): a warning "<message>" (at most SY_ASSIMP_MAX_WARNINGS stored, all counted). */
#define asp_warn(L, ...) sy_loader_warnf(asp_warnings((L)->info), __VA_ARGS__)
/* Creates an object of type t (recorded for the rollback); on failure the message names `what`. */
sy_result asp_new(asp_loader *L, sy_object_type t, const char *name, const char *what, uint32_t *id);
/* Destroys every created object, newest first. */
void asp_rollback(asp_loader *L);
/* The aiFileIO that serves L's model from memory and every other file confined (UserData = L). */
struct aiFileIO asp_file_io(asp_loader *L);
/* Reads a file the model names (path joined to the model's folder; uri as the model gives it)
 * within max_file_bytes, confined; *data malloc()ed. Errors name the model and the uri. */
sy_result asp_read_named(asp_loader *L, const char *uri, void **data, size_t *size, sy_error *err);
/* Refuses, before Assimp sees it, a file that declares more than its bytes can hold. */
sy_result asp_precheck(asp_loader *L);
/* A line for the log (module "assimp", item the file): sy_log, or L->notes when it is set. */
void asp_note(asp_loader *L, sy_log_level level, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/* Assimp's log into asp_note while attached: warnings and errors as notes, the rest as debug. */
void asp_log_attach(asp_loader *L);
void asp_log_detach(void);
/* Assimp's string as a C string (bounded). */
const char *asp_str(const struct aiString *s);

/* >>materials (sy_assimp_materials.c) ---------------------------------------------------------- */

/* Material i (and the textures it uses) into L->materials[i]. */
sy_result asp_create_material(asp_loader *L, unsigned i);
void asp_free_textures(asp_loader *L);

/* >>scene (sy_assimp_scene.c) ------------------------------------------------------------------ */

/* The budget for every mesh and placement, before any is made. */
sy_result asp_charge(asp_loader *L);
/* Mesh i into L->meshes[i] (skipped with a warning when it has nothing to draw). */
sy_result asp_create_mesh(asp_loader *L, unsigned i);
/* The node tree under a new root (units and up axis), cameras and lights. */
sy_result asp_create_nodes(asp_loader *L);

/* >>anim (sy_assimp_anim.c) ------------------------------------------------------------------- */

/* Mesh i's bones (joints and weights, at most SY_SKIN_MAX_INFLUENCES per vertex: the largest kept,
 * renormalised) and anim meshes (morph target deltas: Assimp's absolute positions and normals minus
 * the mesh's) into p; the budget charged first. What cannot be used is dropped with a warning. */
sy_result asp_mesh_deform(asp_loader *L, unsigned i, const struct aiMesh *m, sy_primitive *p);
/* Mesh i's default morph weights (the anim meshes' mWeight) once the mesh exists. */
sy_result asp_mesh_weights(asp_loader *L, unsigned i);
/* The node named `name` (the first in breadth-first order), NULL when none. */
asp_named *asp_find_named(asp_loader *L, const char *name);
/* Skins on every node that draws a skinned mesh, and the file's animations as clips (after the nodes). */
sy_result asp_create_skins(asp_loader *L);
sy_result asp_create_animations(asp_loader *L);

/* >>load (sy_assimp.c) ------------------------------------------------------------------------- */

/* Options with every default filled in. */
sy_assimp_options asp_resolve_options(const sy_assimp_options *o);
/* The whole load in this process: read, check, import under the lock (none when notes is set: the
 * import process has no other thread), convert, roll back on failure. path names the file, mem
 * (size mem_size, base_dir) the content when loading from memory (path then being its name).
 * notes NULL: warnings and Assimp's log lines go to sy_log; else every line is kept there and
 * nothing is logged. */
sy_result asp_load_here(const char *path, const void *mem, size_t mem_size, const char *base_dir, sy_scene *scene,
                        const sy_assimp_options *opts, sy_assimp_info *info_out, asp_notes *notes, sy_error *err);

#endif /* SY_ASSIMP_INTERNAL_H */
