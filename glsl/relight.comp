#version 460
// One progressive pass of image-based relighting over a list of covered pixels: for each pixel and
// each sample index, one environment sample and one BRDF sample, combined with the power heuristic
// (docs/shading.md#sampling). The running float32 sum of the estimates is accumulated in sample order, so
// any split into passes and bands gives the same bits. Coverage and the background are composited
// by finalize.comp; the background is written by a pass of its own, once per accumulation.
//
// Invocations run over a compacted, row-major list of the covered pixels (a band of rows is a
// range of it), so no lane idles on background. Every pixel of one dispatch has the same number
// of samples so far; keeping that number (and so the branches below) uniform across the dispatch
// matters on SIMD CPU drivers. Each pixel's own count is its accumulation's alpha.
//
// The preview (source PREVIEW) relights the top-left pixel of every block × block block with the
// same sample 0 a full pass gives it, which overwrites it identically later.
//
// With a noise threshold, a pixel stops once its estimated relative error falls below it, tested
// only at fixed sample counts (min_samples, then each power of two), so where it stops does not
// depend on how the samples are split into dispatches (docs/shading.md#adaptive-sampling).
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

// The energy-compensation table of the model (a placeholder when compensation is off).
#define ENERGY_TABLE_SET 0
#define ENERGY_TABLE_BINDING 4

// What is accumulated beside the total, only when asked for (docs/formats.md#aovs): each
// lobe's share of every estimate, and the sum of each estimate's squared luminance. Off, the
// code below is specialised away and the images bound are 1×1 placeholders.
layout(constant_id = 6) const uint LOBE_AOVS = 0u;
layout(constant_id = 7) const uint VARIANCE_AOV = 0u;
// Whether the environment sample is drawn by the product tables (--sampling product): a
// constant, so that the kernel of each estimator holds only its own sampler.
layout(constant_id = 8) const uint PRODUCT_SAMPLING = 0u;
// The side of the g-buffer's visibility grid (docs/formats.md#visibility): both strategies' samples
// carry light only along directions the pixel's surface sees the environment. 0 without
// visibility: every direction above the horizon is seen, and the image bound is a placeholder.
layout(constant_id = 11) const uint VISIBILITY_SIDE = 0u;
// Whether some object catches shadows (docs/formats.md#shadow-catchers): a catcher's pixels
// (flagged in the resolved material) also sum their estimates as if the visibility blocked
// nothing, into `unshadowed`, for finalize.comp to divide. 0: that image is a placeholder.
layout(constant_id = 12) const uint SHADOW_CATCHER = 0u;
// 1: the kernel writes backgrounds only (SOURCE_BACKGROUND), whatever the source. A CPU driver
// pays the whole kernel's set-up per invocation, which for the background pass over every
// pixel of a large image cost more than the preview's relighting; specialised, the rest of
// the kernel is left out.
layout(constant_id = 13) const uint BACKGROUND_ONLY = 0u;

#include "common.glsl"
#include "material.glsl"
#include "brdf.glsl"
#include "sampling.glsl"
#include "sobol.glsl"
#include "environment.glsl"
#include "pixel_list.glsl"
#include "visibility.glsl"

// Layer 0: N.xyz and coverage A; layer 1: V.xyz; layer 2: T.xyz (unit, orthogonal to N).
layout(set = 0, binding = 0, rgba32f) uniform readonly image2DArray surface;
// The resolved material: four layers as material.glsl unpacks them, then emission (rgb) and
// whether the pixel's object catches shadows (a: 1 or 0).
layout(set = 0, binding = 1, rgba32f) uniform readonly image2DArray resolved;
// Covered pixels: the running sum of the radiance estimates (rgb) and their number (a).
// Uncovered pixels are never written.
layout(set = 0, binding = 2, rgba32f) uniform image2D accumulation;
// The environment behind each pixel (rgb) and whether it catches shadows (a: 1 or 0), written
// once per lighting and stacks. A catcher's pixels have it wherever the background is shown.
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D background;
// With LOBE_AOVS, the running sums of each lobe's share: layers diffuse (with subsurface),
// specular, clearcoat and sheen, all weighted as they enter the total.
layout(set = 0, binding = 5, rgba32f) uniform image2DArray lobe_sums;
// With VARIANCE_AOV, the running sum of each estimate's squared luminance, scaled by
// MOMENT_SCALE² (r), and 1 in g once the pixel has stopped under a noise threshold.
layout(set = 0, binding = 6, rgba32f) uniform image2D moments;
// The covered pixels, x | y << 16, row-major, read as a list: entry i is texel (i % width, i / width).
layout(set = 0, binding = 7, r32ui) uniform readonly uimage2D covered;
// The same for the pixels restarted alone (Renderer::restart_pixels).
layout(set = 0, binding = 8, r32ui) uniform readonly uimage2D restarted;
// Under a noise threshold, each row's pixels still active after a dispatch of the covered list.
layout(set = 0, binding = 9, std430) buffer Active {
    uint rows[];
} still_active;
// With VISIBILITY_SIDE, the visibility words of every pixel in turn (row-major), four a texel, so
// that a pixel's words share cache lines; VISIBILITY_ROW texels a row.
layout(set = 0, binding = 10, rgba32ui) uniform readonly uimage2D visibility;
const uint VISIBILITY_ROW = 4096u;
// With SHADOW_CATCHER, every covered pixel's running sum of its estimates with nothing blocked
// (rgb): a catcher's own, any other pixel's the same as its accumulation.
layout(set = 0, binding = 11, rgba32f) uniform image2D unshadowed;
// Under a noise threshold, the pixels still sampling, in two lists (layers) read and written in
// turn: a dispatch of the covered list or of one list writes each pixel it leaves active into
// the other, at its row's place in the covered list plus its rank in the row. Stopped pixels
// then cost the next dispatches nothing, where in the covered list a SIMD group with one pixel
// still sampling ran at full cost.
layout(set = 0, binding = 12, r32ui) uniform uimage2DArray active_lists;
// Where each row's entries start in the covered list (height + 1 of them), then how many of
// each row's pixels the list being read holds (height of them).
layout(set = 0, binding = 13, std430) readonly buffer ActiveRows {
    uint data[];
} active_rows;
// Set 2: the lat-long image a BACKGROUND_IMAGE background shows in place of the environment's
// texels (the environment blurred, or another one: src/environment/backdrop.rs), read
// bilinearly as env_background reads the environment. A 1×1 placeholder otherwise.
layout(set = 2, binding = 0, rgba32f) uniform readonly image2D backdrop;
// Texels of visibility a pixel has.
const uint VISIBILITY_TEXELS = (VISIBILITY_SIDE * VISIBILITY_SIDE + 127u) / 128u;

const int LOBE_DIFFUSE = 0;
const int LOBE_SPECULAR = 1;
const int LOBE_CLEARCOAT = 2;
const int LOBE_SHEEN = 3;

layout(push_constant) uniform Pass {
    uint first_sample;     // samples the dispatch's pixels have; 0 starts their accumulation
    uint sample_count;
    uint seed;
    uint background;       // BACKGROUND_*: what uncovered pixels show
    float cos_rotation;
    float sin_rotation;
    float intensity;
    uint source;           // SOURCE_*: which pixel invocation i stands for
    uint first;            // the invocations' range (list entries, blocks or pixels): first .. end - 1
    uint end;
    uint block;            // SOURCE_PREVIEW: pixels per side of a block
    float noise_threshold; // > 0: stop each pixel once its relative error is below it
    uint min_samples;      // ... but not before this many samples (at least 2)
    uint list_in;          // SOURCE_ACTIVE: the active list read; those left active go to the other
    float background_r;    // BACKGROUND_COLOUR: the linear colour shown
    float background_g;
    float background_b;
} pass;

const uint SOURCE_COVERED = 0u;     // entries of the covered list
const uint SOURCE_RESTARTED = 1u;   // entries of the restarted list
const uint SOURCE_PREVIEW = 2u;     // the blocks' top-left pixels, row-major
const uint SOURCE_BACKGROUND = 3u;  // every pixel, row-major: the background only
const uint SOURCE_ACTIVE = 4u;      // entries of active list list_in, in the covered list's places
const uint BACKGROUND_NONE = 0u;         // black; finalize.comp makes it transparent
const uint BACKGROUND_ENVIRONMENT = 1u;  // the lighting environment
const uint BACKGROUND_IMAGE = 2u;        // the backdrop image, rotated and scaled as the environment
const uint BACKGROUND_COLOUR = 3u;       // (background_r, background_g, background_b), as it is
// Below this mean luminance the error is taken relative to it instead, as relative MSE adds
// 0.01 to r²: dark pixels need no finer an absolute error, and black ones stop.
const float BLACK = 0.1;
// The luminances whose squares are summed are scaled by 2^-40 (exactly), so that the squares of
// every radiance the bounds allow (up to 1e24, squared 1e48) stay finite in f32; what falls
// below f32's range at the other end (under 1e-7) is far below BLACK.
const float MOMENT_SCALE = 1.0 / 1099511627776.0;

// R_y(−rotation)·d: world to environment space.
vec3 to_environment(vec3 d) {
    return vec3(d.x * pass.cos_rotation - d.z * pass.sin_rotation, d.y,
                d.x * pass.sin_rotation + d.z * pass.cos_rotation);
}

// R_y(rotation)·d: environment to world space.
vec3 from_environment(vec3 d) {
    return vec3(d.x * pass.cos_rotation + d.z * pass.sin_rotation, d.y,
                -d.x * pass.sin_rotation + d.z * pass.cos_rotation);
}

// Whether the environment is seen along d (environment space) from the surface of the pixel
// whose visibility starts at texel `first`: its bit on the visibility grid, which is fixed in
// world space. Always, without visibility.
bool seen(uint first, vec3 d) {
    if (VISIBILITY_SIDE == 0u) {
        return true;
    }
    uint cell = visibility_cell(from_environment(d), VISIBILITY_SIDE);
    uint word = cell >> 5u;
    uint t = first + (word >> 2u);
    uvec4 texel = imageLoad(visibility, ivec2(int(t % VISIBILITY_ROW), int(t / VISIBILITY_ROW)));
    return ((texel[word & 3u] >> (cell & 31u)) & 1u) != 0u;
}

// With product tables (PRODUCT_SAMPLING), a pixel samples the environment from its normal's
// cluster's table alone (q = 1 of env_sample_mixture, which the kernel does not call: a SIMD
// driver would run the global sampler masked beside the cluster's for every sample).
uint environment_cluster(vec3 fn) {
    return PRODUCT_SAMPLING == 0u ? 0u : env_cluster(fn);
}

// The environment sample, its texel and the pdf_ω MIS uses (a).
vec3 sample_environment(uint cluster, vec2 u, out vec4 texel) {
    return PRODUCT_SAMPLING == 0u ? env_sample(u, texel) : env_sample_cluster(cluster, u, texel);
}

// The texel at uv, with the pdf_ω of sample_environment in a.
vec4 environment_texel(uint cluster, vec2 uv) {
    return PRODUCT_SAMPLING == 0u ? env_texel(uv) : env_texel_cluster(cluster, uv);
}

// One MIS estimate of reflected radiance toward the view; the frame (fx, fy, fn) is the shading
// frame expressed in environment space, so no per-sample rotation is needed. For a shadow
// catcher, `open` is the same estimate with every direction seen (else 0).
vec3 estimate(uint visibility_first, bool catcher, Lobes s, LobeChoice choice, View view, vec3 fx, vec3 fy, vec3 fn, uint cluster,
              vec2 u_env, vec2 u_brdf, out vec3 open) {
    vec3 result = vec3(0.0);
    open = vec3(0.0);

    vec4 texel;
    vec3 d = sample_environment(cluster, u_env, texel);
    vec3 l = vec3(dot(d, fx), dot(d, fy), dot(d, fn));
    if (l.z > 0.0 && texel.a > 0.0) {
        bool lit = seen(visibility_first, d);
        if (lit || catcher) {
            HalfVector hv = make_half_vector(s, l, view.v);
            vec3 f = disney_brdf(s, view, l, hv);
            float pdf_brdf = brdf_pdf(choice, view, l, hv);
            vec3 light = f * (l.z * mis_weight_over_pdf(texel.a, pdf_brdf)) * texel.rgb;
            result += lit ? light : vec3(0.0);
            open += light;
        }
    }

    l = sample_brdf(s, choice, view, u_brdf);
    if (l.z > 0.0) {
        HalfVector hv = make_half_vector(s, l, view.v);
        float pdf_brdf = brdf_pdf(choice, view, l, hv);
        d = normalize(l.x * fx + l.y * fy + l.z * fn);
        bool lit = pdf_brdf > 0.0 && seen(visibility_first, d);
        if (lit || (catcher && pdf_brdf > 0.0)) {
            texel = environment_texel(cluster, env_direction_to_uv(d));
            vec3 f = disney_brdf(s, view, l, hv);
            vec3 light = f * (l.z * mis_weight_over_pdf(pdf_brdf, texel.a)) * texel.rgb;
            result += lit ? light : vec3(0.0);
            open += light;
        }
    }
    open *= pass.intensity;
    return result * pass.intensity;
}

// Adds one sample's light, whose BRDF lobes are b and MIS weight over pdf w, to `result` and
// each lobe's share to `shares`.
void add_lobes(Lobes s, BrdfLobes b, float w, vec3 radiance, inout vec3 result, inout vec3 shares[4]) {
    float diffuse_weight = 1.0 - s.metallic;
    result += lobes_total(s, b) * w * radiance;
    shares[LOBE_DIFFUSE] += b.diffuse * diffuse_weight * w * radiance;
    shares[LOBE_SPECULAR] += b.specular * w * radiance;
    shares[LOBE_CLEARCOAT] += vec3(b.clearcoat) * w * radiance;
    shares[LOBE_SHEEN] += b.sheen * diffuse_weight * w * radiance;
}

// The same estimate as `estimate`, bit for bit, with each lobe's share of it beside: the
// lobes' sum is the total up to float rounding. A catcher's shares are those of the total.
vec3 estimate_lobes(uint visibility_first, bool catcher, Lobes s, LobeChoice choice, View view, vec3 fx, vec3 fy, vec3 fn, uint cluster,
                    vec2 u_env, vec2 u_brdf, out vec3 open, out vec3 shares[4]) {
    vec3 result = vec3(0.0);
    open = vec3(0.0);
    for (int k = 0; k < 4; k++) {
        shares[k] = vec3(0.0);
    }

    vec4 texel;
    vec3 d = sample_environment(cluster, u_env, texel);
    vec3 l = vec3(dot(d, fx), dot(d, fy), dot(d, fn));
    if (l.z > 0.0 && texel.a > 0.0) {
        bool lit = seen(visibility_first, d);
        if (lit || catcher) {
            HalfVector hv = make_half_vector(s, l, view.v);
            BrdfLobes b = disney_lobes(s, view, l, hv);
            float pdf_brdf = brdf_pdf(choice, view, l, hv);
            float w = l.z * mis_weight_over_pdf(texel.a, pdf_brdf);
            if (lit) {
                add_lobes(s, b, w, texel.rgb, result, shares);
            }
            if (catcher) {
                open += lobes_total(s, b) * w * texel.rgb;
            }
        }
    }

    l = sample_brdf(s, choice, view, u_brdf);
    if (l.z > 0.0) {
        HalfVector hv = make_half_vector(s, l, view.v);
        float pdf_brdf = brdf_pdf(choice, view, l, hv);
        d = normalize(l.x * fx + l.y * fy + l.z * fn);
        bool lit = pdf_brdf > 0.0 && seen(visibility_first, d);
        if (lit || (catcher && pdf_brdf > 0.0)) {
            texel = environment_texel(cluster, env_direction_to_uv(d));
            BrdfLobes b = disney_lobes(s, view, l, hv);
            float w = l.z * mis_weight_over_pdf(pdf_brdf, texel.a);
            if (lit) {
                add_lobes(s, b, w, texel.rgb, result, shares);
            }
            if (catcher) {
                open += lobes_total(s, b) * w * texel.rgb;
            }
        }
    }
    for (int k = 0; k < 4; k++) {
        shares[k] *= pass.intensity;
    }
    open *= pass.intensity;
    return result * pass.intensity;
}

// Whether the pixel's object catches shadows (0 on uncovered pixels, whose material is clear).
bool catches_shadows(ivec2 pixel) {
    return SHADOW_CATCHER != 0u && imageLoad(resolved, ivec3(pixel, 4)).a != 0.0;
}

// Bilinear radiance of the backdrop image at uv, as env_background reads the environment.
vec3 backdrop_background(vec2 uv) {
    ivec2 xs;
    ivec2 ys;
    vec2 t;
    env_bilinear_taps(uv, imageSize(backdrop), xs, ys, t);
    vec3 a = imageLoad(backdrop, ivec2(xs.x, ys.x)).rgb;
    vec3 b = imageLoad(backdrop, ivec2(xs.y, ys.x)).rgb;
    vec3 c = imageLoad(backdrop, ivec2(xs.x, ys.y)).rgb;
    vec3 d = imageLoad(backdrop, ivec2(xs.y, ys.y)).rgb;
    return mix(mix(a, b, t.x), mix(c, d, t.x), t.y);
}

// The background behind `pixel`, where the surface does not cover it all or catches shadows.
void write_background(ivec2 pixel) {
    float coverage = imageLoad(surface, ivec3(pixel, 0)).w;
    bool catcher = catches_shadows(pixel);
    vec3 behind = vec3(0.0);
    if (pass.background != BACKGROUND_NONE && (coverage < 1.0 || catcher)) {
        vec3 view = imageLoad(surface, ivec3(pixel, 1)).xyz;
        vec2 uv = env_direction_to_uv(to_environment(-view));
        if (pass.background == BACKGROUND_COLOUR) {
            behind = vec3(pass.background_r, pass.background_g, pass.background_b);
        } else if (pass.background == BACKGROUND_IMAGE) {
            behind = pass.intensity * backdrop_background(uv);
        } else {
            behind = pass.intensity * env_background(uv);
        }
    }
    imageStore(background, pixel, vec4(behind, catcher ? 1.0 : 0.0));
}

// Whether the stop test runs after `n` samples: at min_samples, then at each power of two,
// where the Sobol points of a pixel are best stratified.
bool checkpoint(uint n) {
    return n == pass.min_samples || (n > pass.min_samples && (n & (n - 1u)) == 0u);
}

// Whether the standard error of the mean luminance, from the sums of the estimates and of their
// squared luminances (as Renderer::read_variance computes it), is below noise_threshold times
// the mean. min_samples >= 2, so n > 1.
// Both sums are in MOMENT_SCALE units, as the test is the same in any.
bool converged(vec3 total, float squares, uint n) {
    float sum = luminance(total) * MOMENT_SCALE;
    float mean = sum / float(n);
    float variance = max(squares - sum * mean, 0.0) / (float(n) * float(n - 1u));
    return sqrt(variance) < pass.noise_threshold * max(mean, BLACK * MOMENT_SCALE);
}

// Adds samples first_sample .. first_sample + sample_count - 1 to a covered pixel.
void relight(ivec2 pixel, ivec2 size) {
    bool adaptive = VARIANCE_AOV != 0u && pass.noise_threshold > 0.0;
    bool restart = pass.first_sample == 0u;
    vec4 moment = (VARIANCE_AOV == 0u || restart) ? vec4(0.0) : imageLoad(moments, pixel);
    if (adaptive && moment.g != 0.0) {
        return;  // stopped at an earlier test
    }
    vec4 normal_coverage = imageLoad(surface, ivec3(pixel, 0));
    vec3 view = imageLoad(surface, ivec3(pixel, 1)).xyz;
    vec3 n = normal_coverage.xyz;
    vec3 t = imageLoad(surface, ivec3(pixel, 2)).xyz;
    vec3 b = cross(n, t);
    vec3 v = vec3(dot(view, t), dot(view, b), dot(view, n));
    vec4 sum = restart ? vec4(0.0) : imageLoad(accumulation, pixel);
    bool catcher = catches_shadows(pixel);
    vec3 open_sum = (SHADOW_CATCHER == 0u || restart) ? vec3(0.0) : imageLoad(unshadowed, pixel).rgb;
    float squares = moment.r;
    vec3 lobes[4];
    for (int k = 0; k < 4; k++) {
        lobes[k] = (LOBE_AOVS == 0u || restart) ? vec3(0.0) : imageLoad(lobe_sums, ivec3(pixel, k)).rgb;
    }
    // Emission is the surface's own radiance: not scaled by the environment's intensity, and
    // seen even where the shading normal faces away. It is added with each sample, so that the
    // sum keeps its sample order.
    vec3 emission = imageLoad(resolved, ivec3(pixel, 4)).rgb;
    uint end_sample = pass.first_sample + pass.sample_count;
    bool stopped = false;
    // Facing away from the eye (a shading normal can), the BRDF is zero: only emission.
    if (v.z <= 0.0) {
        for (uint i = pass.first_sample; i < end_sample; i++) {
            sum.rgb += emission;
            open_sum += emission;
            if (VARIANCE_AOV != 0u) {
                float y = luminance(emission) * MOMENT_SCALE;
                squares += y * y;
            }
            if (adaptive && checkpoint(i + 1u) && converged(sum.rgb, squares, i + 1u)) {
                end_sample = i + 1u;
                stopped = true;
                break;
            }
        }
    } else {
        Material m = unpack_material(imageLoad(resolved, ivec3(pixel, 0)), imageLoad(resolved, ivec3(pixel, 1)),
                                     imageLoad(resolved, ivec3(pixel, 2)), imageLoad(resolved, ivec3(pixel, 3)));
        Lobes s = make_lobes(m);
        View view_terms = make_view(s, v);
        LobeChoice choice = choose_lobes(s, view_terms);
        vec3 fx = to_environment(t);
        vec3 fy = to_environment(b);
        vec3 fn = to_environment(n);
        uint cluster = environment_cluster(fn);
        uint pixel_index = uint(pixel.y) * uint(size.x) + uint(pixel.x);
        uint pixel_seed = hash_combine(hash_u32(pass.seed), pixel_index);
        uint visibility_first = pixel_index * VISIBILITY_TEXELS;
        uint env_seed = hash_combine(pixel_seed, 0x454e56u);
        uint brdf_seed = hash_combine(pixel_seed, 0x425244u);
        for (uint i = pass.first_sample; i < end_sample; i++) {
            vec3 x;
            vec3 open;
            if (LOBE_AOVS != 0u) {
                vec3 shares[4];
                x = emission + estimate_lobes(visibility_first, catcher, s, choice, view_terms, fx, fy, fn, cluster,
                                              sobol_owen_2d(i, env_seed), sobol_owen_2d(i, brdf_seed), open, shares);
                for (int k = 0; k < 4; k++) {
                    lobes[k] += shares[k];
                }
            } else {
                x = emission + estimate(visibility_first, catcher, s, choice, view_terms, fx, fy, fn, cluster,
                                        sobol_owen_2d(i, env_seed), sobol_owen_2d(i, brdf_seed), open);
            }
            sum.rgb += x;
            open_sum += catcher ? emission + open : x;
            if (VARIANCE_AOV != 0u) {
                float y = luminance(x) * MOMENT_SCALE;
                squares += y * y;
            }
            if (adaptive && checkpoint(i + 1u) && converged(sum.rgb, squares, i + 1u)) {
                end_sample = i + 1u;
                stopped = true;
                break;
            }
        }
    }
    if (LOBE_AOVS != 0u) {
        for (int k = 0; k < 4; k++) {
            imageStore(lobe_sums, ivec3(pixel, k), vec4(lobes[k], 0.0));
        }
    }
    if (VARIANCE_AOV != 0u) {
        imageStore(moments, pixel, vec4(squares, stopped ? 1.0 : 0.0, 0.0, 0.0));
    }
    sum.a = float(end_sample);
    imageStore(accumulation, pixel, sum);
    if (SHADOW_CATCHER != 0u) {
        imageStore(unshadowed, pixel, vec4(open_sum, 0.0));
    }
    if (adaptive && !stopped && (pass.source == SOURCE_COVERED || pass.source == SOURCE_ACTIVE)) {
        uint slot = active_rows.data[pixel.y] + atomicAdd(still_active.rows[pixel.y], 1u);
        uint packed = uint(pixel.x) | (uint(pixel.y) << 16);
        imageStore(active_lists, ivec3(list_texel(slot, size.x), int(1u - pass.list_in)), uvec4(packed));
    }
}

void main() {
    uint i = pass.first + gl_GlobalInvocationID.x;
    if (i >= pass.end) {
        return;
    }
    ivec2 size = imageSize(accumulation);
    ivec2 pixel;
    if (BACKGROUND_ONLY != 0u || pass.source == SOURCE_BACKGROUND) {
        write_background(list_texel(i, size.x));
        return;
    } else if (pass.source == SOURCE_PREVIEW) {
        int block = int(max(pass.block, 1u));
        pixel = list_texel(i, (size.x + block - 1) / block) * block;
        if (imageLoad(surface, ivec3(pixel, 0)).w <= 0.0) {
            return;
        }
    } else if (pass.source == SOURCE_ACTIVE) {
        // Entry i stands in row y's place in the covered list; the row's active pixels fill the
        // start of it.
        uint y = uint(unpack_pixel(imageLoad(covered, list_texel(i, size.x)).r).y);
        if (i - active_rows.data[y] >= active_rows.data[uint(size.y) + 1u + y]) {
            return;
        }
        pixel = unpack_pixel(imageLoad(active_lists, ivec3(list_texel(i, size.x), int(pass.list_in))).r);
    } else if (pass.source == SOURCE_RESTARTED) {
        pixel = unpack_pixel(imageLoad(restarted, list_texel(i, size.x)).r);
    } else {
        pixel = unpack_pixel(imageLoad(covered, list_texel(i, size.x)).r);
    }
    relight(pixel, size);
}
