/* sy_load.h — how sy loads a SCENE (sy_load.c): a glTF 2.0, X3D or Assimp-read (OBJ, FBX, COLLADA, PLY,
 * STL, 3MF, 3DS, glTF 1.0, ...) file, recognised by its content,
 * or the word "demo" (the built-in scene), with the loader options and the world flags of every
 * command (sy_cli_load_opts, filled by sy_cli_parse). Thread-safety: the main thread only. */
#ifndef SY_LOAD_H
#define SY_LOAD_H

#include "sy_assimp.h"
#include "sy_compose.h"
#include "sy_gltf.h"
#include "sy_world.h"
#include "sy_x3d.h"

/* A loaded scene: its root, the camera to render from, the background, and what the loader said. */
typedef struct loaded {
    sy_scene *scene;
    sy_node root;
    sy_node camera; /* {0}: frame the bounds */
    sy_background background;
    sy_gltf_info gltf;
    bool is_gltf;
    sy_x3d_info x3d; /* .x3d files (is_x3d) */
    bool is_x3d;
    sy_assimp_info assimp; /* OBJ, FBX, COLLADA, PLY, STL, ... through Assimp (is_assimp) */
    bool is_assimp;
    bool clip_noted; /* sy_cli_set_time said which clip plays by default */
} loaded;

/* Loader options every command shares, taken out of the arguments by sy_cli_parse:
 * --allow-path DIR (repeatable: more folders that a model's external files may lie in), --strict
 * (whatever a loader skips or repairs is an error), --max-scene-mb N (the budget per file,
 * sy_budget.h), --variant NAME (a glTF material variant) and the world flags. */
#define SY_MAX_ALLOW_PATHS 16
/* Where the camera is put (sy render, pick, view, web): --look-at EYE:TARGET[:UP], --orbit AZ,EL[,DIST],
 * --bookmark FILE:N (a view sy view saved, sy_bookmarks.h; exclusive), --fov DEG (the vertical field of view of whichever camera is used). */
typedef struct sy_view_options {
    bool look_at;                   /* --look-at given (or --bookmark FILE:N: the saved view's eye, target, up and
                                     * field of view when it holds one; --fov still wins) */
    bool bookmark;                  /* --bookmark given */
    float eye[3], target[3], up[3]; /* up (0,1,0) when not given */
    bool orbit;                     /* --orbit given */
    float azimuth, elevation, dist; /* degrees, degrees, scene units (0 = frame the bounds) */
    float fov;                      /* --fov in radians; 0 = the camera's */
} sy_view_options;
/* Which nodes are hidden, isolated and selected (sy render, pick, view, web): --hide NODE,
 * --isolate NODE, --select NODE, each repeatable; NODE is a node name (every node of that name) or
 * a whole number: the node id `sy pick` prints (node.id), else the node's index in the scene's
 * creation order (0 = the first node made; sy_scene_next order). */
#define SY_MAX_NODE_OPTIONS 64
typedef struct sy_node_options {
    const char *hide[SY_MAX_NODE_OPTIONS], *isolate[SY_MAX_NODE_OPTIONS], *select[SY_MAX_NODE_OPTIONS];
    uint32_t hide_count, isolate_count, select_count;
} sy_node_options;
typedef struct sy_load_options {
    const char *roots[SY_MAX_ALLOW_PATHS];
    size_t root_count;
    bool strict;
    uint64_t max_scene_bytes; /* --max-scene-mb: the loaders' budget per file (sy_budget.h); 0 = default */
    const char *variant; /* --variant: a glTF file's KHR_materials_variants variant (name or index); NULL = default */
    sy_world_options world; /* --env, --env-color, --env-intensity, --env-hidden, --background, --no-default-light */
    sy_view_options view;   /* --look-at, --orbit, --fov (applied by sy_cli_load) */
    sy_node_options nodes;  /* --hide, --isolate, --select (applied by sy_cli_load) */
} sy_load_options;
extern sy_load_options sy_cli_load_opts;

/* --look-at, --orbit or --fov (code OPT_LOOK_AT, OPT_ORBIT, OPT_FOV) with its value into
 * sy_cli_load_opts.view. Returns 0, or 2 after a usage error naming the option and the reason (a
 * missing part, NaN, eye == target, up parallel to the view, a range; --look-at with --orbit) on
 * stderr. */
int sy_cli_view_option(int c, const char *value);
/* The saved views' file of sy view and sy web (sy_bookmarks.h): given (--bookmarks FILE) as it is,
 * else SCENE.bookmarks beside the scene, none (NULL) for the built-in demo. *owned: what the caller
 * frees (NULL when nothing was allocated); NULL also when out of memory. */
const char *sy_cli_bookmarks_file(const char *scene, const char *given, char **owned);
/* --hide, --isolate or --select (OPT_HIDE, OPT_ISOLATE, OPT_SELECT) with its NODE into
 * sy_cli_load_opts.nodes. Returns 0, or 2 after a usage error (an empty value, too many) on stderr. */
int sy_cli_node_option(int c, const char *value);
/* The nodes NODE names in s (see sy_node_options): *count_out of them into out (at most max);
 * SY_ERR_NOT_FOUND naming NODE and opt when there is none. */
sy_result sy_cli_find_nodes(const sy_scene *s, const char *opt, const char *node, sy_node *out, uint32_t max,
                            uint32_t *count_out, sy_error *err);

/* Loads path ("demo": the built-in scene) into a new scene in *out; camera_sel (NULL: the file's
 * first camera) names or numbers a camera; defaults: a file without a camera gets one framing its
 * bounds. The world flags are applied, and the view options (sy_cli_load_opts.view): --look-at and
 * --orbit put a new camera node "command-line camera" with the chosen camera's projection at the
 * given place (--orbit: around the centre of the root's world bounds, at AZ degrees about +y from +z
 * and EL degrees above the horizon, by default at the distance where the bounds' sphere fills the
 * view, as the default camera frames it); --fov sets the vertical field of view of the camera used
 * (an orthographic one refuses it). Then the node options (sy_cli_load_opts.nodes): --isolate hides
 * every node but the named ones (sy_scene_isolate), --hide hides the named nodes, --select selects
 * them; an unknown NODE fails the load naming the option and NODE. On failure *out is empty. */
sy_result sy_cli_load(const char *path, const char *camera_sel, bool defaults, loaded *out, sy_error *err);
void sy_cli_loaded_free(loaded *l);
/* The clip a scene plays when no --clip is given ({0}: every animation, sy_scene_set_time): a
 * glTF file (or one read through Assimp: an FBX file's takes) whose animations drive the same
 * objects holds alternatives (a character's walk, run and idle on the same joints: the Fox), so its
 * first one plays, as Blender's importer makes it active; animations on separate objects
 * (InterpolationTest's cubes) all play. An X3D file's TimeSensors all run at once, as X3D says. */
sy_animation sy_cli_default_clip(const loaded *ld);
/* --at SECONDS / --clip NAME|INDEX: sets the loaded scene's time (sy_scene_set_time) on that clip, or
 * on sy_cli_default_clip without one (a note says which, once), and commits. Returns 0; 2 after a
 * usage error (an unknown clip, named with the clips there are, on stderr); 1 with *err when the
 * scene refused a value. A scene without animations is told on the log (a note) and left as it is. */
int sy_cli_set_time(loaded *ld, const char *clip, double seconds, sy_error *err);
/* The image size sy render and sy pick use for *w x *h where the user gave 0: 512 high, the width
 * from the loaded camera's aspect ratio when it has one (either given: the other from the aspect);
 * never 0. */
void sy_cli_default_size(const loaded *ld, uint32_t *w, uint32_t *h);
/* X3D Viewpoint fieldOfView covers the smaller image side: adapt yfov to the output size. */
void sy_cli_fit_x3d_cameras(loaded *ld, uint32_t w, uint32_t h);
/* --overlay FILE[:BACKEND]: loads FILE into the same scene under its own root and layers it over
 * the main viewport of spec with the --composite mode (depth, over, replace). */
sy_result sy_cli_add_overlay(loaded *ld, const char *arg, const char *composite, sy_compose_spec *spec, sy_error *err);

#endif /* SY_LOAD_H */
