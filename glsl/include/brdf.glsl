// The Disney 2012 principled BRDF, BRDF Explorer revision (README: Shading model).
//
// Every vector is in the shading frame: N = +Z, tangent X = +X, bitangent Y = +Y, so N·W = W.z.
// What depends only on the material (Lobes) or only on the view (View) is computed once per
// pixel; what depends on the half vector (HalfVector) is shared by f and the sampling pdf.
// Mirrored function by function in src/shading/brdf.rs.
#ifndef LOOKDEV_BRDF_GLSL
#define LOOKDEV_BRDF_GLSL

#include "common.glsl"
#include "material.glsl"

// What the BRDF needs of a material, derived once per pixel rather than once per sample.
struct Lobes {
    vec3 base_color;
    vec3 cspec0;          // specular reflectance at normal incidence
    vec3 sheen_color;     // sheen · Csheen
    float metallic;
    float subsurface;
    float roughness;
    float ax;             // anisotropic GGX alphas
    float ay;
    float clearcoat;      // 0.25 · clearcoat: the clearcoat lobe's weight in the total
    float cc_alpha2;      // GTR1 alpha², at most 1
    float cc_log2_alpha2; // for sampling GTR1
    float cc_norm;        // GTR1 normalisation (α²−1)/(π·ln α²), or 1/π when α ≥ 1
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
    s.cc_log2_alpha2 = log2(s.cc_alpha2);
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

// Smith G for anisotropic GGX with 1/(4·N·W) folded in: g(W) of the README's shading model.
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

// What depends only on the view direction, derived once per pixel.
struct View {
    vec3 v;
    vec3 v_stretched;  // v in the GGX hemisphere configuration, for visible-normal sampling
    float fv;          // S(N·V)
    float g_spec;      // g(V) of the specular lobe
    float g_coat;      // g25(V) of the clearcoat
};

View make_view(Lobes s, vec3 v) {
    View view;
    view.v = v;
    view.v_stretched = normalize(vec3(s.ax * v.x, s.ay * v.y, v.z));
    view.fv = schlick_weight(v.z);
    view.g_spec = smith_g_aniso(v, s.ax, s.ay);
    view.g_coat = smith_g_clearcoat(v.z);
    return view;
}

// The half vector of a pair of directions and the two microfacet distributions at it.
struct HalfVector {
    vec3 h;        // normalize(l + v), or 0 when l = −v
    float d_spec;  // GGX D(h)
    float d_coat;  // GTR1 D(h)
};

HalfVector make_half_vector(Lobes s, vec3 l, vec3 v) {
    HalfVector hv;
    vec3 sum = l + v;
    float len2 = dot(sum, sum);
    hv.h = len2 > 0.0 ? sum * inversesqrt(len2) : vec3(0.0);
    hv.d_spec = len2 > 0.0 ? gtr2_aniso(hv.h, s.ax, s.ay) : 0.0;
    hv.d_coat = len2 > 0.0 ? gtr1(hv.h, s.cc_alpha2, s.cc_norm) : 0.0;
    return hv;
}

// f(l, v), without the cosine. Zero unless both directions are above the surface, which also
// avoids the reference code's 0/0 when both are at grazing.
vec3 disney_brdf(Lobes s, View view, vec3 l, HalfVector hv) {
    float cl = l.z;
    float cv = view.v.z;
    if (cl <= 0.0 || cv <= 0.0) {
        return vec3(0.0);
    }
    float cd = dot(l, hv.h);
    float fl = schlick_weight(cl);
    float fh = schlick_weight(cd);

    // Diffuse: Schlick-style retro-reflection, and the Hanrahan–Krueger-like subsurface.
    float cd2r = cd * cd * s.roughness;
    float fd90 = 0.5 + 2.0 * cd2r;
    float fd = mix(1.0, fd90, fl) * mix(1.0, fd90, view.fv);
    float fss = mix(1.0, cd2r, fl) * mix(1.0, cd2r, view.fv);
    float ss = 1.25 * (fss * (1.0 / (cl + cv) - 0.5) + 0.5);
    vec3 diffuse = (INV_PI * mix(fd, ss, s.subsurface)) * s.base_color + fh * s.sheen_color;

    // Specular: anisotropic GGX.
    vec3 fs = mix(s.cspec0, vec3(1.0), fh);
    float gs = smith_g_aniso(l, s.ax, s.ay) * view.g_spec;

    // Clearcoat: GTR1 with a fixed IOR 1.5.
    float fr = mix(0.04, 1.0, fh);
    float gr = smith_g_clearcoat(cl) * view.g_coat;

    return diffuse * (1.0 - s.metallic) + (gs * hv.d_spec) * fs + vec3(s.clearcoat * gr * fr * hv.d_coat);
}

#endif
