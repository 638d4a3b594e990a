// The BRDF model variants of the BRDF lab (docs/shading.md#brdf-models). Every kernel that shades is one
// pipeline per model: the choices are specialization constants, whose defaults are the Disney 2012
// model, so the driver folds every branch on them away and no kernel is copied per model.
// Mirrored by src/shading/model.rs (Model::specialization writes these constant ids in order).
#ifndef LOOKDEV_MODEL_GLSL
#define LOOKDEV_MODEL_GLSL

const uint DIFFUSE_BURLEY2012 = 0u;
const uint DIFFUSE_LAMBERT = 1u;
const uint DIFFUSE_FROSTBITE = 2u;
const uint DIFFUSE_OREN_NAYAR = 3u;
const uint DIFFUSE_OREN_NAYAR_QUALITATIVE = 4u;
const uint DIFFUSE_OREN_NAYAR_FUJII = 5u;
const uint DIFFUSE_GOTANDA = 6u;
const uint DIFFUSE_HAMMON = 7u;

const uint SPECULAR_D_GTR2 = 0u;
const uint SPECULAR_D_BECKMANN = 1u;
const uint SPECULAR_D_GTR = 2u;

const uint SPECULAR_G_SEPARABLE = 0u;
const uint SPECULAR_G_HEIGHT_CORRELATED = 1u;
const uint SPECULAR_G_BURLEY2012 = 2u;

const uint FRESNEL_SCHLICK = 0u;
const uint FRESNEL_DIELECTRIC = 1u;
const uint FRESNEL_CONDUCTOR = 2u;

layout(constant_id = 0) const uint MODEL_DIFFUSE = DIFFUSE_BURLEY2012;
layout(constant_id = 1) const uint MODEL_SPECULAR_D = SPECULAR_D_GTR2;
layout(constant_id = 2) const uint MODEL_SPECULAR_G = SPECULAR_G_SEPARABLE;
layout(constant_id = 3) const uint MODEL_FRESNEL = FRESNEL_SCHLICK;
layout(constant_id = 4) const float MODEL_GTR_GAMMA = 2.0;
// Kulla–Conty multiple scattering for the specular lobe; only kernels that bind the energy table
// (ENERGY_TABLE_SET and ENERGY_TABLE_BINDING defined before brdf.glsl) can turn it on.
layout(constant_id = 5) const uint MODEL_ENERGY_COMPENSATION = 0u;

#endif
