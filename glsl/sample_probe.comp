#version 460
// Runs one sampling routine on a list of uniform random numbers, returning each sampled direction
// and the pdf the renderer would use for it, for the chi-square tests. Also exposes the Sobol
// sequence, to compare bit for bit with the Rust reference.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#define ENERGY_TABLE_SET 0
#define ENERGY_TABLE_BINDING 3

#include "brdf.glsl"
#include "sampling.glsl"
#include "sobol.glsl"
#include "environment.glsl"

const uint ROUTINE_COSINE = 0u;
const uint ROUTINE_GGX = 1u;
const uint ROUTINE_GTR1 = 2u;
const uint ROUTINE_BRDF = 3u;
const uint ROUTINE_ENVIRONMENT = 4u;
const uint ROUTINE_SOBOL = 5u;
const uint ROUTINE_UV_ROUND_TRIP = 6u;
const uint ROUTINE_PRODUCT = 7u;  // the product mixture: cluster `seed`, share view.w

layout(set = 0, binding = 0, std430) readonly buffer Setup {
    vec4 params[4];
    vec4 view;      // shading frame
    uint routine;
    uint seed;      // for ROUTINE_SOBOL; the cluster for ROUTINE_PRODUCT
};
layout(set = 0, binding = 1, std430) readonly buffer Uniforms {
    vec2 uniforms[];
};
// xyz: the direction (or, for Sobol, the point in xy); w: its pdf.
layout(set = 0, binding = 2, std430) writeonly buffer Samples {
    vec4 samples[];
};

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= samples.length()) {
        return;
    }
    Lobes s = make_lobes(unpack_material(params[0], params[1], params[2], params[3]));
    View v = make_view(s, view.xyz);
    LobeChoice choice = choose_lobes(s, v);
    vec2 u = uniforms[i];
    vec4 result;
    if (routine == ROUTINE_COSINE) {
        vec3 l = sample_cosine(azimuth(u.x), u.y);
        result = vec4(l, pdf_cosine(l));
    } else if (routine == ROUTINE_GGX) {
        // The model's specular sampler: GGX visible normals by default.
        vec3 l = reflect(-v.v, sample_specular_normal(s, v, azimuth(u.x), u.y));
        result = vec4(l, pdf_specular_reflection(v, make_half_vector(s, l, v.v)));
    } else if (routine == ROUTINE_GTR1) {
        vec3 l = reflect(-v.v, sample_gtr1_normal(s.cc_alpha2, s.cc_log2_alpha2, azimuth(u.x), u.y));
        result = vec4(l, pdf_gtr1_reflection(v, make_half_vector(s, l, v.v)));
    } else if (routine == ROUTINE_BRDF) {
        vec3 l = sample_brdf(s, choice, v, u);
        result = vec4(l, brdf_pdf(choice, v, l, make_half_vector(s, l, v.v)));
    } else if (routine == ROUTINE_ENVIRONMENT) {
        vec4 texel;
        vec3 d = env_sample(u, texel);
        // Also check that looking the pdf up from the direction agrees with the sampler's own.
        float looked_up = env_texel(env_direction_to_uv(d)).a;
        result = vec4(d, abs(looked_up - texel.a) <= 1e-3 * texel.a ? texel.a : -1.0);
    } else if (routine == ROUTINE_PRODUCT) {
        vec4 texel;
        vec3 d = env_sample_mixture(seed, view.w, u, texel);
        float looked_up = env_texel_mixture(seed, view.w, env_direction_to_uv(d)).a;
        result = vec4(d, abs(looked_up - texel.a) <= 1e-3 * texel.a ? texel.a : -1.0);
    } else if (routine == ROUTINE_SOBOL) {
        result = vec4(sobol_owen_2d(i, seed), 0.0, 0.0);
    } else {
        vec3 d = env_uv_to_direction(u);
        result = vec4(env_direction_to_uv(d), d.y, 0.0);
    }
    samples[i] = result;
}
