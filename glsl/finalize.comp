#version 460
// Turns the running sums of a band of rows into the image (docs/formats.md#output): each pixel's mean
// estimate, composited over the background by coverage, as linear radiance (for EXR); and, through exposure 2^EV, the tone
// map and the sRGB OETF, as 8-bit display pixels (for PNG and the viewer).
//
// With the background on, both are opaque. With it off, the radiance is premultiplied by coverage
// with alpha = coverage, as compositors expect of EXR, and the display pixels carry straight
// alpha: the surface's own colour, tone-mapped, with alpha = coverage.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 16, local_size_y = 16) in;

#include "tonemap.glsl"

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D accumulation;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D background;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2DArray surface;
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D radiance;
layout(set = 0, binding = 4, rgba8) uniform writeonly image2D display;

layout(push_constant) uniform Finalize {
    float exposure_scale;  // 2^EV
    uint tonemap;
    uint show_background;
    uint first_row;        // the band this dispatch covers: rows first_row .. end_row - 1
    uint end_row;
} settings;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.x, gl_GlobalInvocationID.y + settings.first_row);
    ivec2 size = imageSize(accumulation);
    if (pixel.x >= size.x || pixel.y >= int(settings.end_row)) {
        return;
    }
    float coverage = imageLoad(surface, ivec3(pixel, 0)).w;
    // Uncovered pixels never write their sums, so those are not read.
    vec4 sum = coverage > 0.0 ? imageLoad(accumulation, pixel) : vec4(0.0);
    vec3 surface_radiance = sum.a > 0.0 ? sum.rgb / sum.a : vec3(0.0);
    vec4 linear;
    vec4 shown;
    if (settings.show_background != 0u) {
        vec3 composite = coverage * surface_radiance + (1.0 - coverage) * imageLoad(background, pixel).rgb;
        linear = vec4(composite, 1.0);
        shown = vec4(composite, 1.0);
    } else {
        linear = vec4(coverage * surface_radiance, coverage);
        shown = vec4(surface_radiance, coverage);
    }
    imageStore(radiance, pixel, linear);
    vec3 color = srgb_encode(apply_tonemap(shown.rgb * settings.exposure_scale, settings.tonemap));
    imageStore(display, pixel, vec4(color, shown.a));
}
