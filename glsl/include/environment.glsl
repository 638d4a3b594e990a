// The environment: lat-long mapping, bilinear radiance and importance sampling (LOOKDEV.md §3, §5).
//
// Directions here are in environment space: the world direction rotated by R_y(−rotation).
// u = 0.5 + atan2(d.x, −d.z)/2π (wrapped into [0, 1)), v = acos(d.y)/π, row 0 the zenith.
// The sampling distribution is piecewise constant over a grid of cells in (u, v), weighted by
// luminance·sinθ; pdf_ω = pdf_uv/(2π²·sinθ). Descriptor set 1 holds the environment for every
// kernel that needs it. Mirrored in src/environment/sampling.rs.
#ifndef LOOKDEV_ENVIRONMENT_GLSL
#define LOOKDEV_ENVIRONMENT_GLSL

#include "common.glsl"

layout(set = 1, binding = 0, rgba32f) uniform readonly image2D env_radiance_image;
// The marginal CDF over rows: env_marginal_cdf[0] = 0, env_marginal_cdf[rows] = 1.
layout(set = 1, binding = 1, std430) readonly buffer EnvMarginal {
    uint env_columns;
    uint env_rows;
    uint env_pad0;
    uint env_pad1;
    float env_marginal_cdf[];
};
// One conditional CDF over columns per row, each with columns + 1 entries.
layout(set = 1, binding = 2, std430) readonly buffer EnvConditional {
    float env_conditional_cdf[];
};
// pdf_uv of each cell, row-major.
layout(set = 1, binding = 3, std430) readonly buffer EnvCellPdf {
    float env_cell_pdf[];
};

// v = acos(d.y)/π, computed as atan2(|d.xz|, d.y)/π: the same angle for a unit d, but well
// conditioned near the poles, and accurate where a driver's acos is only approximate.
vec2 env_direction_to_uv(vec3 d) {
    float u = 0.5 + atan(d.x, -d.z) * INV_TWO_PI;
    u -= floor(u);
    float v = atan(length(d.xz), d.y) * INV_PI;
    return vec2(u, v);
}

vec3 env_uv_to_direction(vec2 uv) {
    float phi = TWO_PI * (uv.x - 0.5);
    float theta = PI * uv.y;
    float sin_theta = sin(theta);
    return vec3(sin_theta * sin(phi), cos(theta), -sin_theta * cos(phi));
}

// Bilinear radiance between texel centres, wrapping in u and clamping in v.
vec3 env_radiance(vec2 uv) {
    ivec2 size = imageSize(env_radiance_image);
    vec2 p = uv * vec2(size) - 0.5;
    vec2 f = floor(p);
    vec2 t = p - f;
    int x0 = int(f.x);
    int y0 = int(f.y);
    x0 = x0 < 0 ? size.x - 1 : min(x0, size.x - 1);
    int x1 = x0 + 1 == size.x ? 0 : x0 + 1;
    int y1 = clamp(y0 + 1, 0, size.y - 1);
    y0 = clamp(y0, 0, size.y - 1);
    vec3 a = imageLoad(env_radiance_image, ivec2(x0, y0)).rgb;
    vec3 b = imageLoad(env_radiance_image, ivec2(x1, y0)).rgb;
    vec3 c = imageLoad(env_radiance_image, ivec2(x0, y1)).rgb;
    vec3 d = imageLoad(env_radiance_image, ivec2(x1, y1)).rgb;
    return mix(mix(a, b, t.x), mix(c, d, t.x), t.y);
}

uint env_cell_index(vec2 uv) {
    uint column = min(uint(uv.x * float(env_columns)), env_columns - 1u);
    uint row = min(uint(uv.y * float(env_rows)), env_rows - 1u);
    return row * env_columns + column;
}

// pdf over solid angle of env_sample producing the direction d (unit, environment space) at uv.
float env_pdf(vec2 uv, vec3 d) {
    float sin_theta = sqrt(max(0.0, 1.0 - d.y * d.y));
    if (sin_theta <= 0.0) {
        return 0.0;
    }
    return env_cell_pdf[env_cell_index(uv)] / (2.0 * PI * PI * sin_theta);
}

// Largest row r with marginal_cdf[r] <= u; binary search keeps the warp monotonic, which
// preserves the stratification of the sample points.
uint env_search_rows(float u) {
    uint lo = 0u;
    uint hi = env_rows;
    while (hi - lo > 1u) {
        uint mid = (lo + hi) >> 1;
        if (env_marginal_cdf[mid] <= u) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

uint env_search_columns(uint row, float u) {
    uint base = row * (env_columns + 1u);
    uint lo = 0u;
    uint hi = env_columns;
    while (hi - lo > 1u) {
        uint mid = (lo + hi) >> 1;
        if (env_conditional_cdf[base + mid] <= u) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// Samples a direction in proportion to the distribution; returns it with its uv and pdf_ω.
vec3 env_sample(vec2 u, out vec2 uv, out float pdf) {
    uint row = env_search_rows(u.y);
    float r0 = env_marginal_cdf[row];
    float r1 = env_marginal_cdf[row + 1u];
    float dv = r1 > r0 ? (u.y - r0) / (r1 - r0) : 0.5;

    uint column = env_search_columns(row, u.x);
    uint base = row * (env_columns + 1u);
    float c0 = env_conditional_cdf[base + column];
    float c1 = env_conditional_cdf[base + column + 1u];
    float du = c1 > c0 ? (u.x - c0) / (c1 - c0) : 0.5;

    uv = vec2((float(column) + min(du, ONE_MINUS_EPSILON)) / float(env_columns),
              (float(row) + min(dv, ONE_MINUS_EPSILON)) / float(env_rows));
    float theta = PI * uv.y;
    float sin_theta = sin(theta);
    pdf = sin_theta > 0.0 ? env_cell_pdf[row * env_columns + column] / (2.0 * PI * PI * sin_theta) : 0.0;
    return env_uv_to_direction(uv);
}

#endif
