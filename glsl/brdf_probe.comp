#version 460
// Evaluates the BRDF and the BRDF sampling pdf for a list of (material, l, v) records, so tests
// can compare the GPU against the Rust reference.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#include "brdf.glsl"
#include "sampling.glsl"

struct Record {
    vec4 params[4];
    vec4 l;  // shading frame
    vec4 v;
};
layout(set = 0, binding = 0, std430) readonly buffer Records {
    Record records[];
};
// rgb: f(l, v); a: brdf_pdf(l, v).
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
    LobeChoice choice = choose_lobes(s, r.v.z);
    results[i] = vec4(disney_brdf(s, r.l.xyz, r.v.xyz), brdf_pdf(s, choice, r.l.xyz, r.v.xyz));
}
