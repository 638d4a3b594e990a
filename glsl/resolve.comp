#version 460
// Resolves each pixel's layer stack into one material, parameter by parameter (README: Formats):
// the bottom layer fills, and each layer above blends in with w = clamp(opacity·m, 0, 1), where m
// is its mask (or 1 − mask when inverted; 1 without a mask). Runs once per edit, not per sample.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 16, local_size_y = 16) in;

// Per pixel: the index of its object's stack.
layout(set = 0, binding = 0, r32ui) uniform readonly uimage2D stack_index;
// The masks the look uses, one layer each.
layout(set = 0, binding = 1, r32f) uniform readonly image2DArray masks;

struct Stack {
    uint first_layer;
    uint layer_count;
    uint pad0;
    uint pad1;
};
layout(set = 0, binding = 2, std430) readonly buffer Stacks {
    Stack stacks[];
};

struct Layer {
    vec4 params[4];   // the layer's own material, as Params::to_gpu lays it out
    int mask;         // layer of `masks`, or −1 for none
    uint invert;
    float opacity;
    uint pad;
};
layout(set = 0, binding = 3, std430) readonly buffer Layers {
    Layer layers[];
};

layout(set = 0, binding = 4, rgba32f) uniform writeonly image2DArray resolved;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(stack_index);
    if (pixel.x >= size.x || pixel.y >= size.y) {
        return;
    }
    Stack stack = stacks[imageLoad(stack_index, pixel).r];
    Layer bottom = layers[stack.first_layer];
    vec4 p[4] = bottom.params;
    for (uint i = 1u; i < stack.layer_count; i++) {
        Layer layer = layers[stack.first_layer + i];
        float m = layer.mask >= 0 ? imageLoad(masks, ivec3(pixel, layer.mask)).r : 1.0;
        float w = clamp(layer.opacity * (layer.invert != 0u ? 1.0 - m : m), 0.0, 1.0);
        for (int k = 0; k < 4; k++) {
            p[k] = p[k] * (1.0 - w) + layer.params[k] * w;
        }
    }
    for (int k = 0; k < 4; k++) {
        imageStore(resolved, ivec3(pixel, k), p[k]);
    }
}
