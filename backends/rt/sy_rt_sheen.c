/* sy_rt_sheen.c — KHR_materials_sheen's Charlie lobe and its albedo table (see sy_rt_sheen.h). */
#include "sy_rt_sheen.h"

#include <math.h>

#define SHEEN_PI 3.14159265358979f
#define SHEEN_PI_D 3.14159265358979323846

static float clamp_rough(float r) { return r < SY_RT_SHEEN_MIN_ROUGHNESS ? SY_RT_SHEEN_MIN_ROUGHNESS : (r > 1.0f ? 1.0f : r); }

/* Estevez-Kulla's fitted Lambda for the Charlie distribution (its "numeric helper"). */
static float lambda_helper(float x, float ag)
{
    float t = (1.0f - ag) * (1.0f - ag);
    float a = 21.5473f + (25.3245f - 21.5473f) * t, b = 3.82987f + (3.32435f - 3.82987f) * t;
    float c = 0.19823f + (0.16801f - 0.19823f) * t, d = -1.97760f + (-1.27393f + 1.97760f) * t;
    float e = -4.32054f + (-4.85967f + 4.32054f) * t;
    return a / (1.0f + b * powf(x, c)) + d * x + e;
}
static float lambda_sheen(float c, float ag)
{
    c = fabsf(c);
    return c < 0.5f ? expf(lambda_helper(c, ag)) : expf(2.0f * lambda_helper(0.5f, ag) - lambda_helper(1.0f - c, ag));
}

float sy_rt_sheen_brdf(float r, float nl, float nv, float nh)
{
    float ag = clamp_rough(r);
    ag *= ag;
    float inv = 1.0f / ag, s2 = 1.0f - nh * nh;
    float D = (2.0f + inv) * powf(s2 > 0.0f ? s2 : 0.0f, 0.5f * inv) / (2.0f * SHEEN_PI);
    float V = 1.0f / ((1.0f + lambda_sheen(nv, ag) + lambda_sheen(nl, ag)) * (4.0f * nv * nl));
    return D * (V < 1.0f ? V : 1.0f);
}

double sy_rt_sheen_albedo_integrate(float mu, float r, int theta_steps)
{
    mu = mu < 1e-3f ? 1e-3f : (mu > 1.0f ? 1.0f : mu);
    double sv = sqrt(1.0 - (double)mu * mu), sum = 0.0;
    int np = 2 * theta_steps;
    double dt = 0.5 * SHEEN_PI_D / theta_steps, dp = 2.0 * SHEEN_PI_D / np;
    for (int i = 0; i < theta_steps; ++i) {
        double th = (i + 0.5) * dt, ct = cos(th), st = sin(th);
        for (int j = 0; j < np; ++j) {
            double ph = (j + 0.5) * dp;
            double lx = st * cos(ph), ly = st * sin(ph), lz = ct; /* v = (sv, 0, mu) */
            double hx = lx + sv, hy = ly, hz = lz + mu, hl = sqrt(hx * hx + hy * hy + hz * hz);
            if (!(hl > 0.0)) continue;
            sum += sy_rt_sheen_brdf(r, (float)lz, mu, (float)(hz / hl)) * ct * st * dt * dp;
        }
    }
    return sum;
}

/* E(mu_i, r_j) for mu_i = i / 31 (0 evaluated at 0.001) and r_j = j / 15 (below
 * SY_RT_SHEEN_MIN_ROUGHNESS evaluated at it): sy_rt_sheen_albedo_integrate(mu, r, 512), printed
 * by tests/rt/test_rt_sheen.c when SY_RT_SHEEN_PRINT_TABLE is set; that test checks the table
 * against fresh quadrature. */
#define SHEEN_NMU 32
#define SHEEN_NR 16
static const float sheen_table[SHEEN_NR][SHEEN_NMU] = {
#include "sy_rt_sheen_table.inc"
};

float sy_rt_sheen_albedo(float mu, float r)
{
    float x = (mu < 0.0f ? 0.0f : (mu > 1.0f ? 1.0f : mu)) * (SHEEN_NMU - 1);
    float y = (r < 0.0f ? 0.0f : (r > 1.0f ? 1.0f : r)) * (SHEEN_NR - 1);
    int i = (int)x, j = (int)y;
    if (i > SHEEN_NMU - 2) i = SHEEN_NMU - 2;
    if (j > SHEEN_NR - 2) j = SHEEN_NR - 2;
    float fx = x - (float)i, fy = y - (float)j;
    float a = sheen_table[j][i] + (sheen_table[j][i + 1] - sheen_table[j][i]) * fx;
    float b = sheen_table[j + 1][i] + (sheen_table[j + 1][i + 1] - sheen_table[j + 1][i]) * fx;
    return a + (b - a) * fy;
}
