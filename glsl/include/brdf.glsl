// The Disney 2012 principled BRDF, BRDF Explorer revision (LOOKDEV.md §4).
//
// Every vector is in the shading frame: N = +Z, tangent X = +X, bitangent Y = +Y, so N·W = W.z.
// Mirrored function by function in src/shading/brdf.rs.
#ifndef LOOKDEV_BRDF_GLSL
#define LOOKDEV_BRDF_GLSL

#include "common.glsl"
#include "material.glsl"

// What the BRDF needs of a material, derived once per pixel rather than once per sample.
struct Lobes {
    vec3 base_color;
    vec3 cspec0;       // specular reflectance at normal incidence
    vec3 sheen_color;  // sheen · Csheen
    float metallic;
    float subsurface;
    float roughness;
    float ax;          // anisotropic GGX alphas
    float ay;
    float clearcoat;   // 0.25 · clearcoat: the clearcoat lobe's weight in the total
    float cc_alpha2;   // GTR1 alpha², at most 1
    float cc_norm;     // GTR1 normalisation (α²−1)/(π·ln α²), or 1/π when α ≥ 1
};

// Burley's luminance approximation, used only to isolate the base colour's hue for the tints.
float tint_luminance(vec3 c) {
    return 0.3 * c.r + 0.6 * c.g + 0.1 * c.b;
}

float gtr1_norm(float alpha2) {
    return alpha2 >= 1.0 ? INV_PI : (alpha2 - 1.0) / (PI * log(alpha2));
}

Lobes make_lobes(Material m) {
    Lobes s;
    float lum = tint_luminance(m.base_color);
    vec3 ctint = lum > 0.0 ? m.base_color / lum : vec3(1.0);
    s.base_color = m.base_color;
    s.cspec0 = mix(m.specular * 0.08 * mix(vec3(1.0), ctint, m.specular_tint), m.base_color, m.metallic);
    s.sheen_color = m.sheen * mix(vec3(1.0), ctint, m.sheen_tint);
    s.metallic = m.metallic;
    s.subsurface = m.subsurface;
    s.roughness = m.roughness;
    float aspect = sqrt(1.0 - 0.9 * m.anisotropic);
    float r2 = m.roughness * m.roughness;
    s.ax = max(0.001, r2 / aspect);
    s.ay = max(0.001, r2 * aspect);
    s.clearcoat = 0.25 * m.clearcoat;
    float a = mix(0.1, 0.001, m.clearcoat_gloss);
    s.cc_alpha2 = min(a * a, 1.0);
    s.cc_norm = gtr1_norm(s.cc_alpha2);
    return s;
}

// S(u) = clamp(1 − u, 0, 1)^5, by multiplication: pow() is approximate on some drivers.
float schlick_weight(float u) {
    float m = clamp(1.0 - u, 0.0, 1.0);
    float m2 = m * m;
    return m2 * m2 * m;
}

// GTR1 (Berry) distribution of the clearcoat, for a unit half vector h. The textbook denominator
// 1 + (α²−1)·cos²θh cancels catastrophically near the peak of a glossy coat; α²·cos²θh + sin²θh
// is the same value as a sum of positive terms.
float gtr1(vec3 h, float alpha2, float norm) {
    return norm / (alpha2 * h.z * h.z + h.x * h.x + h.y * h.y);
}

// Anisotropic GTR2 (GGX) distribution; h is the half vector in the shading frame.
float gtr2_aniso(vec3 h, float ax, float ay) {
    float x = h.x / ax;
    float y = h.y / ay;
    float d = x * x + y * y + h.z * h.z;
    return 1.0 / (PI * ax * ay * d * d);
}

// Smith G for anisotropic GGX with 1/(4·N·W) folded in: g(W) of LOOKDEV.md §4.
float smith_g_aniso(vec3 w, float ax, float ay) {
    float x = w.x * ax;
    float y = w.y * ay;
    return 1.0 / (w.z + sqrt(x * x + y * y + w.z * w.z));
}

// The same for the clearcoat's fixed alpha 0.25: g25(W).
float smith_g_clearcoat(float cos_w) {
    float c2 = cos_w * cos_w;
    return 1.0 / (cos_w + sqrt(0.0625 + c2 - 0.0625 * c2));
}

// f(l, v), without the cosine. Zero unless both directions are above the surface, which also
// avoids the reference code's 0/0 when both are at grazing.
vec3 disney_brdf(Lobes s, vec3 l, vec3 v) {
    float cl = l.z;
    float cv = v.z;
    if (cl <= 0.0 || cv <= 0.0) {
        return vec3(0.0);
    }
    vec3 h = normalize(l + v);
    float cd = dot(l, h);
    float fl = schlick_weight(cl);
    float fv = schlick_weight(cv);
    float fh = schlick_weight(cd);

    // Diffuse: Schlick-style retro-reflection, and the Hanrahan–Krueger-like subsurface.
    float cd2r = cd * cd * s.roughness;
    float fd90 = 0.5 + 2.0 * cd2r;
    float fd = mix(1.0, fd90, fl) * mix(1.0, fd90, fv);
    float fss = mix(1.0, cd2r, fl) * mix(1.0, cd2r, fv);
    float ss = 1.25 * (fss * (1.0 / (cl + cv) - 0.5) + 0.5);
    vec3 diffuse = (INV_PI * mix(fd, ss, s.subsurface)) * s.base_color + fh * s.sheen_color;

    // Specular: anisotropic GGX.
    vec3 fs = mix(s.cspec0, vec3(1.0), fh);
    float ds = gtr2_aniso(h, s.ax, s.ay);
    float gs = smith_g_aniso(l, s.ax, s.ay) * smith_g_aniso(v, s.ax, s.ay);

    // Clearcoat: GTR1 with a fixed IOR 1.5.
    float dr = gtr1(h, s.cc_alpha2, s.cc_norm);
    float fr = mix(0.04, 1.0, fh);
    float gr = smith_g_clearcoat(cl) * smith_g_clearcoat(cv);

    return diffuse * (1.0 - s.metallic) + (gs * ds) * fs + vec3(s.clearcoat * gr * fr * dr);
}

#endif
