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

// Sobol dimension 1 (primitive polynomial x + 1), whose generator matrix is Pascal's triangle
// mod 2. By Lucas' theorem, C(j, i) is odd exactly when the bits of i are a subset of those of j,
// so output bit 31 − i is the XOR of the index bits j ⊇ i: a superset XOR transform over the
// five bits of a bit position, five shift-and-mask steps instead of a 32-step loop.
// Dimension 0 is bitfieldReverse(index).
uint sobol_dimension1(uint index) {
    uint z = index;
    z ^= (z >> 1) & 0x55555555u;
    z ^= (z >> 2) & 0x33333333u;
    z ^= (z >> 4) & 0x0f0f0f0fu;
    z ^= (z >> 8) & 0x00ff00ffu;
    z ^= (z >> 16) & 0x0000ffffu;
    return bitfieldReverse(z);
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
