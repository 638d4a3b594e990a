// Owen-scrambled Sobol points, by Burley's "Practical Hash-based Owen Scrambling" (JCGT 2020).
//
// Each 2D group of dimensions draws from the first two Sobol dimensions, a (0,2)-sequence, with
// the index shuffled by its own nested uniform scramble ("padding"), so groups are decorrelated
// while each stays stratified. Mirrored in src/shading/sobol.rs.
#ifndef LOOKDEV_SOBOL_GLSL
#define LOOKDEV_SOBOL_GLSL

// A fast, well-mixed integer hash (Chris Wellons' lowbias32), for seeds.
uint hash_u32(uint x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

uint hash_combine(uint seed, uint value) {
    return hash_u32(seed ^ (value + 0x9e3779b9u + (seed << 6) + (seed >> 2)));
}

// A Laine–Karras style permutation on bit-reversed integers: each operation only carries
// information from lower to higher bits, which is what makes it a nested uniform (Owen) scramble.
uint laine_karras_permutation(uint x, uint seed) {
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

uint nested_uniform_scramble(uint x, uint seed) {
    return bitfieldReverse(laine_karras_permutation(bitfieldReverse(x), seed));
}

// Sobol dimension 1 (primitive polynomial x + 1): its direction numbers are the rows of Pascal's
// triangle mod 2, generated on the fly. Dimension 0 is bitfieldReverse(index).
uint sobol_dimension1(uint index) {
    uint result = 0u;
    uint direction = 0x80000000u;
    for (uint bit = 0u; bit < 32u; bit++) {
        if ((index & (1u << bit)) != 0u) {
            result ^= direction;
        }
        direction ^= direction >> 1;
    }
    return result;
}

// 24 high bits to a float in [0, 1), exactly.
float u32_to_unit_float(uint x) {
    return float(x >> 8) * (1.0 / 16777216.0);
}

// Point `index` of the Owen-scrambled 2D Sobol sequence for one pixel and one dimension group.
vec2 sobol_owen_2d(uint index, uint seed) {
    uint shuffled = nested_uniform_scramble(index, seed);
    uint x = nested_uniform_scramble(bitfieldReverse(shuffled), hash_combine(seed, 1u));
    uint y = nested_uniform_scramble(sobol_dimension1(shuffled), hash_combine(seed, 2u));
    return vec2(u32_to_unit_float(x), u32_to_unit_float(y));
}

#endif
