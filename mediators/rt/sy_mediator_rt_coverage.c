/* sy_mediator_rt_coverage.c — coverage (the coverage class, SY_CAP_COVERAGE): every object's
 * pixels in a view, as an image (a stable colour per node) and as numbers (sy_context_coverage)
 * (sy_mediator_rt_internal.h); what is under one pixel (SY_CAP_PICK). */
#include "sy_mediator_rt_internal.h"
#include "sy_pick_ray.h"

#include <stdlib.h>
#include <string.h>

/* Coverage as an image: every object gets a stable colour from its node id (for viewing and
 * layering); sy_rti_coverage (sy_context_coverage) gives the numbers. */
sy_result sy_rti_coverage_render(rt_state *st, const sy_rt_camera *cam, const sy_rt_render_desc *d,
                                 sy_layer *layer, sy_error *err)
{
    size_t n = (size_t)d->width * d->height;
    uint32_t *ids = malloc(n * sizeof *ids);
    if (!ids) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "coverage: out of memory");
    sy_rt_result r = sy_rt_coverage(st->dev, cam, d, ids, layer->depth);
    if (r == SY_RT_OK)
        for (size_t i = 0; i < n; ++i) {
            uint32_t node = sy_rti_inst_node_get(st, ids[i]);
            float *c = layer->rgba + 4 * i;
            if (!ids[i]) {
                c[0] = c[1] = c[2] = c[3] = 0.0f;
                continue;
            }
            uint32_t hsh = node * 2654435761u;
            c[0] = 0.2f + 0.8f * (float)(hsh & 255u) / 255.0f;
            c[1] = 0.2f + 0.8f * (float)((hsh >> 8) & 255u) / 255.0f;
            c[2] = 0.2f + 0.8f * (float)((hsh >> 16) & 255u) / 255.0f;
            c[3] = 1.0f;
        }
    free(ids);
    return r == SY_RT_OK ? SY_OK : sy_rti_fail(st, err, r, "coverage");
}

static int coverage_order(const void *pa, const void *pb)
{
    const sy_coverage_entry *a = pa, *b = pb;
    if (a->pixels != b->pixels) return a->pixels > b->pixels ? -1 : 1;
    return a->node_id < b->node_id ? -1 : a->node_id > b->node_id;
}

/* SY_CAP_COVERAGE (sy_context_coverage): works on any state of this adapter; the coverage class
 * offers it. */
sy_result sy_rti_coverage(void *state, const sy_camera_view *view, uint32_t width, uint32_t height,
                          sy_coverage_entry **entries_out, uint32_t *count_out, sy_error *err)
{
    rt_state *st = state;
    *entries_out = NULL;
    *count_out = 0;
    sy_rt_camera cam;
    sy_rti_camera_of(view, &cam);
    sy_rt_render_desc d = {.image_width = width, .image_height = height, .width = width, .height = height};
    size_t n;
    if (!sy_size_mul(width, height, &n) || n == 0) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "coverage: bad size %ux%u", width, height);
    uint32_t *ids = malloc(n * sizeof *ids);
    if (!ids) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "coverage: out of memory for %ux%u", width, height);
    sy_rt_result cr = sy_rt_commit(st->dev); /* no-op unless a failed sync left changes */
    if (cr != SY_RT_OK) {
        free(ids);
        return sy_rti_fail(st, err, cr, "commit");
    }
    sy_rt_result r = sy_rt_coverage(st->dev, &cam, &d, ids, NULL);
    if (r != SY_RT_OK) {
        free(ids);
        return sy_rti_fail(st, err, r, "coverage");
    }
    /* count pixels per node */
    for (size_t i = 0; i < n; ++i) ids[i] = sy_rti_inst_node_get(st, ids[i]);
    sy_coverage_entry *out = NULL;
    uint32_t m = 0, cap = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!ids[i]) continue;
        uint32_t k = 0;
        /* few distinct objects per view in practice; a linear scan with move-to-front stays cheap */
        while (k < m && out[k].node_id != ids[i]) k++;
        if (k == m) {
            if (m == cap) {
                uint32_t nc = cap ? cap * 2 : 64;
                sy_coverage_entry *no = realloc(out, sizeof *no * nc);
                if (!no) {
                    free(out);
                    free(ids);
                    return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "coverage: out of memory");
                }
                out = no;
                cap = nc;
            }
            out[m].node_id = ids[i];
            out[m].pixels = 0;
            m++;
        }
        out[k].pixels++;
        if (k > 0) { /* move to front */
            sy_coverage_entry t = out[k];
            out[k] = out[0];
            out[0] = t;
        }
    }
    free(ids);
    if (m > 1) qsort(out, m, sizeof *out, coverage_order);
    *entries_out = out;
    *count_out = m;
    return SY_OK;
}

/* SY_CAP_PICK: Embree names the instance and the triangle (sy_rt_pick); the instance's node,
 * placement, mesh, primitive and material come from the mirror; the numbers from sy_pick_ray.h. */
sy_result sy_rti_pick(void *state, const sy_camera_view *view, uint32_t width, uint32_t height, uint32_t x, uint32_t y,
                      sy_pick_result *out, sy_error *err)
{
    rt_state *st = state;
    sy_rt_camera cam;
    sy_rti_camera_of(view, &cam);
    sy_rt_result r = sy_rt_commit(st->dev); /* no-op unless a failed sync left changes */
    if (r != SY_RT_OK) return sy_rti_fail(st, err, r, "commit");
    sy_rt_pick_hit h;
    r = sy_rt_pick(st->dev, &cam, width, height, x, y, &h);
    if (r != SY_RT_OK) return sy_rti_fail(st, err, r, "pick");
    sy_mirror_instance_info info;
    if (!h.instance.id || !sy_mirror_instance_find(st->mirror, sy_rti_inst_node_get(st, h.instance.id), h.instance.id, &info))
        return SY_OK;
    sy_pick_name(out, &info, h.triangle);
    if (!sy_pick_triangle(view, width, height, x, y, h.transform, (const float(*)[3])h.vertices, out)) {
        /* a ray along the triangle's plane: Embree's own numbers */
        float b[3] = {1.0f - h.u - h.v, h.u, h.v};
        out->hit = true;
        for (int k = 0; k < 3; ++k) out->barycentrics[k] = b[k];
        out->depth = h.depth;
    }
    return SY_OK;
}
