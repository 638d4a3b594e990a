// The eleven Disney parameters (and the complex IOR's edge parameter) and their GPU layout: the
// first four of the five vec4s Params::to_gpu writes. The fifth holds emission, which is no part
// of the BRDF: relight.comp reads it on its own.
#ifndef LOOKDEV_MATERIAL_GLSL
#define LOOKDEV_MATERIAL_GLSL

struct Material {
    vec3 base_color;  // linear Rec.709
    float metallic;
    float subsurface;
    float specular;
    float specular_tint;
    float roughness;
    float anisotropic;
    float sheen;
    float sheen_tint;
    float clearcoat;
    float clearcoat_gloss;
    vec3 ior_edge;    // where the complex IOR lies between its two dielectric ends (presets' ior_n, ior_k)
};

Material unpack_material(vec4 p0, vec4 p1, vec4 p2, vec4 p3) {
    Material m;
    m.base_color = p0.rgb;
    m.metallic = p0.a;
    m.subsurface = p1.x;
    m.specular = p1.y;
    m.specular_tint = p1.z;
    m.roughness = p1.w;
    m.anisotropic = p2.x;
    m.sheen = p2.y;
    m.sheen_tint = p2.z;
    m.clearcoat = p2.w;
    m.clearcoat_gloss = p3.x;
    m.ior_edge = p3.yzw;
    return m;
}

#endif
