// The environment: lat-long mapping, radiance lookups and importance sampling
// (docs/formats.md#environments, docs/shading.md#sampling).
//
// Directions here are in environment space: the world direction rotated by R_y(−rotation).
// u = 0.5 + atan2(d.x, −d.z)/2π (wrapped into [0, 1)), v = acos(d.y)/π, row 0 the zenith.
// Lighting treats the map as piecewise constant over its texels; sampling draws from a density
// that is piecewise constant in solid angle over cells of whole texels, so each texel stores its
// cell's pdf_ω beside its radiance and one fetch gives both. Only the background, which is seen
// directly, is filtered bilinearly. Descriptor set 1 holds the environment for every kernel that
// needs it. Mirrored in src/environment/sampling.rs; the tables are built in distribution.rs.
#ifndef LOOKDEV_ENVIRONMENT_GLSL
#define LOOKDEV_ENVIRONMENT_GLSL

#include "common.glsl"

// rgb: radiance; a: pdf over solid angle of the sampling cell that holds the texel.
layout(set = 1, binding = 0, rgba32f) uniform readonly image2D env_texels;
// Inverse-CDF tables: row 0 over rows of cells, row 1 + r over the cells of row r. Bucket k of a
// table is (cdf[g], cdf[g + 1], g, guide[k + 1]) with g = guide[k]: the intervals that values of u
// in bucket k can fall in run from g to guide[k + 1], and usually that is just g.
layout(set = 1, binding = 1, rgba32f) uniform readonly image2D env_buckets;
// The same tables' plain CDF values, for the rare bucket that spans several intervals.
layout(set = 1, binding = 2, r32f) uniform readonly image2D env_cdf;
layout(set = 1, binding = 3, std430) readonly buffer EnvInfo {
    uint env_width;    // texels
    uint env_height;
    uint env_block_x;  // texels per cell
    uint env_block_y;
    uint env_columns;  // cells
    uint env_rows;
};

// v = acos(d.y)/π, computed as atan2(|d.xz|, d.y)/π: the same angle for a unit d, but well
// conditioned near the poles, and accurate where a driver's acos is only approximate.
vec2 env_direction_to_uv(vec3 d) {
    float u = 0.5 + atan(d.x, -d.z) * INV_TWO_PI;
    u -= floor(u);
    float v = atan(length(d.xz), d.y) * INV_PI;
    return vec2(u, v);
}

// The direction with azimuth u and polar angle θ given by its cosine and sine.
vec3 env_direction(float u, float cos_theta, float sin_theta) {
    float phi = TWO_PI * (u - 0.5);
    return vec3(sin_theta * sin(phi), cos_theta, -sin_theta * cos(phi));
}

vec3 env_uv_to_direction(vec2 uv) {
    float theta = PI * uv.y;
    return env_direction(uv.x, cos(theta), sin(theta));
}

// The texel holding uv: its radiance (rgb) and its cell's pdf_ω (a).
vec4 env_texel(vec2 uv) {
    ivec2 size = ivec2(env_width, env_height);
    return imageLoad(env_texels, min(ivec2(uv * vec2(size)), size - 1));
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

// The last interval r of table `table` (n intervals) with cdf[r] <= u, and (cdf[r], cdf[r + 1]).
uint env_search(uint table, uint n, float u, out vec2 bounds) {
    uint k = min(uint(u * float(n)), n - 1u);
    vec4 entry = imageLoad(env_buckets, ivec2(k, table));
    uint lo = uint(entry.z);
    uint hi = uint(entry.w) + 1u;
    bounds = entry.xy;
    if (hi - lo > 1u) {
        while (hi - lo > 1u) {
            uint mid = (lo + hi) >> 1;
            if (imageLoad(env_cdf, ivec2(mid, table)).x <= u) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        bounds = vec2(imageLoad(env_cdf, ivec2(lo, table)).x, imageLoad(env_cdf, ivec2(lo + 1u, table)).x);
    }
    return lo;
}

// cos θ at the top edge of texel row y.
float env_row_cos(uint y) {
    return cos(PI * float(y) / float(env_height));
}

// Samples a direction in proportion to the distribution: a cell by the tables, then a point
// uniform in solid angle within it (uniform in azimuth and in cos θ). Returns the direction and
// its texel: radiance and pdf_ω.
vec3 env_sample(vec2 u, out vec4 texel) {
    vec2 bounds;
    uint row = env_search(0u, env_rows, u.y, bounds);
    float dv = bounds.y > bounds.x ? (u.y - bounds.x) / (bounds.y - bounds.x) : 0.5;
    uint column = env_search(1u + row, env_columns, u.x, bounds);
    float du = bounds.y > bounds.x ? (u.x - bounds.x) / (bounds.y - bounds.x) : 0.5;
    du = min(du, ONE_MINUS_EPSILON);
    dv = min(dv, ONE_MINUS_EPSILON);

    uvec2 start = uvec2(column * env_block_x, row * env_block_y);
    uvec2 end = min(start + uvec2(env_block_x, env_block_y), uvec2(env_width, env_height));
    float x = float(start.x) + du * float(end.x - start.x);
    float z = mix(env_row_cos(start.y), env_row_cos(end.y), dv);
    float sin_theta = sqrt(max(0.0, 1.0 - z * z));
    // With one texel row per cell the row is known; otherwise find it from the angle.
    uint y = env_block_y == 1u ? start.y
                               : clamp(uint(atan(sin_theta, z) * INV_PI * float(env_height)), start.y, end.y - 1u);
    texel = imageLoad(env_texels, ivec2(min(uint(x), end.x - 1u), y));
    return env_direction(x / float(env_width), z, sin_theta);
}

#endif
