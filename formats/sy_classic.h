/** @file
 * sy_classic.h — classic (fixed-function) shading onto the glTF model of the core, one rule each,
 * shared by every loader that reads such files (X3D Material, the Assimp formats: OBJ / MTL, FBX,
 * COLLADA, 3DS, ...):
 *   - a Phong / Blinn-Phong highlight exponent n becomes a GGX roughness: alpha = sqrt(2 / (n + 2))
 *     (the Beckmann slope whose lobe matches the Blinn-Phong lobe of exponent n), roughness =
 *     sqrt(alpha) (glTF squares roughness into alpha); no highlight (a black specular colour or a
 *     zero highlight strength) gives roughness 1. Exponent 0 -> 1.0, 25.6 -> 0.54, 128 -> 0.35,
 *     1000 -> 0.21.
 *   - a light with classic attenuation 1 / (c + l d + q d^2) of a colour whose full value lights a
 *     white surface fully becomes KHR_lights_punctual units: directional i -> i * pi lux (the
 *     irradiance that makes a white Lambertian surface reflect i); point / spot i -> i * pi / q
 *     candela when q > 0 (the inverse-square term kept exactly), else i * pi * d^2 candela with d
 *     the distance from the light to a reference point (the loaders use the centre of the scene
 *     bounds, at least 5 % of their diagonal), so that point is lit as the unattenuated light lit it.
 * Ownership: plain values. Thread-safety: pure functions. */
#ifndef SY_CLASSIC_H
#define SY_CLASSIC_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** GGX roughness for a Blinn-Phong exponent (clamped to [0, 2048]); specular_max is the largest
 * component of the specular colour times the highlight strength (<= 0: roughness 1). */
float sy_classic_roughness(float exponent, float specular_max);

/** KHR_lights_punctual intensity of a point or spot light of classic intensity i (the largest colour
 * component; 1 = full lighting) with quadratic attenuation q (<= 0 or not finite: none), at distance d
 * from the reference point (see above). */
float sy_classic_point_intensity(float i, float q, float d);

/** KHR_lights_punctual illuminance (lux) of a directional light of classic intensity i. */
float sy_classic_directional_intensity(float i);

#ifdef __cplusplus
}
#endif
#endif /* SY_CLASSIC_H */
