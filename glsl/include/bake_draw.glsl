// The per-draw constants of the bake's vertex and fragment shaders (src/asset/bake.rs: DrawConstants),
// 128 bytes: the least every device allows.
layout(push_constant) uniform Draw {
    mat4 view_projection;   // world to clip, with the pass's sub-pixel jitter
    vec4 eye;               // xyz: the eye; w: 1 for a perspective camera, 0 for orthographic
    vec4 toward_eye;        // xyz: the unit direction toward an orthographic camera
    uint object_id;
    uint material;          // the material's index + 1; 0 for none
    uint flags;             // DRAW_* below
    float normal_scale;     // normalTexture.scale
    uint uv_sets;           // texcoord sets: bits 0-1 normal map, 2-3 metallic-roughness, 4-5 base colour
    float alpha_cutoff;     // alphaMode MASK: fragments below this alpha are not surface
    float anisotropy_cos;   // KHR_materials_anisotropy rotation, from the tangent toward the bitangent
    float anisotropy_sin;
} draw;

const uint DRAW_DOUBLE_SIDED = 1u;
const uint DRAW_NORMAL_MAP = 2u;
const uint DRAW_METAL_ROUGH_MAP = 4u;
const uint DRAW_ALPHA_MASK = 8u;
const uint DRAW_BASE_COLOR_MAP = 16u;

uint uv_set(uint shift) {
    return (draw.uv_sets >> shift) & 3u;
}
