// BRDF importance sampling and multiple importance sampling (docs/shading.md#sampling).
//
// Directions are in the shading frame (N = +Z). Every sampler has a matching pdf, over solid
// angle, that accounts for every direction it can produce. The samplers take the azimuth as
// (cos φ, sin φ), so that sample_brdf computes it once whichever lobe it picks: lanes that pick
// different lobes then diverge only over a few lines. Mirrored in src/shading/sampling.rs.
#ifndef LOOKDEV_SAMPLING_GLSL
#define LOOKDEV_SAMPLING_GLSL

#include "brdf.glsl"

// Probabilities of picking each lobe for one-sample MIS; they sum to 1.
struct LobeChoice {
    float diffuse;    // diffuse, subsurface and sheen: cosine sampling
    float specular;   // GGX visible normals, or the model's distribution of normals
    float clearcoat;  // GTR1 half vectors
};

// Whether any pixel's BRDF sample may be drawn from the cosine lobe: the diffuse lobes', and the
// energy compensation's, whose multiple-scattering lobe is sampled so even on a metal.
const bool COSINE_LOBE = SCENE_DIFFUSE != 0u || MODEL_ENERGY_COMPENSATION != 0u;

// Picks lobes in proportion to an estimate of their reflectance at this view angle.
LobeChoice choose_lobes(Lobes s, View view) {
    float w_diffuse = SCENE_DIFFUSE != 0u ? (1.0 - s.metallic) * (luminance(s.base_color) + 0.25 * luminance(s.sheen_color)) : 0.0;
    if (MODEL_ENERGY_COMPENSATION != 0u) {
        // The multiple-scattering lobe is nearly cosine-shaped; its albedo is F_ms·(1 − E(μv)).
        w_diffuse += luminance(s.ms_fresnel) * view.ms_v;
    }
    float w_specular = luminance(mix(s.cspec0, vec3(1.0), view.fv));
    float w_clearcoat = SCENE_CLEARCOAT != 0u ? s.clearcoat * mix(0.04, 1.0, view.fv) : 0.0;
    float total = w_diffuse + w_specular + w_clearcoat;
    if (!(total > 0.0)) {
        return LobeChoice(1.0, 0.0, 0.0);
    }
    return LobeChoice(w_diffuse / total, w_specular / total, w_clearcoat / total);
}

// (cos φ, sin φ) for φ = 2π·x.
vec2 azimuth(float x) {
    float phi = TWO_PI * x;
    return vec2(cos(phi), sin(phi));
}

// Cosine-weighted hemisphere: a uniform disk (r = √u) lifted to the hemisphere.
vec3 sample_cosine(vec2 azimuth, float u) {
    float r = sqrt(u);
    return vec3(r * azimuth, sqrt(max(0.0, 1.0 - u)));
}

float pdf_cosine(vec3 l) {
    return max(l.z, 0.0) * INV_PI;
}

// A GGX microfacet normal visible from v, by Dupuy and Benyoub's spherical caps (2023), given v
// in the hemisphere configuration (View.v_stretched).
vec3 sample_ggx_visible_normal(vec3 v_stretched, float ax, float ay, vec2 azimuth, float u) {
    float z = (1.0 - u) * (1.0 + v_stretched.z) - v_stretched.z;
    float sin_theta = sqrt(clamp(1.0 - z * z, 0.0, 1.0));
    vec3 h = vec3(sin_theta * azimuth, z) + v_stretched;
    return normalize(vec3(ax * h.x, ay * h.y, h.z));
}

// pdf of l = reflect(−v, h) for visible-normal sampling: G1(v)·D(h)/(4·N·v) = g(v)·D(h)/2.
float pdf_ggx_reflection(View view, HalfVector hv) {
    return hv.h.z > 0.0 ? 0.5 * view.g_vndf * hv.d_spec : 0.0;
}

// A Beckmann normal, from the distribution of normals D(h)·cosθh: Gaussian slopes, stretched.
vec3 sample_beckmann_normal(float ax, float ay, vec2 azimuth, float u) {
    float r = sqrt(-log(1.0 - u));
    return normalize(vec3(ax * r * azimuth.x, ay * r * azimuth.y, 1.0));
}

// A GTR-γ normal from D(h)·cosθh (Burley 2012, appendix B): with s = 1 + (α²−1)·cos²θh,
// s^(1−γ) = (1−u)·α^(2(1−γ)) + u; γ = 1 is GTR1's logarithmic form. Written with expm1 and log1p
// so that it stays accurate as α → 1, where 1 − s and 1 − α² both vanish.
vec3 sample_gtr_normal(float alpha2, float gamma, vec2 azimuth, float u) {
    float cos2;
    if (alpha2 >= 1.0) {
        cos2 = 1.0 - u;
    } else {
        float log_alpha2 = log_accurate(alpha2);
        float one_minus_s;
        if (abs(gamma - 1.0) < 1e-4) {
            one_minus_s = -expm1_accurate(log_alpha2 * (1.0 - u));
        } else {
            // ln s = ln((1−u)·e^l + u)/(1−γ); for l > 0 as l + ln(1 + u·(e^−l − 1)), where e^l
            // would overflow at the ends of γ's range.
            float e = 1.0 - gamma;
            float l = e * log_alpha2;
            float log_s = (l > 0.0 ? l + log1p_accurate(u * expm1_accurate(-l))
                                   : log1p_accurate((1.0 - u) * expm1_accurate(l))) / e;
            one_minus_s = -expm1_accurate(log_s);
        }
        cos2 = one_minus_s / (1.0 - alpha2);
    }
    cos2 = clamp(cos2, 0.0, 1.0);
    return vec3(sqrt(1.0 - cos2) * azimuth, sqrt(cos2));
}

// pdf of l = reflect(−v, h) when h is drawn from D(h)·cosθh: D(h)·|N·h|/(4·|v·h|), counting both
// half vectors ±normalize(l + v), as for GTR1 below.
float pdf_normal_reflection(float d, View view, vec3 h) {
    float vh = abs(dot(view.v, h));
    return vh > 0.0 ? d * abs(h.z) / (4.0 * vh) : 0.0;
}

// pdf of the specular sampler of the model.
float pdf_specular_reflection(View view, HalfVector hv) {
    if (MODEL_SPECULAR_D == SPECULAR_D_GTR2) {
        return pdf_ggx_reflection(view, hv);
    }
    return pdf_normal_reflection(hv.d_spec, view, hv.h);
}

// A specular half vector of the model: GGX visible normals, or the distribution of normals.
vec3 sample_specular_normal(Lobes s, View view, vec2 azimuth, float u) {
    if (MODEL_SPECULAR_D == SPECULAR_D_BECKMANN) {
        return sample_beckmann_normal(s.ax, s.ay, azimuth, u);
    }
    if (MODEL_SPECULAR_D == SPECULAR_D_GTR) {
        return sample_gtr_normal(s.ax * s.ax, MODEL_GTR_GAMMA, azimuth, u);
    }
    return sample_ggx_visible_normal(view.v_stretched, s.ax, s.ay, azimuth, u);
}

// A GTR1 half vector (Burley 2012, appendix B): cos²θh = (1 − α^(2(1−u)))/(1 − α²).
vec3 sample_gtr1_normal(float alpha2, float log2_alpha2, vec2 azimuth, float u) {
    float cos2 = alpha2 >= 1.0 ? 1.0 - u : (1.0 - exp2(log2_alpha2 * (1.0 - u))) / (1.0 - alpha2);
    cos2 = clamp(cos2, 0.0, 1.0);
    return vec3(sqrt(1.0 - cos2) * azimuth, sqrt(cos2));
}

// pdf of l = reflect(−v, h) for GTR1 half-vector sampling: D(h)·(N·h)/(4·|v·h|), with h the one
// of ±normalize(l + v) in the upper hemisphere. GTR1 half vectors are not restricted to those
// facing v, so a sample may reflect to below the horizon through a half vector opposite to
// l + v; counting those keeps the pdf exact over the whole sphere. D is even in h.
float pdf_gtr1_reflection(View view, HalfVector hv) {
    float vh = abs(dot(view.v, hv.h));
    return vh > 0.0 ? hv.d_coat * abs(hv.h.z) / (4.0 * vh) : 0.0;
}

// The one-sample MIS pdf of sample_brdf: Σ pᵢ·pdfᵢ(l).
float brdf_pdf(LobeChoice c, View view, vec3 l, HalfVector hv) {
    float pdf = COSINE_LOBE ? c.diffuse * pdf_cosine(l) : 0.0;
    if (c.specular > 0.0) {
        pdf += c.specular * pdf_specular_reflection(view, hv);
    }
    if (SCENE_CLEARCOAT != 0u && c.clearcoat > 0.0) {
        pdf += c.clearcoat * pdf_gtr1_reflection(view, hv);
    }
    return pdf;
}

// Picks a lobe with u.x, then reuses u.x, rescaled to [0, 1) within the lobe's interval, for
// the azimuth, so a stratified u stays stratified within each lobe.
vec3 sample_brdf(Lobes s, LobeChoice c, View view, vec2 u) {
    float x;
    uint lobe;
    if (COSINE_LOBE && u.x < c.diffuse) {
        lobe = 0u;
        x = u.x / c.diffuse;
    } else if (SCENE_CLEARCOAT == 0u || u.x < c.diffuse + c.specular || c.clearcoat <= 0.0) {
        lobe = 1u;
        x = (u.x - c.diffuse) / c.specular;
    } else {
        lobe = 2u;
        x = (u.x - c.diffuse - c.specular) / c.clearcoat;
    }
    vec2 phi = azimuth(min(x, ONE_MINUS_EPSILON));
    if (COSINE_LOBE && lobe == 0u) {
        return sample_cosine(phi, u.y);
    }
    vec3 h = SCENE_CLEARCOAT == 0u || lobe == 1u ? sample_specular_normal(s, view, phi, u.y)
                                                 : sample_gtr1_normal(s.cc_alpha2, s.cc_log2_alpha2, phi, u.y);
    return reflect(-view.v, h);
}

// The power heuristic (β = 2) for one sample from each of two techniques, divided by the sampling
// technique's own pdf: the factor that multiplies f·cosθ·L for a sample drawn with pdf `own`.
float mis_weight_over_pdf(float own, float other) {
    return own / (own * own + other * other);
}

#endif
