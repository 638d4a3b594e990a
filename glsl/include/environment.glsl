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
// The sizes, read alike by every invocation: a uniform block, which a CPU driver loads once for
// all lanes where it reads a storage buffer lane by lane.
layout(set = 1, binding = 3, std140) uniform EnvInfo {
    uint env_width;    // texels
    uint env_height;
    uint env_block_x;  // texels per cell
    uint env_block_y;
    uint env_columns;  // cells
    uint env_rows;
    uint env_product_grid;    // product sampling: clusters per cube-face side; 0 when off
    uint env_coarse_columns;  // coarse cells, each a block of cells
    uint env_coarse_rows;
    uint env_product_ratio_row;  // env_product_cdf's row of cluster 0's ratios
};
// Product sampling (src/environment/product.rs): the bucket entries and CDFs, laid out as
// env_buckets and env_cdf are, of one table per cluster of normals over the coarse cells (row k
// for cluster k), then one per coarse cell over its rows of cells, several to a row (most are
// short), where env_product_index says; env_product_cdf then holds, from env_product_ratio_row
// on, one row per cluster of the ratio of its pdf to the global pdf in each coarse cell. 1×1
// placeholders when off.
layout(set = 1, binding = 4, rgba32f) uniform readonly image2D env_product_buckets;
layout(set = 1, binding = 5, r32f) uniform readonly image2D env_product_cdf;
// Product sampling's span guides (Product::spans): texel (c0 + k, row) is first | last << 16,
// the cells of row `row` that the target of bucket k of the span from c0 can fall in. 1×1 when
// off.
layout(set = 1, binding = 6, r32ui) uniform readonly uimage2D env_product_spans;
// Product sampling's lookups (Product::index), which spare each sample integer divisions that
// lavapipe runs lane by lane, word i at texel (i % 1024, i / 1024) (INDEX_WIDTH in
// src/environment/gpu.rs): each texel column's coarse column; each texel row's coarse row times
// env_coarse_columns; then per coarse cell its columns of cells c0 | c1 << 16, its rows
// r0 | r1 << 16, and where its table starts, x | row << 16. 1×1 when off.
layout(set = 1, binding = 7, r32ui) uniform readonly uimage2D env_product_index;

uint env_product_word(uint i) {
    return imageLoad(env_product_index, ivec2(i & 1023u, i >> 10)).x;
}

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

// The coordinates of the texel holding uv.
ivec2 env_texel_at(vec2 uv) {
    ivec2 size = ivec2(env_width, env_height);
    return min(ivec2(uv * vec2(size)), size - 1);
}

// The texel holding uv: its radiance (rgb) and its cell's pdf_ω (a).
vec4 env_texel(vec2 uv) {
    return imageLoad(env_texels, env_texel_at(uv));
}

// The texel columns (xs) and rows (ys) around uv in a lat-long image of `size` texels, and the
// weights between them (t), for a bilinear lookup between texel centres: wrapping in u and
// clamping in v. Any lat-long image the background shows is read so.
void env_bilinear_taps(vec2 uv, ivec2 size, out ivec2 xs, out ivec2 ys, out vec2 t) {
    vec2 p = uv * vec2(size) - 0.5;
    vec2 f = floor(p);
    t = p - f;
    int x0 = int(f.x);
    int y0 = int(f.y);
    x0 = x0 < 0 ? size.x - 1 : min(x0, size.x - 1);
    int x1 = x0 + 1 == size.x ? 0 : x0 + 1;
    int y1 = clamp(y0 + 1, 0, size.y - 1);
    y0 = clamp(y0, 0, size.y - 1);
    xs = ivec2(x0, x1);
    ys = ivec2(y0, y1);
}

// Bilinear radiance between texel centres, wrapping in u and clamping in v: for the background.
vec3 env_background(vec2 uv) {
    ivec2 xs;
    ivec2 ys;
    vec2 t;
    env_bilinear_taps(uv, ivec2(env_width, env_height), xs, ys, t);
    vec3 a = imageLoad(env_texels, ivec2(xs.x, ys.x)).rgb;
    vec3 b = imageLoad(env_texels, ivec2(xs.y, ys.x)).rgb;
    vec3 c = imageLoad(env_texels, ivec2(xs.x, ys.y)).rgb;
    vec3 d = imageLoad(env_texels, ivec2(xs.y, ys.y)).rgb;
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

// The point at (du, dv) of cell (row, column), uniform in azimuth and in cos θ, and its texel.
vec3 env_point_in_cell(uint row, uint column, float du, float dv, out uvec2 at) {
    uvec2 start = uvec2(column * env_block_x, row * env_block_y);
    uvec2 end = min(start + uvec2(env_block_x, env_block_y), uvec2(env_width, env_height));
    float x = float(start.x) + du * float(end.x - start.x);
    float z = mix(env_row_cos(start.y), env_row_cos(end.y), dv);
    float sin_theta = sqrt(max(0.0, 1.0 - z * z));
    // With one texel row per cell the row is known; otherwise find it from the angle.
    uint y = env_block_y == 1u ? start.y
                               : clamp(uint(atan(sin_theta, z) * INV_PI * float(env_height)), start.y, end.y - 1u);
    at = uvec2(min(uint(x), end.x - 1u), y);
    return env_direction(x / float(env_width), z, sin_theta);
}

// Samples a direction in proportion to the distribution: a cell by the tables, then a point
// uniform in solid angle within it (uniform in azimuth and in cos θ). Returns the direction and
// its texel's coordinates.
vec3 env_sample_at(vec2 u, out uvec2 at) {
    vec2 bounds;
    uint row = env_search(0u, env_rows, u.y, bounds);
    float dv = bounds.y > bounds.x ? (u.y - bounds.x) / (bounds.y - bounds.x) : 0.5;
    uint column = env_search(1u + row, env_columns, u.x, bounds);
    float du = bounds.y > bounds.x ? (u.x - bounds.x) / (bounds.y - bounds.x) : 0.5;
    du = min(du, ONE_MINUS_EPSILON);
    dv = min(dv, ONE_MINUS_EPSILON);
    return env_point_in_cell(row, column, du, dv, at);
}

// As env_sample_at, returning the texel: radiance and pdf_ω.
vec3 env_sample(vec2 u, out vec4 texel) {
    uvec2 at;
    vec3 d = env_sample_at(u, at);
    texel = imageLoad(env_texels, ivec2(at));
    return d;
}

// The cluster of the unit normal n (environment space): the face of its largest axis, then a
// cell of env_product_grid² on that face. Mirrors product::cluster_of.
uint env_cluster(vec3 n) {
    vec3 a = abs(n);
    uint face;
    vec2 p;
    if (a.x >= a.y && a.x >= a.z) {
        face = n.x > 0.0 ? 0u : 1u;
        p = n.yz / a.x;
    } else if (a.y >= a.z) {
        face = n.y > 0.0 ? 2u : 3u;
        p = n.xz / a.y;
    } else {
        face = n.z > 0.0 ? 4u : 5u;
        p = n.xy / a.z;
    }
    uint grid = env_product_grid;
    uvec2 cell = min(uvec2((p * 0.5 + 0.5) * float(grid)), uvec2(grid - 1u));
    return (face * grid + cell.y) * grid + cell.x;
}

// The ratio of `cluster`'s product pdf to the global pdf at texel `at`.
float env_product_ratio(uint cluster, uvec2 at) {
    uint c = env_product_word(at.x) + env_product_word(env_width + at.y);
    return imageLoad(env_product_cdf, ivec2(c, env_product_ratio_row + cluster)).x;
}

// env_search on the product table that starts at texel `origin`.
uint env_product_search(ivec2 origin, uint n, float u, out vec2 bounds) {
    uint k = min(uint(u * float(n)), n - 1u);
    vec4 entry = imageLoad(env_product_buckets, origin + ivec2(k, 0));
    uint lo = uint(entry.z);
    uint hi = uint(entry.w) + 1u;
    bounds = entry.xy;
    if (hi - lo > 1u) {
        while (hi - lo > 1u) {
            uint mid = (lo + hi) >> 1;
            if (imageLoad(env_product_cdf, origin + ivec2(mid, 0)).x <= u) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        bounds = vec2(imageLoad(env_product_cdf, origin + ivec2(lo, 0)).x,
                      imageLoad(env_product_cdf, origin + ivec2(lo + 1u, 0)).x);
    }
    return lo;
}

// Where u lies in the interval bounds, in [0, 1); ½ for an empty interval.
float env_rescale(float u, vec2 bounds) {
    float t = bounds.y > bounds.x ? (u - bounds.x) / (bounds.y - bounds.x) : 0.5;
    return clamp(t, 0.0, ONE_MINUS_EPSILON);
}

// Samples `cluster`'s product distribution: a coarse cell by its table (u.x), a row of cells in
// it by the coarse cell's table (u.y), a cell of that row by the global conditional table within
// the coarse cell's span (u.x rescaled, from the span's guide), and a point in the cell.
// Mirrors Product::sample.
vec3 env_sample_product(uint cluster, vec2 u, out uvec2 at) {
    vec2 bounds;
    uint cells = env_coarse_columns * env_coarse_rows;
    uint c = env_product_search(ivec2(0, cluster), cells, u.x, bounds);
    float ux = env_rescale(u.x, bounds);
    uint span_at = env_width + env_height + 3u * c;
    uint columns = env_product_word(span_at);
    uint rows = env_product_word(span_at + 1u);
    uint table = env_product_word(span_at + 2u);
    uint c0 = columns & 0xffffu;
    uint c1 = columns >> 16;
    uint r0 = rows & 0xffffu;
    uint r1 = rows >> 16;
    uint k = env_product_search(ivec2(table & 0xffffu, table >> 16), r1 - r0, u.y, bounds);
    float dv = env_rescale(u.y, bounds);
    uint row = r0 + k;
    float a = imageLoad(env_cdf, ivec2(c0, 1u + row)).x;
    float b = imageLoad(env_cdf, ivec2(c1, 1u + row)).x;
    float target = a + ux * (b - a);
    // The span's own guide names the cells the target can fall in, usually one (the row's guide
    // table would crowd a dim span into one long search); a binary search among them otherwise.
    uint n = c1 - c0;
    uint guide = imageLoad(env_product_spans, ivec2(c0 + min(uint(ux * float(n)), n - 1u), row)).x;
    uint lo = guide & 0xffffu;
    uint hi = (guide >> 16) + 1u;
    while (hi - lo > 1u) {
        uint mid = (lo + hi) >> 1;
        if (imageLoad(env_cdf, ivec2(mid, 1u + row)).x <= target) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    bounds = vec2(imageLoad(env_cdf, ivec2(lo, 1u + row)).x, imageLoad(env_cdf, ivec2(lo + 1u, 1u + row)).x);
    return env_point_in_cell(row, lo, env_rescale(target, bounds), dv, at);
}

// The environment sample of product sampling: from `cluster`'s table with probability q, from
// the global tables otherwise, u.x choosing and then reused, rescaled. texel.a is the mixture's
// pdf_ω.
vec3 env_sample_mixture(uint cluster, float q, vec2 u, out vec4 texel) {
    uvec2 at;
    vec3 d;
    if (u.x < q) {
        d = env_sample_product(cluster, vec2(min(u.x / q, ONE_MINUS_EPSILON), u.y), at);
    } else {
        d = env_sample_at(vec2(min((u.x - q) / (1.0 - q), ONE_MINUS_EPSILON), u.y), at);
    }
    texel = imageLoad(env_texels, ivec2(at));
    texel.a *= (1.0 - q) + q * env_product_ratio(cluster, at);
    return d;
}

// The environment sample of product sampling with q = 1: `cluster`'s table alone. Bit for bit
// env_sample_mixture(cluster, 1.0, u, texel), without the global sampler's code, which a SIMD
// driver would otherwise run masked beside it.
vec3 env_sample_cluster(uint cluster, vec2 u, out vec4 texel) {
    uvec2 at;
    vec3 d = env_sample_product(cluster, u, at);
    texel = imageLoad(env_texels, ivec2(at));
    texel.a *= env_product_ratio(cluster, at);
    return d;
}

// The texel at uv with env_sample_cluster's pdf_ω in a.
vec4 env_texel_cluster(uint cluster, vec2 uv) {
    ivec2 at = env_texel_at(uv);
    vec4 texel = imageLoad(env_texels, at);
    texel.a *= env_product_ratio(cluster, uvec2(at));
    return texel;
}

// The texel at uv with the mixture's pdf_ω in a.
vec4 env_texel_mixture(uint cluster, float q, vec2 uv) {
    ivec2 at = env_texel_at(uv);
    vec4 texel = imageLoad(env_texels, at);
    texel.a *= (1.0 - q) + q * env_product_ratio(cluster, uvec2(at));
    return texel;
}

#endif