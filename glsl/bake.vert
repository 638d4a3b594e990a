#version 460
// The bake's vertex stage: world-space vertices (flattened and transformed on the CPU) to clip
// space, and each texture slot's texcoords (KHR_texture_transform applied). Everything else passes
// through to the fragment stage.
#extension GL_GOOGLE_include_directive : require

#include "bake_draw.glsl"
#include "bake_material.glsl"

layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec4 tangent;     // xyz, w = bitangent sign (glTF)
layout(location = 3) in vec2 uv0;
layout(location = 4) in vec2 uv1;
layout(location = 5) in vec4 color;       // COLOR_0, or white

layout(location = 0) out vec3 world_position;
layout(location = 1) out vec3 world_normal;
layout(location = 2) out vec4 world_tangent;
layout(location = 3) out vec4 out_color;
layout(location = SLOT_MASK) flat out uint slot_mask;
layout(location = SLOT_TEXCOORDS) out vec4 slot_uv[SLOT_PAIRS];
// The triangle's index in the vertex buffer: draws are not indexed, three vertices a triangle.
layout(location = TRIANGLE_LOCATION) flat out uint triangle;

void main() {
    world_position = position;
    triangle = uint(gl_VertexIndex) / 3u;
    world_normal = normal;
    world_tangent = tangent;
    out_color = color;
    slot_mask = 0u;
    for (uint pair = 0u; pair < SLOT_PAIRS; pair++) {
        vec2 even = slot_texcoord(2u * pair, uv0, uv1);
        vec2 odd = 2u * pair + 1u < SLOTS ? slot_texcoord(2u * pair + 1u, uv0, uv1) : vec2(0.0);
        slot_uv[pair] = vec4(even, odd);
    }
    for (uint slot = 0u; slot < SLOTS; slot++) {
        slot_mask |= MATERIAL.slots[slot].present != 0u ? 1u << slot : 0u;
    }
    gl_Position = draw.view_projection * vec4(position, 1.0);
}
