#version 460
// The bake's maps pass: the scene drawn again, as bake.frag draws it, for each material's textures
// as the values of the maps its look binds (docs/commands.md#maps, and src/asset/materials.rs:
// MapKind). The textures' factors stay in the presets, except where a parameter is not linear in
// its texture: there the map holds the parameter itself. Each sample says which material it is
// of, so that it counts for that material's maps whatever the geometry pass saw there.
#extension GL_GOOGLE_include_directive : require

#include "bake_draw.glsl"
#include "bake_material.glsl"

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec4 world_tangent;
layout(location = 3) in vec4 color;
layout(location = SLOT_MASK) flat in uint slot_mask;
layout(location = SLOT_TEXCOORDS) in vec4 slot_uv[SLOT_PAIRS];

// A slot's texel, or white where the slot is empty. Sampled before any fragment is discarded, so
// that every lane of a quad has its derivatives; the branch is the same for the whole draw.
#define SAMPLE(slot) \
    ((slot_mask & (1u << slot)) != 0u ? texture(textures[slot], SLOT_UV(slot_uv, slot), draw.lod_bias) : vec4(1.0))

layout(location = 0) out vec4 out_base_color;  // rgb: the base colour texel × COLOR_0
layout(location = 1) out vec4 out_emission;    // rgb: the emissive texel
layout(location = 2) out vec4 out_metal_rough_coat;  // metallic, roughness, clearcoat, clearcoat_gloss
layout(location = 3) out vec4 out_sheen_specular;    // sheen, sheen_tint, specular
layout(location = 4) out uint out_material;          // the material's index + 1

// Rec.709 luminance, as src/asset/materials.rs weighs colours.
float luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

// Disney's sheen_tint whose sheen colour mix(1, C_tint, t) best matches `sheen` in hue, by least
// squares, as src/asset/materials.rs: sheen_tint.
float sheen_tint(vec3 sheen, vec3 base) {
    float lum_sheen = luminance(sheen);
    float lum_base = luminance(base);
    if (lum_sheen <= 0.0 || lum_base <= 0.0) {
        return 0.0;
    }
    vec3 target = sheen / lum_sheen - 1.0;
    vec3 tint = base / lum_base - 1.0;
    float denominator = dot(tint, tint);
    return denominator < 1e-8 ? 0.0 : clamp(dot(target, tint) / denominator, 0.0, 1.0);
}

void main() {
    vec4 base_color = SAMPLE(SLOT_BASE_COLOR);
    vec4 metal_rough = SAMPLE(SLOT_METAL_ROUGH);
    vec4 emissive = SAMPLE(SLOT_EMISSIVE);
    float coat = SAMPLE(SLOT_CLEARCOAT).r;
    float coat_roughness = SAMPLE(SLOT_CLEARCOAT_ROUGHNESS).g;
    vec3 sheen_texel = SAMPLE(SLOT_SHEEN_COLOR).rgb;
    float specular_texel = SAMPLE(SLOT_SPECULAR).a;
    vec3 specular_color_texel = SAMPLE(SLOT_SPECULAR_COLOR).rgb;
    if (cut_out(base_color, color)) {
        discard;
    }
    vec3 base = base_color.rgb * color.rgb;
    float r = MATERIAL.clearcoat_roughness * coat_roughness;
    float gloss = clamp((0.1 - r * r) / 0.099, 0.0, 1.0);

    vec3 sheen_factor = MATERIAL.sheen_color_factor.rgb;
    vec3 sheen = sheen_factor * sheen_texel;
    float sheen_ratio = luminance(sheen_factor) > 0.0 ? luminance(sheen) / luminance(sheen_factor) : 0.0;
    float tint = sheen_tint(sheen, MATERIAL.base_color_factor.rgb * base);

    vec3 specular_factor = MATERIAL.specular_color_factor.rgb;
    float colour_ratio = luminance(specular_factor) > 0.0
        ? luminance(specular_factor * specular_color_texel) / luminance(specular_factor) : 0.0;

    out_base_color = vec4(base, 0.0);
    out_material = draw.material + 1u;
    out_emission = vec4(emissive.rgb, 0.0);
    out_metal_rough_coat = vec4(metal_rough.b, metal_rough.g, coat, gloss);
    out_sheen_specular = vec4(clamp(sheen_ratio, 0.0, 1.0), tint, clamp(specular_texel * colour_ratio, 0.0, 1.0), 0.0);
}
