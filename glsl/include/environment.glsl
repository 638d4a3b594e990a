// The environment: lat-long mapping, radiance lookups and importance sampling (LOOKDEV.md §3, §5).
//
// Directions here are in environment space: the world direction rotated by R_y(−rotation).
// u = 0.5 + atan2(d.x, −d.z)/2π (wrapped into [0, 1)), v = acos(d.y)/π, row 0 the zenith.
// Lighting treats the map as piecewise constant over its texels, which is exactly the function
// the sampling distribution is built from (cells of whole texels, weighted by luminance·sinθ), so
// one texel fetch gives both the radiance and the pdf. Only the background, which is seen
// directly, is filtered bilinearly. pdf_ω = pdf_uv/(2π²·sinθ). Descriptor set 1 holds the
// environment for every kernel that needs it. Mirrored in src/environment/sampling.rs.
#ifndef LOOKDEV_ENVIRONMENT_GLSL
#define LOOKDEV_ENVIRONMENT_GLSL

#include "common.glsl"

// rgb: radiance; a: pdf_uv of the sampling cell that holds the texel.
layout(set = 1, binding = 0, rgba32f) uniform readonly image2D env_texels;
// The marginal CDF over rows of cells: env_marginal_cdf[0] = 0, env_marginal_cdf[rows] = 1.
layout(set = 1, binding = 1, std430) readonly buffer EnvMarginal {
    uint env_width;    // texels
    uint env_height;
    uint env_block;    // texels per cell side
    uint env_columns;  // cells
    uint env_rows;
    uint env_pad0;
    uint env_pad1;
    uint env_pad2;
    float env_marginal_cdf[];
};
// One conditional CDF over columns per row of cells, each with columns + 1 entries.
layout(set = 1, binding = 2, std430) readonly buffer EnvConditional {
    float env_conditional_cdf[];
};
// Guide tables: rows + 1 entries for the marginal, then columns + 1 per row. guide[k] is the
// last interval whose CDF value is at most k/n, so a search only spans the buckets around u.
layout(set = 1, binding = 3, std430) readonly buffer EnvGuides {
    uint env_guides[];
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

// The texel holding uv: its radiance (rgb) and its cell's pdf_uv (a).
vec4 env_texel(vec2 uv) {
    ivec2 size = ivec2(env_width, env_height);
    return imageLoad(env_texels, min(ivec2(uv * vec2(size)), size - 1));
}

// pdf over solid angle, from pdf_uv, at a direction d (unit, environment space).
float env_pdf(float pdf_uv, vec3 d) {
    float sin_theta = sqrt(max(0.0, 1.0 - d.y * d.y));
    return sin_theta > 0.0 ? pdf_uv / (2.0 * PI * PI * sin_theta) : 0.0;
}

// Bilinear radiance between texel centres, wrapping in u and clamping in v: for the background.
vec3 env_background(vec2 uv) {
    ivec2 size = ivec2(env_width, env_height);
    vec2 p = uv * vec2(size) - 0.5;
    vec2 f = floor(p);
    vec2 t = p - f;
    int x0 = int(f.x);
    int y0 = int(f.y);
    x0 = x0 < 0 ? size.x - 1 : min(x0, size.x - 1);
    int x1 = x0 + 1 == size.x ? 0 : x0 + 1;
    int y1 = clamp(y0 + 1, 0, size.y - 1);
    y0 = clamp(y0, 0, size.y - 1);
    vec3 a = imageLoad(env_texels, ivec2(x0, y0)).rgb;
    vec3 b = imageLoad(env_texels, ivec2(x1, y0)).rgb;
    vec3 c = imageLoad(env_texels, ivec2(x0, y1)).rgb;
    vec3 d = imageLoad(env_texels, ivec2(x1, y1)).rgb;
    return mix(mix(a, b, t.x), mix(c, d, t.x), t.y);
}

// Last row r with marginal_cdf[r] <= u. The guides bound the binary search; taking the buckets
// either side of u's keeps it right even if u·rows rounds into a neighbouring bucket.
uint env_search_rows(float u) {
    int k = int(u * float(env_rows));
    uint lo = env_guides[max(k - 1, 0)];
    uint hi = min(env_guides[min(k + 2, int(env_rows))] + 1u, env_rows);
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
    uint guides = env_rows + 1u + base;
    int k = int(u * float(env_columns));
    uint lo = env_guides[guides + uint(max(k - 1, 0))];
    uint hi = min(env_guides[guides + uint(min(k + 2, int(env_columns)))] + 1u, env_columns);
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

// Samples a direction in proportion to the distribution. Returns it with its uv and its texel
// (radiance and pdf_uv), fetched from the texel the sample lies in.
vec3 env_sample(vec2 u, out vec2 uv, out vec4 texel) {
    uint row = env_search_rows(u.y);
    float r0 = env_marginal_cdf[row];
    float r1 = env_marginal_cdf[row + 1u];
    float dv = r1 > r0 ? (u.y - r0) / (r1 - r0) : 0.5;

    uint column = env_search_columns(row, u.x);
    uint base = row * (env_columns + 1u);
    float c0 = env_conditional_cdf[base + column];
    float c1 = env_conditional_cdf[base + column + 1u];
    float du = c1 > c0 ? (u.x - c0) / (c1 - c0) : 0.5;

    uvec2 start = uvec2(column, row) * env_block;
    uvec2 end = min(start + env_block, uvec2(env_width, env_height));
    vec2 position = vec2(start) + min(vec2(du, dv), vec2(ONE_MINUS_EPSILON)) * vec2(end - start);
    uv = position / vec2(env_width, env_height);
    texel = imageLoad(env_texels, ivec2(min(uvec2(position), end - 1u)));
    return env_uv_to_direction(uv);
}

#endif
