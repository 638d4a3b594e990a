#version 460
// Turns the running sums of a band of rows into the image (docs/formats.md#output): each pixel's mean
// estimate, composited over the background by coverage, as linear radiance (for EXR); and, through exposure 2^EV, the tone
// map and the sRGB OETF, as 8-bit display pixels (for PNG and the viewer).
//
// With the background on, both are opaque. With it off, the radiance is premultiplied by coverage
// with alpha = coverage, as compositors expect of EXR, and the display pixels carry straight
// alpha: the surface's own colour, tone-mapped, with alpha = coverage.
//
// With block > 1, the rows are the viewer's preview after a change: relight.comp has relit only
// each block's top-left pixel, once. Each pixel's surface radiance is then interpolated
// bilinearly between the nearest of those that show its own object (object ids keep one
// object's colour from bleeding into its neighbour's), over its own coverage and background.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 16, local_size_y = 16) in;

// Whether the preview's interpolation is compiled in: a SIMD CPU driver runs a branch no lane
// takes, so without a preview it costs about a third of the pass.
layout(constant_id = 0) const uint PREVIEW = 1u;

#include "tonemap.glsl"

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D accumulation;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D background;
layout(set = 0, binding = 2, rgba32f) uniform readonly image2DArray surface;
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D radiance;
layout(set = 0, binding = 4, rgba8) uniform writeonly image2D display;
layout(set = 0, binding = 5, r32ui) uniform readonly uimage2D object_ids;

layout(push_constant) uniform Finalize {
    float exposure_scale;  // 2^EV
    uint tonemap;
    uint show_background;
    uint first_row;        // the band this dispatch covers: rows first_row .. end_row - 1
    uint end_row;
    uint block;            // 1: the sums are every pixel's; > 1: a preview, one sample per block
} settings;

// The preview's surface radiance at `pixel`: the relit block corners within `reach` pixels,
// weighted by a tent of that radius (bilinear at reach = block), that are covered and, with
// `same_object`, show the pixel's object. The weight is 0 when none qualifies.
vec4 interpolate(ivec2 pixel, ivec2 size, int block, int reach, bool same_object) {
    uint id = imageLoad(object_ids, pixel).r;
    ivec2 first = ((pixel - ivec2(reach - 1)) + ivec2(block - 1)) / block;  // ceil, for x >= 0
    first = max(first, ivec2(0));
    vec3 total = vec3(0.0);
    float weight = 0.0;
    for (int cy = first.y; cy * block < pixel.y + reach && cy * block < size.y; cy++) {
        for (int cx = first.x; cx * block < pixel.x + reach && cx * block < size.x; cx++) {
            ivec2 corner = ivec2(cx, cy) * block;
            if (imageLoad(surface, ivec3(corner, 0)).w <= 0.0) {
                continue;  // uncovered corners hold no sums of this accumulation
            }
            if (same_object && imageLoad(object_ids, corner).r != id) {
                continue;
            }
            vec2 d = abs(vec2(corner - pixel)) / float(reach);
            float w = max(1.0 - d.x, 0.0) * max(1.0 - d.y, 0.0);
            vec4 sum = imageLoad(accumulation, corner);
            if (w > 0.0 && sum.a > 0.0) {
                total += w * sum.rgb / sum.a;
                weight += w;
            }
        }
    }
    return vec4(weight > 0.0 ? total / weight : vec3(0.0), weight);
}

// The preview's surface radiance: the same object's corners nearby, else farther, else any
// covered corner (a sliver too thin for the blocks).
vec3 preview_radiance(ivec2 pixel, ivec2 size, int block) {
    vec4 r = interpolate(pixel, size, block, block, true);
    if (r.a == 0.0) {
        r = interpolate(pixel, size, block, 2 * block, true);
    }
    if (r.a == 0.0) {
        r = interpolate(pixel, size, block, 2 * block, false);
    }
    return r.rgb;
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.x, gl_GlobalInvocationID.y + settings.first_row);
    ivec2 size = imageSize(accumulation);
    if (pixel.x >= size.x || pixel.y >= int(settings.end_row)) {
        return;
    }
    float coverage = imageLoad(surface, ivec3(pixel, 0)).w;
    // Uncovered pixels never write their sums, so those are not read.
    vec3 surface_radiance = vec3(0.0);
    if (PREVIEW != 0u && settings.block > 1u) {
        if (coverage > 0.0) {
            surface_radiance = preview_radiance(pixel, size, int(settings.block));
        }
    } else {
        vec4 sum = coverage > 0.0 ? imageLoad(accumulation, pixel) : vec4(0.0);
        surface_radiance = sum.a > 0.0 ? sum.rgb / sum.a : vec3(0.0);
    }
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
