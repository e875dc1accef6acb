/* test_rt_bench.c — sy_rt_bench_rays on a scene of many instanced and baked meshes: what makes its
 * comparison fair, not how fast it is (speed lives in `sy bench rays`, docs/BACKENDS.md): the
 * PRIMARY integrator and the raw-Embree kernel traced the same rays to the same hits (their depth
 * images agree at every pixel), and the hits are those of the scene (a 20 x 20 quad filling the
 * view behind 64 spheres: every ray hits). It prints the measured throughput and overhead. */
#include "rt_test.h"
#include "sy_rt_bench.h"


int main(void)
{
    sy_rt_device *dev = rt_device();
    sy_rt_mesh s = rt_uv_sphere(dev, 1.0f, 64, true);
    sy_rt_material mat = rt_lambert(dev, 0.6f, 0.5f, 0.4f);
    float xf[16];
    for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j) {
            rt_translation(xf, -7.0f + 2.0f * i, -7.0f + 2.0f * j, 0.0f);
            rt_place(dev, s, xf, mat, ((i + j) & 1) ? SY_RT_INSTANCE_BAKED : 0);
        }
    rt_identity(xf);
    rt_translation(xf, 0.0f, 0.0f, -1.5f);
    rt_place(dev, rt_quad(dev, 20.0f), xf, mat, SY_RT_INSTANCE_BAKED);
    MUST(sy_rt_commit(dev));
    sy_rt_camera cam = rt_camera(12.0f, 0.7f);
    sy_rt_bench_result r;
    MUST(sy_rt_bench_rays(dev, &cam, 512, 512, 5, &r));
    printf("bench 512x512, %u threads: primary %.2f Mrays/s, raw embree %.2f Mrays/s, overhead %.1f %%\n", r.threads,
           r.primary_mrays, r.raw_mrays, r.overhead_percent);
    EXPECT_MSG(r.primary_mrays > 0 && r.raw_mrays > 0 && isfinite(r.overhead_percent), "bench numbers %g %g %g", r.primary_mrays,
               r.raw_mrays, r.overhead_percent);
    EXPECT_MSG(r.differing_pixels == 0, "%llu of %d pixels differ between the integrator and raw Embree",
               (unsigned long long)r.differing_pixels, 512 * 512);
    EXPECT_MSG(r.hits == 512u * 512u, "%llu of %d camera rays hit (the quad fills the view)", (unsigned long long)r.hits,
               512 * 512);
    sy_rt_device_destroy(dev);
    return sy_check_finish("test_rt_bench");
}
