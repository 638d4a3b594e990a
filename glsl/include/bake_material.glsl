// The bake's materials (src/asset/bake.rs: GpuMaterial), their textures and their cut-outs,
// shared by the geometry pass (bake.frag) and the maps pass (bake_maps.frag), which must agree
// on every fragment they keep.

// Texture slots, in the order of src/asset/textures.rs: Slot.
const uint SLOT_NORMAL = 0u;
const uint SLOT_BASE_COLOR = 1u;
const uint SLOT_METAL_ROUGH = 2u;
const uint SLOT_EMISSIVE = 3u;
const uint SLOT_CLEARCOAT = 4u;
const uint SLOT_CLEARCOAT_ROUGHNESS = 5u;
const uint SLOT_SHEEN_COLOR = 6u;
const uint SLOT_SPECULAR = 7u;
const uint SLOT_SPECULAR_COLOR = 8u;
const uint SLOTS = 9u;

// A texture whose slot is empty is a neutral stand-in: a flat normal, or white. sRGB textures are
// decoded by the sampler. Only the fragment stage samples them.
layout(set = 0, binding = 0) uniform sampler2D textures[SLOTS];

// The varying locations of the slots' texcoords (two slots a location, from SLOT_TEXCOORDS on)
// and of the bits of the slots that hold a texture (SLOT_MASK, flat).
#define SLOT_MASK 4
#define SLOT_TEXCOORDS 5
#define SLOT_PAIRS 5
// The varying location of the triangle's index (flat), after the texcoords'.
#define TRIANGLE_LOCATION (SLOT_TEXCOORDS + SLOT_PAIRS)

// Where a slot samples: texcoord = (dot(u.xyz, (uv, 1)), dot(v.xyz, (uv, 1))), KHR_texture_transform.
struct TextureSlot {
    vec4 u;
    vec4 v;
    uint tex_coord;   // TEXCOORD_0 or TEXCOORD_1
    uint present;     // 0: the slot is empty
    uint pad0;
    uint pad1;
};

struct Material {
    uint flags;                 // MATERIAL_* below
    float alpha_cutoff;         // alphaMode MASK: fragments whose alpha is below this are not surface
    float normal_scale;         // normalTexture.scale
    float anisotropy_cos;       // KHR_materials_anisotropy rotation, from the tangent toward the bitangent
    float anisotropy_sin;
    float clearcoat_roughness;  // clearcoatRoughnessFactor
    float pad0;
    float pad1;
    vec4 base_color_factor;     // rgb (for the sheen tint), and alpha (for the cut-out)
    vec4 sheen_color_factor;    // rgb
    vec4 specular_color_factor; // rgb
    TextureSlot slots[SLOTS];
};

layout(set = 0, binding = 1, std430) readonly buffer Materials {
    Material materials[];
};

const uint MATERIAL_DOUBLE_SIDED = 1u;
const uint MATERIAL_ALPHA_MASK = 2u;

#define MATERIAL materials[draw.material]

// Where a slot samples: its texcoord set, transformed. The vertex stage computes it, so that the
// fragment stage's derivatives (and so the mip level) come from interpolation alone: helper
// invocations on a triangle's edge need not read the material buffer.
vec2 slot_texcoord(uint slot, vec2 uv0, vec2 uv1) {
    TextureSlot s = MATERIAL.slots[slot];
    vec3 uv = vec3(s.tex_coord == 1u ? uv1 : uv0, 1.0);
    return vec2(dot(s.u.xyz, uv), dot(s.v.xyz, uv));
}

// Whether an alphaMode MASK material cuts this fragment out: the base colour's alpha (the
// factor's times the texture's times COLOR_0's) below the cutoff.
bool cut_out(vec4 base_color_texel, vec4 color) {
    float alpha = MATERIAL.base_color_factor.a * base_color_texel.a * color.a;
    return (MATERIAL.flags & MATERIAL_ALPHA_MASK) != 0u && alpha < MATERIAL.alpha_cutoff;
}

// A slot's texcoords among the packed pairs: slot 2k in pair k's xy, slot 2k + 1 in its zw.
#define SLOT_UV(pairs, slot) ((slot) % 2u == 0u ? pairs[(slot) / 2u].xy : pairs[(slot) / 2u].zw)
