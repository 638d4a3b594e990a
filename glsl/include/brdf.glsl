// The Disney 2012 principled BRDF, BRDF Explorer revision (docs/shading.md#shading-model), and the BRDF
// lab's variants of its diffuse, D, G and F terms (docs/shading.md#brdf-models), chosen by the
// specialization constants of model.glsl. With the default constants every function computes
// exactly what the Disney model computes.
//
// Every vector is in the shading frame: N = +Z, tangent X = +X, bitangent Y = +Y, so N·W = W.z.
// What depends only on the material (Lobes) or only on the view (View) is computed once per
// pixel; what depends on the half vector (HalfVector) is shared by f and the sampling pdf.
// Mirrored function by function in src/shading/brdf.rs.
#ifndef LOOKDEV_BRDF_GLSL
#define LOOKDEV_BRDF_GLSL

#include "common.glsl"
#include "material.glsl"
#include "model.glsl"

// Which lobes some pixel of the scene has, from its layer stacks (LobesPresent in
// src/material/stack.rs): SCENE_DIFFUSE where some metallic is below 1 (the diffuse, subsurface
// and sheen lobes, all weighted by 1 − metallic), SCENE_CLEARCOAT where some clearcoat is above
// 0. A kernel specialised without a lobe leaves out its code, which a SIMD driver would
// otherwise run, masked, for every sample. On by default: every kernel but relight, and the
// CPU reference, evaluate every lobe.
layout(constant_id = 9) const uint SCENE_DIFFUSE = 1u;
layout(constant_id = 10) const uint SCENE_CLEARCOAT = 1u;

// What the BRDF needs of a material, derived once per pixel rather than once per sample.
struct Lobes {
    vec3 base_color;
    vec3 cspec0;          // specular reflectance at normal incidence
    vec3 sheen_color;     // sheen · Csheen
    float metallic;
    float subsurface;
    float roughness;
    float specular;       // the specular parameter, for models with a scalar dielectric F0
    float ax;             // anisotropic alphas of the distribution (GTR-γ: isotropic)
    float ay;
    float gx;             // alphas of the shadowing term: ax, ay, or the 2012 notes' remap
    float gy;
    float d_log_norm;     // ln of the GTR-γ normalisation
    float clearcoat;      // 0.25 · clearcoat: the clearcoat lobe's weight in the total
    float cc_alpha2;      // GTR1 alpha², at most 1
    float cc_log2_alpha2; // for sampling GTR1
    float cc_norm;        // GTR1 normalisation (α²−1)/(π·ln α²), or 1/π when α ≥ 1
    vec3 ior_n;           // complex IOR per channel, for the exact Fresnel variants
    vec3 ior_k;
    vec3 ms_scale;        // energy compensation: F_ms/(π·(1 − E_avg))
    vec3 ms_fresnel;      // F_ms, the Fresnel colour of multiple scattering
};

// Burley's luminance approximation, used only to isolate the base colour's hue for the tints.
float tint_luminance(vec3 c) {
    return 0.3 * c.r + 0.6 * c.g + 0.1 * c.b;
}

float gtr1_norm(float alpha2) {
    return alpha2 >= 1.0 ? INV_PI : (alpha2 - 1.0) / (PI * log(alpha2));
}

// e^x − 1 without cancellation for small x (the series to x⁵: relative error below 2e-8).
float expm1_accurate(float x) {
    return abs(x) < 0.1 ? x * (1.0 + x * (0.5 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x / 120.0)))) : exp(x) - 1.0;
}

// ln(1 + y) without cancellation for small y; GPU logarithms are only accurate to an absolute
// 2^-21 near 1, which is a large relative error there.
float log1p_accurate(float y) {
    return abs(y) < 0.05 ? y * (1.0 - y * (0.5 - y * (1.0 / 3.0 - y * (0.25 - y * 0.2)))) : log(1.0 + y);
}

// ln x, accurate relative to the result also near x = 1 (x − 1 is exact there).
float log_accurate(float x) {
    return abs(x - 1.0) < 0.05 ? log1p_accurate(x - 1.0) : log(x);
}

// ln of GTR's normalisation for exponent γ (Burley 2012, appendix B): (γ−1)(α²−1)/(π(1 −
// α^(2(1−γ)))), the γ → 1 limit (α²−1)/(π ln α²), and 1/π for α ≥ 1. A logarithm, because
// α^(2(1−γ)) overflows a float at the ends of the range (e^124 at γ = 10, α = 0.001) where the
// distribution itself is finite.
float gtr_log_norm(float alpha2, float gamma) {
    if (alpha2 >= 1.0) {
        return -log(PI);
    }
    float log_alpha2 = log_accurate(alpha2);
    if (abs(gamma - 1.0) < 1e-4) {
        return log((alpha2 - 1.0) / log_alpha2) - log(PI);
    }
    float l = (1.0 - gamma) * log_alpha2;
    // ln|e^l − 1|; for l > 0, l + ln(1 − e^−l), which cannot overflow.
    float log_expm1 = l > 0.0 ? l + log(-expm1_accurate(-l)) : log(-expm1_accurate(l));
    return log(abs(gamma - 1.0) * (1.0 - alpha2)) - log(PI) - log_expm1;
}

// n and k of the complex IOR whose normal reflectance is r and whose edge parameter is e: n runs
// from the dielectric (1+√r)/(1−√r) at e = 0 to (1−√r)/(1+√r) at e = 1, and k follows from r.
vec2 complex_ior(float r, float e) {
    float rc = clamp(r, 0.0, 0.9999);
    float sr = sqrt(rc);
    float n_hi = (1.0 + sr) / (1.0 - sr);
    float n_lo = (1.0 - sr) / (1.0 + sr);
    float n = n_hi + (n_lo - n_hi) * e;
    float k2 = (rc * (n + 1.0) * (n + 1.0) - (n - 1.0) * (n - 1.0)) / (1.0 - rc);
    return vec2(n, sqrt(max(k2, 0.0)));
}

#ifdef ENERGY_TABLE_BINDING
// Directional albedo E(μ, roughness) of the single-scattering specular lobe with F = 1, on a
// 32×32 grid (√μ and roughness from 0 to 1: √μ packs the nodes where E changes fastest, at
// grazing), then its cosine-weighted average E_avg(roughness), 32 values. E is built on the GPU
// by energy_table.comp for the model's D and G; E_avg is its exact average (src/render/energy.rs).
layout(set = ENERGY_TABLE_SET, binding = ENERGY_TABLE_BINDING, std430) readonly buffer EnergyTable {
    float energy_table[];
};
const int ENERGY_TABLE_SIZE = 32;

float energy_albedo(float mu, float roughness) {
    float x = sqrt(clamp(mu, 0.0, 1.0)) * float(ENERGY_TABLE_SIZE - 1);
    float y = clamp(roughness, 0.0, 1.0) * float(ENERGY_TABLE_SIZE - 1);
    int x0 = min(int(x), ENERGY_TABLE_SIZE - 2);
    int y0 = min(int(y), ENERGY_TABLE_SIZE - 2);
    float fx = x - float(x0);
    float fy = y - float(y0);
    int i = y0 * ENERGY_TABLE_SIZE + x0;
    float bottom = mix(energy_table[i], energy_table[i + 1], fx);
    float top = mix(energy_table[i + ENERGY_TABLE_SIZE], energy_table[i + ENERGY_TABLE_SIZE + 1], fx);
    return mix(bottom, top, fy);
}

float energy_average(float roughness) {
    float y = clamp(roughness, 0.0, 1.0) * float(ENERGY_TABLE_SIZE - 1);
    int y0 = min(int(y), ENERGY_TABLE_SIZE - 2);
    int i = ENERGY_TABLE_SIZE * ENERGY_TABLE_SIZE + y0;
    return mix(energy_table[i], energy_table[i + 1], y - float(y0));
}

// Kulla and Conty's multiple-scattering lobe: F_ms·(1 − E(μl))(1 − E(μv))/(π(1 − E_avg)), with
// F_avg of Schlick's form for the material's F0 and F_ms = F_avg²·E_avg/(1 − F_avg(1 − E_avg)).
void add_energy_compensation(inout Lobes s) {
    float e_avg = energy_average(s.roughness);
    vec3 f_avg = s.cspec0 + (1.0 - s.cspec0) / 21.0;
    s.ms_fresnel = f_avg * f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg));
    s.ms_scale = 1.0 - e_avg > 1e-6 ? s.ms_fresnel / (PI * (1.0 - e_avg)) : vec3(0.0);
}
#endif

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
    s.specular = m.specular;
    float aspect = sqrt(1.0 - 0.9 * m.anisotropic);
    float r2 = m.roughness * m.roughness;
    s.ax = max(0.001, r2 / aspect);
    s.ay = max(0.001, r2 * aspect);
    s.d_log_norm = 0.0;
    if (MODEL_SPECULAR_D == SPECULAR_D_GTR) {
        // GTR with γ ≠ 2 does not keep its shape when stretched, so it is isotropic.
        float a = sqrt(s.ax * s.ay);
        s.ax = a;
        s.ay = a;
        s.d_log_norm = gtr_log_norm(a * a, MODEL_GTR_GAMMA);
    }
    s.gx = s.ax;
    s.gy = s.ay;
    if (MODEL_SPECULAR_G == SPECULAR_G_BURLEY2012) {
        // The 2012 notes' remap of the roughness for G: α_g = (0.5 + roughness/2)².
        float rg = 0.5 + 0.5 * m.roughness;
        s.gx = max(0.001, rg * rg / aspect);
        s.gy = max(0.001, rg * rg * aspect);
        if (MODEL_SPECULAR_D == SPECULAR_D_GTR) {
            s.gx = rg * rg;
            s.gy = rg * rg;
        }
    }
    s.clearcoat = 0.25 * m.clearcoat;
    float a = mix(0.1, 0.001, m.clearcoat_gloss);
    s.cc_alpha2 = min(a * a, 1.0);
    s.cc_log2_alpha2 = log2(s.cc_alpha2);
    s.cc_norm = gtr1_norm(s.cc_alpha2);
    s.ior_n = vec3(1.0);
    s.ior_k = vec3(0.0);
    if (MODEL_FRESNEL != FRESNEL_SCHLICK) {
        vec3 edge = MODEL_FRESNEL == FRESNEL_CONDUCTOR ? m.ior_edge : vec3(0.0);
        for (int c = 0; c < 3; c++) {
            vec2 nk = complex_ior(s.cspec0[c], edge[c]);
            s.ior_n[c] = nk.x;
            s.ior_k[c] = nk.y;
        }
    }
    s.ms_scale = vec3(0.0);
    s.ms_fresnel = vec3(0.0);
#ifdef ENERGY_TABLE_BINDING
    if (MODEL_ENERGY_COMPENSATION != 0u) {
        add_energy_compensation(s);
    }
#endif
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

// GTR with exponent γ, isotropic: c/(α²·cos²θh + sin²θh)^γ, from ln c, in logarithms (both c
// and the power leave a float's range at the ends of γ's).
float gtr_gamma(vec3 h, float alpha2, float log_norm, float gamma) {
    return exp(log_norm - gamma * log(alpha2 * h.z * h.z + h.x * h.x + h.y * h.y));
}

// Anisotropic Beckmann: exp(−tan²θh·(cos²φ/αx² + sin²φ/αy²))/(π·αx·αy·cos⁴θh).
float beckmann_aniso(vec3 h, float ax, float ay) {
    float z2 = h.z * h.z;
    if (z2 <= 0.0) {
        return 0.0;
    }
    float x = h.x / ax;
    float y = h.y / ay;
    return exp(-(x * x + y * y) / z2) / (PI * ax * ay * z2 * z2);
}

// The specular distribution of the model, for a unit half vector in the upper hemisphere (the
// GTR and Beckmann forms are even in h, as GTR1's is).
float specular_d(Lobes s, vec3 h) {
    if (MODEL_SPECULAR_D == SPECULAR_D_BECKMANN) {
        return beckmann_aniso(h, s.ax, s.ay);
    }
    if (MODEL_SPECULAR_D == SPECULAR_D_GTR) {
        return gtr_gamma(h, s.ax * s.ax, s.d_log_norm, MODEL_GTR_GAMMA);
    }
    return gtr2_aniso(h, s.ax, s.ay);
}

// Smith G for anisotropic GGX with 1/(4·N·W) folded in: g(W) of the shading model in docs/shading.md.
float smith_g_aniso(vec3 w, float ax, float ay) {
    float x = w.x * ax;
    float y = w.y * ay;
    return 1.0 / (w.z + sqrt(x * x + y * y + w.z * w.z));
}

// erfc(x) for x ≥ 0 (Abramowitz and Stegun 7.1.26, absolute error below 1.5e-7), as the
// polynomial times e^(−x²), so that the Beckmann Λ keeps its accuracy where erfc is tiny.
float erfc_poly(float x) {
    float t = 1.0 / (1.0 + 0.3275911 * x);
    return t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
}

// Smith Λ of anisotropic Beckmann, with a = cotθ/α(φ): (erf(a) − 1)/2 + e^(−a²)/(2a√π).
float beckmann_lambda(vec3 w, float ax, float ay) {
    float x = w.x * ax;
    float y = w.y * ay;
    float t = sqrt(x * x + y * y);
    if (t <= 0.0) {
        return 0.0;
    }
    float a = w.z / t;
    float e = exp(-a * a);
    return e * (0.28209479177387814 / a - 0.5 * erfc_poly(a));
}

// Smith Λ of the model's distribution family (GTR-γ has none in closed form and uses GGX's, as
// the 2012 notes pair GTR1 with a GGX G).
float smith_lambda(vec3 w, float gx, float gy) {
    if (MODEL_SPECULAR_D == SPECULAR_D_BECKMANN) {
        return beckmann_lambda(w, gx, gy);
    }
    float x = w.x * gx;
    float y = w.y * gy;
    return 0.5 * (sqrt(x * x + y * y + w.z * w.z) / w.z - 1.0);
}

// G1(W)/(2·N·W) of the model's distribution family: the separable g(W).
float smith_g(vec3 w, float gx, float gy) {
    if (MODEL_SPECULAR_D == SPECULAR_D_BECKMANN) {
        return 1.0 / (2.0 * w.z * (1.0 + beckmann_lambda(w, gx, gy)));
    }
    return smith_g_aniso(w, gx, gy);
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
    float g_spec;      // g(V) of the specular lobe's shadowing
    float g_vndf;      // g(V) of GGX at the distribution's alphas, for the visible-normal pdf
    float lambda_v;    // Λ(V) of the shadowing, for the height-correlated G
    float g_coat;      // g25(V) of the clearcoat
    float ms_v;        // 1 − E(N·V) of the energy compensation
};

View make_view(Lobes s, vec3 v) {
    View view;
    view.v = v;
    view.v_stretched = normalize(vec3(s.ax * v.x, s.ay * v.y, v.z));
    view.fv = schlick_weight(v.z);
    view.g_spec = smith_g(v, s.gx, s.gy);
    view.g_vndf = smith_g_aniso(v, s.ax, s.ay);
    view.lambda_v = MODEL_SPECULAR_G == SPECULAR_G_HEIGHT_CORRELATED ? smith_lambda(v, s.gx, s.gy) : 0.0;
    view.g_coat = smith_g_clearcoat(v.z);
    view.ms_v = 0.0;
#ifdef ENERGY_TABLE_BINDING
    if (MODEL_ENERGY_COMPENSATION != 0u) {
        view.ms_v = 1.0 - energy_albedo(v.z, s.roughness);
    }
#endif
    return view;
}

// The half vector of a pair of directions and the two microfacet distributions at it.
struct HalfVector {
    vec3 h;        // normalize(l + v), or 0 when l = −v
    float d_spec;  // the specular D(h)
    float d_coat;  // GTR1 D(h)
};

HalfVector make_half_vector(Lobes s, vec3 l, vec3 v) {
    HalfVector hv;
    vec3 sum = l + v;
    float len2 = dot(sum, sum);
    hv.h = len2 > 0.0 ? sum * inversesqrt(len2) : vec3(0.0);
    hv.d_spec = len2 > 0.0 ? specular_d(s, hv.h) : 0.0;
    hv.d_coat = SCENE_CLEARCOAT != 0u && len2 > 0.0 ? gtr1(hv.h, s.cc_alpha2, s.cc_norm) : 0.0;
    return hv;
}

// The unpolarised Fresnel reflectance of a surface of complex IOR n + ik at incidence cos θ = c:
// the conductor equations, which for k = 0 are the dielectric ones.
float fresnel_complex(float n, float k, float c) {
    float c2 = c * c;
    float s2 = 1.0 - c2;
    float t0 = n * n - k * k - s2;
    float a2b2 = sqrt(t0 * t0 + 4.0 * n * n * k * k);
    float a = sqrt(max(0.5 * (a2b2 + t0), 0.0));
    float t1 = a2b2 + c2;
    float t2 = 2.0 * a * c;
    float rs = (t1 - t2) / (t1 + t2);
    float t3 = c2 * a2b2 + s2 * s2;
    float t4 = t2 * s2;
    float rp = rs * (t3 - t4) / (t3 + t4);
    return 0.5 * (rp + rs);
}

// The specular Fresnel colour at cos θd = cd, with fh = S(cd).
vec3 specular_fresnel(Lobes s, float cd, float fh) {
    if (MODEL_FRESNEL == FRESNEL_SCHLICK) {
        return mix(s.cspec0, vec3(1.0), fh);
    }
    float c = clamp(cd, 0.0, 1.0);
    return vec3(fresnel_complex(s.ior_n.r, s.ior_k.r, c), fresnel_complex(s.ior_n.g, s.ior_k.g, c),
                fresnel_complex(s.ior_n.b, s.ior_k.b, c));
}

// cos(φl − φv) of two directions, or 0 when either is along the normal (where every model that
// uses it multiplies it by zero).
float cos_phi_difference(vec3 l, vec3 v) {
    float ll = dot(l.xy, l.xy);
    float vv = dot(v.xy, v.xy);
    return ll > 0.0 && vv > 0.0 ? dot(l.xy, v.xy) * inversesqrt(ll * vv) : 0.0;
}

// The diffuse BRDFs of seed 004 other than Burley's, with the base colour: f_d(l, v). Roughness
// maps to each model's own: σ = roughness (radians) for Oren–Nayar and Fujii, α = roughness² for
// Gotanda's GGX+Smith fit and Hammon's.
vec3 diffuse_model(Lobes s, vec3 l, vec3 v, vec3 h, float cd, float fl, float fv) {
    float cl = l.z;
    float cv = v.z;
    vec3 rho = s.base_color;
    float r = s.roughness;
    if (MODEL_DIFFUSE == DIFFUSE_FROSTBITE) {
        // Lagarde and de Rousiers 2014: Burley's retro-reflection, renormalised.
        float energy_bias = 0.5 * r;
        float energy_factor = mix(1.0, 1.0 / 1.51, r);
        float fd90 = energy_bias + 2.0 * cd * cd * r;
        return rho * (INV_PI * mix(1.0, fd90, fl) * mix(1.0, fd90, fv) * energy_factor);
    }
    if (MODEL_DIFFUSE == DIFFUSE_OREN_NAYAR || MODEL_DIFFUSE == DIFFUSE_OREN_NAYAR_QUALITATIVE) {
        // α = max(θl, θv), β = min(θl, θv); their sines and tangents come from the cosines, and
        // tan((α+β)/2) = (sin α + sin β)/(cos α + cos β), so only the full model's polynomial
        // terms need the angles themselves.
        float sigma2 = r * r;
        float cos_alpha = min(cl, cv);
        float cos_beta = max(cl, cv);
        float sin_alpha = sqrt(max(1.0 - cos_alpha * cos_alpha, 0.0));
        float sin_beta = sqrt(max(1.0 - cos_beta * cos_beta, 0.0));
        float tan_beta = sin_beta / cos_beta;
        float cos_phi = cos_phi_difference(l, v);
        if (MODEL_DIFFUSE == DIFFUSE_OREN_NAYAR_QUALITATIVE) {
            float a = 1.0 - 0.5 * sigma2 / (sigma2 + 0.33);
            float b = 0.45 * sigma2 / (sigma2 + 0.09);
            return rho * (INV_PI * (a + b * max(0.0, cos_phi) * sin_alpha * tan_beta));
        }
        // Oren and Nayar 1994, the Gaussian model: direct illumination plus interreflection.
        float alpha = acos(clamp(cos_alpha, -1.0, 1.0));
        float beta = acos(clamp(cos_beta, -1.0, 1.0));
        float s9 = sigma2 / (sigma2 + 0.09);
        float c1 = 1.0 - 0.5 * sigma2 / (sigma2 + 0.33);
        float two_beta_pi = 2.0 * beta * INV_PI;
        float c2 = 0.45 * s9 * (cos_phi >= 0.0 ? sin_alpha : sin_alpha - two_beta_pi * two_beta_pi * two_beta_pi);
        float four_ab = 4.0 * alpha * beta * INV_PI * INV_PI;
        float c3 = 0.125 * s9 * four_ab * four_ab;
        float tan_half = (sin_alpha + sin_beta) / (cos_alpha + cos_beta);
        float direct = c1 + cos_phi * c2 * tan_beta + (1.0 - abs(cos_phi)) * c3 * tan_half;
        float inter = 0.17 * sigma2 / (sigma2 + 0.13) * (1.0 - cos_phi * two_beta_pi * two_beta_pi);
        return INV_PI * (rho * direct + rho * rho * inter);
    }
    if (MODEL_DIFFUSE == DIFFUSE_OREN_NAYAR_FUJII) {
        // Fujii's improved Oren–Nayar, with his constants for σ in [0, 1].
        float st = dot(l, v) - cl * cv;
        float t = st <= 0.0 ? 1.0 : max(cl, cv);
        float a = 1.0 / (PI + (0.5 * PI - 2.0 / 3.0) * r);
        return rho * (a + r * a * st / t);
    }
    if (MODEL_DIFFUSE == DIFFUSE_GOTANDA) {
        // Gotanda 2014, Oren–Nayar with GGX+Smith: the fit of f·cosθl, divided by cosθl here.
        float sg = r * r;
        float sg2 = sg * sg;
        float f0 = min(0.08 * s.specular, 1.0);
        float fr = (1.0 - (0.542026 * sg2 + 0.303573 * sg) / (sg2 + 1.36053))
                 * (1.0 - pow(1.0 - cv, 5.0 - 4.0 * sg2) / (sg2 + 1.36053))
                 * ((-0.733996 * sg2 * sg + 1.50912 * sg2 - 1.16402 * sg) * pow(1.0 - cv, 1.0 + 1.0 / (39.0 * sg2 * sg2 + 1.0)) + 1.0);
        float lm_over_cl = (max(1.0 - 2.0 * sg, 0.0) * (1.0 - schlick_weight(cl)) + min(2.0 * sg, 1.0))
                         * ((1.0 - 0.5 * sg) + 0.5 * sg * cl);
        float vd = (sg2 / ((sg2 + 0.09) * (1.31072 + 0.995584 * cv)))
                 * (1.0 - pow(1.0 - cl, (1.0 - 0.3726732 * cv * cv) / (0.188566 + 0.38841 * cv)));
        float bp = dot(l, v) - cv * cl;
        if (bp < 0.0) {
            bp *= 1.4 * cv * cl;
        }
        return rho * (21.0 / (20.0 * PI) * (1.0 - f0) * (fr * lm_over_cl + vd * bp / cl));
    }
    if (MODEL_DIFFUSE == DIFFUSE_HAMMON) {
        // Hammon 2017: GGX+Smith diffuse, single scattering plus a multiple-scattering term.
        float alpha = r * r;
        float facing = 0.5 + 0.5 * dot(l, v);
        float rough = h.z > 0.0 ? facing * (0.9 - 0.4 * facing) * ((0.5 + h.z) / h.z) : 0.0;
        float smooth_term = 1.05 * (1.0 - fl) * (1.0 - fv);
        float single = INV_PI * mix(smooth_term, rough, alpha);
        float multi = 0.1159 * alpha;
        return rho * (single + rho * multi);
    }
    return rho * INV_PI;  // Lambert
}

// The specular lobe's shadowing with 1/(4·N·L·N·V) folded in.
float specular_shadowing(Lobes s, View view, vec3 l) {
    if (MODEL_SPECULAR_G == SPECULAR_G_HEIGHT_CORRELATED) {
        return 1.0 / (4.0 * l.z * view.v.z * (1.0 + smith_lambda(l, s.gx, s.gy) + view.lambda_v));
    }
    return smith_g(l, s.gx, s.gy) * view.g_spec;
}

// f(l, v) by lobe, each term as it enters f: diffuse (with subsurface) and sheen are still to be
// weighted by 1 − metallic, which lobes_total applies. Zero unless both directions are above
// the surface, which also avoids the reference code's 0/0 when both are at grazing.
struct BrdfLobes {
    vec3 diffuse;
    vec3 sheen;
    vec3 specular;
    float clearcoat;
};

BrdfLobes disney_lobes(Lobes s, View view, vec3 l, HalfVector hv) {
    BrdfLobes b = BrdfLobes(vec3(0.0), vec3(0.0), vec3(0.0), 0.0);
    float cl = l.z;
    float cv = view.v.z;
    if (cl <= 0.0 || cv <= 0.0) {
        return b;
    }
    float cd = dot(l, hv.h);
    float fl = schlick_weight(cl);
    float fh = schlick_weight(cd);

    if (SCENE_DIFFUSE != 0u) {
        // Diffuse: Schlick-style retro-reflection, and the Hanrahan–Krueger-like subsurface.
        float cd2r = cd * cd * s.roughness;
        float fss = mix(1.0, cd2r, fl) * mix(1.0, cd2r, view.fv);
        float ss = 1.25 * (fss * (1.0 / (cl + cv) - 0.5) + 0.5);
        if (MODEL_DIFFUSE == DIFFUSE_BURLEY2012) {
            float fd90 = 0.5 + 2.0 * cd2r;
            float fd = mix(1.0, fd90, fl) * mix(1.0, fd90, view.fv);
            b.diffuse = (INV_PI * mix(fd, ss, s.subsurface)) * s.base_color;
        } else {
            vec3 fd = diffuse_model(s, l, view.v, hv.h, cd, fl, view.fv);
            b.diffuse = mix(fd, (INV_PI * ss) * s.base_color, s.subsurface);
        }
        b.sheen = fh * s.sheen_color;
    }

    // Specular: the model's D, G and F (anisotropic GGX, separable Smith, Schlick by default).
    vec3 fs = specular_fresnel(s, cd, fh);
    float gs = specular_shadowing(s, view, l);
    b.specular = (gs * hv.d_spec) * fs;
#ifdef ENERGY_TABLE_BINDING
    if (MODEL_ENERGY_COMPENSATION != 0u) {
        b.specular += s.ms_scale * ((1.0 - energy_albedo(cl, s.roughness)) * view.ms_v);
    }
#endif

    if (SCENE_CLEARCOAT != 0u) {
        // Clearcoat: GTR1 with a fixed IOR 1.5.
        float fr = mix(0.04, 1.0, fh);
        float gr = smith_g_clearcoat(cl) * view.g_coat;
        b.clearcoat = s.clearcoat * gr * fr * hv.d_coat;
    }
    return b;
}

// f, the lobes together: (diffuse + sheen)·(1 − metallic) + specular + clearcoat.
vec3 lobes_total(Lobes s, BrdfLobes b) {
    vec3 f = b.specular;
    if (SCENE_DIFFUSE != 0u) {
        f = (b.diffuse + b.sheen) * (1.0 - s.metallic) + f;
    }
    if (SCENE_CLEARCOAT != 0u) {
        f += vec3(b.clearcoat);
    }
    return f;
}

// f(l, v), without the cosine.
vec3 disney_brdf(Lobes s, View view, vec3 l, HalfVector hv) {
    return lobes_total(s, disney_lobes(s, view, l, hv));
}

#endif
