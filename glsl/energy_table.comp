#version 460
// Builds the energy-compensation table of a model (docs/shading.md#brdf-models): the directional albedo
// E(μ, roughness) of its single-scattering specular lobe with F = 1, for the model's D and G (the
// pipeline's specialization), by a deterministic midpoint quadrature of the model's own specular
// sampler: E = ∫ f·cosθl dl = mean of f·cosθl/pdf over the sampler's unit square. One invocation
// per node of the 32×32 grid in (√μ, roughness); src/render/energy.rs adds the averages.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#include "brdf.glsl"
#include "sampling.glsl"

layout(set = 0, binding = 0, std430) writeonly buffer Table {
    float albedo[];
};

const uint SIZE = 32u;         // ENERGY_TABLE_SIZE
const uint QUADRATURE = 64u;   // points per axis of the unit square

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= SIZE * SIZE) {
        return;
    }
    float t = float(i % SIZE) / float(SIZE - 1u);
    float mu = max(t * t, 1e-4);
    Material m;
    m.base_color = vec3(1.0);
    m.metallic = 1.0;
    m.subsurface = 0.0;
    m.specular = 0.5;
    m.specular_tint = 0.0;
    m.roughness = float(i / SIZE) / float(SIZE - 1u);
    m.anisotropic = 0.0;
    m.sheen = 0.0;
    m.sheen_tint = 0.0;
    m.clearcoat = 0.0;
    m.clearcoat_gloss = 1.0;
    m.ior_edge = vec3(0.0);
    Lobes s = make_lobes(m);
    vec3 v = vec3(sqrt(1.0 - mu * mu), 0.0, mu);
    View view = make_view(s, v);
    float sum = 0.0;
    for (uint a = 0u; a < QUADRATURE; a++) {
        vec2 phi = azimuth((float(a) + 0.5) / float(QUADRATURE));
        for (uint b = 0u; b < QUADRATURE; b++) {
            vec3 l = reflect(-v, sample_specular_normal(s, view, phi, (float(b) + 0.5) / float(QUADRATURE)));
            if (l.z <= 0.0) {
                continue;
            }
            HalfVector hv = make_half_vector(s, l, v);
            float pdf = pdf_specular_reflection(view, hv);
            if (pdf > 0.0) {
                sum += specular_shadowing(s, view, l) * hv.d_spec * l.z / pdf;
            }
        }
    }
    albedo[i] = sum / float(QUADRATURE * QUADRATURE);
}
