// BRDF importance sampling and multiple importance sampling (LOOKDEV.md §5).
//
// Directions are in the shading frame (N = +Z). Every sampler has a matching pdf, over solid
// angle, that accounts for every direction it can produce. Mirrored in src/shading/sampling.rs.
#ifndef LOOKDEV_SAMPLING_GLSL
#define LOOKDEV_SAMPLING_GLSL

#include "brdf.glsl"

// Probabilities of picking each lobe for one-sample MIS; they sum to 1.
struct LobeChoice {
    float diffuse;    // diffuse, subsurface and sheen: cosine sampling
    float specular;   // GGX visible normals
    float clearcoat;  // GTR1 half vectors
};

// Picks lobes in proportion to an estimate of their reflectance at this view angle.
LobeChoice choose_lobes(Lobes s, float cos_v) {
    float fv = schlick_weight(cos_v);
    float w_diffuse = (1.0 - s.metallic) * (luminance(s.base_color) + 0.25 * luminance(s.sheen_color));
    float w_specular = luminance(mix(s.cspec0, vec3(1.0), fv));
    float w_clearcoat = s.clearcoat * mix(0.04, 1.0, fv);
    float total = w_diffuse + w_specular + w_clearcoat;
    if (!(total > 0.0)) {
        return LobeChoice(1.0, 0.0, 0.0);
    }
    return LobeChoice(w_diffuse / total, w_specular / total, w_clearcoat / total);
}

// Cosine-weighted hemisphere, by Shirley and Chiu's concentric disk mapping.
vec3 sample_cosine(vec2 u) {
    vec2 d = 2.0 * u - 1.0;
    if (d.x == 0.0 && d.y == 0.0) {
        return vec3(0.0, 0.0, 1.0);
    }
    float r;
    float phi;
    if (abs(d.x) > abs(d.y)) {
        r = d.x;
        phi = (PI / 4.0) * (d.y / d.x);
    } else {
        r = d.y;
        phi = (PI / 2.0) - (PI / 4.0) * (d.x / d.y);
    }
    float z = sqrt(max(0.0, 1.0 - r * r));
    return vec3(r * cos(phi), r * sin(phi), z);
}

float pdf_cosine(vec3 l) {
    return max(l.z, 0.0) * INV_PI;
}

// A GGX microfacet normal visible from v, by Dupuy and Benyoub's spherical caps (2023).
vec3 sample_ggx_visible_normal(vec3 v, float ax, float ay, vec2 u) {
    vec3 vh = normalize(vec3(ax * v.x, ay * v.y, v.z));
    float phi = TWO_PI * u.x;
    float z = (1.0 - u.y) * (1.0 + vh.z) - vh.z;
    float sin_theta = sqrt(clamp(1.0 - z * z, 0.0, 1.0));
    vec3 hh = vec3(sin_theta * cos(phi), sin_theta * sin(phi), z) + vh;
    return normalize(vec3(ax * hh.x, ay * hh.y, hh.z));
}

// pdf of l = reflect(−v, h) for visible-normal sampling: G1(v)·D(h)/(4·N·v) = g(v)·D(h)/2.
float pdf_ggx_reflection(vec3 v, vec3 h, float ax, float ay) {
    return h.z > 0.0 ? 0.5 * smith_g_aniso(v, ax, ay) * gtr2_aniso(h, ax, ay) : 0.0;
}

// A GTR1 half vector (Burley 2012, appendix B): cos²θh = (1 − α^(2(1−u)))/(1 − α²).
vec3 sample_gtr1_normal(float alpha2, vec2 u) {
    float phi = TWO_PI * u.x;
    float cos2 = alpha2 >= 1.0 ? 1.0 - u.y : (1.0 - pow(alpha2, 1.0 - u.y)) / (1.0 - alpha2);
    cos2 = clamp(cos2, 0.0, 1.0);
    float sin_theta = sqrt(1.0 - cos2);
    return vec3(sin_theta * cos(phi), sin_theta * sin(phi), sqrt(cos2));
}

// pdf of l = reflect(−v, h) for GTR1 half-vector sampling: D(h)·(N·h)/(4·|v·h|), where h is
// ±normalize(l + v), whichever is in the upper hemisphere. GTR1 half vectors are not restricted
// to those facing v, so a sample may reflect to below the horizon through a half vector opposite
// to l + v; counting those keeps the pdf exact over the whole sphere.
float pdf_gtr1_reflection(vec3 v, vec3 h, float alpha2, float norm) {
    h = h.z < 0.0 ? -h : h;
    float vh = abs(dot(v, h));
    return vh > 0.0 ? gtr1(h, alpha2, norm) * h.z / (4.0 * vh) : 0.0;
}

// The one-sample MIS pdf of sample_brdf: Σ pᵢ·pdfᵢ(l).
float brdf_pdf(Lobes s, LobeChoice c, vec3 l, vec3 v) {
    vec3 sum = l + v;
    float len2 = dot(sum, sum);
    float pdf = c.diffuse * pdf_cosine(l);
    if (len2 > 0.0) {
        vec3 h = sum * inversesqrt(len2);
        if (c.specular > 0.0) {
            pdf += c.specular * pdf_ggx_reflection(v, h, s.ax, s.ay);
        }
        if (c.clearcoat > 0.0) {
            pdf += c.clearcoat * pdf_gtr1_reflection(v, h, s.cc_alpha2, s.cc_norm);
        }
    }
    return pdf;
}

// Picks a lobe with u.x, then reuses u.x, rescaled to [0, 1), for that lobe's own sample, so a
// stratified u stays stratified within each lobe.
vec3 sample_brdf(Lobes s, LobeChoice c, vec3 v, vec2 u) {
    if (u.x < c.diffuse) {
        u.x = min(u.x / c.diffuse, ONE_MINUS_EPSILON);
        return sample_cosine(u);
    }
    u.x -= c.diffuse;
    if (u.x < c.specular || c.clearcoat <= 0.0) {
        u.x = min(u.x / c.specular, ONE_MINUS_EPSILON);
        vec3 h = sample_ggx_visible_normal(v, s.ax, s.ay, u);
        return reflect(-v, h);
    }
    u.x = min((u.x - c.specular) / c.clearcoat, ONE_MINUS_EPSILON);
    vec3 h = sample_gtr1_normal(s.cc_alpha2, u);
    return reflect(-v, h);
}

// The power heuristic (β = 2) for one sample from each of two techniques, divided by the sampling
// technique's own pdf: the factor that multiplies f·cosθ·L for a sample drawn with pdf `own`.
float mis_weight_over_pdf(float own, float other) {
    return own / (own * own + other * other);
}

#endif
