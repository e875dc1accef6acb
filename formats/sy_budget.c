/* sy_budget.c — one memory budget per loaded file (see sy_budget.h). */
#include "sy_budget.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

uint64_t sy_budget_default_bytes(void)
{
    const uint64_t floor = (uint64_t)256 << 20;
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0) return floor;
    uint64_t eighth = (uint64_t)pages / 8u * (uint64_t)page;
    return eighth > floor ? eighth : floor;
}

sy_budget sy_budget_make(const char *file, uint64_t limit)
{
    sy_budget b = {file ? file : "(memory)", limit ? limit : sy_budget_default_bytes(), 0};
    return b;
}

static double mib(uint64_t bytes) { return (double)bytes / (1024.0 * 1024.0); }

bool sy_budget_fits(const sy_budget *b, uint64_t count, uint64_t unit)
{
    uint64_t left = b->limit > b->used ? b->limit - b->used : 0;
    return unit == 0 || count <= left / unit;
}

sy_result sy_budget_charge(sy_budget *b, uint64_t count, uint64_t unit, sy_error *err, const char *what, ...)
{
    if (sy_budget_fits(b, count, unit)) {
        b->used += count * unit;
        return SY_OK;
    }
    char item[256];
    va_list ap;
    va_start(ap, what);
    vsnprintf(item, sizeof item, what, ap);
    va_end(ap);
    /* count x unit may overflow 64 bits: reported as at least what is left */
    double need = (double)count * (double)unit;
    bool placed = strncmp(item, b->file, strlen(b->file)) == 0; /* the item names the file already */
    return sy_error_set(err, SY_ERR_LIMIT,
                        "%s%s%s: needs %.1f MiB, past the scene budget of %.0f MiB (%.1f MiB used so far; "
                        "sy --max-scene-mb, loader option max_scene_bytes)",
                        placed ? "" : b->file, placed ? "" : ": ", item, need / (1024.0 * 1024.0), mib(b->limit),
                        mib(b->used));
}

sy_result sy_budget_charge_placements(sy_budget *b, const sy_scene *scene, sy_node root, sy_error *err)
{
    if (!sy_node_get(scene, root)) return SY_OK;
    uint64_t left = b->limit > b->used ? b->limit - b->used : 0;
    uint64_t cap = left / SY_BUDGET_PLACEMENT_BYTES + 1u; /* path counts saturate here */
    /* the graph below root, in depth-first post-order (each node once) */
    uint32_t max_index = 0;
    for (uint32_t id = sy_scene_next(scene, SY_TYPE_NODE, 0); id; id = sy_scene_next(scene, SY_TYPE_NODE, id))
        if ((id & SY_HANDLE_INDEX_MASK) > max_index) max_index = id & SY_HANDLE_INDEX_MASK;
    size_t n = (size_t)max_index + 1u;
    uint8_t *state = calloc(n, 1);         /* 0 new, 1 on the walk, 2 done */
    uint64_t *paths = calloc(n, sizeof *paths);
    uint32_t *order = malloc(n * sizeof *order), norder = 0;
    struct frame {
        uint32_t id, next;
    } *stack = malloc(n * sizeof *stack);
    if (!state || !paths || !order || !stack) {
        free(state), free(paths), free(order), free(stack);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: counting placements of %zu nodes: out of memory", b->file, n);
    }
    uint32_t depth = 0;
    stack[depth++] = (struct frame){root.id, 0};
    state[root.id & SY_HANDLE_INDEX_MASK] = 1;
    while (depth) {
        struct frame *f = &stack[depth - 1];
        uint32_t nc = 0;
        const uint32_t *ch = sy_node_children(sy_node_get(scene, (sy_node){f->id}), &nc);
        if (f->next < nc) {
            uint32_t c = ch[f->next++];
            if (!sy_node_get(scene, (sy_node){c}) || state[c & SY_HANDLE_INDEX_MASK]) continue; /* stale, or seen */
            state[c & SY_HANDLE_INDEX_MASK] = 1;
            stack[depth++] = (struct frame){c, 0}; /* depth <= n: each node is pushed once */
            continue;
        }
        state[f->id & SY_HANDLE_INDEX_MASK] = 2;
        order[norder++] = f->id;
        depth--;
    }
    /* reverse post-order is topological: parents before children */
    uint64_t total = 0;
    paths[root.id & SY_HANDLE_INDEX_MASK] = 1;
    for (uint32_t k = norder; k-- > 0;) {
        uint32_t id = order[k];
        uint64_t p = paths[id & SY_HANDLE_INDEX_MASK];
        total = total + p < cap ? total + p : cap;
        uint32_t nc = 0;
        const uint32_t *ch = sy_node_children(sy_node_get(scene, (sy_node){id}), &nc);
        for (uint32_t i = 0; i < nc; ++i) {
            if (!sy_node_get(scene, (sy_node){ch[i]})) continue;
            uint64_t *q = &paths[ch[i] & SY_HANDLE_INDEX_MASK];
            *q = *q + p < cap ? *q + p : cap;
        }
    }
    free(state), free(paths), free(order), free(stack);
    return sy_budget_charge(b, total, SY_BUDGET_PLACEMENT_BYTES, err, "%s%llu placements (nodes x paths through the graph)",
                            total >= cap ? "at least " : "", (unsigned long long)total);
}
