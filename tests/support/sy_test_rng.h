/* sy_test_rng.h — the one pseudo-random generator of the C tests: splitmix64 (Steele, Lea, Flood
 * 2014), deterministic per seed so that a failing seed reruns alike. Header-only; the state is the
 * caller's. Thread-safety: one state per thread. */
#ifndef SY_TEST_RNG_H
#define SY_TEST_RNG_H

#include <stdint.h>

/* The next 64 random bits of *state (any seed, 0 included). */
static inline uint64_t sy_test_splitmix64(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

#endif /* SY_TEST_RNG_H */
