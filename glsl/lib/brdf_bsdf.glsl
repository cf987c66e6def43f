// brdf_bsdf.glsl: the BSDF of docs/brdf.md as a mixture, with eval, pdf and importance sampling
// in the local shading frame, used by every integrator and by brdf_test.comp: a sum of a
// Lambert layer (Lambert f = C = albedo/pi, or coupled to a Fresnel layer above it), one
// specular lobe (the mirror f = delta(wi - r(wo)) / (n.wi); normalised Phong (Lafortune &
// Willems 1994) and Blinn-Phong; Torrance-Sparrow f = F D G / (4 (n.wo)(n.wi)) with Blinn's
// D = (e+2)/(2pi) (n.wh)^e and the V-cavity G; Beckmann and GGX with height-correlated Smith
// G, GGX sampled by visible normals), a dielectric interface (rough dielectrics after Walter
// et al. 2007 as written in pbrt-v4) and a diffuse transmission, under a clear coat and a
// sheen. The maths are brdf_scatter.glsl's; brdf_material.glsl builds a Bsdf from a material.
//
// Conventions: normal = +z; wo points to the viewer, wi to the light, both away from the
// surface. bsdf_eval returns f (no cosine); bsdf_eval_pdf also the solid-angle density with
// which bsdf_sample picks wi; Dirac lobes are not in eval/pdf, only in sample (BRDF_FLAG_DELTA).
// Transmission transports importance (flux): the 1/eta^2 radiance scale is left out, so
// R + T = 1 at a smooth interface; it cancels on closed objects.
#ifndef BRDF_BSDF_GLSL
#define BRDF_BSDF_GLSL

#include "brdf_scatter.glsl"
#include "lobes.h"

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

// A sum of BRDFs (docs/brdf.md, section 2): a Lambert layer, one specular lobe and a
// dielectric interface (reflection + refraction), each with its weight.
struct Bsdf {
    vec3 diffuse; uint lobe;          // Lambert weight kd; the lobe's kind
    vec3 specular; uint fresnel;      // lobe weight ks (Schlick: F0); the lobe's Fresnel
    vec3 eta; float shape;            // conductor index; exponent (Phong, Blinn) or alpha
    vec3 k; float ior;                // conductor extinction; dielectric index (in / out)
    vec3 tint; float dielectric;      // dielectric part: transmission tint, weight (0: none)
    vec3 couple_f0; float couple_f90; // Schlick of the layer over the diffuse (0, 0: none)
    float f90;                        // Schlick F90 of the lobe
    // The layers over all of the above (bsdf_layers; GN_FEAT_LAYERS): a clear coat, a GGX
    // dielectric of index 1.5 with its own normal, and a sheen (Charlie distribution).
    float coat;                       // the coat's weight (0: none)
    vec3 coat_n; float coat_alpha;    // the coat's normal (unit, local frame); its GGX alpha
    vec3 sheen; float sheen_r;        // the sheen's colour (0: none); its roughness
    // KHR_materials_anisotropy (bsdf_anisotropy; GN_FEAT_ANISO): the GGX of the lobe and the
    // glass stretched to alpha aniso_at along aniso_dir (unit, local xy), shape across it.
    vec2 aniso_dir; float aniso_at;   // aniso_at 0: isotropic
    // In the base (bsdf_gltf_film; GN_FEAT_LAYERS): KHR_materials_iridescence's thin film on
    // the lobe's Schlick Fresnel and KHR_materials_diffuse_transmission's Lambert lobe through
    // the surface (thin-walled).
    float irid; float irid_ior;       // the film's weight (0: none); its index
    float irid_d; float irid_wd;      // its thickness (nm); the dielectric lobe's weight (1-m)(1-t) specular
    vec3 irid_f0; float irid_wm;      // the dielectric's F0 under the film; the metal's weight m
    vec3 irid_base;                   // the metal's F0 (base colour)
    vec3 irid_avg;                    // the cosine-weighted mean of the dielectric's F_film (brdf_irid_mean)
    vec3 dt;                          // the transmission's Lambert weight kt (0: none)
};

struct BsdfSample {
    vec3 wi;
    vec3 weight; // f |n.wi| / pdf; for a Dirac lobe its reflectance over its probability
    float pdf;   // solid-angle pdf; for a Dirac lobe the probability of choosing it
    uint flags;  // BRDF_FLAG_*; 0 when no direction was sampled (weight 0)
};

// No direction sampled (weight 0).
BsdfSample brdf_no_sample()
{
    BsdfSample s;
    s.wi = vec3(0.0, 0.0, 1.0);
    s.weight = vec3(0.0);
    s.pdf = 0.0;
    s.flags = 0u;
    return s;
}

// A sampled non-Dirac direction wi with its f and whole-mixture pdf (none if pdf is 0).
BsdfSample brdf_sample_from(vec3 wi, vec3 f, float pdf, uint flags)
{
    BsdfSample s = brdf_no_sample();
    if (!(pdf > 0.0))
        return s;
    s.wi = wi;
    s.pdf = pdf;
    s.weight = f * abs(wi.z) / pdf;
    s.flags = flags;
    return s;
}

bool brdf_is_aniso(Bsdf b)
{
    return GN_HAS(GN_FEAT_ANISO) && b.aniso_at > 0.0;
}

// w from the local frame to the anisotropy frame (x along aniso_dir) and back.
vec3 brdf_to_aniso(Bsdf b, vec3 w)
{
    vec2 t = b.aniso_dir;
    return vec3(dot(w.xy, t), t.x * w.y - t.y * w.x, w.z);
}

vec3 brdf_from_aniso(Bsdf b, vec3 w)
{
    vec2 t = b.aniso_dir;
    return vec3(t.x * w.x - t.y * w.y, t.y * w.x + t.x * w.y, w.z);
}

// The base's GGX (the lobe's and the glass's, alpha = shape): anisotropic where the Bsdf is.
float brdf_base_d(Bsdf b, vec3 h)
{
    if (brdf_is_aniso(b))
        return brdf_ggx_aniso_d(brdf_to_aniso(b, h), vec2(b.aniso_at, b.shape));
    return brdf_d_ggx(h, b.shape);
}

float brdf_base_g1(Bsdf b, vec3 w)
{
    if (brdf_is_aniso(b))
        return brdf_ggx_aniso_g1(brdf_to_aniso(b, w), vec2(b.aniso_at, b.shape));
    return brdf_g1_ggx(w, b.shape);
}

float brdf_base_v(Bsdf b, vec3 wo, vec3 wi)
{
    if (brdf_is_aniso(b))
        return brdf_ggx_aniso_v(brdf_to_aniso(b, wo), brdf_to_aniso(b, wi), vec2(b.aniso_at, b.shape));
    return brdf_v_ggx(wo, wi, b.shape);
}

vec3 brdf_base_vndf(Bsdf b, vec3 w, vec2 u)
{
    if (brdf_is_aniso(b))
        return brdf_from_aniso(b, brdf_ggx_aniso_vndf(brdf_to_aniso(b, w), vec2(b.aniso_at, b.shape), u));
    return brdf_ggx_sample_vndf(w, b.shape, u);
}

// wo refracted through the interface with normal n and eta = eta_inside / eta_outside

// The cosine-weighted mean 2 int F c dc of the dielectric's F under the film (specular times
// F_film), which has no closed form: Gauss-Legendre with 6 nodes (exact for Schlick's F, a
// polynomial of degree 6; the film's F is smooth in cos), unrolled (a loop costs llvmpipe passes).
vec3 brdf_irid_mean(Bsdf b)
{
    vec3 x = vec3(0.2386191860831969, 0.6612093864662645, 0.9324695142031521) * 0.5;
    vec3 w = vec3(0.4679139345726910, 0.3607615730481386, 0.1713244923791704);
    vec3 c = 0.5 - x, d = 0.5 + x;
    vec3 m = w.x * (c.x * brdf_iridescence(c.x, b.irid_ior, b.irid_d, b.irid_f0) +
                    d.x * brdf_iridescence(d.x, b.irid_ior, b.irid_d, b.irid_f0));
    m += w.y * (c.y * brdf_iridescence(c.y, b.irid_ior, b.irid_d, b.irid_f0) +
                d.y * brdf_iridescence(d.y, b.irid_ior, b.irid_d, b.irid_f0));
    m += w.z * (c.z * brdf_iridescence(c.z, b.irid_ior, b.irid_d, b.irid_f0) +
                d.z * brdf_iridescence(d.z, b.irid_ior, b.irid_d, b.irid_f0));
    return b.couple_f90 * m;
}

// The lobe's Fresnel under the film: the dielectric's and the metal's, each weighted as
// bsdf_gltf weights their Schlick F0.
vec3 brdf_irid_lobe(Bsdf b, float c)
{
    return b.irid_wd * brdf_iridescence(c, b.irid_ior, b.irid_d, b.irid_f0) +
           b.irid_wm * brdf_iridescence(c, b.irid_ior, b.irid_d, b.irid_base);
}

// The glass's reflectance at microfacet cosine mo (either side; its transmittance is 1 - F):
// the exact dielectric F, and under an iridescent film F + factor (F_film - F_Schlick), the
// film's change to Schlick's F of the same index, taken at the outside's cosine, so that a
// pair of directions through the surface has one F either way (reciprocal, R + T = 1 on both
// sides). Total internal reflection stays 1; a film of thickness 0 or index 1 changes nothing.
vec3 brdf_glass_fresnel(Bsdf b, float mo)
{
    float fr = brdf_fresnel_dielectric(mo, b.ior);
    if (!GN_HAS(GN_FEAT_LAYERS) || !(b.irid > 0.0) || fr >= 1.0)
        return vec3(fr);
    float c = abs(mo);
    if (mo < 0.0) // from inside: the cosine of the refracted direction outside
        c = sqrt(max(1.0 - b.ior * b.ior * (1.0 - c * c), 0.0));
    vec3 f0 = vec3(brdf_schlick_f0(b.ior));
    vec3 film = brdf_iridescence(c, b.irid_ior, b.irid_d, f0) - brdf_fresnel_schlick(c, f0, 1.0);
    return clamp(vec3(fr) + b.irid * film, vec3(0.0), vec3(1.0));
}

// ---- the parts of a Bsdf -----------------------------------------------------------------

// The lobe's Fresnel factor times its weight, at cos = wo.wh.
vec3 brdf_lobe_fresnel(Bsdf b, float c)
{
    if (GN_HAS(GN_FEAT_FRESNEL_DIELECTRIC) && b.fresnel == BRDF_FRESNEL_DIELECTRIC)
        return b.specular * brdf_fresnel_dielectric(c, b.ior);
    if (GN_HAS(GN_FEAT_FRESNEL_CONDUCTOR) && b.fresnel == BRDF_FRESNEL_CONDUCTOR)
        return b.specular * brdf_fresnel_conductor(c, b.eta, b.k);
    if (GN_HAS(GN_FEAT_FRESNEL_SCHLICK) && b.fresnel == BRDF_FRESNEL_SCHLICK) {
        vec3 f = brdf_fresnel_schlick(c, b.specular, b.f90);
        if (GN_HAS(GN_FEAT_LAYERS) && b.irid > 0.0) // KHR_materials_iridescence: F = mix(F, F_film, factor)
            f = mix(f, brdf_irid_lobe(b, c), b.irid);
        return f;
    }
    return b.specular;
}

// Lambert under a Fresnel layer: kd/pi (1 - F(wo))(1 - F(wi)) / (1 - F_avg), with
// F_avg = F0 + (F90 - F0)/21 the cosine-weighted mean of Schlick's F. Its albedo is
// kd (1 - F(wo)) (Shirley et al. 1997), it is reciprocal, and with couple_f0 = f90 = 0 it is
// the plain Lambert kd/pi. kd: the reflection's (diffuse) or the diffuse transmission's (dt)
// weight; co, ci: the cosines' magnitudes. Under an iridescent film F is the lobe's,
// mix(F, F_film, factor), and F_avg its mean (b.irid_avg).
vec3 brdf_coupled(Bsdf b, vec3 kd, float co, float ci)
{
    if (!GN_HAS(GN_FEAT_COUPLED)) // couple_f0 = couple_f90 = 0: exactly the plain Lambert
        return kd / BRDF_PI;
    vec3 fo = brdf_fresnel_schlick(co, b.couple_f0, b.couple_f90);
    vec3 fi = brdf_fresnel_schlick(ci, b.couple_f0, b.couple_f90);
    vec3 avg = b.couple_f0 + (b.couple_f90 - b.couple_f0) / 21.0;
    if (GN_HAS(GN_FEAT_LAYERS) && b.irid > 0.0) {
        fo = mix(fo, b.couple_f90 * brdf_iridescence(co, b.irid_ior, b.irid_d, b.irid_f0), b.irid);
        fi = mix(fi, b.couple_f90 * brdf_iridescence(ci, b.irid_ior, b.irid_d, b.irid_f0), b.irid);
        avg = mix(avg, b.irid_avg, b.irid);
    }
    return kd / BRDF_PI * (1.0 - fo) * (1.0 - fi) / max(1.0 - avg, vec3(1e-6));
}

vec3 brdf_diffuse(Bsdf b, float co, float ci)
{
    return brdf_coupled(b, b.diffuse, co, ci);
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
        float d = brdf_base_d(b, h);
        dv = d * brdf_base_v(b, wo, wi);
        pdf_h = brdf_base_g1(b, wo) * oh * d / wo.z;
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
        h = brdf_base_vndf(b, wo, u);
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
    vec3 fr = brdf_glass_fresnel(b, mo);
    float pr = brdf_mean(fr); // the probability of sampling reflection
    float d = brdf_base_d(b, wm);
    float v = brdf_base_v(b, wo, wi);
    float pdf_m = brdf_base_g1(b, wo) * abs(mo) * d / abs(co);
    if (reflect) {
        f = fr * d * v;
        pdf = pr * pdf_m / (4.0 * abs(mo));
    } else {
        float denom = mi + mo / etap;
        denom *= denom;
        f = b.tint * ((1.0 - fr) * d * 4.0 * v * abs(mi * mo) / denom);
        pdf = (1.0 - pr) * pdf_m * abs(mi) / denom;
    }
}

// ---- KHR_materials_diffuse_transmission: a Lambert lobe through the surface -----------------
// kt/pi on the other side, coupled to the base's Fresnel on both sides as the reflection is
// (brdf_coupled at |cos|): the two share the diffuse albedo, kd (1 - F) + kt (1 - F). Thin-walled:
// the path goes on beyond the surface in the medium it was in. Part of the base's diffuse part:
// one cosine-weighted sample, on the far side with the transmission's share of the two albedos.

bool brdf_has_dt(Bsdf b)
{
    return any(greaterThan(b.dt, vec3(0.0)));
}

// The albedo estimates at wo of the diffuse reflection (x, none from below) and transmission (y).
vec2 brdf_dt_weights(Bsdf b, vec3 wo)
{
    vec3 t = 1.0 - brdf_fresnel_schlick(abs(wo.z), b.couple_f0, b.couple_f90);
    vec3 r = wo.z > 0.0 ? b.diffuse * t : vec3(0.0);
    t *= b.dt;
    return vec2(brdf_mean(r), brdf_mean(t));
}

// The probability that the diffuse part samples the far side.
float brdf_dt_prob(Bsdf b, vec3 wo)
{
    vec2 w = brdf_dt_weights(b, wo);
    return w.y > 0.0 ? w.y / (w.x + w.y) : 0.0;
}

// Adds the transmission to the base's f and pdf (px: the diffuse part's probability), and
// takes its share of the diffuse part's pdf from the reflection.
void brdf_dt_eval_pdf(Bsdf b, vec3 wo, vec3 wi, float px, inout vec3 f, inout float pdf)
{
    float q = brdf_dt_prob(b, wo), pd = px * abs(wi.z) / BRDF_PI;
    if (wo.z > 0.0 && wi.z > 0.0) {
        pdf = max(pdf - q * pd, 0.0); // (all of the diffuse part's: q = 1, and rounding may leave -ulp)
    } else if (wo.z * wi.z < 0.0) {
        f += brdf_coupled(b, b.dt, abs(wo.z), abs(wi.z));
        pdf += q * pd;
    }
}

// Probabilities of sampling the diffuse layer, the lobe and the dielectric from wo: their
// albedo estimates at wo, normalised.
vec3 brdf_part_weights(Bsdf b, vec3 wo)
{
    vec3 p = vec3(0.0);
    if (wo.z > 0.0) {
        vec3 d = b.diffuse * (1.0 - brdf_fresnel_schlick(wo.z, b.couple_f0, b.couple_f90));
        p.x = brdf_mean(d);
        if (GN_HAS(GN_FEAT_LOBES) && b.lobe != BRDF_LOBE_NONE) {
            vec3 s = brdf_lobe_fresnel(b, wo.z);
            p.y = brdf_mean(s);
        }
    }
    if (GN_HAS(GN_FEAT_LAYERS) && brdf_has_dt(b))
        p.x += brdf_dt_weights(b, wo).y;
    if (GN_HAS(GN_FEAT_GLASS) && wo.z != 0.0)
        p.z = b.dielectric;
    return p;
}

vec3 brdf_part_probs(Bsdf b, vec3 wo)
{
    vec3 p = brdf_part_weights(b, wo);
    float sum = p.x + p.y + p.z;
    return sum > 0.0 ? p / sum : vec3(0.0);
}

// ---- the base: the sum of the parts ------------------------------------------------------

// f(wo, wi) and pdf(wo, wi) of the base's non-Dirac parts.
void brdf_base_eval_pdf(Bsdf b, vec3 wo, vec3 wi, out vec3 f, out float pdf)
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
    if (GN_HAS(GN_FEAT_ROUGH_GLASS) && b.dielectric > 0.0 && !lobes_smooth(b.shape)) {
        vec3 ft;
        float pt;
        brdf_rough_dielectric(b, wo, wi, ft, pt);
        f += b.dielectric * ft;
        pdf += p.z * pt;
    }
    if (GN_HAS(GN_FEAT_LAYERS) && brdf_has_dt(b))
        brdf_dt_eval_pdf(b, wo, wi, p.x, f, pdf);
}

// Picks a part with u.x (then reuses u.x, rescaled, for reflect-or-refract) and a direction
// from it with u.yz. A non-Dirac direction gets the pdf of the whole mixture (one-sample
// MIS over the parts), so weight = eval * |cos| / pdf exactly.
BsdfSample brdf_base_sample(Bsdf b, vec3 wo, vec3 u)
{
    BsdfSample s = brdf_no_sample();
    vec3 p = brdf_part_probs(b, wo);
    vec3 wi;
    bool reflect = true; // the side the chosen part sends wi to: a part's direction that
                         // lands on the other side is no sample of it (pbrt-v4 does the same)
    if (u.x < p.x) {
        wi = sampling_cosine_hemisphere(u.yz);
        if (GN_HAS(GN_FEAT_LAYERS) && brdf_has_dt(b) && u.x < p.x * brdf_dt_prob(b, wo)) {
            wi.z = wo.z > 0.0 ? -wi.z : wi.z; // diffuse transmission: the far side
            reflect = false;
        }
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
        if (GN_HAS(GN_FEAT_SMOOTH_GLASS) && lobes_smooth(b.shape)) {
            vec3 fr = brdf_glass_fresnel(b, wo.z);
            float pr = brdf_mean(fr);
            if (x < pr) {
                s.wi = vec3(-wo.xy, wo.z);
                s.pdf = p.z * pr;
                s.weight = b.dielectric * (fr / pr) / p.z;
                s.flags = BRDF_FLAG_REFLECTION | BRDF_FLAG_DELTA;
            } else if (brdf_refract(wo, vec3(0.0, 0.0, 1.0), b.ior, s.wi)) {
                s.pdf = p.z * (1.0 - pr);
                s.weight = b.dielectric * b.tint * ((1.0 - fr) / (1.0 - pr)) / p.z;
                s.flags = BRDF_FLAG_TRANSMISSION | BRDF_FLAG_DELTA;
            }
            return s;
        }
        if (!GN_HAS(GN_FEAT_ROUGH_GLASS))
            return s;
        vec3 wm = brdf_base_vndf(b, wo.z >= 0.0 ? wo : -wo, u.yz);
        float mo = dot(wo, wm);
        reflect = x < brdf_mean(brdf_glass_fresnel(b, mo));
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
    brdf_base_eval_pdf(b, wo, wi, f, pdf);
    return brdf_sample_from(wi, f, pdf, reflect ? BRDF_FLAG_REFLECTION : BRDF_FLAG_TRANSMISSION);
}

// ---- the layers: KHR_materials_clearcoat and _sheen over the base ---------------------------
// f = coat + (1 - c F(min)) (sheen + (1 - s E(max)) base), docs/brdf.md:
// - coat: c F(max(n_c.wo, n_c.wi)) D V of GGX (alpha_c) about the coat's normal n_c, with
//   Schlick's F of F0 = 0.04 (index 1.5); the extension's README takes both Fresnel weights
//   at n_c.wo, which is not reciprocal; at the mirror direction the two agree. F(max) <= F(wo)
//   keeps the coat's albedo below c F(n_c.wo), and the base's weight 1 - c F(min) below
//   1 - c F(n_c.wo): the sum never exceeds 1;
// - sheen: colour D_Charlie V (Estevez & Kulla 2017) / max(1, E(wo), E(wi)), E the lobe's
//   directional albedo (sheen_albedo.h), which exceeds 1 within a few degrees of grazing
//   (up to 1.5 at low roughness): the division keeps the albedo <= 1 and the lobe
//   reciprocal, and changes nothing elsewhere; the base scaled by
//   1 - max(colour) max(min(E, 1)(wo), min(E, 1)(wi)), the README's min of its two scalings;
// - light through the base (transmission) crosses the layers once, on the side it is outside.

bool brdf_has_layers(Bsdf b)
{
    return lobes_layers(b.coat, b.sheen.r, b.sheen.g, b.sheen.b);
}

// w in the coat's frame (normal b.coat_n).
vec3 brdf_to_coat(Bsdf b, vec3 w)
{
    vec3 t, bt;
    sampling_basis(b.coat_n, t, bt);
    return vec3(dot(w, t), dot(w, bt), dot(w, b.coat_n));
}

vec3 brdf_from_coat(Bsdf b, vec3 w)
{
    vec3 t, bt;
    sampling_basis(b.coat_n, t, bt);
    return w.x * t + w.y * bt + w.z * b.coat_n;
}

// The sheen's f (colour 1) and the pdf of its half-vector sampling, both above the surface.
void brdf_sheen(Bsdf b, vec3 wo, vec3 wi, out float f, out float pdf)
{
    float a = brdf_sheen_alpha(b.sheen_r);
    vec3 h = normalize(wo + wi);
    float d = brdf_d_charlie(h, a);
    float norm = max(1.0, max(brdf_sheen_table(wo.z, b.sheen_r), brdf_sheen_table(wi.z, b.sheen_r)));
    f = d / ((1.0 + brdf_sheen_lambda(wo.z, a) + brdf_sheen_lambda(wi.z, a)) * 4.0 * wo.z * wi.z * norm);
    if (min(wo.z, wi.z) < BRDF_SHEEN_COS_MIN)
        f = 0.0;
    pdf = d * h.z / (4.0 * dot(wo, h));
}

// The weights of the coat, the sheen and the base (the layers below the sheen) at wo, before
// normalisation: their albedo estimates.
vec3 brdf_layer_weights(Bsdf b, vec3 wo)
{
    float co = brdf_to_coat(b, wo).z;
    float c = wo.z > 0.0 && co > 0.0 ? b.coat * brdf_coat_fresnel(co) : 0.0;
    float e = wo.z > 0.0 ? brdf_sheen_albedo(wo.z, b.sheen_r) : 0.0;
    vec3 pb = brdf_part_weights(b, wo);
    return vec3(c, (1.0 - c) * e * (b.sheen.r + b.sheen.g + b.sheen.b) / 3.0,
                (1.0 - c) * (1.0 - brdf_max3(b.sheen) * e) * (pb.x + pb.y + pb.z));
}

vec3 brdf_layer_probs(Bsdf b, vec3 wo)
{
    vec3 p = brdf_layer_weights(b, wo);
    float sum = p.x + p.y + p.z;
    return sum > 0.0 ? p / sum : vec3(0.0);
}

// What the layers leave of the layers below them between wo and wi (symmetric in the two):
// x what the coat leaves of the sheen and the base, y what the sheen leaves of the base.
vec2 brdf_layer_scale(Bsdf b, vec3 wo, vec3 wi)
{
    if (wo.z <= 0.0 && wi.z <= 0.0)
        return vec2(1.0);
    float co = clamp(brdf_to_coat(b, wo).z, 0.0, 1.0), ci = clamp(brdf_to_coat(b, wi).z, 0.0, 1.0);
    float so = max(wo.z, 0.0), si = max(wi.z, 0.0), c, e;
    if (wo.z > 0.0 && wi.z > 0.0) {
        c = min(co, ci);
        e = max(brdf_sheen_albedo(so, b.sheen_r), brdf_sheen_albedo(si, b.sheen_r));
    } else { // through the base: the layers once, at the outside direction
        c = wo.z > 0.0 ? co : ci;
        e = brdf_sheen_albedo(max(so, si), b.sheen_r);
    }
    return vec2(1.0 - b.coat * brdf_coat_fresnel(c), 1.0 - brdf_max3(b.sheen) * e);
}

// f and pdf of the coat's and the sheen's lobes (non-Dirac), each pdf that of its own sampling.
void brdf_layer_lobes(Bsdf b, vec3 wo, vec3 wi, out vec3 fc, out float pc, out vec3 fs, out float ps)
{
    fc = vec3(0.0);
    pc = 0.0;
    fs = vec3(0.0);
    ps = 0.0;
    if (wo.z <= 0.0 || wi.z <= 0.0)
        return;
    if (b.coat > 0.0 && !lobes_smooth(b.coat_alpha)) {
        vec3 o = brdf_to_coat(b, wo), i = brdf_to_coat(b, wi);
        if (o.z > 0.0 && i.z > 0.0) {
            float a = b.coat_alpha;
            vec3 h = normalize(o + i);
            float d = brdf_d_ggx(h, a);
            fc = vec3(b.coat * brdf_coat_fresnel(max(o.z, i.z)) * d * brdf_v_ggx(o, i, a));
            pc = brdf_g1_ggx(o, a) * d / (4.0 * o.z);
        }
    }
    if (any(greaterThan(b.sheen, vec3(0.0)))) {
        float f;
        brdf_sheen(b, wo, wi, f, ps);
        fs = b.sheen * f;
    }
}

// ---- the public BSDF API ------------------------------------------------------------------

// f(wo, wi) and pdf(wo, wi) of the non-Dirac parts, in one pass (light sampling with MIS
// needs both). Without layers exactly the base's.
void bsdf_eval_pdf(Bsdf b, vec3 wo, vec3 wi, out vec3 f, out float pdf)
{
    brdf_base_eval_pdf(b, wo, wi, f, pdf);
    if (GN_HAS(GN_FEAT_LAYERS) && brdf_has_layers(b)) {
        vec3 p = brdf_layer_probs(b, wo), fc, fs;
        float pc, ps;
        brdf_layer_lobes(b, wo, wi, fc, pc, fs, ps);
        vec2 k = brdf_layer_scale(b, wo, wi);
        f = fc + k.x * (fs + f * k.y);
        pdf = p.x * pc + p.y * ps + p.z * pdf;
    }
}

// The layers' own sampling: u.x picks the coat, the sheen or the base (then u.x rescaled for
// the base's own choice); a Dirac coat or base lobe keeps its one strategy.
BsdfSample bsdf_sample(Bsdf b, vec3 wo, vec3 u)
{
    if (!GN_HAS(GN_FEAT_LAYERS) || !brdf_has_layers(b))
        return brdf_base_sample(b, wo, u);
    BsdfSample s = brdf_no_sample();
    vec3 p = brdf_layer_probs(b, wo);
    vec3 wi;
    uint flags = BRDF_FLAG_REFLECTION;
    if (u.x < p.x) {
        vec3 o = brdf_to_coat(b, wo);
        if (lobes_smooth(b.coat_alpha)) {
            s.wi = brdf_from_coat(b, vec3(-o.xy, o.z));
            if (s.wi.z <= 0.0)
                return s;
            s.pdf = p.x;
            s.weight = vec3(b.coat * brdf_coat_fresnel(o.z) / p.x);
            s.flags = BRDF_FLAG_REFLECTION | BRDF_FLAG_DELTA;
            return s;
        }
        vec3 h = brdf_ggx_sample_vndf(o, b.coat_alpha, u.yz), i = 2.0 * dot(o, h) * h - o;
        if (i.z <= 0.0)
            return s; // below the coat: outside the coat's pdf (brdf_layer_lobes)
        wi = brdf_from_coat(b, i);
    } else if (u.x < p.x + p.y) {
        // Charlie's normal with density D cos: sin = u^(alpha / (2 alpha + 1))
        float a = brdf_sheen_alpha(b.sheen_r), st = pow(u.y, a / (2.0 * a + 1.0)), phi = 2.0 * BRDF_PI * u.z;
        vec3 h = vec3(st * cos(phi), st * sin(phi), sqrt(max(0.0, 1.0 - st * st)));
        float oh = dot(wo, h);
        if (oh <= 0.0)
            return s; // the other half vector -h would be below: no sample of the sheen
        wi = 2.0 * oh * h - wo;
    } else if (p.z > 0.0) {
        float x = min((u.x - p.x - p.y) / p.z, 0.99999994);
        BsdfSample bs = brdf_base_sample(b, wo, vec3(x, u.yz));
        if (bs.flags == 0u)
            return bs;
        if ((bs.flags & BRDF_FLAG_DELTA) != 0u) {
            vec2 k = brdf_layer_scale(b, wo, bs.wi);
            bs.weight *= k.x * k.y / p.z;
            bs.pdf *= p.z;
            return bs;
        }
        wi = bs.wi;
        flags = bs.flags;
    } else {
        return s;
    }
    if ((wi.z * wo.z > 0.0) != (flags == BRDF_FLAG_REFLECTION))
        return s;
    vec3 f;
    float pdf;
    bsdf_eval_pdf(b, wo, wi, f, pdf);
    return brdf_sample_from(wi, f, pdf, flags);
}

vec3 bsdf_eval(Bsdf b, vec3 wo, vec3 wi)
{
    vec3 f;
    float pdf;
    bsdf_eval_pdf(b, wo, wi, f, pdf);
    return f;
}

#endif
