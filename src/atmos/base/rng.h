// atmos: a counter-based random number source for Monte Carlo (host and device).
//
// Every path's generator is seeded from (seed, key, sample index) only (key:
// the pixel index or query index), so a render is the same for any thread
// count, any tiling, and for a render split into passes or resumed from a
// checkpoint. The seed is hashed with the SplitMix64 finaliser (Steele et al.
// 2014); the stream is PCG32 (XSH-RR, O'Neill 2014). Both are small, fast and
// statistically strong enough for rendering.
#pragma once

#include <stdint.h>

#include "atmos/platform.h"

namespace atmos {

// SplitMix64's output function: a bijective 64-bit mixer.
ATMOS_HD inline uint64_t Mix64(uint64_t z) {
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

class Rng {
  public:
    // The generator of sample `sample` of `key` (a pixel or a query) under `seed`.
    ATMOS_HD Rng(uint64_t seed, uint64_t key, uint64_t sample) {
        const uint64_t s = Mix64(seed ^ Mix64(key ^ Mix64(sample + 0x632BE59BD9B4E019ull)));
        inc_ = (Mix64(s ^ 0xD1B54A32D192ED03ull) << 1) | 1u;
        state_ = 0;
        Next();
        state_ += s;
        Next();
    }

    ATMOS_HD uint32_t Next() {
        const uint64_t old = state_;
        state_ = old * 6364136223846793005ull + inc_;
        const uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
        const uint32_t rot = static_cast<uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
    }

    // Uniform in [0, 1) with 53 random bits.
    ATMOS_HD double Uniform() {
        const uint64_t hi = Next() >> 5;  // 27 bits
        const uint64_t lo = Next() >> 6;  // 26 bits
        return static_cast<double>((hi << 26) | lo) * (1.0 / 9007199254740992.0);
    }

  private:
    uint64_t state_ = 0;
    uint64_t inc_ = 1;
};

}  // namespace atmos
