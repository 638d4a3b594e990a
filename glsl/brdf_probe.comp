#version 460
// Evaluates the BRDF and the BRDF sampling pdf for a list of (material, l, v) records, so tests
// can compare the GPU against the Rust reference; the model is the pipeline's specialization.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#define ENERGY_TABLE_SET 0
#define ENERGY_TABLE_BINDING 2

#include "brdf.glsl"
#include "sampling.glsl"

struct Record {
    vec4 params[4];  // the material's BRDF, as Params::brdf_gpu lays it out
    vec4 l;  // shading frame
    vec4 v;
};
layout(set = 0, binding = 0, std430) readonly buffer Records {
    Record records[];
};
// rgb: f(l, v); a: brdf_pdf(l, v) for v above the surface (the renderer never samples below it).
layout(set = 0, binding = 1, std430) writeonly buffer Results {
    vec4 results[];
};

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= records.length()) {
        return;
    }
    Record r = records[i];
    Lobes s = make_lobes(unpack_material(r.params[0], r.params[1], r.params[2], r.params[3]));
    View view = make_view(s, r.v.xyz);
    HalfVector hv = make_half_vector(s, r.l.xyz, r.v.xyz);
    float pdf = r.v.z > 0.0 ? brdf_pdf(choose_lobes(s, view), view, r.l.xyz, hv) : 0.0;
    results[i] = vec4(disney_brdf(s, view, r.l.xyz, hv), pdf);
}
