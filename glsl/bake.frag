#version 460
// The bake's geometry pass: one g-buffer sample of the nearest surface
// (docs/commands.md#lookdev-bake-modelgltfglb---out-gbufferexr).
// Writes the shading normal (the normal map applied through the MikkTSpace tangent frame), the
// tangent (turned by the material's anisotropy rotation), the view vector, the object and
// material, and COLOR_0. Back faces of double-sided materials turn their whole frame around, as
// glTF asks.
#extension GL_GOOGLE_include_directive : require

#include "bake_draw.glsl"
#include "bake_material.glsl"

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec4 world_tangent;
layout(location = 3) in vec4 color;
layout(location = SLOT_MASK) flat in uint slot_mask;
layout(location = SLOT_TEXCOORDS) in vec4 slot_uv[SLOT_PAIRS];
layout(location = TRIANGLE_LOCATION) flat in uint triangle;

// A slot's texel, or white where the slot is empty. Sampled before any fragment is discarded, so
// that every lane of a quad has its derivatives; the branch is the same for the whole draw.
#define SAMPLE(slot) \
    ((slot_mask & (1u << slot)) != 0u ? texture(textures[slot], SLOT_UV(slot_uv, slot), draw.lod_bias) : vec4(1.0))

layout(location = 0) out vec4 out_normal;       // xyz; w = 1 marks a covered sample
layout(location = 1) out vec4 out_tangent;      // xyz; w = bitangent sign
layout(location = 2) out vec4 out_view;         // xyz
layout(location = 3) out uvec2 out_ids;         // object id, material index + 1
layout(location = 4) out vec4 out_color;        // COLOR_0
layout(location = 5) out uvec4 out_surface;     // the world position's bits, the triangle's index

// The least N·V a shading normal keeps.
const float MIN_FACING = 0.01;

void main() {
    vec4 base_color = SAMPLE(SLOT_BASE_COLOR);
    vec3 normal_texel = SAMPLE(SLOT_NORMAL).xyz;
    if (cut_out(base_color, color)) {
        discard;
    }
    vec3 n = normalize(world_normal);
    vec3 t = world_tangent.xyz - n * dot(n, world_tangent.xyz);
    t = dot(t, t) > 1e-12 ? normalize(t) : vec3(0.0);
    float handedness = world_tangent.w < 0.0 ? -1.0 : 1.0;
    vec3 b = handedness * cross(n, t);
    if (!gl_FrontFacing && (MATERIAL.flags & MATERIAL_DOUBLE_SIDED) != 0u) {
        n = -n;
        t = -t;
        b = -b;
    }
    vec3 shading = n;
    if ((slot_mask & (1u << SLOT_NORMAL)) != 0u && dot(t, t) > 0.0) {
        vec3 bump = normal_texel * 2.0 - 1.0;
        bump.xy *= MATERIAL.normal_scale;
        shading = normalize(bump.x * t + bump.y * b + bump.z * n);
    }
    vec3 view = draw.eye.w > 0.5 ? normalize(draw.eye.xyz - world_position) : draw.toward_eye.xyz;
    // A normal map (or smooth normals at a silhouette) can turn the shading normal away from the
    // eye, where the BRDF is zero and the pixel would shade black: bend it back just past the
    // silhouette, toward the eye.
    float facing = dot(shading, view);
    if (facing < MIN_FACING) {
        vec3 across = shading - view * facing;
        shading = dot(across, across) > 1e-12 ? normalize(normalize(across) + MIN_FACING * view) : n;
    }
    // The tangent of the shading frame, turned toward the material's anisotropy direction.
    vec3 anisotropy = MATERIAL.anisotropy_cos * t + MATERIAL.anisotropy_sin * b;
    vec3 tangent = anisotropy - shading * dot(shading, anisotropy);
    tangent = dot(tangent, tangent) > 1e-12 ? normalize(tangent) : vec3(0.0);
    out_normal = vec4(shading, 1.0);
    out_tangent = vec4(tangent, handedness);
    out_view = vec4(view, 0.0);
    out_ids = uvec2(draw.object_id, draw.material + 1u);
    out_color = color;
    out_surface = uvec4(floatBitsToUint(world_position), triangle);
}
