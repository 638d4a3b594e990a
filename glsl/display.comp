#version 460
// Turns the running sums into display pixels: the mean, exposure 2^EV, the tone map, then the
// sRGB OETF (LOOKDEV.md §6). Without a background the colour is un-premultiplied by coverage
// and alpha is the coverage, so PNGs composite with straight alpha.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 16, local_size_y = 16) in;

#include "tonemap.glsl"

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D accumulation;
layout(set = 0, binding = 1, rgba8) uniform writeonly image2D display;

layout(push_constant) uniform Display {
    float inverse_sample_count;
    float exposure_scale;  // 2^EV
    uint tonemap;
    uint straight_alpha;   // 1 when the background is off
} settings;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(accumulation);
    if (pixel.x >= size.x || pixel.y >= size.y) {
        return;
    }
    vec4 mean = imageLoad(accumulation, pixel) * settings.inverse_sample_count;
    vec3 color = mean.rgb;
    float alpha = 1.0;
    if (settings.straight_alpha != 0u) {
        alpha = clamp(mean.a, 0.0, 1.0);
        color = alpha > 0.0 ? color / alpha : vec3(0.0);
    }
    color = srgb_encode(apply_tonemap(color * settings.exposure_scale, settings.tonemap));
    imageStore(display, pixel, vec4(color, alpha));
}
