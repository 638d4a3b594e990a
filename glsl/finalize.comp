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
//
// A shadow catcher's pixels (flagged in the background's alpha) show the background darkened
// by the share of their light that the visibility blocks, their sums over their unshadowed
// sums, per channel (docs/formats.md#shadow-catchers); with the background off, a black shadow
// whose alpha is 1 minus that share's mean, as Cycles' shadow catcher gives.
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
// Every covered pixel's sum of unshadowed estimates (rgb) where some object catches shadows; a
// placeholder, never read, where none does.
layout(set = 0, binding = 6, rgba32f) uniform readonly image2D unshadowed;

layout(push_constant) uniform Finalize {
    float exposure_scale;  // 2^EV
    uint tonemap;
    uint show_background;
    uint first_row;        // the band this dispatch covers: rows first_row .. end_row - 1
    uint end_row;
    uint block;            // 1: the sums are every pixel's; > 1: a preview, one sample per block
} settings;

// The mean estimate of a pixel's sums (0 without samples).
vec3 mean_of(vec4 sum) {
    return sum.a > 0.0 ? sum.rgb / sum.a : vec3(0.0);
}

// The preview's surface radiance at `pixel`: the relit block corners within `reach` pixels,
// weighted by a tent of that radius (bilinear at reach = block), that are covered and, with
// `same_object`, show the pixel's object. The weight is 0 when none qualifies. For a shadow
// catcher, `open` is the same of the unshadowed sums.
vec4 interpolate(ivec2 pixel, ivec2 size, int block, int reach, bool same_object, bool catcher, out vec3 open) {
    uint id = imageLoad(object_ids, pixel).r;
    ivec2 first = ((pixel - ivec2(reach - 1)) + ivec2(block - 1)) / block;  // ceil, for x >= 0
    first = max(first, ivec2(0));
    vec3 total = vec3(0.0);
    vec3 open_total = vec3(0.0);
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
                if (catcher) {
                    open_total += w * imageLoad(unshadowed, corner).rgb / sum.a;
                }
                weight += w;
            }
        }
    }
    open = weight > 0.0 ? open_total / weight : vec3(0.0);
    return vec4(weight > 0.0 ? total / weight : vec3(0.0), weight);
}

// The preview's surface radiance: the same object's corners nearby, else farther, else any
// covered corner (a sliver too thin for the blocks); and, for a catcher, the unshadowed.
vec3 preview_radiance(ivec2 pixel, ivec2 size, int block, bool catcher, out vec3 open) {
    vec4 r = interpolate(pixel, size, block, block, true, catcher, open);
    if (r.a == 0.0) {
        r = interpolate(pixel, size, block, 2 * block, true, catcher, open);
    }
    if (r.a == 0.0) {
        r = interpolate(pixel, size, block, 2 * block, false, catcher, open);
    }
    return r.rgb;
}

// The share of a catcher's light that reaches it, per channel: 1 where a channel has no light
// even unshadowed, as Cycles divides.
vec3 shadow_share(vec3 shadowed, vec3 open) {
    return vec3(open.r != 0.0 ? shadowed.r / open.r : 1.0, open.g != 0.0 ? shadowed.g / open.g : 1.0,
                open.b != 0.0 ? shadowed.b / open.b : 1.0);
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.x, gl_GlobalInvocationID.y + settings.first_row);
    ivec2 size = imageSize(accumulation);
    if (pixel.x >= size.x || pixel.y >= int(settings.end_row)) {
        return;
    }
    float coverage = imageLoad(surface, ivec3(pixel, 0)).w;
    vec4 behind = imageLoad(background, pixel);
    bool catcher = behind.a != 0.0;
    // Uncovered pixels never write their sums, so those are not read.
    vec3 surface_radiance = vec3(0.0);
    vec3 open = vec3(0.0);
    if (PREVIEW != 0u && settings.block > 1u) {
        if (coverage > 0.0) {
            surface_radiance = preview_radiance(pixel, size, int(settings.block), catcher, open);
        }
    } else {
        vec4 sum = coverage > 0.0 ? imageLoad(accumulation, pixel) : vec4(0.0);
        surface_radiance = mean_of(sum);
        if (catcher) {
            open = mean_of(vec4(imageLoad(unshadowed, pixel).rgb, sum.a));
        }
    }
    vec4 linear;
    vec4 shown;
    if (catcher) {
        vec3 share = shadow_share(surface_radiance, open);
        if (settings.show_background != 0u) {
            vec3 composite = coverage * share * behind.rgb + (1.0 - coverage) * behind.rgb;
            linear = vec4(composite, 1.0);
        } else {
            linear = vec4(0.0, 0.0, 0.0, coverage * (1.0 - (share.r + share.g + share.b) / 3.0));
        }
        shown = linear;
    } else if (settings.show_background != 0u) {
        vec3 composite = coverage * surface_radiance + (1.0 - coverage) * behind.rgb;
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
