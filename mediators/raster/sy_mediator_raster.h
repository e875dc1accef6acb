/** @file
 * sy_mediator_raster.h — the mediator between the core scene and the OpenGL rasterizer back-end
 * (backends/raster).
 *
 * Mirrors textures, materials, meshes, lights and the node graph from change values (never from
 * the live scene), flattens the graph into placements (one world matrix per path; a DAG node
 * reached along k paths gets k placements) and keeps the GL objects in sync incrementally: a
 * transform change sets the model matrices of the node's subtree only (no upload), a material
 * change is one uniform-buffer update, a new mesh one upload of its vertex and index buffers.
 * Emissive meshes stay plain emissive surfaces (pixel = emissive x strength).
 *
 * Parameters (sy_params; declared in the class's param_table, the authority that core checks and
 * `sy backends --params` prints): gl = osmesa (default) | egl | glfw, msaa (1..32, default 4; clamped to
 * the context's limit with a warning), shadow_map_size (16..16384; default 0: follows the frame, the power of two
 * at or above twice its larger side, 256 to 2048), max_texture_size
 * (0 = the GL limit; larger textures are downscaled with a warning), window_width/window_height
 * (GLFW window, default 640 x 480). Warnings go to sy_log (module "raster", sy_log.h).
 *
 * Ownership/thread-safety: as any mediator (see core/sy_mediator.h); the GL context is made
 * current on the calling thread by every call; gl=glfw needs the main thread (GLFW's rule). */
#ifndef SY_MEDIATOR_RASTER_H
#define SY_MEDIATOR_RASTER_H

#include "sy_mediator.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Registers raster (the build's registration list calls it). */
sy_result sy_mediator_raster_register(sy_error *err);
/** The rasterizer class ("raster"). Static storage. */
const sy_mediator_class *sy_mediator_raster_class(void);

/** Counters for tests and benchmarks. Upload counts are those of the last rendered frame: every
 * upload between the end of the previous frame and the end of the last one (syncs included). */
typedef struct sy_mediator_raster_counters {
    /** @{ live back-end objects */
    uint32_t instances, meshes, materials, textures, lights; /** @} */
    /** @{ placements recomputed and change entries handled by the last sync */
    uint32_t last_sync_placements, last_sync_entries; /** @} */
    /** @{ of the last sync: the mirror's deformation of skinned / morphed meshes, and the re-upload
     * of their vertex buffers (sy_gl_mesh_update; sy_mirror_sync_stats) */
    double last_sync_deform_seconds, last_sync_upload_seconds; /** @} */
    /** @{ of the last sync: primitive instances given a deformed pose, and of them the poses another
     * context's mirror had deformed already (shared, not deformed again: sy_deform_cache.h) */
    uint32_t last_sync_deformed, last_sync_deform_shared; /** @} */
    /** @{ uploads of the last frame (vertex and index buffers, their bytes, uniform buffers, textures) */
    uint64_t vertex_buffer_uploads, vertex_bytes, uniform_buffer_uploads, texture_uploads; /** @} */
    uint64_t model_matrix_updates; /**< instance transforms set in the last frame */
    /** @{ uploads since creation */
    uint64_t total_vertex_buffer_uploads, total_texture_uploads; /** @} */
    /** @{ effective MSAA samples; shadow maps rendered in the last frame */
    uint32_t msaa_samples, shadow_maps; /** @} */
    /** @{ draw calls and main-pass triangles of the last frame */
    uint64_t draw_calls, triangles_drawn; /** @} */
    uint64_t instances_culled; /**< instances outside the view in the last frame (not drawn) */
    uint64_t deferred_draws;   /**< instances the last frame shaded deferred (sy_gl_device_desc.forward) */
    uint64_t deferred_pixels;  /**< pixels its deferred pass shaded (tiles those instances touch) */
    uint32_t warnings; /**< warnings so far */
    char last_warning[256]; /**< the last warning */
} sy_mediator_raster_counters;
/** state is the mediator state of a "raster" context (sy_context_state). */
void sy_mediator_raster_counters_get(void *state, sy_mediator_raster_counters *out);
/** "OpenGL 4.5 (Core Profile) Mesa ... on llvmpipe (...) (osmesa)". Borrowed. */
const char *sy_mediator_raster_info(void *state);
/** Benchmark floor: the same visible buffers drawn with a trivial shader into the same targets
 * (lit = "trivial lit": one directional light, Lambert on the vertex normals, constant ambient),
 * read back into the layer's colour and depth as a frame is. */
sy_result sy_mediator_raster_render_floor(void *state, const sy_render_request *req, bool lit, sy_layer *layer,
                                          sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_MEDIATOR_RASTER_H */
