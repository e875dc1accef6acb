/* test_rt_sheen.c — the path tracer's layer helpers on their own (backends/rt internals):
 *   - sy_rt_sheen_albedo (the bilinear 32 x 16 table of the Charlie sheen lobe's directional
 *     albedo) against fresh quadrature (sy_rt_sheen_albedo_integrate, 256 x 512 midpoints) at
 *     points between the table's nodes: within 0.01 + 3 %; the lobe is dark at normal incidence for
 *     low roughness and brightest toward grazing;
 *   - sy_rt_iridescence_fresnel: a film of thickness 0 is no film (Schlick of the base's F0 within
 *     0.01); a 400 nm film of IOR 1.3 over glass (F0 0.04) colours the normal-incidence reflectance
 *     (channels differ by more than 0.01) and stays within [0, 1].
 * With SY_RT_SHEEN_PRINT_TABLE=1 it prints the table (backends/rt/sy_rt_sheen_table.inc; 512 steps). */
#include "../support/sy_check.h"
#include "sy_rt_iridescence.h"
#include "sy_rt_sheen.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static void print_table(void)
{
    for (int j = 0; j < 16; ++j) {
        printf("    {");
        for (int i = 0; i < 32; ++i) {
            printf("%.5ff%s", (float)sy_rt_sheen_albedo_integrate((float)i / 31.0f, (float)j / 15.0f, 512), i < 31 ? ", " : "");
            if (i % 8 == 7 && i < 31) printf("\n     ");
        }
        printf("},\n");
    }
}

int main(void)
{
    if (getenv("SY_RT_SHEEN_PRINT_TABLE")) {
        print_table();
        return 0;
    }
    const float mus[] = {0.05f, 0.2f, 0.45f, 0.7f, 0.95f}, rs[] = {0.1f, 0.35f, 0.62f, 0.9f};
    for (size_t a = 0; a < sizeof rs / sizeof rs[0]; ++a)
        for (size_t b = 0; b < sizeof mus / sizeof mus[0]; ++b) {
            double want = sy_rt_sheen_albedo_integrate(mus[b], rs[a], 256), got = sy_rt_sheen_albedo(mus[b], rs[a]);
            EXPECT_MSG(fabs(got - want) <= 0.01 + 0.03 * want, "sheen albedo (mu %.2f, r %.2f): table %.4f, quadrature %.4f",
                       (double)mus[b], (double)rs[a], got, want);
        }
    EXPECT_MSG(sy_rt_sheen_albedo(1.0f, 0.1f) < 0.01f && sy_rt_sheen_albedo(0.1f, 0.1f) > 0.3f,
               "sheen albedo at low roughness: normal %.4f, grazing %.4f", (double)sy_rt_sheen_albedo(1.0f, 0.1f),
               (double)sy_rt_sheen_albedo(0.1f, 0.1f));
    sy_rt_v3 f0 = v3(0.04f, 0.04f, 0.04f);
    for (float c = 0.1f; c <= 1.0f; c += 0.3f) {
        sy_rt_v3 f = sy_rt_iridescence_fresnel(c, 1.3f, 0.0f, f0);
        float m = 1.0f - c, s = 0.04f + 0.96f * m * m * m * m * m;
        EXPECT_MSG(fabsf(f.x - s) < 0.01f && fabsf(f.y - s) < 0.01f && fabsf(f.z - s) < 0.01f,
                   "no film at cos %.2f: %.4f %.4f %.4f, Schlick %.4f", (double)c, (double)f.x, (double)f.y, (double)f.z, (double)s);
    }
    sy_rt_v3 f = sy_rt_iridescence_fresnel(1.0f, 1.3f, 400.0f, f0);
    float hi = fmaxf(f.x, fmaxf(f.y, f.z)), lo = fminf(f.x, fminf(f.y, f.z));
    EXPECT_MSG(hi - lo > 0.01f && lo >= 0.0f && hi <= 1.0f, "400 nm film: %.4f %.4f %.4f", (double)f.x, (double)f.y, (double)f.z);
    printf("400 nm film at normal incidence: %.4f %.4f %.4f\n", (double)f.x, (double)f.y, (double)f.z);
    return sy_check_finish("rt_sheen");
}
