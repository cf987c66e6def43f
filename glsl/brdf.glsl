// brdf.glsl: the BSDFs of the lecture (materials-lecture.txt) with eval, pdf and importance
// sampling in the local shading frame, used by every integrator and by brdf_test.comp.
// Lambert f = C = albedo/pi; the mirror f = delta(wi - r(wo)) / (n.wi); normalised Phong
// (Lafortune & Willems 1994) and Blinn-Phong; Torrance-Sparrow f = F D G / (4 (n.wo)(n.wi))
// with Blinn's D = (e+2)/(2pi) (n.wh)^e and the V-cavity G (Cook & Torrance 1982); Beckmann
// and GGX with height-correlated Smith G (Heitz 2014), GGX sampled by visible normals (Heitz
// 2018); rough dielectrics after Walter et al. 2007 as written in pbrt-v4; the exact
// dielectric and conductor Fresnel equations and Schlick's approximation. docs/brdf.md
// derives each one and names the test that checks it.
//
// Conventions: normal = +z; wo points to the viewer, wi to the light, both away from the
// surface. bsdf_eval returns f (no cosine); bsdf_pdf is the solid-angle density with which
// bsdf_sample picks wi; Dirac lobes are not in eval/pdf, only in sample (BRDF_FLAG_DELTA).
// Transmission transports importance (flux): the 1/eta^2 radiance scale is left out, so
// R + T = 1 at a smooth interface; it cancels on closed objects.
#ifndef BRDF_GLSL
#define BRDF_GLSL

#include "brdf_models.h"
#include "sampling.glsl"

#define BRDF_PI 3.14159265358979
// Below this GGX/Beckmann alpha a lobe is treated as smooth (a Dirac lobe): a narrower
// lobe is under a tenth of a degree wide, which float directions cannot resolve.
#define BRDF_ALPHA_MIN 1e-3

// Bsdf.lobe: the one specular lobe
#define BRDF_LOBE_NONE 0u
#define BRDF_LOBE_MIRROR 1u
#define BRDF_LOBE_PHONG 2u
#define BRDF_LOBE_BLINN 3u
#define BRDF_LOBE_TS 4u // Torrance-Sparrow: Blinn's D, V-cavity G
#define BRDF_LOBE_BECKMANN 5u
#define BRDF_LOBE_GGX 6u

// Bsdf.fresnel: the Fresnel factor of the lobe
#define BRDF_FRESNEL_NONE 0u       // the lobe's weight only
#define BRDF_FRESNEL_DIELECTRIC 1u // exact, index ior
#define BRDF_FRESNEL_CONDUCTOR 2u  // exact, complex index eta + i k
#define BRDF_FRESNEL_SCHLICK 3u    // F0 = specular, F90 = f90

// A sum of BRDFs (the lecture's "adding BRDFs"): a Lambert layer, one specular lobe and a
// dielectric interface (reflection + refraction), each with its weight.
struct Bsdf {
    vec3 diffuse; uint lobe;          // Lambert weight kd; the lobe's kind
    vec3 specular; uint fresnel;      // lobe weight ks (Schlick: F0); the lobe's Fresnel
    vec3 eta; float shape;            // conductor index; exponent (Phong, Blinn) or alpha
    vec3 k; float ior;                // conductor extinction; dielectric index (in / out)
    vec3 tint; float dielectric;      // dielectric part: transmission tint, weight (0: none)
    vec3 couple_f0; float couple_f90; // Schlick of the layer over the diffuse (0, 0: none)
    float f90;                        // Schlick F90 of the lobe
};

struct BsdfSample {
    vec3 wi;
    vec3 weight; // f |n.wi| / pdf; for a Dirac lobe its reflectance over its probability
    float pdf;   // solid-angle pdf; for a Dirac lobe the probability of choosing it
    uint flags;  // BRDF_FLAG_*; 0 when no direction was sampled (weight 0)
};

// ---- Fresnel --------------------------------------------------------------------------

// The lecture's dielectric Fresnel: r_par, r_perp and F_r = (r_par^2 + r_perp^2) / 2 for
// unpolarised light (F_t = 1 - F_r). eta = eta_inside / eta_outside with the normal on the
// outside; cos_i < 0 means light arrives from inside. 1 under total internal reflection.
float brdf_fresnel_dielectric(float cos_i, float eta)
{
    cos_i = clamp(cos_i, -1.0, 1.0);
    if (cos_i < 0.0) {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    float sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0)
        return 1.0;
    float cos_t = sqrt(1.0 - sin2_t);
    float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (r_par * r_par + r_perp * r_perp);
}

// Unpolarised reflectance of a conductor with complex index eta + i k seen from a medium of
// index 1 (the closed form of the Fresnel equations with a complex cos_t, as in pbrt).
vec3 brdf_fresnel_conductor(float cos_i, vec3 eta, vec3 k)
{
    float c = clamp(cos_i, 0.0, 1.0), c2 = c * c, s2 = 1.0 - c2;
    vec3 eta2 = eta * eta, k2 = k * k;
    vec3 t0 = eta2 - k2 - s2;
    vec3 a2b2 = sqrt(t0 * t0 + 4.0 * eta2 * k2);
    vec3 t1 = a2b2 + c2;
    vec3 a = sqrt(max(0.5 * (a2b2 + t0), 0.0));
    vec3 t2 = 2.0 * c * a;
    vec3 rs = (t1 - t2) / (t1 + t2);
    vec3 t3 = c2 * a2b2 + s2 * s2;
    vec3 t4 = t2 * s2;
    vec3 rp = rs * (t3 - t4) / (t3 + t4);
    return 0.5 * (rp + rs);
}

// Schlick's approximation F = F0 + (F90 - F0)(1 - cos)^5 (the lecture has F90 = 1).
vec3 brdf_fresnel_schlick(float cos_i, vec3 f0, float f90)
{
    float m = clamp(1.0 - cos_i, 0.0, 1.0), m2 = m * m;
    return f0 + (f90 - f0) * (m2 * m2 * m);
}

// F0 = ((eta_t - eta_i) / (eta_t + eta_i))^2 with eta_i = 1.
float brdf_schlick_f0(float ior)
{
    float r = (ior - 1.0) / (ior + 1.0);
    return r * r;
}

// ---- microfacet distributions and masking ----------------------------------------------

// GLSL leaves pow(0, 0) undefined; a cosine <= 0 is outside every lobe here.
float brdf_pow(float x, float e)
{
    return x > 0.0 ? pow(x, e) : 0.0;
}

// Blinn's distribution as the lecture writes it: D = (e + 2) / (2 pi) (wh.n)^e.
float brdf_d_blinn(float cos_h, float e)
{
    return (e + 2.0) / (2.0 * BRDF_PI) * brdf_pow(cos_h, e);
}

float brdf_d_beckmann(vec3 h, float a)
{
    float c2 = h.z * h.z;
    if (h.z <= 0.0)
        return 0.0;
    return exp(-dot(h.xy, h.xy) / (c2 * a * a)) / (BRDF_PI * a * a * c2 * c2);
}

// Trowbridge-Reitz: D = a^2 / (pi (cos^2 (a^2 - 1) + 1)^2), with sin^2 taken from x, y so
// the peak keeps its precision when alpha is small.
float brdf_d_ggx(vec3 h, float a)
{
    if (h.z <= 0.0)
        return 0.0;
    float d = dot(h.xy, h.xy) + h.z * h.z * a * a;
    return a * a / (BRDF_PI * d * d);
}

// Smith G1 of GGX, 2 |c| / (|c| + sqrt(c^2 + a^2 s^2)): no division by a small cosine.
float brdf_g1_ggx(vec3 w, float a)
{
    float c = abs(w.z);
    return 2.0 * c / (c + sqrt(w.z * w.z + a * a * dot(w.xy, w.xy)));
}

// Height-correlated Smith G2 / (4 |n.wo| |n.wi|) of GGX (Heitz 2014, eq. 99), finite at
// grazing angles.
float brdf_v_ggx(vec3 wo, vec3 wi, float a)
{
    float lo = abs(wi.z) * sqrt(wo.z * wo.z + a * a * dot(wo.xy, wo.xy));
    float li = abs(wo.z) * sqrt(wi.z * wi.z + a * a * dot(wi.xy, wi.xy));
    return 0.5 / (lo + li);
}

// Smith Lambda of Beckmann: (erf(m) - 1)/2 + exp(-m^2) / (2 m sqrt(pi)), m = cot / alpha;
// erfc by Numerical Recipes' Chebyshev fit (relative error < 1.2e-7).
float brdf_lambda_beckmann(vec3 w, float a)
{
    float s = length(w.xy);
    if (s == 0.0)
        return 0.0;
    float m = max(abs(w.z) / (a * s), 1e-7);
    float t = 1.0 / (1.0 + 0.5 * m);
    float erfc = t * exp(-m * m - 1.26551223 + t * (1.00002368 + t * (0.37409196 + t * (0.09678418 +
                 t * (-0.18628806 + t * (0.27886807 + t * (-1.13520398 + t * (1.48851587 +
                 t * (-0.82215223 + t * 0.17087277)))))))));
    return max(0.0, 0.5 * (exp(-m * m) / (m * 1.7724538509) - erfc));
}

// Visible normal of GGX seen from w (w.z > 0), Heitz 2018 (JCGT 7(4)): pdf of the normal is
// G1(w) max(0, w.h) D(h) / w.z.
vec3 brdf_ggx_sample_vndf(vec3 w, float a, vec2 u)
{
    vec3 vh = normalize(vec3(a * w.x, a * w.y, w.z));
    float len2 = dot(vh.xy, vh.xy);
    vec3 t1 = len2 > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(len2) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(vh, t1);
    float r = sqrt(u.x), phi = 2.0 * BRDF_PI * u.y;
    float p1 = r * cos(phi), p2 = r * sin(phi);
    float s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3(a * nh.x, a * nh.y, max(0.0, nh.z)));
}

// wo refracted through the interface with normal n and eta = eta_inside / eta_outside
// (n on the outside); false under total internal reflection.
bool brdf_refract(vec3 wo, vec3 n, float eta, out vec3 wt)
{
    float ci = dot(n, wo);
    if (ci < 0.0) {
        eta = 1.0 / eta;
        ci = -ci;
        n = -n;
    }
    float s2t = max(0.0, 1.0 - ci * ci) / (eta * eta);
    wt = vec3(0.0);
    if (s2t >= 1.0)
        return false;
    wt = -wo / eta + (ci / eta - sqrt(1.0 - s2t)) * n;
    return true;
}

// ---- the parts of a Bsdf -----------------------------------------------------------------

// The lobe's Fresnel factor times its weight, at cos = wo.wh.
vec3 brdf_lobe_fresnel(Bsdf b, float c)
{
    if (GN_HAS(GN_FEAT_FRESNEL_DIELECTRIC) && b.fresnel == BRDF_FRESNEL_DIELECTRIC)
        return b.specular * brdf_fresnel_dielectric(c, b.ior);
    if (GN_HAS(GN_FEAT_FRESNEL_CONDUCTOR) && b.fresnel == BRDF_FRESNEL_CONDUCTOR)
        return b.specular * brdf_fresnel_conductor(c, b.eta, b.k);
    if (GN_HAS(GN_FEAT_FRESNEL_SCHLICK) && b.fresnel == BRDF_FRESNEL_SCHLICK)
        return brdf_fresnel_schlick(c, b.specular, b.f90);
    return b.specular;
}

// Lambert under a Fresnel layer: kd/pi (1 - F(wo))(1 - F(wi)) / (1 - F_avg), with
// F_avg = F0 + (F90 - F0)/21 the cosine-weighted mean of Schlick's F. Its albedo is
// kd (1 - F(wo)) (Shirley et al. 1997), it is reciprocal, and with couple_f0 = f90 = 0 it is
// the plain Lambert kd/pi.
vec3 brdf_diffuse(Bsdf b, float co, float ci)
{
    if (!GN_HAS(GN_FEAT_COUPLED)) // couple_f0 = couple_f90 = 0: exactly the plain Lambert
        return b.diffuse / BRDF_PI;
    vec3 fo = brdf_fresnel_schlick(co, b.couple_f0, b.couple_f90);
    vec3 fi = brdf_fresnel_schlick(ci, b.couple_f0, b.couple_f90);
    vec3 avg = b.couple_f0 + (b.couple_f90 - b.couple_f0) / 21.0;
    return b.diffuse / BRDF_PI * (1.0 - fo) * (1.0 - fi) / max(1.0 - avg, vec3(1e-6));
}

// f and pdf of the specular lobe for wo, wi above the surface.
void brdf_lobe(Bsdf b, vec3 wo, vec3 wi, out vec3 f, out float pdf)
{
    f = vec3(0.0);
    pdf = 0.0;
    float n = b.shape;
    if (b.lobe == BRDF_LOBE_NONE || b.lobe == BRDF_LOBE_MIRROR)
        return;
    if (GN_HAS(GN_FEAT_PHONG) && b.lobe == BRDF_LOBE_PHONG) {
        // (n+2)/(2 pi) cos^n of the angle between r(wi) and wo: albedo ks at normal
        // incidence and less elsewhere; sampled about r(wo) with (n+1)/(2 pi) cos^n.
        float v = brdf_pow(dot(vec3(-wi.xy, wi.z), wo), n);
        f = b.specular * ((n + 2.0) / (2.0 * BRDF_PI) * v);
        pdf = (n + 1.0) / (2.0 * BRDF_PI) * v;
        return;
    }
    if (!GN_HAS(GN_FEAT_BLINN | GN_FEAT_TS | GN_FEAT_BECKMANN | GN_FEAT_GGX))
        return;
    vec3 h = normalize(wo + wi);
    float oh = dot(wo, h);
    if (GN_HAS(GN_FEAT_BLINN) && b.lobe == BRDF_LOBE_BLINN) {
        // Normalised so the albedo at normal incidence is exactly ks (docs/brdf.md): the
        // usual (n+8)/(8 pi) exceeds 1 by up to 7%.
        float v = brdf_pow(h.z, n);
        float norm = (n + 2.0) * (n + 4.0) / (8.0 * BRDF_PI * (n + exp2(-0.5 * n)));
        f = b.specular * (norm * v);
        pdf = (n + 1.0) / (2.0 * BRDF_PI) * v / (4.0 * oh);
        return;
    }
    if (!GN_HAS(GN_FEAT_TS | GN_FEAT_BECKMANN | GN_FEAT_GGX))
        return;
    vec3 fr = brdf_lobe_fresnel(b, oh);
    float dv = 0.0, pdf_h = 0.0; // D G / (4 cos_o cos_i); pdf of the normal h
    if (GN_HAS(GN_FEAT_TS) && b.lobe == BRDF_LOBE_TS) {
        float d = brdf_d_blinn(h.z, n);
        float g = min(1.0, 2.0 * h.z * min(wo.z, wi.z) / oh);
        dv = d * g / (4.0 * wo.z * wi.z);
        pdf_h = d * h.z;
    } else if (GN_HAS(GN_FEAT_BECKMANN) && b.lobe == BRDF_LOBE_BECKMANN) {
        float d = brdf_d_beckmann(h, n);
        float g = 1.0 / (1.0 + brdf_lambda_beckmann(wo, n) + brdf_lambda_beckmann(wi, n));
        dv = d * g / (4.0 * wo.z * wi.z);
        pdf_h = d * h.z;
    } else if (GN_HAS(GN_FEAT_GGX) && b.lobe == BRDF_LOBE_GGX) {
        float d = brdf_d_ggx(h, n);
        dv = d * brdf_v_ggx(wo, wi, n);
        pdf_h = brdf_g1_ggx(wo, n) * oh * d / wo.z;
    }
    f = fr * dv;
    pdf = pdf_h / (4.0 * oh);
}

// A direction from the specular lobe's sampling density (may lie below the surface).
vec3 brdf_lobe_sample(Bsdf b, vec3 wo, vec2 u)
{
    float n = b.shape, phi = 2.0 * BRDF_PI * u.y;
    if (GN_HAS(GN_FEAT_PHONG) && b.lobe == BRDF_LOBE_PHONG) {
        vec3 r = vec3(-wo.xy, wo.z), t, bt;
        sampling_basis(r, t, bt);
        float c = pow(u.x, 1.0 / (n + 1.0)), s = sqrt(max(0.0, 1.0 - c * c));
        return (t * cos(phi) + bt * sin(phi)) * s + r * c;
    }
    vec3 h = vec3(0.0, 0.0, 1.0);
    if (GN_HAS(GN_FEAT_GGX) && b.lobe == BRDF_LOBE_GGX) {
        h = brdf_ggx_sample_vndf(wo, n, u);
    } else if (GN_HAS(GN_FEAT_BLINN | GN_FEAT_TS | GN_FEAT_BECKMANN)) {
        float c; // cos of the normal: density (n+1)/(2pi) c^n, D c for TS and Beckmann
        if (GN_HAS(GN_FEAT_BLINN) && b.lobe == BRDF_LOBE_BLINN)
            c = pow(u.x, 1.0 / (n + 1.0));
        else if (GN_HAS(GN_FEAT_TS) && b.lobe == BRDF_LOBE_TS)
            c = pow(u.x, 1.0 / (n + 2.0));
        else
            c = inversesqrt(1.0 - n * n * log(1.0 - u.x));
        float s = sqrt(max(0.0, 1.0 - c * c));
        h = vec3(s * cos(phi), s * sin(phi), c);
    }
    return 2.0 * dot(wo, h) * h - wo;
}

// f and pdf of the rough dielectric (GGX, alpha = shape), either side, reflection and
// refraction, each chosen with its Fresnel probability. The generalised half vector
// wm ~ eta wi + wo (Walter et al. 2007, eqs. 16, 21; pbrt-v4's DielectricBxDF).
void brdf_rough_dielectric(Bsdf b, vec3 wo, vec3 wi, out vec3 f, out float pdf)
{
    f = vec3(0.0);
    pdf = 0.0;
    float co = wo.z, ci = wi.z, a = b.shape;
    if (co == 0.0 || ci == 0.0)
        return;
    bool reflect = co * ci > 0.0;
    float etap = reflect ? 1.0 : (co > 0.0 ? b.ior : 1.0 / b.ior);
    vec3 wm = wi * etap + wo;
    if (dot(wm, wm) < 1e-20)
        return;
    wm = normalize(wm);
    if (wm.z < 0.0)
        wm = -wm;
    float mo = dot(wm, wo), mi = dot(wm, wi);
    if (mo * co <= 0.0 || mi * ci <= 0.0)
        return; // the microfacet faces away from one of the directions
    float fr = brdf_fresnel_dielectric(mo, b.ior);
    float d = brdf_d_ggx(wm, a);
    float v = brdf_v_ggx(wo, wi, a);
    float pdf_m = brdf_g1_ggx(wo, a) * abs(mo) * d / abs(co);
    if (reflect) {
        f = vec3(fr * d * v);
        pdf = fr * pdf_m / (4.0 * abs(mo));
    } else {
        float denom = mi + mo / etap;
        denom *= denom;
        f = b.tint * ((1.0 - fr) * d * 4.0 * v * abs(mi * mo) / denom);
        pdf = (1.0 - fr) * pdf_m * abs(mi) / denom;
    }
}

// Probabilities of sampling the diffuse layer, the lobe and the dielectric from wo: their
// albedo estimates at wo, normalised.
vec3 brdf_part_probs(Bsdf b, vec3 wo)
{
    vec3 p = vec3(0.0);
    if (wo.z > 0.0) {
        vec3 d = b.diffuse * (1.0 - brdf_fresnel_schlick(wo.z, b.couple_f0, b.couple_f90));
        p.x = (d.r + d.g + d.b) / 3.0;
        if (GN_HAS(GN_FEAT_LOBES) && b.lobe != BRDF_LOBE_NONE) {
            vec3 s = brdf_lobe_fresnel(b, wo.z);
            p.y = (s.r + s.g + s.b) / 3.0;
        }
    }
    if (GN_HAS(GN_FEAT_GLASS) && wo.z != 0.0)
        p.z = b.dielectric;
    float sum = p.x + p.y + p.z;
    return sum > 0.0 ? p / sum : vec3(0.0);
}

// ---- the public BSDF API ------------------------------------------------------------------

// f(wo, wi) and pdf(wo, wi) of the non-Dirac parts, in one pass (light sampling with MIS
// needs both).
void bsdf_eval_pdf(Bsdf b, vec3 wo, vec3 wi, out vec3 f, out float pdf)
{
    vec3 p = brdf_part_probs(b, wo);
    f = vec3(0.0);
    pdf = 0.0;
    if (wo.z > 0.0 && wi.z > 0.0) {
        vec3 fl;
        float pl;
        brdf_lobe(b, wo, wi, fl, pl);
        f = brdf_diffuse(b, wo.z, wi.z) + fl;
        pdf = p.x * wi.z / BRDF_PI + p.y * pl;
    }
    if (GN_HAS(GN_FEAT_ROUGH_GLASS) && b.dielectric > 0.0 && b.shape >= BRDF_ALPHA_MIN) {
        vec3 ft;
        float pt;
        brdf_rough_dielectric(b, wo, wi, ft, pt);
        f += b.dielectric * ft;
        pdf += p.z * pt;
    }
}

vec3 bsdf_eval(Bsdf b, vec3 wo, vec3 wi)
{
    vec3 f;
    float pdf;
    bsdf_eval_pdf(b, wo, wi, f, pdf);
    return f;
}

float bsdf_pdf(Bsdf b, vec3 wo, vec3 wi)
{
    vec3 f;
    float pdf;
    bsdf_eval_pdf(b, wo, wi, f, pdf);
    return pdf;
}

// Picks a part with u.x (then reuses u.x, rescaled, for reflect-or-refract) and a direction
// from it with u.yz. A non-Dirac direction gets the pdf of the whole mixture (one-sample
// MIS over the parts), so weight = eval * |cos| / pdf exactly.
BsdfSample bsdf_sample(Bsdf b, vec3 wo, vec3 u)
{
    BsdfSample s;
    s.wi = vec3(0.0, 0.0, 1.0);
    s.weight = vec3(0.0);
    s.pdf = 0.0;
    s.flags = 0u;
    vec3 p = brdf_part_probs(b, wo);
    vec3 wi;
    bool reflect = true; // the side the chosen part sends wi to: a part's direction that
                         // lands on the other side is no sample of it (pbrt-v4 does the same)
    if (u.x < p.x) {
        wi = sampling_cosine_hemisphere(u.yz);
    } else if (GN_HAS(GN_FEAT_LOBES) && u.x < p.x + p.y) {
        if (GN_HAS(GN_FEAT_MIRROR) && b.lobe == BRDF_LOBE_MIRROR) {
            s.wi = vec3(-wo.xy, wo.z);
            s.pdf = p.y;
            s.weight = brdf_lobe_fresnel(b, wo.z) / p.y;
            s.flags = BRDF_FLAG_REFLECTION | BRDF_FLAG_DELTA;
            return s;
        }
        wi = brdf_lobe_sample(b, wo, u.yz);
    } else if (GN_HAS(GN_FEAT_GLASS) && p.z > 0.0) {
        float x = min((u.x - p.x - p.y) / p.z, 1.0);
        if (GN_HAS(GN_FEAT_SMOOTH_GLASS) && b.shape < BRDF_ALPHA_MIN) {
            float fr = brdf_fresnel_dielectric(wo.z, b.ior);
            if (x < fr) {
                s.wi = vec3(-wo.xy, wo.z);
                s.pdf = p.z * fr;
                s.weight = vec3(b.dielectric / p.z);
                s.flags = BRDF_FLAG_REFLECTION | BRDF_FLAG_DELTA;
            } else if (brdf_refract(wo, vec3(0.0, 0.0, 1.0), b.ior, s.wi)) {
                s.pdf = p.z * (1.0 - fr);
                s.weight = b.dielectric * b.tint / p.z;
                s.flags = BRDF_FLAG_TRANSMISSION | BRDF_FLAG_DELTA;
            }
            return s;
        }
        if (!GN_HAS(GN_FEAT_ROUGH_GLASS))
            return s;
        vec3 wm = brdf_ggx_sample_vndf(wo.z >= 0.0 ? wo : -wo, b.shape, u.yz);
        float mo = dot(wo, wm);
        reflect = x < brdf_fresnel_dielectric(mo, b.ior);
        if (reflect)
            wi = 2.0 * mo * wm - wo;
        else if (!brdf_refract(wo, wm, b.ior, wi))
            return s;
    } else {
        return s;
    }
    if ((wi.z * wo.z > 0.0) != reflect)
        return s;
    vec3 f;
    float pdf;
    bsdf_eval_pdf(b, wo, wi, f, pdf);
    if (!(pdf > 0.0))
        return s;
    s.wi = wi;
    s.pdf = pdf;
    s.weight = f * abs(wi.z) / pdf;
    s.flags = reflect ? BRDF_FLAG_REFLECTION : BRDF_FLAG_TRANSMISSION;
    return s;
}

// ---- construction ---------------------------------------------------------------------------

Bsdf brdf_empty()
{
    Bsdf b;
    b.diffuse = vec3(0.0);
    b.lobe = BRDF_LOBE_NONE;
    b.specular = vec3(0.0);
    b.fresnel = BRDF_FRESNEL_NONE;
    b.eta = vec3(1.0);
    b.shape = 0.0;
    b.k = vec3(0.0);
    b.ior = 1.5;
    b.tint = vec3(1.0);
    b.dielectric = 0.0;
    b.couple_f0 = vec3(0.0);
    b.couple_f90 = 0.0;
    b.f90 = 1.0;
    return b;
}

// The models of brdf_models.h (ids from 1) from a colour and four scalars (the slots there).
Bsdf bsdf_from_model(uint model, vec3 color, vec4 params)
{
    Bsdf b = brdf_empty();
    if (model == BRDF_LAMBERT) {
        b.diffuse = color;
    } else if (model == BRDF_MIRROR) {
        b.lobe = BRDF_LOBE_MIRROR;
        b.specular = color;
    } else if (model >= BRDF_PHONG && model <= BRDF_GGX) {
        b.diffuse = color;
        b.specular = vec3(params[BRDF_P_SPECULAR]);
        b.shape = params[BRDF_P_SHAPE];
        b.ior = params[BRDF_P_IOR];
        b.lobe = model == BRDF_PHONG ? BRDF_LOBE_PHONG
               : model == BRDF_BLINN_PHONG ? BRDF_LOBE_BLINN
               : model == BRDF_TORRANCE_SPARROW ? BRDF_LOBE_TS
               : model == BRDF_BECKMANN ? BRDF_LOBE_BECKMANN : BRDF_LOBE_GGX;
        if (model >= BRDF_TORRANCE_SPARROW)
            b.fresnel = BRDF_FRESNEL_DIELECTRIC;
        if (model >= BRDF_BECKMANN && b.shape < BRDF_ALPHA_MIN)
            b.lobe = BRDF_LOBE_MIRROR;
    } else if (model == BRDF_CONDUCTOR) {
        b.lobe = params[BRDF_P_ALPHA] < BRDF_ALPHA_MIN ? BRDF_LOBE_MIRROR : BRDF_LOBE_GGX;
        b.fresnel = BRDF_FRESNEL_CONDUCTOR;
        b.specular = vec3(1.0);
        b.eta = color;
        b.k = params.xyz;
        b.shape = params[BRDF_P_ALPHA];
    } else if (model == BRDF_DIELECTRIC) {
        b.dielectric = 1.0;
        b.tint = color;
        b.ior = params[BRDF_P_DIELECTRIC_IOR];
        b.shape = params[BRDF_P_DIELECTRIC_ALPHA];
    }
    return b;
}

// glTF 2.0 metallic-roughness with KHR_materials_specular, _transmission and _ior, as a sum
// weighted (1-m)(1-t) dielectric-over-diffuse + m metal + (1-m) t rough glass:
// - one GGX lobe (alpha = roughness^2) with Schlick's F whose F0, F90 mix the dielectric's
//   (F0 = min(((ior-1)/(ior+1))^2 specular_color, 1) specular, F90 = specular) and the
//   metal's (F0 = base colour, F90 = 1); Schlick is linear in F0, F90, so the mix is exact;
// - the diffuse base colour coupled to the dielectric's Fresnel (brdf_diffuse), not the
//   spec's fresnel_mix (1 - F(v.h)), which is not energy conserving: 1.3 at 80 degrees for
//   a white base (docs/brdf.md);
// - transmission as the rough (or smooth) dielectric of index ior, tinted by base colour.
Bsdf bsdf_gltf(vec3 base_color, float metallic, float roughness, float specular,
               vec3 specular_color, float ior, float transmission)
{
    Bsdf b = brdf_empty();
    float m = clamp(metallic, 0.0, 1.0), t = clamp(transmission, 0.0, 1.0);
    float alpha = clamp(roughness, 0.0, 1.0);
    alpha *= alpha;
    vec3 f0 = min(vec3(brdf_schlick_f0(ior)) * specular_color, vec3(1.0)) * specular;
    float wd = (1.0 - m) * (1.0 - t);
    b.diffuse = wd * base_color;
    b.couple_f0 = f0;
    b.couple_f90 = specular;
    b.lobe = alpha < BRDF_ALPHA_MIN ? BRDF_LOBE_MIRROR : BRDF_LOBE_GGX;
    b.shape = alpha;
    b.fresnel = BRDF_FRESNEL_SCHLICK;
    b.specular = wd * f0 + m * base_color;
    b.f90 = wd * specular + m;
    b.dielectric = (1.0 - m) * t;
    b.tint = base_color;
    b.ior = max(ior, 1.01); // at 1 the rough BTDF collapses to a Dirac along -wo
    return b;
}

#endif
