/* sy_ltc.c — decodes the LTC tables (sy_ltc.h) from the bytes of data/ltc_ggx.bin, which the build
 * embeds as sy_ltc_bytes (sy_ltc_data.c, written by CMakeLists.txt at configure time): little-endian
 * IEEE-754 singles, so the decoding is the same on any host. */
#include "sy_ltc.h"

#include <stdint.h>
#include <string.h>

extern const unsigned char sy_ltc_bytes[2 * SY_LTC_FLOATS * 4];

static void decode(const unsigned char *b, float *out)
{
    for (uint32_t i = 0; i < SY_LTC_FLOATS; ++i, b += 4) {
        uint32_t u = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
        memcpy(&out[i], &u, sizeof u);
    }
}

void sy_ltc_tables(float *ltc1, float *ltc2)
{
    decode(sy_ltc_bytes, ltc1);
    decode(sy_ltc_bytes + SY_LTC_FLOATS * 4, ltc2);
}
