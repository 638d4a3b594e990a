#version 460
// The bake's fragment stage: one g-buffer sample of the nearest surface (README: lookdev bake).
// Writes the shading normal (the normal map applied through the MikkTSpace tangent frame), the
// tangent (turned by the material's anisotropy rotation), the view vector, the object and
// material, COLOR_0, the raw metallic and roughness texture values and the base colour texture. Back faces of
// double-sided materials turn their whole frame around, as glTF asks.
#extension GL_GOOGLE_include_directive : require

#include "bake_draw.glsl"

layout(set = 0, binding = 0) uniform sampler2D normal_map;
layout(set = 0, binding = 1) uniform sampler2D metal_rough_map;
layout(set = 0, binding = 2) uniform sampler2D base_color_map;

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec4 world_tangent;
layout(location = 3) in vec2 uv0;
layout(location = 4) in vec2 uv1;
layout(location = 5) in vec4 color;

layout(location = 0) out vec4 out_normal;       // xyz; w = 1 marks a covered sample
layout(location = 1) out vec4 out_tangent;      // xyz; w = bitangent sign
layout(location = 2) out vec4 out_view;         // xyz
layout(location = 3) out uvec2 out_ids;         // object id, material index + 1
layout(location = 4) out vec4 out_color;        // COLOR_0
layout(location = 5) out vec2 out_metal_rough;  // the texture's B (metallic) and G (roughness)
layout(location = 6) out vec4 out_base_color;   // the base colour texture, linear; white without one

// The least N·V a shading normal keeps.
const float MIN_FACING = 0.01;

vec2 texcoord(uint set) {
    return set == 1u ? uv1 : uv0;
}

vec3 srgb_to_linear(vec3 c) {
    return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

void main() {
    vec4 base_color = vec4(1.0);
    if ((draw.flags & DRAW_BASE_COLOR_MAP) != 0u) {
        base_color = texture(base_color_map, texcoord(uv_set(4u)));
    }
    if ((draw.flags & DRAW_ALPHA_MASK) != 0u && color.a * base_color.a < draw.alpha_cutoff) {
        discard;
    }
    vec3 n = normalize(world_normal);
    vec3 t = world_tangent.xyz - n * dot(n, world_tangent.xyz);
    t = dot(t, t) > 1e-12 ? normalize(t) : vec3(0.0);
    float handedness = world_tangent.w < 0.0 ? -1.0 : 1.0;
    vec3 b = handedness * cross(n, t);
    if (!gl_FrontFacing && (draw.flags & DRAW_DOUBLE_SIDED) != 0u) {
        n = -n;
        t = -t;
        b = -b;
    }
    vec3 shading = n;
    if ((draw.flags & DRAW_NORMAL_MAP) != 0u && dot(t, t) > 0.0) {
        vec3 m = texture(normal_map, texcoord(uv_set(0u))).xyz * 2.0 - 1.0;
        m.xy *= draw.normal_scale;
        shading = normalize(m.x * t + m.y * b + m.z * n);
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
    vec3 anisotropy = draw.anisotropy_cos * t + draw.anisotropy_sin * b;
    vec3 tangent = anisotropy - shading * dot(shading, anisotropy);
    tangent = dot(tangent, tangent) > 1e-12 ? normalize(tangent) : vec3(0.0);
    vec2 metal_rough = vec2(0.0);
    if ((draw.flags & DRAW_METAL_ROUGH_MAP) != 0u) {
        vec4 texel = texture(metal_rough_map, texcoord(uv_set(2u)));
        metal_rough = vec2(texel.b, texel.g);
    }
    out_normal = vec4(shading, 1.0);
    out_tangent = vec4(tangent, handedness);
    out_view = vec4(view, 0.0);
    out_ids = uvec2(draw.object_id, draw.material);
    out_color = color;
    out_metal_rough = metal_rough;
    // Filtered as stored (sRGB), then decoded: the texture is a plain UNORM image.
    out_base_color = vec4(srgb_to_linear(base_color.rgb), base_color.a);
}
