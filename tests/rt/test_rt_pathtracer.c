/* test_rt_pathtracer.c — the PATHTRACER integrator through the public sy_rt API.
 *
 * Energy and unbiasedness (analytic answers):
 *   - white furnace: a closed Lambertian sphere of albedo 1 (flat facets, no specular lobe) inside a
 *     constant environment L returns L (whole-sphere mean within 1 %, per channel; the
 *     environment is sampled by next-event estimation with MIS, so this checks both strategies);
 *   - the same with an equirectangular environment texture of constant value x intensity;
 *   - GGX metal with F0 = 1 (base 1, metallic 1, roughness 0.5 = alpha 0.25): single-scattering
 *     microfacets lose the energy of multiple scattering and never gain any. Independent numerical
 *     integration of the directional albedo E(mu) (height-correlated Smith) averaged over the
 *     sphere's disk (weight 2 mu) gives 0.88, so the mean must lie in [0.86 L, 0.91 L];
 *   - a smooth glass sphere (transmission 1, IOR 1.5, base 1) in the furnace returns L within 1 %
 *     (reflection, refraction and total internal reflection conserve energy);
 *   - integrating spheres (see test_integrating_sphere): half emitter / half reflector, and a point
 *     light at the centre; analytic multi-bounce answers within 1 %, plus the direct/indirect
 *     split of the AOVs;
 *   - a small emitter seen at a grazing angle from the floor (test_area_light_grazing): the
 *     analytic irradiance within 2 % (its shadow rays once ended behind the emitter: 0.037 of it);
 *   - importance-sampled environment map (nearest filter, random texels + one bright "sun" texel)
 *     over a white Lambertian ground quad: the pixel value equals (1/pi) * the cosine-weighted
 *     integral of the map over the upper hemisphere, computed here by brute force (within 2 %).
 * Material layers (test_sheen, test_iridescence): KHR_materials_sheen's albedo scaling keeps a white
 * sheen over white Lambert in the furnace at L (without it the sum would reach 1.5 L); a white sheen
 * over a black base lights the rim several times more than the centre, in both tracers alike;
 * KHR_materials_iridescence colours a dielectric's grey reflection of a white furnace;
 * KHR_materials_anisotropy stretches a highlight along the tangent, or across it when rotated; the
 * clear coat's highlight follows the coat's own normal map and ignores the base's.
 * Determinism and tiling: same seed = bit-identical; 4 calls of 1 sample = 1 call of 4; the four
 * quadrants rendered separately stitch bit-identically; another seed differs.
 * Bad input: degenerate triangles and a zero-area emitter give no non-finite value and no
 * dropped sample. */
#include "rt_test.h"

#define PI_F 3.14159265358979f

/* UV sphere of radius r at the origin, outward counter-clockwise winding, flat (no normals). */
static sy_rt_mesh make_sphere(sy_rt_device *dev, float r, uint32_t seg, uint32_t rings)
{
    uint32_t nv = (seg + 1) * (rings + 1), nt = seg * rings * 2;
    float *pos = malloc(nv * 3 * sizeof *pos);
    uint32_t *idx = malloc(nt * 3 * sizeof *idx), t = 0;
    for (uint32_t j = 0; j <= rings; ++j)
        for (uint32_t i = 0; i <= seg; ++i) {
            float th = PI_F * (float)j / (float)rings, ph = 2.0f * PI_F * (float)i / (float)seg;
            float *p = pos + 3 * (j * (seg + 1) + i);
            p[0] = r * sinf(th) * cosf(ph);
            p[1] = r * cosf(th);
            p[2] = -r * sinf(th) * sinf(ph);
        }
    for (uint32_t j = 0; j < rings; ++j)
        for (uint32_t i = 0; i < seg; ++i) {
            uint32_t a = j * (seg + 1) + i, b = a + seg + 1;
            /* (a, b, a+1) and (a+1, b, b+1) face outward for this parameterisation */
            idx[3 * t] = a, idx[3 * t + 1] = b, idx[3 * t + 2] = a + 1, ++t;
            idx[3 * t] = a + 1, idx[3 * t + 1] = b, idx[3 * t + 2] = b + 1, ++t;
        }
    return rt_mesh_take(dev, pos, idx, nv, nt);
}

typedef struct img {
    uint32_t w, h;
    float *rgba, *depth;
    sy_rt_accum *acc;
} img;

static img pt_render(sy_rt_device *dev, const sy_rt_camera *cam, uint32_t w, uint32_t h, uint32_t spp, uint32_t seed,
                     uint32_t max_depth)
{
    img r = {w, h, malloc((size_t)w * h * 4 * sizeof(float)), malloc((size_t)w * h * sizeof(float)), NULL};
    MUST(sy_rt_accum_create(dev, w, h, &r.acc));
    sy_rt_render_desc d = rt_desc(SY_RT_INTEGRATOR_PATHTRACER, w, h);
    d.accum = r.acc;
    d.samples = spp;
    d.seed = seed;
    d.max_depth = max_depth;
    MUST(sy_rt_render(dev, cam, &d, r.rgba, r.depth));
    return r;
}

static void img_free(img *i)
{
    free(i->rgba);
    free(i->depth);
    sy_rt_accum_destroy(i->acc);
}

static size_t count_nonfinite(const img *i)
{
    size_t n = 0;
    for (size_t k = 0; k < (size_t)i->w * i->h * 4; ++k) n += !isfinite(i->rgba[k]);
    return n;
}

/* Mean colour over pixels whose depth is finite (the object) or all pixels (object = false). */
static void mean_rgb(const img *i, bool object, double out[3])
{
    double s[3] = {0, 0, 0};
    size_t n = 0;
    for (size_t k = 0; k < (size_t)i->w * i->h; ++k) {
        if (object && !isfinite(i->depth[k])) continue;
        for (int c = 0; c < 3; ++c) s[c] += i->rgba[4 * k + (size_t)c];
        n++;
    }
    for (int c = 0; c < 3; ++c) out[c] = n ? s[c] / (double)n : 0.0;
}

/* A unit sphere of material md in a constant environment L (see furnace_case), seen from distance 3. */
static sy_rt_device *furnace_scene(const sy_rt_material_desc *md, const float L[3], bool env_texture)
{
    sy_rt_device *dev = rt_device();
    /* env_texture: a constant 8x4 map of value L / 2 at intensity 2; otherwise a uniform
     * environment, i.e. a 1x1 map of value L. The background shows the same environment, so that
     * pixels on the silhouette see L where they miss. */
    float px[8 * 4 * 3];
    uint32_t tw = env_texture ? 8 : 1, th = env_texture ? 4 : 1;
    float scale = env_texture ? 0.5f : 1.0f;
    for (uint32_t k = 0; k < tw * th; ++k) px[3 * k] = L[0] * scale, px[3 * k + 1] = L[1] * scale, px[3 * k + 2] = L[2] * scale;
    sy_rt_texture_desc td = {.width = tw, .height = th, .channels = 3, .format = SY_RT_TEXEL_FLOAT32, .pixels = px,
                             .wrap_t = SY_RT_WRAP_CLAMP};
    sy_rt_texture tex;
    MUST(sy_rt_texture_create(dev, &td, &tex));
    MUST(sy_rt_set_environment(dev, tex, 1.0f / scale));
    sy_rt_background bg = {.mode = SY_RT_BACKGROUND_TEXTURE, .texture = tex, .intensity = 1.0f / scale};
    MUST(sy_rt_set_background(dev, &bg));
    sy_rt_material mat = rt_material(dev, md);
    rt_place(dev, make_sphere(dev, 1.0f, 64, 32), NULL, mat, 0);
    MUST(sy_rt_commit(dev));
    return dev;
}

static void furnace_case(const char *name, const sy_rt_material_desc *md, double lo, double hi, bool env_texture)
{
    const float L[3] = {0.25f, 0.5f, 1.0f};
    sy_rt_device *dev = furnace_scene(md, L, env_texture);
    sy_rt_camera cam = rt_camera(3.0f, 0.4f);
    img im = pt_render(dev, &cam, 48, 48, 64, 1, 64);
    double m[3];
    mean_rgb(&im, true, m);
    for (int c = 0; c < 3; ++c)
        EXPECT_MSG(m[c] >= lo * L[c] && m[c] <= hi * L[c], "%s: channel %d mean %.5f, expected [%.4f, %.4f]", name, c, m[c],
                   lo * L[c], hi * L[c]);
    printf("%s: mean/L = %.4f %.4f %.4f\n", name, m[0] / L[0], m[1] / L[1], m[2] / L[2]);
    EXPECT_MSG(count_nonfinite(&im) == 0 && sy_rt_accum_nonfinite(im.acc) == 0, "%s: non-finite values", name);
    img_free(&im);
    sy_rt_device_destroy(dev);
}

static void test_furnaces(void)
{
    /* each case: the default material (sy_rt_material_desc_init) with these values */
    static const struct {
        const char *name;
        float metallic, specular, roughness, transmission, iridescence, clearcoat, clearcoat_roughness;
        double lo, hi;
        bool env_texture;
    } cases[] = {
        /* pure Lambert, albedo 1 */
        {"furnace lambert", 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.99, 1.01, false},
        {"furnace lambert, environment map", 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.99, 1.01, true},
        {"furnace GGX metal F0=1", 1.0f, 1.0f, 0.5f, 0.0f, 0.0f, 0.0f, 0.0f, 0.86, 0.91, false},
        {"furnace smooth glass", 0.0f, 1.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 0.99, 1.01, false},
        /* KHR_materials_iridescence on glass: the film's colour splits reflection and refraction per
         * channel (chosen by their mean, weighted by colour), which still sums to 1 per channel */
        {"furnace smooth iridescent glass", 0.0f, 1.0f, 0.0f, 1.0f, 1.0f, 0.0f, 0.0f, 0.99, 1.01, false},
        {"furnace rough iridescent glass", 0.0f, 1.0f, 0.3f, 1.0f, 1.0f, 0.0f, 0.0f, 0.9, 1.01, false},
        /* KHR_materials_clearcoat: the coat reflects F_coat(n . wo) and lets 1 - F_coat(n . wo) of the
         * base through (the specification's albedo scaling): a smooth coat over white Lambert keeps the
         * furnace's L; a rough one loses what single-scattering GGX loses where the coat's Fresnel is
         * large (the F0 = 1 metal above loses 11 % at this roughness; weighted by the coat's Fresnel,
         * whose disk average is 0.086, that is 1 to 5 %), and never gains */
        {"furnace smooth clearcoat over Lambert", 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.99, 1.01, false},
        {"furnace rough clearcoat over Lambert", 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 1.0f, 0.5f, 0.95, 1.005, false},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        sy_rt_material_desc d;
        sy_rt_material_desc_init(&d);
        d.metallic = cases[i].metallic;
        d.specular = cases[i].specular;
        d.roughness = cases[i].roughness;
        d.transmission = cases[i].transmission;
        d.ior = 1.5f;
        d.iridescence = cases[i].iridescence;
        d.clearcoat = cases[i].clearcoat;
        d.clearcoat_roughness = cases[i].clearcoat_roughness;
        furnace_case(cases[i].name, &d, cases[i].lo, cases[i].hi, cases[i].env_texture);
    }
}

/* KHR_materials_volume: a smooth glass sphere (IOR 1.5, radius 1) absorbing with attenuation colour
 * (1, 0.5, 0.25) at distance 1 in a uniform furnace L = 1. At the centre, at normal incidence with
 * F0 = 0.04 and T = exp(-2 sigma) over the diameter (sigma = -ln(colour)): the reflected
 * environment F0, plus (1 - F0) T [(1 - F0) + F0 T (1 - F0) + ...] through the sphere and back out:
 * red (no absorption: energy conserved) 1, green 0.273, blue 0.098 (the centre 6x6 pixels, both
 * tracers). Without a volume (thickness 0: thin-walled in glTF) every channel is 1. */
static void test_absorbing_glass(void)
{
    const float L[3] = {1.0f, 1.0f, 1.0f};
    const double expect[2][3] = {{1.0, 0.273, 0.098}, {1.0, 1.0, 1.0}};
    for (int thin = 0; thin < 2; ++thin) {
        sy_rt_material_desc d;
        sy_rt_material_desc_init(&d);
        d.metallic = 0.0f, d.roughness = 0.0f, d.transmission = 1.0f, d.ior = 1.5f;
        d.thickness = thin ? 0.0f : 1.0f;
        d.attenuation_distance = 1.0f;
        d.attenuation_color[0] = 1.0f, d.attenuation_color[1] = 0.5f, d.attenuation_color[2] = 0.25f;
        sy_rt_device *dev = furnace_scene(&d, L, false);
        sy_rt_camera cam = rt_camera(3.0f, 0.4f);
        for (int whitted = 0; whitted < 2; ++whitted) {
            img im;
            if (whitted) {
                im = (img){48, 48, malloc(48 * 48 * 4 * sizeof(float)), malloc(48 * 48 * sizeof(float)), NULL};
                sy_rt_render_desc rd = rt_desc(SY_RT_INTEGRATOR_WHITTED, 48, 48);
                rd.max_depth = 16;
                MUST(sy_rt_render(dev, &cam, &rd, im.rgba, im.depth));
            } else {
                im = pt_render(dev, &cam, 48, 48, 64, 1, 64);
            }
            double m[3] = {0, 0, 0};
            for (uint32_t y = 21; y < 27; ++y)
                for (uint32_t x = 21; x < 27; ++x)
                    for (int c = 0; c < 3; ++c) m[c] += im.rgba[4 * (y * 48 + x) + (uint32_t)c] / 36.0;
            for (int c = 0; c < 3; ++c)
                EXPECT_MSG(fabs(m[c] - expect[thin][c]) < 0.02, "%s, %s: centre channel %d = %.4f, expected %.3f",
                           whitted ? "whitted" : "pathtracer", thin ? "thin-walled" : "absorbing", c, m[c], expect[thin][c]);
            printf("absorbing glass (%s, %s): centre %.4f %.4f %.4f\n", whitted ? "whitted" : "pathtracer",
                   thin ? "thin-walled" : "volume", m[0], m[1], m[2]);
            img_free(&im);
        }
        sy_rt_device_destroy(dev);
    }
}

/* Renders one of the tracers at 48 x 48 (64 spp for the path tracer). */
static img render48(sy_rt_device *dev, const sy_rt_camera *cam, bool whitted)
{
    if (!whitted) return pt_render(dev, cam, 48, 48, 64, 1, 64);
    img im = {48, 48, malloc(48 * 48 * 4 * sizeof(float)), malloc(48 * 48 * sizeof(float)), NULL};
    sy_rt_render_desc rd = rt_desc(SY_RT_INTEGRATOR_WHITTED, 48, 48);
    rd.max_depth = 16;
    MUST(sy_rt_render(dev, cam, &rd, im.rgba, im.depth));
    return im;
}

/* Mean luminance of the sphere's pixels whose depth lies in [lo, hi] (the unit sphere at distance
 * 3: 2 at the centre, about 2.7-2.8 at the silhouette). */
static double depth_band_mean(const img *i, float lo, float hi)
{
    double s = 0.0;
    size_t n = 0;
    for (size_t k = 0; k < (size_t)i->w * i->h; ++k) {
        if (!(i->depth[k] >= lo && i->depth[k] <= hi)) continue;
        s += 0.2126 * i->rgba[4 * k] + 0.7152 * i->rgba[4 * k + 1] + 0.0722 * i->rgba[4 * k + 2];
        n++;
    }
    return n ? s / (double)n : -1.0;
}

/* KHR_materials_sheen. (1) A white sheen (roughness 1: E <= 0.75 everywhere) over white Lambert in
 * the furnace: sheen + (1 - E) x Lambert returns L (within 2 %: the fitted visibility term and the
 * table); without the albedo scaling the mean would be about 1.5 L. (2) A white sheen of roughness
 * 0.5 over a black base (base colour 0, specular 0) under a uniform white environment: the Charlie
 * lobe's albedo is 0.03 at normal incidence and 0.2-0.7 from n . v = 0.5 to grazing, so the rim
 * (depth >= 2.45) must exceed 0.1 and 3x the centre (depth <= 2.05); without the sheen both are 0.
 * Whitted sees the environment through the same lobe with its stratified environment samples: its
 * whole-sphere mean within the one-look ratio 0.67-1.5 of the path tracer's. */
static void test_sheen(void)
{
    sy_rt_material_desc d;
    sy_rt_material_desc_init(&d);
    d.metallic = 0.0f, d.specular = 0.0f;
    d.sheen_color[0] = d.sheen_color[1] = d.sheen_color[2] = 1.0f;
    d.sheen_roughness = 1.0f;
    furnace_case("furnace white sheen over Lambert", &d, 0.98, 1.02, false);

    const float L[3] = {1.0f, 1.0f, 1.0f};
    sy_rt_material_desc_init(&d);
    d.metallic = 0.0f, d.specular = 0.0f;
    d.base_color[0] = d.base_color[1] = d.base_color[2] = 0.0f;
    d.sheen_color[0] = d.sheen_color[1] = d.sheen_color[2] = 1.0f;
    d.sheen_roughness = 0.5f;
    sy_rt_device *dev = furnace_scene(&d, L, false);
    sy_rt_camera cam = rt_camera(3.0f, 0.4f);
    double all[2];
    for (int whitted = 0; whitted < 2; ++whitted) {
        img im = render48(dev, &cam, whitted);
        double rim = depth_band_mean(&im, 2.45f, 3.0f), centre = depth_band_mean(&im, 1.9f, 2.05f), m[3];
        mean_rgb(&im, true, m);
        all[whitted] = m[1];
        const char *name = whitted ? "whitted" : "pathtracer";
        printf("sheen over black (%s): rim %.4f centre %.4f mean %.4f\n", name, rim, centre, m[1]);
        EXPECT_MSG(rim > 0.1 && rim > 3.0 * centre && centre >= 0.0, "%s: sheen rim %.4f, centre %.4f", name, rim, centre);
        EXPECT_MSG(rim < 1.0, "%s: sheen rim %.4f reflects more than the environment", name, rim);
        img_free(&im);
    }
    EXPECT_MSG(all[1] > 0.67 * all[0] && all[1] < 1.5 * all[0], "sheen: whitted mean %.4f vs path tracer %.4f", all[1], all[0]);
    sy_rt_device_destroy(dev);
}

/* KHR_materials_iridescence: a black dielectric (roughness 0.3, and 0: Whitted's mirror ray and the
 * path tracer's delta lobe; IOR 1.5) in a white furnace reflects grey at its centre (the channels within 2 % of each other); a 400 nm film of IOR 1.3 (iridescence 1)
 * colours it (the largest channel at least 1.2x the smallest) and never reflects more than the
 * furnace; path tracer and Whitted. */
static void test_iridescence(void)
{
    const float L[3] = {1.0f, 1.0f, 1.0f};
    for (int run = 0; run < 4; ++run) {
        int on = run & 1;
        sy_rt_material_desc d;
        sy_rt_material_desc_init(&d);
        d.metallic = 0.0f, d.roughness = run < 2 ? 0.3f : 0.0f;
        d.base_color[0] = d.base_color[1] = d.base_color[2] = 0.0f;
        d.iridescence = on ? 1.0f : 0.0f;
        sy_rt_device *dev = furnace_scene(&d, L, false);
        sy_rt_camera cam = rt_camera(3.0f, 0.4f);
        for (int whitted = 0; whitted < 2; ++whitted) {
            img im = render48(dev, &cam, whitted);
            double m[3] = {0, 0, 0}; /* the centre 6 x 6 pixels: near normal incidence */
            for (uint32_t y = 21; y < 27; ++y)
                for (uint32_t x = 21; x < 27; ++x)
                    for (int c = 0; c < 3; ++c) m[c] += im.rgba[4 * (y * 48 + x) + (uint32_t)c] / 36.0;
            double hi = fmax(m[0], fmax(m[1], m[2])), lo = fmin(m[0], fmin(m[1], m[2]));
            const char *name = whitted ? "whitted" : "pathtracer";
            printf("iridescence %s, roughness %.1f (%s): centre %.4f %.4f %.4f\n", on ? "on" : "off", (double)d.roughness, name,
                   m[0], m[1], m[2]);
            if (on) EXPECT_MSG(hi > 1.2 * lo && hi < 1.0, "%s: iridescent mean %.4f %.4f %.4f", name, m[0], m[1], m[2]);
            else EXPECT_MSG(hi < 1.02 * lo && lo > 0.0, "%s: plain mean %.4f %.4f %.4f", name, m[0], m[1], m[2]);
            img_free(&im);
        }
        sy_rt_device_destroy(dev);
    }
}

/* Luminance moments of an image about its centre (pixel units): m[0] = sum L, m[1] = sum L dx,
 * m[2] = sum L dx^2, m[3] = sum L dy^2. */
static void lum_moments(const img *im, double m[4])
{
    m[0] = m[1] = m[2] = m[3] = 0.0;
    for (uint32_t y = 0; y < im->h; ++y)
        for (uint32_t x = 0; x < im->w; ++x) {
            const float *p = im->rgba + 4 * ((size_t)y * im->w + x);
            double l = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            double dx = x + 0.5 - 0.5 * im->w, dy = y + 0.5 - 0.5 * im->h;
            m[0] += l, m[1] += l * dx, m[2] += l * dx * dx, m[3] += l * dy * dy;
        }
}

/* A quad [-3, 3]^2 of material d facing the camera (returned) at distance 3, with a point light of
 * 10 cd beside the camera; committed. */
static sy_rt_camera quad_under_light(sy_rt_device *dev, const sy_rt_material_desc *d)
{
    sy_rt_material mat = rt_material(dev, d);
    rt_place(dev, rt_quad(dev, 3.0f), NULL, mat, 0);
    sy_rt_light_desc ld = {.type = SY_RT_LIGHT_POINT, .color = {1, 1, 1}, .intensity = 10.0f, .position = {0.0f, 0.0f, 3.0f}};
    sy_rt_light light;
    MUST(sy_rt_light_create(dev, &ld, &light));
    MUST(sy_rt_commit(dev));
    return rt_camera(3.0f, 0.8f);
}

/* KHR_materials_anisotropy: a white GGX metal quad (roughness 0.3, uv u along +X) facing a camera
 * at distance 3 with a point light beside the camera. The highlight's luminance-weighted second
 * moments about the image centre: isotropic, X and Y within 15 % of each other; strength 0.8 stretches
 * it along the tangent (+u = X: X/Y above 2); rotated by pi/2 along Y (X/Y below 0.5). Both tracers. */
static void test_anisotropy(void)
{
    const float setups[3][2] = {{0.0f, 0.0f}, {0.8f, 0.0f}, {0.8f, 1.5707963f}};
    for (int k = 0; k < 3; ++k) {
        sy_rt_device *dev = rt_device();
        sy_rt_material_desc d;
        sy_rt_material_desc_init(&d);
        d.roughness = 0.3f;
        d.anisotropy = setups[k][0], d.anisotropy_rotation = setups[k][1];
        sy_rt_camera cam = quad_under_light(dev, &d);
        for (int whitted = 0; whitted < 2; ++whitted) {
            img im = render48(dev, &cam, whitted);
            double m[4];
            lum_moments(&im, m);
            double r = m[2] / fmax(m[3], 1e-12);
            const char *name = whitted ? "whitted" : "pathtracer";
            printf("anisotropy %.1f rotation %.2f (%s): highlight X/Y spread %.3f\n", (double)setups[k][0], (double)setups[k][1], name, r);
            if (k == 0) EXPECT_MSG(r > 0.85 && r < 1.15, "%s: isotropic highlight X/Y %.3f", name, r);
            else if (k == 1) EXPECT_MSG(r > 2.0, "%s: anisotropic highlight X/Y %.3f, expected stretched along X", name, r);
            else EXPECT_MSG(r < 0.5, "%s: rotated anisotropic highlight X/Y %.3f, expected stretched along Y", name, r);
            img_free(&im);
        }
        sy_rt_device_destroy(dev);
    }
}

/* KHR_materials_clearcoat's normal: a coat (roughness 0.2) over a black base (base colour 0,
 * specular 0) on the quad of test_anisotropy, point light by the camera. The coat's highlight sits
 * at the image centre (luminance-weighted centroid within 1 px) without normal maps, and also with a
 * base normal map tilted 10 degrees toward +X (the coat follows the vertex normal, not the base's
 * map); the same tilt as the coat's own normal map moves it about 3 tan(10 deg) = 0.53 units toward
 * -X, 5.3 px at this camera (centroid at least 3 px left). Both tracers. */
static void test_clearcoat_normal(void)
{
    const float sn = sinf(10.0f * PI_F / 180.0f), cs = cosf(10.0f * PI_F / 180.0f);
    const uint8_t texel[3] = {(uint8_t)lrintf((0.5f + 0.5f * sn) * 255.0f), 128, (uint8_t)lrintf((0.5f + 0.5f * cs) * 255.0f)};
    for (int k = 0; k < 3; ++k) { /* 0 no maps, 1 base map, 2 coat map */
        sy_rt_device *dev = rt_device();
        sy_rt_texture_desc td = {.width = 1, .height = 1, .channels = 3, .format = SY_RT_TEXEL_UNORM8, .pixels = texel};
        sy_rt_texture tex;
        MUST(sy_rt_texture_create(dev, &td, &tex));
        sy_rt_material_desc d;
        sy_rt_material_desc_init(&d);
        d.metallic = 0.0f, d.specular = 0.0f;
        d.base_color[0] = d.base_color[1] = d.base_color[2] = 0.0f;
        d.clearcoat = 1.0f, d.clearcoat_roughness = 0.2f;
        if (k == 1) d.normal_texture.texture = tex;
        if (k == 2) d.clearcoat_normal_texture.texture = tex;
        sy_rt_camera cam = quad_under_light(dev, &d);
        for (int whitted = 0; whitted < 2; ++whitted) {
            img im = render48(dev, &cam, whitted);
            double m[4];
            lum_moments(&im, m);
            double sl = m[0], cx = sl > 0.0 ? m[1] / sl : 99.0;
            const char *name = whitted ? "whitted" : "pathtracer";
            printf("clearcoat normal case %d (%s): highlight centroid x %+.2f px, total %.3f\n", k, name, cx, sl);
            if (k < 2) EXPECT_MSG(fabs(cx) < 1.0, "%s: coat highlight at %+.2f px (case %d), expected the centre", name, cx, k);
            else EXPECT_MSG(cx < -3.0 && cx > -8.0, "%s: coat highlight at %+.2f px with the coat's tilted normal", name, cx);
            img_free(&im);
        }
        sy_rt_device_destroy(dev);
    }
}

/* Area of the triangles of a mesh description (for form factors). */
static double sphere_part(sy_rt_device *dev, float r, uint32_t seg, uint32_t rings, uint32_t j0, uint32_t j1,
                          sy_rt_material mat)
{
    uint32_t nv = (seg + 1) * (rings + 1), nt = seg * (j1 - j0) * 2, t = 0;
    float *pos = malloc(nv * 3 * sizeof *pos);
    uint32_t *idx = malloc(nt * 3 * sizeof *idx);
    for (uint32_t j = 0; j <= rings; ++j)
        for (uint32_t i = 0; i <= seg; ++i) {
            float th = PI_F * (float)j / (float)rings, ph = 2.0f * PI_F * (float)i / (float)seg;
            float *p = pos + 3 * (j * (seg + 1) + i);
            p[0] = r * sinf(th) * cosf(ph), p[1] = r * cosf(th), p[2] = -r * sinf(th) * sinf(ph);
        }
    double area = 0;
    for (uint32_t j = j0; j < j1; ++j)
        for (uint32_t i = 0; i < seg; ++i) {
            uint32_t a = j * (seg + 1) + i, b = a + seg + 1;
            uint32_t tri[2][3] = {{a, b, a + 1}, {a + 1, b, b + 1}};
            for (int k = 0; k < 2; ++k, ++t) {
                const float *p0 = pos + 3 * tri[k][0], *p1 = pos + 3 * tri[k][1], *p2 = pos + 3 * tri[k][2];
                double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]}, e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
                double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2], cz = e1[0] * e2[1] - e1[1] * e2[0];
                area += 0.5 * sqrt(cx * cx + cy * cy + cz * cz);
                memcpy(idx + 3 * t, tri[k], sizeof tri[k]);
            }
        }
    sy_rt_mesh_desc d = {.positions = pos, .indices = idx, .vertex_count = nv, .triangle_count = nt};
    sy_rt_mesh m;
    MUST(sy_rt_mesh_create(dev, &d, &m));
    rt_place(dev, m, NULL, mat, 0);
    free(pos);
    free(idx);
    return area;
}

/* Integrating spheres (inside a sphere the form factor from any wall element to a wall region is
 * the region's area / the sphere's area, and a point light at the centre irradiates the wall
 * uniformly with I / R^2):
 *   (a) lower half a double-sided emitter of radiance E (1024 triangles, alias-table sampled),
 *       upper half Lambertian with albedo a = 0.6: the upper wall has L = a f E / (1 - a (1 - f))
 *       with f = emitting area fraction;
 *   (b) a closed Lambertian sphere (a = 0.5, R = 2) with a point light of intensity I at its
 *       centre: L = a I / (pi R^2 (1 - a)).
 * Both need every bounce, unbiased Russian roulette and correct light pdfs and MIS weights. */
static void test_integrating_sphere(void)
{
    sy_rt_device *dev = rt_device();
    sy_rt_material_desc d;
    sy_rt_material_desc_init(&d);
    d.base_color[0] = d.base_color[1] = d.base_color[2] = 0.0f;
    d.specular = 0.0f; /* a black, non-reflecting emitter */
    d.emissive[0] = 1.0f, d.emissive[1] = 2.0f, d.emissive[2] = 0.5f;
    d.double_sided = true;
    sy_rt_material glow = rt_material(dev, &d);
    const float a = 0.6f;
    double up = sphere_part(dev, 2.0f, 64, 32, 0, 16, rt_lambert(dev, a, a, a));
    double down = sphere_part(dev, 2.0f, 64, 32, 16, 32, glow);
    MUST(sy_rt_commit(dev));
    sy_rt_stats st;
    sy_rt_device_stats(dev, &st);
    EXPECT_MSG(st.area_light_triangles >= 64 * 16 * 2 - 64 && st.area_light_triangles <= 64 * 16 * 2,
               "area triangles %u (the pole triangles are degenerate and skipped)", st.area_light_triangles);
    double fe = down / (up + down), k = a * fe / (1.0 - a * (1.0 - fe));
    /* camera at the centre looking up (+Y): sees only the reflecting half */
    sy_rt_camera cam = rt_camera(0.0f, 1.0f);
    memset(cam.camera_to_world, 0, sizeof cam.camera_to_world);
    cam.camera_to_world[0] = 1.0f;
    cam.camera_to_world[6] = 1.0f;  /* camera y -> world +z */
    cam.camera_to_world[9] = -1.0f; /* camera z -> world -y: looks up */
    cam.camera_to_world[15] = 1.0f;
    img im = pt_render(dev, &cam, 24, 24, 64, 7, 64);
    double m[3];
    mean_rgb(&im, false, m);
    for (int c = 0; c < 3; ++c)
        EXPECT_MSG(fabs(m[c] / (k * d.emissive[c]) - 1.0) < 0.01, "integrating sphere (a) channel %d: %.5f, expected %.5f", c,
                   m[c], k * d.emissive[c]);
    printf("integrating sphere, emissive half: mean / expected = %.4f %.4f %.4f\n", m[0] / (k * d.emissive[0]),
           m[1] / (k * d.emissive[1]), m[2] / (k * d.emissive[2]));
    /* direct lighting only (max_depth 1): a f E; the AOVs split the full render into direct a f E
     * and indirect (the rest) */
    img im1 = pt_render(dev, &cam, 24, 24, 64, 7, 1);
    mean_rgb(&im1, false, m);
    EXPECT_MSG(fabs(m[1] / (a * fe * d.emissive[1]) - 1.0) < 0.01, "max_depth 1: %.5f, expected %.5f", m[1], a * fe * d.emissive[1]);
    float *dir = malloc(24 * 24 * 3 * sizeof(float)), *ind = malloc(24 * 24 * 3 * sizeof(float));
    MUST(sy_rt_accum_read(dev, im.acc, SY_RT_AOV_DIRECT, dir));
    MUST(sy_rt_accum_read(dev, im.acc, SY_RT_AOV_INDIRECT, ind));
    double sd = 0, si = 0;
    for (int i = 0; i < 24 * 24; ++i) sd += dir[3 * i + 1], si += ind[3 * i + 1];
    sd /= 24 * 24, si /= 24 * 24;
    double ed = a * fe * d.emissive[1], ei = k * d.emissive[1] - ed;
    EXPECT_MSG(fabs(sd / ed - 1.0) < 0.01 && fabs(si / ei - 1.0) < 0.02, "direct %.4f (%.4f), indirect %.4f (%.4f)", sd, ed, si, ei);
    free(dir);
    free(ind);
    img_free(&im);
    img_free(&im1);
    sy_rt_device_destroy(dev);

    dev = rt_device();
    sphere_part(dev, 2.0f, 64, 32, 0, 32, rt_lambert(dev, 0.5f, 0.5f, 0.5f));
    sy_rt_light_desc ld = {.type = SY_RT_LIGHT_POINT, .color = {1.0f, 0.5f, 0.25f}, .intensity = 10.0f};
    sy_rt_light l;
    MUST(sy_rt_light_create(dev, &ld, &l));
    MUST(sy_rt_commit(dev));
    im = pt_render(dev, &cam, 24, 24, 64, 11, 64);
    mean_rgb(&im, false, m);
    for (int c = 0; c < 3; ++c) {
        double e = 0.5 * ld.intensity * ld.color[c] / (M_PI * 4.0 * 0.5);
        EXPECT_MSG(fabs(m[c] / e - 1.0) < 0.01, "integrating sphere (b) channel %d: %.5f, expected %.5f", c, m[c], e);
    }
    printf("integrating sphere, point light: mean / expected = %.4f\n", m[0] / (0.5 * 10.0 / (M_PI * 2.0)));
    img_free(&im);
    sy_rt_device_destroy(dev);
}

static void test_env_importance(void)
{
    sy_rt_device *dev = rt_device();
    enum { EW = 32, EH = 16 };
    static float px[EW * EH * 3];
    uint32_t s = 12345;
    for (int k = 0; k < EW * EH * 3; ++k) {
        s = s * 1664525u + 1013904223u;
        px[k] = (float)(s >> 8) / 16777216.0f * 0.2f;
    }
    int sun = (3 * EW + 20) * 3; /* row 3: about 40 degrees above the horizon */
    px[sun] = 400.0f, px[sun + 1] = 300.0f, px[sun + 2] = 200.0f;
    sy_rt_texture_desc td = {.width = EW, .height = EH, .channels = 3, .format = SY_RT_TEXEL_FLOAT32, .pixels = px,
                             .wrap_t = SY_RT_WRAP_CLAMP, .filter = SY_RT_FILTER_NEAREST};
    sy_rt_texture tex;
    MUST(sy_rt_texture_create(dev, &td, &tex));
    MUST(sy_rt_set_environment(dev, tex, 1.0f));
    /* ground: a big white Lambertian quad facing +Y at y = 0 */
    float xf[16];
    rt_identity(xf);
    xf[0] = 100.0f;
    xf[5] = 0.0f, xf[6] = -100.0f; /* local y -> world -z */
    xf[9] = 1.0f, xf[10] = 0.0f;   /* local z -> world +y */
    rt_place(dev, rt_quad(dev, 1.0f), xf, rt_lambert(dev, 1.0f, 1.0f, 1.0f), 0);
    MUST(sy_rt_commit(dev));
    /* camera 1 m above the ground looking straight down, narrow view */
    sy_rt_camera cam = rt_camera(0.0f, 0.05f);
    memset(cam.camera_to_world, 0, sizeof cam.camera_to_world);
    cam.camera_to_world[0] = 1.0f;
    cam.camera_to_world[6] = -1.0f; /* camera y -> world -z */
    cam.camera_to_world[9] = 1.0f;  /* camera z -> world +y (looks down -y) */
    cam.camera_to_world[13] = 1.0f;
    cam.camera_to_world[15] = 1.0f;
    img im = pt_render(dev, &cam, 8, 8, 256, 3, 1);
    double m[3];
    mean_rgb(&im, false, m);
    /* expected: (1/pi) * sum over the upper hemisphere of Le * cos(theta) dOmega (fine grid) */
    double e[3] = {0, 0, 0};
    const int N = 2048, M = 1024;
    for (int j = 0; j < M / 2; ++j)
        for (int i = 0; i < N; ++i) {
            double v = (j + 0.5) / M, u = (i + 0.5) / N, th = v * M_PI, ph = (u - 0.5) * 2.0 * M_PI;
            double dy = cos(th), dom = (2.0 * M_PI / N) * (M_PI / M) * sin(th);
            int tx = (int)(u * EW), ty = (int)(v * EH);
            (void)ph;
            for (int c = 0; c < 3; ++c) e[c] += px[(ty * EW + tx) * 3 + c] * dy * dom / M_PI;
        }
    for (int c = 0; c < 3; ++c)
        EXPECT_MSG(fabs(m[c] / e[c] - 1.0) < 0.02, "env importance channel %d: %.5f, expected %.5f", c, m[c], e[c]);
    printf("environment map: mean / expected = %.4f %.4f %.4f\n", m[0] / e[0], m[1] / e[1], m[2] / e[2]);
    img_free(&im);
    sy_rt_device_destroy(dev);
}

/* A small scene with every light type, glossy and rough materials. */
static sy_rt_device *mixed_scene(void)
{
    sy_rt_device *dev = rt_device();
    float xf[16];
    rt_rot_y(xf, 0.3f, 0.0f, 0.0f, -1.0f);
    sy_rt_material_desc d;
    sy_rt_material_desc_init(&d);
    d.roughness = 0.3f;
    d.metallic = 0.5f;
    sy_rt_material glossy = rt_material(dev, &d);
    rt_place(dev, rt_quad(dev, 1.0f), xf, glossy, 0);
    rt_translation(xf, 0.3f, 0.2f, 0.0f);
    rt_place(dev, make_sphere(dev, 0.3f, 16, 8), xf, rt_lambert(dev, 0.8f, 0.3f, 0.2f), 0);
    rt_translation(xf, -0.5f, 0.8f, 0.5f);
    rt_place(dev, rt_quad(dev, 0.2f), xf, rt_emitter(dev, 5.0f, 5.0f, 4.0f), 0);
    sy_rt_light_desc ld = {.type = SY_RT_LIGHT_POINT, .color = {1, 1, 1}, .intensity = 2.0f, .position = {0.5f, 1.0f, 1.0f}};
    sy_rt_light l;
    MUST(sy_rt_light_create(dev, &ld, &l));
    sy_rt_background bg = {.mode = SY_RT_BACKGROUND_COLOR, .color = {0.1f, 0.1f, 0.2f}};
    MUST(sy_rt_set_background(dev, &bg));
    MUST(sy_rt_commit(dev));
    return dev;
}

static void test_determinism_and_tiles(void)
{
    sy_rt_device *dev = mixed_scene();
    sy_rt_camera cam = rt_camera(2.5f, 0.6f);
    const uint32_t W = 32;
    img a = pt_render(dev, &cam, W, W, 4, 42, 8), b = pt_render(dev, &cam, W, W, 4, 42, 8);
    EXPECT_MSG(!memcmp(a.rgba, b.rgba, W * W * 4 * sizeof(float)), "same seed must give the same image");
    img c = pt_render(dev, &cam, W, W, 4, 43, 8);
    EXPECT_MSG(memcmp(a.rgba, c.rgba, W * W * 4 * sizeof(float)) != 0, "another seed must change the noise");
    /* 4 calls of 1 sample */
    img p = pt_render(dev, &cam, W, W, 1, 42, 8);
    for (int k = 0; k < 3; ++k) {
        sy_rt_render_desc d = rt_desc(SY_RT_INTEGRATOR_PATHTRACER, W, W);
        d.accum = p.acc;
        d.samples = 1;
        d.seed = 42;
        d.max_depth = 8;
        MUST(sy_rt_render(dev, &cam, &d, p.rgba, p.depth));
    }
    EXPECT_MSG(sy_rt_accum_samples(p.acc) == 4, "accum has %u samples", sy_rt_accum_samples(p.acc));
    EXPECT_MSG(!memcmp(a.rgba, p.rgba, W * W * 4 * sizeof(float)), "4 x 1 sample must equal 1 x 4 samples bit for bit");
    /* quadrants */
    size_t diff = 0;
    for (uint32_t q = 0; q < 4; ++q) {
        uint32_t x0 = (q % 2) * (W / 2), y0 = (q / 2) * (W / 2), hw = W / 2;
        sy_rt_accum *acc;
        MUST(sy_rt_accum_create(dev, hw, hw, &acc));
        float *rgba = malloc(hw * hw * 4 * sizeof(float));
        sy_rt_render_desc d = rt_desc(SY_RT_INTEGRATOR_PATHTRACER, W, W);
        d.x = x0, d.y = y0, d.width = hw, d.height = hw;
        d.accum = acc;
        d.samples = 4;
        d.seed = 42;
        d.max_depth = 8;
        MUST(sy_rt_render(dev, &cam, &d, rgba, NULL));
        for (uint32_t y = 0; y < hw; ++y)
            diff += memcmp(rgba + 4 * y * hw, a.rgba + 4 * ((y0 + y) * W + x0), hw * 4 * sizeof(float)) != 0;
        free(rgba);
        sy_rt_accum_destroy(acc);
    }
    EXPECT_MSG(diff == 0, "%zu quadrant rows differ from the full image", diff);
    EXPECT_MSG(count_nonfinite(&a) == 0, "non-finite pixels in the mixed scene");
    /* variance AOV: finite, non-negative, not all zero */
    float *var = malloc(W * W * 3 * sizeof(float));
    MUST(sy_rt_accum_read(dev, a.acc, SY_RT_AOV_VARIANCE, var));
    size_t bad = 0, pos = 0;
    for (size_t k = 0; k < W * W * 3; ++k) bad += !(isfinite(var[k]) && var[k] >= 0.0f), pos += var[k] > 0.0f;
    EXPECT_MSG(bad == 0 && pos > 0, "variance AOV: %zu bad, %zu positive", bad, pos);
    free(var);
    /* accumulation validation */
    sy_rt_render_desc d = rt_desc(SY_RT_INTEGRATOR_PATHTRACER, W, W);
    EXPECT_MSG(sy_rt_render(dev, &cam, &d, a.rgba, NULL) == SY_RT_ERROR_INVALID_ARGUMENT, "no accum accepted");
    d.accum = p.acc;
    d.width = W / 2;
    EXPECT_MSG(sy_rt_render(dev, &cam, &d, a.rgba, NULL) == SY_RT_ERROR_INVALID_ARGUMENT && strstr(sy_rt_device_error(dev), "accum"),
               "accum size mismatch accepted: %s", sy_rt_device_error(dev));
    img_free(&a);
    img_free(&b);
    img_free(&c);
    img_free(&p);
    sy_rt_device_destroy(dev);
}

static void test_degenerate(void)
{
    sy_rt_device *dev = rt_device();
    /* a mesh with degenerate triangles (repeated vertex, collinear) next to a good one, all emissive,
     * plus a zero-area emitter */
    const float pos[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 3, 0, 0};
    const uint32_t idx[] = {0, 1, 2, 0, 0, 1, 1, 3, 4, 2, 2, 2};
    sy_rt_mesh_desc md = {.positions = pos, .indices = idx, .vertex_count = 5, .triangle_count = 4};
    sy_rt_mesh m;
    MUST(sy_rt_mesh_create(dev, &md, &m));
    float xf[16];
    rt_translation(xf, -0.5f, -0.5f, -1.0f);
    rt_place(dev, m, xf, rt_emitter(dev, 2.0f, 2.0f, 2.0f), 0);
    const float zpos[] = {0.2f, 0.2f, 0, 0.2f, 0.2f, 0, 0.2f, 0.2f, 0};
    sy_rt_mesh_desc zd = {.positions = zpos, .vertex_count = 3, .triangle_count = 1};
    sy_rt_mesh zm;
    MUST(sy_rt_mesh_create(dev, &zd, &zm));
    rt_place(dev, zm, xf, rt_emitter(dev, 1e6f, 1e6f, 1e6f), 0);
    rt_translation(xf, 0.0f, 0.0f, -2.0f);
    rt_place(dev, rt_quad(dev, 3.0f), xf, rt_lambert(dev, 0.7f, 0.7f, 0.7f), 0);
    MUST(sy_rt_commit(dev));
    sy_rt_stats st;
    sy_rt_device_stats(dev, &st);
    EXPECT_MSG(st.area_light_triangles == 1, "only the good emissive triangle is a light (got %u)", st.area_light_triangles);
    sy_rt_camera cam = rt_camera(1.0f, 0.8f);
    img im = pt_render(dev, &cam, 32, 32, 8, 5, 8);
    EXPECT_MSG(count_nonfinite(&im) == 0, "%zu non-finite values", count_nonfinite(&im));
    EXPECT_MSG(sy_rt_accum_nonfinite(im.acc) == 0, "%llu samples dropped", (unsigned long long)sy_rt_accum_nonfinite(im.acc));
    double mm[3];
    mean_rgb(&im, true, mm);
    EXPECT_MSG(mm[0] > 0.0, "the lit quad shows light");
    img_free(&im);
    sy_rt_device_destroy(dev);
}

/* A small emitter seen at a grazing angle (rt_grazing_emitter_scene). Its next-event shadow rays
 * once ended behind the emitter's plane and the emitter shadowed itself (only the BSDF-sampled
 * hits, weighted by MIS, were left: 0.037 of the answer). The image (16 x 16 pixels over 2 cm of
 * floor, 64 samples) must have the analytic mean within 2 %. */
static void test_area_light_grazing(void)
{
    sy_rt_device *dev = rt_device();
    double expect;
    sy_rt_camera cam = rt_grazing_emitter_scene(dev, &expect);
    img im = pt_render(dev, &cam, 16, 16, 64, 7, 8);
    double m[3];
    mean_rgb(&im, false, m);
    printf("area light at a grazing angle: mean / expected = %.4f\n", m[0] / expect);
    EXPECT_MSG(rt_near(m[0], expect, 0.02), "area light at a grazing angle: mean %.6g, expected %.6g", m[0], expect);
    img_free(&im);
    sy_rt_device_destroy(dev);
}

int main(void)
{
    test_furnaces();
    test_absorbing_glass();
    test_sheen();
    test_iridescence();
    test_anisotropy();
    test_clearcoat_normal();
    test_integrating_sphere();
    test_env_importance();
    test_area_light_grazing();
    test_determinism_and_tiles();
    test_degenerate();
    return sy_check_finish("rt_pathtracer");
}
