/* sy_bench.h — `sy bench` benchmarks. They print ratios measured in one run (never pass/fail on
 * time): sync (incremental update vs translating from scratch), rays (our primary-ray throughput
 * vs raw Embree on the same rays) and the others below, one file each (sy_bench_KIND.c; what they
 * share: sy_bench.c). Thread-safety: single-threaded callers. */
#ifndef SY_BENCH_H
#define SY_BENCH_H

#include "sy_bench_os.h" /* sy_bench_rss_now_kib */
#include "sy_viewport.h"

/* Generated scene of `nodes` leaf nodes (100 per group) with ~tris triangles each; times building
 * the back-end scene from scratch (context creation + first sync) against `repeats` single
 * transform changes (commit + sync), and reports bytes of change log per change. */
sy_result sy_bench_sync(uint32_t nodes, uint32_t tris, uint32_t repeats, sy_error *err);

/* Primary-ray throughput of the whitted back-end's device against raw rtcIntersect1 for the view
 * of the viewport desc (camera or framing), width x height, best of repeats. */
sy_result sy_bench_rays(sy_scene *scene, const sy_viewport_desc *vd, uint32_t width, uint32_t height, uint32_t repeats,
                        sy_error *err);

/* Viewport costs on the demo scene: compositing two 1920x1080 layers (depth and alpha-over, one
 * core), switching a viewport's back-end away and back (the second switch must not translate the
 * scene again: reported as sync times), and stereo (side-by-side) cost per eye against mono for
 * every registered back-end, at width x height per eye. */
sy_result sy_bench_viewports(uint32_t width, uint32_t height, uint32_t repeats, sy_error *err);

/* Rasterizer on OSMesa (or gl=... in vd->params): median frame time of the scene in vd and of a
 * generated 1M-triangle scene (100 meshes; as generated, then written to a .glb and loaded by
 * sy_cli_load: the user's path) at width x height against the floor (the same buffers
 * drawn with a trivial shader into the same targets), the time from a transform change to the
 * next finished frame, and GL uploads per frame. */
sy_result sy_bench_raster(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width,
                          uint32_t height, uint32_t repeats, sy_error *err);

/* glTF loading (formats): for each sample model under data_dir (one variant per model, binary when
 * present) and for a generated .glb of about `tris` triangles (written to a temporary directory),
 * the median time of tinygltf's parse alone next to the whole sy_gltf_load (our translation
 * overhead as a ratio) over `repeats` runs, and the peak RSS growth of one load (forked child)
 * relative to the bytes read. A missing data_dir only skips the sample models. */
sy_result sy_bench_load(const char *data_dir, uint32_t tris, uint32_t repeats, sy_error *err);

/* Memory (issue 19): for each ray tracer (backend, or whitted and pathtracer when NULL), a forked
 * child builds a height field of about `tris` unique triangles (sy_height_field_generate, apps/scenes)
 * through the normal path (scene blobs -> mediator -> back-end), renders one width x height frame,
 * and reports its peak RSS per triangle with the breakdown: scene, back-end copies, Embree's
 * allocations; then another child the same with the grid written to a temporary .glb and loaded by
 * sy_gltf_load (the user's path), and the ratio of the two peaks. glb: the file alone. */
sy_result sy_bench_memory(uint32_t tris, const char *backend, bool glb, uint32_t width, uint32_t height, sy_error *err);

/* Path tracer (issue 3): samples per second (1-spp passes over width x height, median and mean of
 * `passes`), Mrays/s (closest-hit + shadow rays) and the Whitted back-end's frame time on the same
 * scene and viewport, then the restart latency: the time of the first pass after a transform
 * change (sync included) against one pass. All threads. */
sy_result sy_bench_pathtracer(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width,
                              uint32_t height, uint32_t passes, sy_error *err);

/* Noise-reduction filters (issue 7, backends/filters) on the analytic render surrogate
 * (sy_filter_synth.h) at width x height: filter time per frame at 4 spp for every method (median
 * of `repeats`, all cores and one thread), then RMSE / relMSE / SSIM against the converged image
 * at 1, 4, 16, 64, 256 spp with every method fed the same progressive samples; png_path (may be
 * NULL) receives the contact sheet (rows = spp, columns = methods + reference). */
sy_result sy_bench_filters(uint32_t width, uint32_t height, uint32_t repeats, const char *png_path, sy_error *err);

/* The same comparison on the path tracer's feature buffers for the view of vd (its camera node
 * gives positions and the headlight), against the linear RGB reference EXR of the same size
 * (e.g. the Cycles Cornell box): 1..256 passes of 1 spp, metrics at 1, 4, 16, 64, 256 spp, the
 * path-tracing pass time and the fast pixel filter's cost as a ratio to it; optional sheet. The
 * radiance filter runs on the path tracer's stored-sample hook in a second viewport of the same
 * view (filter=radiance, same seed: the same samples), one filter frame per 1-spp pass. */
sy_result sy_bench_filters_scene(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width,
                                 uint32_t height, const char *reference_exr, const char *png_path, sy_error *err);

/* sy bench temporal (sy_bench_temporal.c, issue 36): the path tracer's temporal reuse on a camera
 * path of `frames` frames of 1 spp at width x height against references of ref_spp samples per view
 * (relMSE and flicker, plain and temporal, with their ratios), and the temporal stage's cost per
 * 640x360 frame (the median of cost_frames moving frames, 1..12, and its breakdown into the stage's
 * parts). png_prefix (may be NULL): PREFIX_plain.png, PREFIX_temporal.png and PREFIX_reference.png of
 * the middle frame. */
sy_result sy_bench_temporal(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width,
                            uint32_t height, uint32_t frames, uint32_t ref_spp, uint32_t cost_frames,
                            const char *png_prefix, sy_error *err);

/* sy bench instances (sy_bench_instances.c, built with the Embree back-ends): `instances` nodes
 * instancing one height field of about `tris` triangles, rendered with every picture back-end:
 * first frame (translation included), median and worst frame of an orbit of `frames` frames, the
 * rasterizer's triangles drawn and instances culled, coverage IoU against Whitted, peak RSS; for the
 * scene as generated, then written to a .glb with normals and to one without (positions and indices)
 * and loaded back by sy_cli_load, with the ratios between the three. `only` (NULL = all): that
 * back-end alone (Whitted still renders its first frame for the IoU). out_dir (an existing folder)
 * keeps the two files there as instances.glb and instances_no_normals.glb; NULL: a temporary folder,
 * removed at the end. */
sy_result sy_bench_instances(uint32_t instances, uint32_t tris, uint32_t width, uint32_t height, uint32_t frames,
                             const char *only, const char *out_dir, sy_error *err);
/* Distance to the limit (issue 19, part 6; apps/sy/sy_bench_limit.c): one path-traced frame of the
 * view in vd (spp samples per pixel, width x height) is recorded ray by ray, then the frame and raw
 * Embree on exactly those rays (rtcIntersect1/rtcOccluded1, the 4/8/16-wide packets, the 1M
 * streams; the back-end's threads) are timed `repeats` times, interleaved; prints the path
 * tracer's rays/s as a share of each form's (median, min .. max) and any replayed answer that
 * differs from the frame's. */
sy_result sy_bench_limit(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width,
                         uint32_t height, uint32_t spp, uint32_t repeats, sy_error *err);
/* sy bench limit [SCENE] [-w W -h H] [--spp N] [--repeats N]: argv[0] is "limit". Without SCENE the
 * Cornell box (../shared/testdata/cornell) and the demo. Returns the exit status. */
int sy_cmd_bench_limit(int argc, char **argv);

/* sy bench deform (issue 35): a generated tube of about `vertices` vertices skinned to 16 joints;
 * the deform step, the mirror's sync and, per back-end (whitted, raster), a posed frame's set +
 * commit + sync against building the scene from scratch, `repeats` frames (sy_bench_deform.c). */
sy_result sy_bench_deform(uint32_t vertices, uint32_t repeats, sy_error *err);

/* sy bench anim (issue 35, sy_bench_anim.c): a tube of about `vertices` vertices skinned to 16
 * animated joints and `nodes` animated nodes, each written to a .glb and loaded by sy_gltf_load;
 * per frame (`frames` of the clip) the clock, commit, change list, the mirror (its deformation)
 * and, per back-end, the sync (deformation, BVH refit or upload, top-level commit) against
 * translating the same frame from scratch. */
sy_result sy_bench_anim(uint32_t vertices, uint32_t nodes, uint32_t frames, sy_error *err);

/* sy bench lights (issue 39, apps/sy/sy_bench_lights.c): a generated many-lights scene (`quads`
 * small emissive quads, `points` point lights of varied power, 30 boxes over a large floor) written
 * to out_dir/many_lights.gltf (NULL: a new temporary directory) and loaded by the normal loader;
 * the path tracer with light_tree=on and =off, 1-spp passes interleaved until each has `seconds`
 * of render time, each compared (relMSE) with a reference (the tree, another seed, 8 x the time);
 * then the tree's size and build time and one light's update (its refit). Writes the three images
 * as PNG beside the scene. */
sy_result sy_bench_lights(uint32_t quads, uint32_t points, uint32_t width, uint32_t height, double seconds,
                          const char *out_dir, sy_error *err);
/* Minimum, median and maximum of n > 0 values (sorts v in place): benchmarks report the median of
 * their rounds with the spread. */
typedef struct sy_bench_spread {
    double min, median, max;
} sy_bench_spread;
sy_bench_spread sy_bench_spread_of(double *v, uint32_t n);

/* For the benchmarks' own files (sy_bench.c, sy_bench_load.c). */
/* qsort comparison of doubles, ascending */
int sy_bench_cmp_double(const void *a, const void *b);
/* One frame of win (samples: per pixel for a progressive back-end, 0 = its default pass) timed
 * into *secs (sy bench pathtracer, sy bench filters). */
sy_result sy_bench_frame(sy_window *win, sy_scene *scene, sy_context_pool *pool, uint32_t samples, sy_layer *out,
                         double *secs, sy_error *err);
/* A transform change: node n placed at (x, 0, 0), unrotated and unscaled, and the scene committed
 * (sy bench sync, sy bench raster). */
sy_result sy_bench_move(sy_scene *s, sy_node n, float x, sy_error *err);
/* Mirror callbacks of a back-end that keeps nothing: the mirror's own cost (primitive_update: the
 * deformation in place), for sy bench deform and sy bench anim. */
extern const struct sy_mirror_callbacks sy_bench_nop_mirror;
/* The skinned tube of sy bench deform and sy bench anim: height 2 along +Y, radius 0.1, `rings` rings
 * (>= 2) of SY_BENCH_TUBE_SEGMENTS vertices, SY_BENCH_TUBE_JOINTS joints evenly along it (joint k at
 * height k * 2 / (JOINTS - 1)), two influences per vertex. Fills positions and normals (3 floats a
 * vertex), joints (4 a vertex: into j32 or j16, the other NULL; zeroed by the caller), weights (4 a
 * vertex, zeroed by the caller) and triangle indices ((rings - 1) * SEGMENTS * 2 triangles). */
#define SY_BENCH_TUBE_JOINTS 16u
#define SY_BENCH_TUBE_SEGMENTS 64u
void sy_bench_tube(uint32_t rings, float *pos, float *nrm, uint32_t *j32, uint16_t *j16, float *w, uint32_t *idx);
/* A .glb with a (grid + 1)^2-vertex grid of 2 * grid^2 triangles: POSITION, NORMAL, TEXCOORD_0,
 * uint32 indices; written through sy_atomic_file (sy bench load, sy bench memory). */
sy_result sy_bench_write_grid_glb(const char *path, uint32_t grid, sy_error *err);
/* The user's path for a generated scene (issue 39, part 0): the scene under root written to a .glb
 * (sy_gltf_write_scene_file) and loaded back by sy_cli_load as `sy render` loads it (no default
 * camera added) into *out (free it with sy_cli_loaded_free). path: where the file is written and
 * kept; NULL: a temporary folder, removed with the file once loaded. *bytes_out (may be NULL): the
 * file's size. Used by sy bench instances, raster, sync, governor and cull (sy bench memory writes
 * its grid with sy_bench_write_grid_glb instead: its children measure the load itself). */
struct loaded;
sy_result sy_bench_reload_glb(const sy_scene *s, sy_node root, const char *path, const char *generator,
                              struct loaded *out, uint64_t *bytes_out, sy_error *err);
/* The first node with a mesh under root, first children first (in a loaded copy of a generated
 * scene, the node the generated scene's first leaf became). SY_ERR_NOT_FOUND when there is none. */
sy_result sy_bench_first_mesh_node(const sy_scene *s, sy_node root, sy_node *out, sy_error *err);
/* A benchmark of a back-end this build lacks (SY_WITH_EMBREE / SY_WITH_RASTER off) says so. */
#define SY_BENCH_WITHOUT(err, what, option)                                                                            \
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "sy bench: %s needs a back-end this sy was built without (%s=OFF)",   \
                        what, option)

#endif /* SY_BENCH_H */
