/* sy_classic.c — classic shading onto the glTF model (see sy_classic.h). */
#include "sy_classic.h"

#include <math.h>

#define CLASSIC_PI 3.14159265358979f

float sy_classic_roughness(float exponent, float specular_max)
{
    if (!(specular_max > 0.0f)) return 1.0f;
    float n = isfinite(exponent) ? fmaxf(0.0f, fminf(2048.0f, exponent)) : 0.0f;
    float alpha = sqrtf(2.0f / (n + 2.0f));
    return fminf(1.0f, sqrtf(alpha));
}

float sy_classic_point_intensity(float i, float q, float d)
{
    if (q > 0.0f && isfinite(q)) return i * CLASSIC_PI / q;
    return i * CLASSIC_PI * d * d;
}

float sy_classic_directional_intensity(float i) { return i * CLASSIC_PI; }
