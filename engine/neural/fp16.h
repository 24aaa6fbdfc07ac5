// Portable IEEE 754 binary16 <-> binary32 conversion (round to nearest, ties to even), without F16C
// or compiler _Float16 support. Used to export fp16 weights and to emulate the shaders' fp16 rounding
// in the CPU reference. Semantics (pinned by tests/neural/fp16_test.cpp):
//   - finite values beyond the fp16 range round to +-inf (65520 and above; 65504 is the max finite);
//   - subnormal halves are produced and read exactly (smallest 2^-24 ~ 5.96e-8); below 2^-25 -> +-0;
//   - +-inf stay +-inf; NaN stays NaN (quiet, payload top bits kept, never turned into inf);
//   - the sign of zero is kept.
#pragma once
#include <cstdint>
#include <cstring>

namespace nbvh {

inline uint16_t float_to_half_bits(float f) {
    uint32_t x;
    std::memcpy(&x, &f, 4);
    const uint32_t sign = (x >> 16) & 0x8000u;
    const uint32_t exp = (x >> 23) & 0xFFu;
    uint32_t mant = x & 0x7FFFFFu;
    if (exp == 0xFFu) { // inf or NaN
        if (mant == 0u) return uint16_t(sign | 0x7C00u);
        return uint16_t(sign | 0x7E00u | (mant >> 13)); // quiet NaN, keep top payload bits
    }
    const int e = int(exp) - 127 + 15; // biased half exponent
    if (e >= 31) return uint16_t(sign | 0x7C00u); // overflow -> inf
    if (e <= 0) {
        // Subnormal half (or zero): shift the full 24-bit significand; round to nearest even.
        if (e < -10) return uint16_t(sign); // below half of the smallest subnormal -> 0
        mant |= 0x800000u;                 // implicit bit
        const uint32_t shift = uint32_t(14 - e); // 14..24
        uint32_t h = mant >> shift;
        const uint32_t rem = mant & ((1u << shift) - 1u);
        const uint32_t half_way = 1u << (shift - 1u);
        if (rem > half_way || (rem == half_way && (h & 1u))) ++h; // may carry into the min normal: fine
        return uint16_t(sign | h);
    }
    uint32_t h = (uint32_t(e) << 10) | (mant >> 13);
    const uint32_t rem = mant & 0x1FFFu;
    if (rem > 0x1000u || (rem == 0x1000u && (h & 1u))) ++h; // carry may reach inf (0x7C00): correct
    return uint16_t(sign | h);
}

inline float half_bits_to_float(uint16_t h) {
    const uint32_t sign = uint32_t(h & 0x8000u) << 16;
    const uint32_t exp = (h >> 10) & 0x1Fu;
    uint32_t mant = h & 0x3FFu;
    uint32_t x;
    if (exp == 0u) {
        if (mant == 0u) {
            x = sign;
        } else { // subnormal: normalise
            int e = -1;
            do {
                ++e;
                mant <<= 1;
            } while ((mant & 0x400u) == 0u);
            x = sign | (uint32_t(127 - 15 - e) << 23) | ((mant & 0x3FFu) << 13);
        }
    } else if (exp == 31u) {
        x = sign | 0x7F800000u | (mant << 13);
    } else {
        x = sign | ((exp - 15u + 127u) << 23) | (mant << 13);
    }
    float f;
    std::memcpy(&f, &x, 4);
    return f;
}

// Round a float to the nearest representable half (the fp16 emulation step).
inline float round_to_half(float f) { return half_bits_to_float(float_to_half_bits(f)); }

} // namespace nbvh
