#version 460
// Resolves each pixel's layer stack into one material, parameter by parameter (docs/formats.md#looks).
// A layer's value at a pixel is its own value times, for each parameter bound to a map, the
// map's value there. The bottom layer fills, and each layer above blends in with
// w = clamp(opacity·m, 0, 1), where m is its mask after its levels (or 1 − that when inverted;
// 1 without a mask). A blurred mask is a channel of its own (gbuffer::blur).
// Runs once per edit, not per sample, over a list of pixels: the covered pixels of the stacks
// that changed since the last resolve (every other stack resolves as it did before; uncovered
// pixels are never relit nor read, as the AOVs and the denoiser weigh by coverage, so they keep
// the image's clear 0). Each pixel whose material comes out different, bit for bit, from what
// `resolved` held is flagged in `changed`, so that an edit restarts only the pixels it changed
// (docs/commands.md#edit-local-re-convergence).
#extension GL_GOOGLE_include_directive : require

#include "pixel_list.glsl"

layout(local_size_x = 64) in;

// Whether some layer binds a map (PackedStacks::binds_maps). Without, the map code is left out:
// a SIMD driver runs its twenty tests per layer and pixel even when none is taken, and keeps
// the material's values in memory around them.
layout(constant_id = 0) const uint MAPS = 1u;

// Per pixel: the index of its object's stack.
layout(set = 0, binding = 0, r32ui) uniform readonly uimage2D stack_index;
// The g-buffer channels the look uses, masks and map channels alike, one layer each.
layout(set = 0, binding = 1, r32f) uniform readonly image2DArray channels;

// The stacks, one texel each (GpuStack): first layer, layer count, whether the object catches
// shadows. Stack s is texel (s % 1024, s / 1024).
layout(set = 0, binding = 2, rgba32ui) uniform readonly uimage2D stacks;
// The layers, twelve texels each (GpuLayer, 192 bytes): the layer's own material (five texels,
// float bits, as Params::to_gpu lays it out); per value, the layer of `channels` it is
// multiplied by, or −1 (five); then its mask (a layer of `channels`, or −1), invert, opacity
// (float bits) and padding; then the mask's levels (float bits: black, white, gamma, and 1 where
// they apply). 64 layers a row. Images rather than storage buffers,
// which a CPU driver reads lane by lane.
layout(set = 0, binding = 3, rgba32ui) uniform readonly uimage2D layers;

uvec4 layer_texel(uint layer, uint k) {
    return imageLoad(layers, ivec2((layer & 63u) * 12u + k, layer >> 6));
}

layout(set = 0, binding = 4, rgba32f) uniform image2DArray resolved;
// The pixels to resolve, as a list (pixel_list.glsl).
layout(set = 0, binding = 5, r32ui) uniform readonly uimage2D pixels;
// One bit per pixel, index y·width + x, cleared before the dispatch: set where a pixel's
// material changed.
layout(set = 0, binding = 6, std430) buffer Changed {
    uint changed[];
};

// The list entries this dispatch resolves: first .. end - 1.
layout(push_constant) uniform Pass {
    uint first;
    uint end;
} pass;

float channel(ivec2 pixel, int layer) {
    return imageLoad(channels, ivec3(pixel, layer)).r;
}

// The mask value after the layer's levels (MaskAdjust::levels): (m − black) / (white − black),
// clamped, to the power 1/gamma. Skipped where they change nothing, so that masks outside
// [0, 1] blend as they always have.
float mask_levels(float m, vec4 levels) {
    if (levels.w == 0.0) {
        return m;
    }
    float t = clamp((m - levels.x) / (levels.y - levels.x), 0.0, 1.0);
    return pow(t, 1.0 / levels.z);
}

// The layer's material at this pixel: its values, each bound one times its map.
void layer_material(uint index, ivec2 pixel, out vec4 p[5]) {
    for (int k = 0; k < 5; k++) {
        p[k] = uintBitsToFloat(layer_texel(index, uint(k)));
        if (MAPS != 0u) {
            ivec4 maps = ivec4(layer_texel(index, 5u + uint(k)));
            for (int c = 0; c < 4; c++) {
                if (maps[c] >= 0) {
                    p[k][c] *= channel(pixel, maps[c]);
                }
            }
        }
    }
}

void main() {
    uint entry = pass.first + gl_GlobalInvocationID.x;
    if (entry >= pass.end) {
        return;
    }
    ivec2 size = imageSize(stack_index);
    ivec2 pixel = unpack_pixel(imageLoad(pixels, list_texel(entry, size.x)).r);
    uint s = imageLoad(stack_index, pixel).r;
    uvec3 stack = imageLoad(stacks, ivec2(s & 1023u, s >> 10)).xyz;  // first layer, layer count, catcher
    vec4 p[5];
    layer_material(stack.x, pixel, p);
    for (uint i = 1u; i < stack.y; i++) {
        uint index = stack.x + i;
        uvec4 blend = layer_texel(index, 10u);  // mask, invert, opacity, pad
        int mask = int(blend.x);
        float m = mask >= 0 ? mask_levels(channel(pixel, mask), uintBitsToFloat(layer_texel(index, 11u))) : 1.0;
        float w = clamp(uintBitsToFloat(blend.z) * (blend.y != 0u ? 1.0 - m : m), 0.0, 1.0);
        vec4 q[5];
        layer_material(index, pixel, q);
        for (int k = 0; k < 5; k++) {
            p[k] = p[k] * (1.0 - w) + q[k] * w;
        }
    }
    // The emission's unused fourth value says whether the object catches shadows.
    p[4].a = stack.z != 0u ? 1.0 : 0.0;
    bool differs = false;
    for (int k = 0; k < 5; k++) {
        uvec4 before = floatBitsToUint(imageLoad(resolved, ivec3(pixel, k)));
        differs = differs || any(notEqual(before, floatBitsToUint(p[k])));
        imageStore(resolved, ivec3(pixel, k), p[k]);
    }
    if (differs) {
        uint index = uint(pixel.y * size.x + pixel.x);
        atomicOr(changed[index >> 5], 1u << (index & 31u));
    }
}
