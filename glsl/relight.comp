#version 460
// One progressive pass of image-based relighting over a band of rows: for each covered pixel and
// each sample index, one environment sample and one BRDF sample, combined with the power heuristic
// (docs/shading.md#sampling). The running float32 sum of the estimates is accumulated in sample order, so
// any split into passes and bands gives the same bits. Coverage and the background are composited
// by finalize.comp, so background pixels cost nothing after the first pass of an accumulation.
// Every pixel of a band has the same number of samples so far; keeping that number (and so the
// branches below) uniform across the dispatch matters on SIMD CPU drivers.
//
// With block > 1 (the viewer's preview after a change) each invocation stands for a block × block
// block of pixels: it writes the background of all of them and relights only the block's top-left
// pixel, with the same sample 0 a full pass gives it, which overwrites it identically later.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 16, local_size_y = 16) in;

// The energy-compensation table of the model (a placeholder when compensation is off).
#define ENERGY_TABLE_SET 0
#define ENERGY_TABLE_BINDING 4

// What is accumulated beside the total, only when asked for (docs/formats.md#aovs): each
// lobe's share of every estimate, and the sum of each estimate's squared luminance. Off, the
// code below is specialised away and the images bound are 1×1 placeholders.
layout(constant_id = 6) const uint LOBE_AOVS = 0u;
layout(constant_id = 7) const uint VARIANCE_AOV = 0u;

#include "common.glsl"
#include "material.glsl"
#include "brdf.glsl"
#include "sampling.glsl"
#include "sobol.glsl"
#include "environment.glsl"

// Layer 0: N.xyz and coverage A; layer 1: V.xyz; layer 2: T.xyz (unit, orthogonal to N).
layout(set = 0, binding = 0, rgba32f) uniform readonly image2DArray surface;
// The resolved material: four layers as material.glsl unpacks them, then emission (rgb).
layout(set = 0, binding = 1, rgba32f) uniform readonly image2DArray resolved;
// Covered pixels: the running sum of the radiance estimates (rgb) and their number (a).
// Uncovered pixels are never written.
layout(set = 0, binding = 2, rgba32f) uniform image2D accumulation;
// The environment behind each pixel (rgb), written by the first pass of an accumulation.
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D background;
// With LOBE_AOVS, the running sums of each lobe's share: layers diffuse (with subsurface),
// specular, clearcoat and sheen, all weighted as they enter the total.
layout(set = 0, binding = 5, rgba32f) uniform image2DArray lobe_sums;
// With VARIANCE_AOV, the running sum of each estimate's squared luminance (r).
layout(set = 0, binding = 6, rgba32f) uniform image2D moments;

const int LOBE_DIFFUSE = 0;
const int LOBE_SPECULAR = 1;
const int LOBE_CLEARCOAT = 2;
const int LOBE_SHEEN = 3;

layout(push_constant) uniform Pass {
    uint first_sample;     // samples the band's pixels have; 0 starts a new accumulation
    uint sample_count;
    uint seed;
    uint show_background;
    float cos_rotation;
    float sin_rotation;
    float intensity;
    uint first_row;        // the band this dispatch covers: rows first_row .. end_row - 1
    uint end_row;
    uint block;            // pixels per side of the block one invocation covers: 1 for a full pass
} pass;

// R_y(−rotation)·d: world to environment space.
vec3 to_environment(vec3 d) {
    return vec3(d.x * pass.cos_rotation - d.z * pass.sin_rotation, d.y,
                d.x * pass.sin_rotation + d.z * pass.cos_rotation);
}

// One MIS estimate of reflected radiance toward the view; the frame (fx, fy, fn) is the shading
// frame expressed in environment space, so no per-sample rotation is needed.
vec3 estimate(Lobes s, LobeChoice choice, View view, vec3 fx, vec3 fy, vec3 fn, vec2 u_env, vec2 u_brdf) {
    vec3 result = vec3(0.0);

    vec4 texel;
    vec3 d = env_sample(u_env, texel);
    vec3 l = vec3(dot(d, fx), dot(d, fy), dot(d, fn));
    if (l.z > 0.0 && texel.a > 0.0) {
        HalfVector hv = make_half_vector(s, l, view.v);
        vec3 f = disney_brdf(s, view, l, hv);
        float pdf_brdf = brdf_pdf(choice, view, l, hv);
        result += f * (l.z * mis_weight_over_pdf(texel.a, pdf_brdf)) * texel.rgb;
    }

    l = sample_brdf(s, choice, view, u_brdf);
    if (l.z > 0.0) {
        HalfVector hv = make_half_vector(s, l, view.v);
        float pdf_brdf = brdf_pdf(choice, view, l, hv);
        if (pdf_brdf > 0.0) {
            d = normalize(l.x * fx + l.y * fy + l.z * fn);
            texel = env_texel(env_direction_to_uv(d));
            vec3 f = disney_brdf(s, view, l, hv);
            result += f * (l.z * mis_weight_over_pdf(pdf_brdf, texel.a)) * texel.rgb;
        }
    }
    return result * pass.intensity;
}

// The same estimate as `estimate`, bit for bit, with each lobe's share of it beside: the
// lobes' sum is the total up to float rounding.
vec3 estimate_lobes(Lobes s, LobeChoice choice, View view, vec3 fx, vec3 fy, vec3 fn, vec2 u_env, vec2 u_brdf,
                    out vec3 shares[4]) {
    vec3 result = vec3(0.0);
    for (int k = 0; k < 4; k++) {
        shares[k] = vec3(0.0);
    }
    float diffuse_weight = 1.0 - s.metallic;

    vec4 texel;
    vec3 d = env_sample(u_env, texel);
    vec3 l = vec3(dot(d, fx), dot(d, fy), dot(d, fn));
    if (l.z > 0.0 && texel.a > 0.0) {
        HalfVector hv = make_half_vector(s, l, view.v);
        BrdfLobes b = disney_lobes(s, view, l, hv);
        float pdf_brdf = brdf_pdf(choice, view, l, hv);
        float w = l.z * mis_weight_over_pdf(texel.a, pdf_brdf);
        result += lobes_total(s, b) * w * texel.rgb;
        shares[LOBE_DIFFUSE] += b.diffuse * diffuse_weight * w * texel.rgb;
        shares[LOBE_SPECULAR] += b.specular * w * texel.rgb;
        shares[LOBE_CLEARCOAT] += vec3(b.clearcoat) * w * texel.rgb;
        shares[LOBE_SHEEN] += b.sheen * diffuse_weight * w * texel.rgb;
    }

    l = sample_brdf(s, choice, view, u_brdf);
    if (l.z > 0.0) {
        HalfVector hv = make_half_vector(s, l, view.v);
        float pdf_brdf = brdf_pdf(choice, view, l, hv);
        if (pdf_brdf > 0.0) {
            d = normalize(l.x * fx + l.y * fy + l.z * fn);
            texel = env_texel(env_direction_to_uv(d));
            BrdfLobes b = disney_lobes(s, view, l, hv);
            float w = l.z * mis_weight_over_pdf(pdf_brdf, texel.a);
            result += lobes_total(s, b) * w * texel.rgb;
            shares[LOBE_DIFFUSE] += b.diffuse * diffuse_weight * w * texel.rgb;
            shares[LOBE_SPECULAR] += b.specular * w * texel.rgb;
            shares[LOBE_CLEARCOAT] += vec3(b.clearcoat) * w * texel.rgb;
            shares[LOBE_SHEEN] += b.sheen * diffuse_weight * w * texel.rgb;
        }
    }
    for (int k = 0; k < 4; k++) {
        shares[k] *= pass.intensity;
    }
    return result * pass.intensity;
}

void main() {
    int block = int(max(pass.block, 1u));
    ivec2 pixel = ivec2(gl_GlobalInvocationID.x, gl_GlobalInvocationID.y) * block + ivec2(0, pass.first_row);
    ivec2 size = imageSize(accumulation);
    if (pixel.x >= size.x || pixel.y >= int(pass.end_row)) {
        return;
    }
    vec4 normal_coverage = imageLoad(surface, ivec3(pixel, 0));
    float coverage = normal_coverage.w;
    vec3 view = imageLoad(surface, ivec3(pixel, 1)).xyz;
    if (pass.first_sample == 0u) {
        // The same for every pass, so computed once per accumulation.
        for (int dy = 0; dy < block; dy++) {
            for (int dx = 0; dx < block; dx++) {
                ivec2 q = pixel + ivec2(dx, dy);
                if (q.x >= size.x || q.y >= int(pass.end_row)) {
                    continue;
                }
                float q_coverage = imageLoad(surface, ivec3(q, 0)).w;
                vec3 behind = vec3(0.0);
                if (pass.show_background != 0u && q_coverage < 1.0) {
                    vec3 q_view = imageLoad(surface, ivec3(q, 1)).xyz;
                    behind = pass.intensity * env_background(env_direction_to_uv(to_environment(-q_view)));
                }
                imageStore(background, q, vec4(behind, 0.0));
            }
        }
    }
    if (coverage <= 0.0) {
        return;
    }

    vec3 n = normal_coverage.xyz;
    vec3 t = imageLoad(surface, ivec3(pixel, 2)).xyz;
    vec3 b = cross(n, t);
    vec3 v = vec3(dot(view, t), dot(view, b), dot(view, n));
    vec4 sum = pass.first_sample == 0u ? vec4(0.0) : imageLoad(accumulation, pixel);
    // Emission is the surface's own radiance: not scaled by the environment's intensity, and
    // seen even where the shading normal faces away. It is added with each sample, so that the
    // sum keeps its sample order.
    vec3 emission = imageLoad(resolved, ivec3(pixel, 4)).rgb;
    uint end_sample = pass.first_sample + pass.sample_count;
    // Facing away from the eye (a shading normal can), the BRDF is zero: only emission.
    if (v.z <= 0.0) {
        for (uint i = pass.first_sample; i < end_sample; i++) {
            sum.rgb += emission;
        }
        if (LOBE_AOVS != 0u && pass.first_sample == 0u) {
            for (int k = 0; k < 4; k++) {
                imageStore(lobe_sums, ivec3(pixel, k), vec4(0.0));
            }
        }
        if (VARIANCE_AOV != 0u) {
            float y = luminance(emission);
            float squares = pass.first_sample == 0u ? 0.0 : imageLoad(moments, pixel).r;
            imageStore(moments, pixel, vec4(squares + float(pass.sample_count) * y * y, 0.0, 0.0, 0.0));
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
        uint pixel_seed = hash_combine(hash_u32(pass.seed), uint(pixel.y) * uint(size.x) + uint(pixel.x));
        uint env_seed = hash_combine(pixel_seed, 0x454e56u);
        uint brdf_seed = hash_combine(pixel_seed, 0x425244u);
        if (LOBE_AOVS == 0u && VARIANCE_AOV == 0u) {
            for (uint i = pass.first_sample; i < end_sample; i++) {
                sum.rgb += emission + estimate(s, choice, view_terms, fx, fy, fn, sobol_owen_2d(i, env_seed),
                                               sobol_owen_2d(i, brdf_seed));
            }
        } else {
            vec3 lobes[4];
            for (int k = 0; k < 4; k++) {
                lobes[k] = (LOBE_AOVS == 0u || pass.first_sample == 0u) ? vec3(0.0)
                                                                          : imageLoad(lobe_sums, ivec3(pixel, k)).rgb;
            }
            float squares = (VARIANCE_AOV == 0u || pass.first_sample == 0u) ? 0.0 : imageLoad(moments, pixel).r;
            for (uint i = pass.first_sample; i < end_sample; i++) {
                vec3 shares[4];
                vec3 x = emission + estimate_lobes(s, choice, view_terms, fx, fy, fn, sobol_owen_2d(i, env_seed),
                                                   sobol_owen_2d(i, brdf_seed), shares);
                sum.rgb += x;
                for (int k = 0; k < 4; k++) {
                    lobes[k] += shares[k];
                }
                float y = luminance(x);
                squares += y * y;
            }
            if (LOBE_AOVS != 0u) {
                for (int k = 0; k < 4; k++) {
                    imageStore(lobe_sums, ivec3(pixel, k), vec4(lobes[k], 0.0));
                }
            }
            if (VARIANCE_AOV != 0u) {
                imageStore(moments, pixel, vec4(squares, 0.0, 0.0, 0.0));
            }
        }
    }
    sum.a = float(end_sample);
    imageStore(accumulation, pixel, sum);
}
