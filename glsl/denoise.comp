#version 460
// One iteration of the viewer's display filter: an edge-avoiding à-trous wavelet filter
// (Dammertz et al. 2010) of the linear radiance, guided by the g-buffer. Each iteration is a
// 5×5 B3-spline kernel with holes `step` pixels apart (1, 2, 4, …), each tap weighted down by
// how far its normal, its base colour and its radiance are from the centre's, and dropped
// outright on another object or where the surface does not cover the whole pixel: noise is
// averaged within a surface and edges stay sharp. Pixels the surface covers only in part (the
// silhouettes, whose radiance holds some background) and background pixels, which are exact
// already, pass through. The last
// iteration also makes display pixels, as finalize.comp does. Only ever shown, never saved.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 16, local_size_y = 16) in;

#include "tonemap.glsl"

// Linear radiance in (finalize.comp's, or the previous iteration's) and out.
layout(set = 0, binding = 0, rgba32f) uniform readonly image2D source;
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D filtered;
// Layer 0: N.xyz and coverage A.
layout(set = 0, binding = 2, rgba32f) uniform readonly image2DArray surface;
layout(set = 0, binding = 3, r32ui) uniform readonly uimage2D object_ids;
// The resolved material; layer 0 holds the base colour (rgb).
layout(set = 0, binding = 4, rgba32f) uniform readonly image2DArray resolved;
// The last iteration's display pixels.
layout(set = 0, binding = 5, rgba8) uniform writeonly image2D display;

layout(push_constant) uniform Denoise {
    int step;              // pixels between the kernel's taps
    float sigma_color;     // radiance difference (tone-compressed) that halves a tap's weight, about
    float sigma_albedo;    // base-colour difference, likewise
    float normal_power;    // exponent of the normals' cosine
    uint last;             // 1: also write the display pixels
    float exposure_scale;  // 2^EV
    uint tonemap;
    uint show_background;
} pass;

const float KERNEL[3] = float[3](3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0);

// Radiance squeezed into [0, 1) per channel, so that a firefly does not stop every tap.
vec3 compress(vec3 c) {
    return c / (1.0 + c);
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(source);
    if (pixel.x >= size.x || pixel.y >= size.y) {
        return;
    }
    vec4 centre = imageLoad(source, pixel);
    vec4 normal_coverage = imageLoad(surface, ivec3(pixel, 0));
    vec4 result = centre;
    if (normal_coverage.w >= 1.0) {
        uint id = imageLoad(object_ids, pixel).r;
        vec3 albedo = imageLoad(resolved, ivec3(pixel, 0)).rgb;
        vec3 colour = compress(centre.rgb);
        vec4 total = vec4(0.0);
        float weight = 0.0;
        for (int j = -2; j <= 2; j++) {
            for (int i = -2; i <= 2; i++) {
                ivec2 q = pixel + ivec2(i, j) * pass.step;
                if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) {
                    continue;
                }
                vec4 q_normal_coverage = imageLoad(surface, ivec3(q, 0));
                if (q_normal_coverage.w < 1.0 || imageLoad(object_ids, q).r != id) {
                    continue;
                }
                vec4 q_value = imageLoad(source, q);
                vec3 dc = compress(q_value.rgb) - colour;
                vec3 da = imageLoad(resolved, ivec3(q, 0)).rgb - albedo;
                float w = KERNEL[abs(i)] * KERNEL[abs(j)]
                    * pow(max(dot(normal_coverage.xyz, q_normal_coverage.xyz), 0.0), pass.normal_power)
                    * exp(-dot(dc, dc) / (pass.sigma_color * pass.sigma_color))
                    * exp(-dot(da, da) / (pass.sigma_albedo * pass.sigma_albedo));
                total += w * q_value;
                weight += w;
            }
        }
        // The centre always counts (weight KERNEL[0]² at least), so weight > 0.
        result = total / weight;
    }
    imageStore(filtered, pixel, result);
    if (pass.last != 0u) {
        // As finalize.comp: opaque with the background on; else premultiplied in, straight out.
        vec3 shown = result.rgb;
        float alpha = 1.0;
        if (pass.show_background == 0u) {
            alpha = result.a;
            shown = alpha > 0.0 ? result.rgb / alpha : vec3(0.0);
        }
        vec3 color = srgb_encode(apply_tonemap(shown * pass.exposure_scale, pass.tonemap));
        imageStore(display, pixel, vec4(color, alpha));
    }
}
