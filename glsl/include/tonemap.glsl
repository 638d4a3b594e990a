// Display transforms: tone maps and the sRGB OETF. Mirrored in src/shading/tonemap.rs.
#ifndef LOOKDEV_TONEMAP_GLSL
#define LOOKDEV_TONEMAP_GLSL

const uint TONEMAP_LINEAR = 0u;
const uint TONEMAP_NEUTRAL = 1u;
const uint TONEMAP_ACES = 2u;
const uint TONEMAP_AGX = 3u;

// Khronos PBR Neutral (github.com/KhronosGroup/ToneMapping, PBR_Neutral).
vec3 tonemap_neutral(vec3 color) {
    const float start_compression = 0.8 - 0.04;
    const float desaturation = 0.15;
    float x = min(color.r, min(color.g, color.b));
    float offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    color -= offset;
    float peak = max(color.r, max(color.g, color.b));
    if (peak < start_compression) {
        return color;
    }
    const float d = 1.0 - start_compression;
    float new_peak = 1.0 - d * d / (peak + d - start_compression);
    color *= new_peak / peak;
    float g = 1.0 - 1.0 / (desaturation * (peak - new_peak) + 1.0);
    return mix(color, vec3(new_peak), g);
}

// ACES 1.0 RRT+ODT for sRGB, Stephen Hill's fit: input matrix, rational curve, output matrix.
vec3 tonemap_aces(vec3 color) {
    // Matrices are written row by row; GLSL's mat3 constructor takes columns, hence v * M.
    const mat3 input_rows = mat3(
        0.59719, 0.35458, 0.04823,
        0.07600, 0.90834, 0.01566,
        0.02840, 0.13383, 0.83777);
    const mat3 output_rows = mat3(
        1.60475, -0.53108, -0.07367,
        -0.10208, 1.10813, -0.00605,
        -0.00327, -0.07276, 1.07602);
    vec3 v = color * input_rows;
    vec3 a = v * (v + 0.0245786) - 0.000090537;
    vec3 b = v * (0.983729 * v + 0.4329510) + 0.238081;
    return clamp((a / b) * output_rows, 0.0, 1.0);
}

// AgX (Troy Sobotka) base look: inset matrix, log2 encoding over [−12.47, 4.03] EV around 0.18,
// the 7th-order sigmoid fit of Wrensch's minimal AgX, outset matrix, then the look's 2.2 display
// gamma undone so the result is display-linear, ready for the sRGB OETF.
vec3 tonemap_agx(vec3 color) {
    const mat3 inset_rows = mat3(
        0.842479062253094, 0.0784335999999992, 0.0792237451477643,
        0.0423282422610123, 0.878468636469772, 0.0791661274605434,
        0.0423756549057051, 0.0784336, 0.879142973793104);
    const mat3 outset_rows = mat3(
        1.19687900512017, -0.0980208811401368, -0.0990297440797205,
        -0.0528968517574562, 1.15190312990417, -0.0989611768448433,
        -0.0529716355144438, -0.0980434501171241, 1.15107367264116);
    const float min_ev = -12.47393;
    const float max_ev = 4.026069;
    vec3 v = max(color * inset_rows, vec3(1e-10));
    v = clamp((log2(v) - min_ev) / (max_ev - min_ev), 0.0, 1.0);
    vec3 v2 = v * v;
    vec3 v4 = v2 * v2;
    v = -17.86 * v4 * v2 * v + 78.01 * v4 * v2 - 126.7 * v4 * v + 92.06 * v4 - 28.72 * v2 * v
        + 4.361 * v2 - 0.1718 * v + 0.002857;
    v = max(v * outset_rows, vec3(0.0));
    return clamp(pow(v, vec3(2.2)), 0.0, 1.0);
}

vec3 apply_tonemap(vec3 color, uint tonemap) {
    color = max(color, vec3(0.0));
    if (tonemap == TONEMAP_NEUTRAL) {
        color = tonemap_neutral(color);
    } else if (tonemap == TONEMAP_ACES) {
        color = tonemap_aces(color);
    } else if (tonemap == TONEMAP_AGX) {
        color = tonemap_agx(color);
    }
    return clamp(color, 0.0, 1.0);
}

// The sRGB OETF (IEC 61966-2-1), piecewise.
vec3 srgb_encode(vec3 c) {
    vec3 low = 12.92 * c;
    vec3 high = 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055;
    return mix(high, low, lessThanEqual(c, vec3(0.0031308)));
}

#endif
