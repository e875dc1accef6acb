/* png_compare.c — test tool: `png_compare A.png B.png MAXDIFF [MIN_DISTINCT]` exits 0 when both
 * images have the same size and no channel differs by more than MAXDIFF (8-bit units), and A has
 * at least MIN_DISTINCT distinct colours (default 1: catches a uniform, empty image). Prints why
 * otherwise (exit 1). */
#include "sy_png.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int distinct_colours(const uint8_t *p, size_t n, int cap)
{
    uint32_t seen[256];
    int count = 0;
    for (size_t i = 0; i < n && count < cap && count < 256; ++i) {
        uint32_t c;
        memcpy(&c, p + 4 * i, 4);
        int k = 0;
        while (k < count && seen[k] != c) k++;
        if (k == count) seen[count++] = c;
    }
    return count;
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: png_compare A.png B.png MAXDIFF [MIN_DISTINCT]\n");
        return 2;
    }
    int maxdiff = atoi(argv[3]), min_distinct = argc > 4 ? atoi(argv[4]) : 1;
    int wa, ha, wb, hb;
    uint8_t *a = NULL, *b = NULL;
    sy_error e = {0};
    if (sy_png_read_rgba8(argv[1], &wa, &ha, &a, &e) != SY_OK || sy_png_read_rgba8(argv[2], &wb, &hb, &b, &e) != SY_OK) {
        fprintf(stderr, "png_compare: %s\n", e.message);
        free(a);
        return 1;
    }
    int rc = 0;
    if (wa != wb || ha != hb) {
        fprintf(stderr, "png_compare: sizes differ: %dx%d vs %dx%d\n", wa, ha, wb, hb);
        rc = 1;
    } else {
        size_t n = (size_t)wa * ha, worst_i = 0;
        int worst = 0;
        for (size_t i = 0; i < n * 4; ++i) {
            int d = abs((int)a[i] - (int)b[i]);
            if (d > worst) worst = d, worst_i = i;
        }
        int distinct = distinct_colours(a, n, min_distinct);
        printf("png_compare: %dx%d, max channel difference %d (pixel %zu), %s%d distinct colours\n", wa, ha, worst,
               worst_i / 4, distinct >= min_distinct ? ">= " : "", distinct);
        if (worst > maxdiff) rc = 1;
        if (distinct < min_distinct) rc = 1;
    }
    free(a);
    free(b);
    return rc;
}
