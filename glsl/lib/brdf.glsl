// brdf.glsl: the BSDFs of docs/brdf.md with eval, pdf and importance
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
// surface. bsdf_eval returns f (no cosine); bsdf_eval_pdf also the solid-angle density with
// which bsdf_sample picks wi; Dirac lobes are not in eval/pdf, only in sample (BRDF_FLAG_DELTA).
// Transmission transports importance (flux): the 1/eta^2 radiance scale is left out, so
// R + T = 1 at a smooth interface; it cancels on closed objects.
#ifndef BRDF_GLSL
#define BRDF_GLSL

#include "brdf_models.h"
#include "sampling.glsl"
#include "sheen_albedo.h"
// The sheen's table (sheen_albedo.h) comes in a texel buffer of float bits (src/render/brdf.c:
// brdf_sheen_table): as a constant array llvmpipe took minutes to compile the kernel. A kernel
// that has the table elsewhere defines BRDF_SHEEN_FETCH before including this file.
#ifndef BRDF_SHEEN_FETCH
#extension GL_EXT_samplerless_texture_functions : require // a buffer image, no sampler (scene.glsl)
layout(binding = BRDF_BIND_SHEEN) uniform utextureBuffer sheen_table;
#define BRDF_SHEEN_FETCH(i) uintBitsToFloat(texelFetch(sheen_table, (i)).x)
#endif

#define BRDF_PI GN_PI

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

// ---- Fresnel --------------------------------------------------------------------------

// The exact dielectric Fresnel: r_par, r_perp and F_r = (r_par^2 + r_perp^2) / 2 for
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

// Schlick's approximation F = F0 + (F90 - F0)(1 - cos)^5 (F90 = 1 for a plain dielectric).
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

// Blinn's distribution in its classic form: D = (e + 2) / (2 pi) (wh.n)^e.
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

// ---- anisotropic GGX (KHR_materials_anisotropy) --------------------------------------------
// Heitz 2014 (JCGT 3(2)), eqs. 85-86, and Heitz 2018's sampling with alpha = (a_t, a_b) on the
// axes of the frame (x along the anisotropy direction): the isotropic formulas above are the
// case a_t = a_b, kept apart so that a lobe without anisotropy keeps its exact values.

// D = 1 / (pi a_t a_b (x^2/a_t^2 + y^2/a_b^2 + z^2)^2), h in the anisotropy frame.
float brdf_ggx_aniso_d(vec3 h, vec2 a)
{
    if (h.z <= 0.0)
        return 0.0;
    vec3 s = vec3(h.x / a.x, h.y / a.y, h.z);
    float d = dot(s, s);
    return 1.0 / (BRDF_PI * a.x * a.y * d * d);
}

// G1 = 2 |c| / (|c| + sqrt(c^2 + a_t^2 x^2 + a_b^2 y^2)).
float brdf_ggx_aniso_g1(vec3 w, vec2 a)
{
    vec2 s = a * w.xy;
    float c = abs(w.z);
    return 2.0 * c / (c + sqrt(w.z * w.z + dot(s, s)));
}

// Height-correlated G2 / (4 |n.wo| |n.wi|), as brdf_v_ggx.
float brdf_ggx_aniso_v(vec3 wo, vec3 wi, vec2 a)
{
    vec2 so = a * wo.xy, si = a * wi.xy;
    float lo = abs(wi.z) * sqrt(wo.z * wo.z + dot(so, so));
    float li = abs(wo.z) * sqrt(wi.z * wi.z + dot(si, si));
    return 0.5 / (lo + li);
}

// Visible normal seen from w (w.z > 0), Heitz 2018 (JCGT 7(4)), of the GGX stretched by
// (a_t, a_b) on the frame's axes: pdf of the normal is G1(w) max(0, w.h) D(h) / w.z.
vec3 brdf_ggx_aniso_vndf(vec3 w, vec2 a, vec2 u)
{
    vec3 vh = normalize(vec3(a * w.xy, w.z));
    float len2 = dot(vh.xy, vh.xy);
    vec3 t1 = len2 > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(len2) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(vh, t1);
    float r = sqrt(u.x), phi = 2.0 * BRDF_PI * u.y;
    float p1 = r * cos(phi), p2 = r * sin(phi);
    float s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3(a * nh.xy, max(0.0, nh.z)));
}

// The isotropic case (the same floats: each axis is scaled by a alone).
vec3 brdf_ggx_sample_vndf(vec3 w, float a, vec2 u) { return brdf_ggx_aniso_vndf(w, vec2(a), u); }

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

// ---- KHR_materials_iridescence: a thin film over the base's Fresnel -------------------------
// Belcour & Barla 2017 ("A Practical Extension to Microfacet Theory for the Modeling of
// Varying Iridescence") as the extension's reference evaluates it in RGB: the Airy sum of the
// film's multiple reflections written as a DC term plus its first two orders of interference,
// each order's spectrum integrated against the colour-matching functions in closed form
// through a fit of their Fourier transform by Gaussians (brdf_irid_sensitivity). The inner
// interface's reflectance is Schlick's, as the base's is; outside index 1.

// The colour-matching functions' response (XYZ, then linear sRGB) to a cosine of optical path
// difference opd (nm) and phase shift: Belcour & Barla's Gaussian fit of their Fourier
// transform, the extension's constants.
vec3 brdf_irid_sensitivity(float opd, vec3 shift)
{
    float phase = 2.0 * BRDF_PI * opd * 1e-9;
    vec3 val = vec3(5.4856e-13, 4.4201e-13, 5.2481e-13);
    vec3 pos = vec3(1.6810e+06, 1.7953e+06, 2.2084e+06);
    vec3 var = vec3(4.3278e+09, 9.3046e+09, 6.6121e+09);
    vec3 xyz = val * sqrt(2.0 * BRDF_PI * var) * cos(pos * phase + shift) * exp(-phase * phase * var);
    xyz.x += 9.7470e-14 * sqrt(2.0 * BRDF_PI * 4.5282e+09) * cos(2.2399e+06 * phase + shift.x) *
             exp(-4.5282e+09 * phase * phase);
    xyz /= 1.0685e-7;
    return mat3(3.2404542, -0.9692660, 0.0556434, -1.5371385, 1.8760108, -0.2040259,
                -0.4985314, 0.0415560, 1.0572252) * xyz;
}

// Reflectance at cos1 (from outside, index 1) of a film of index film_ior and thickness d (nm)
// over a base whose normal-incidence reflectance against index 1 is f0 (its index recovered
// from f0). Clamped to [0, 1]: the fit's colours can leave the gamut.
vec3 brdf_iridescence(float cos1, float film_ior, float d, vec3 f0)
{
    // A film of thickness 0 is no film (the approximation is not continuous there by itself).
    float n2 = mix(1.0, film_ior, smoothstep(0.0, 0.03, d));
    float c1 = clamp(cos1, 0.0, 1.0);
    // Snell: n2 >= 1, so no total reflection; cos^2 in the film as (n2^2 - sin^2) / n2^2, which
    // keeps grazing cosines exact where the film's index is the outside's
    float c2 = sqrt(max(n2 * n2 - 1.0 + c1 * c1, 0.0)) / n2;
    // The outer interface by the exact Fresnel equations (with the cosines above), not
    // Schlick's as the extension's reference has it: Schlick's F90 of 1 would reflect at
    // grazing angles where no film is (index 1, or thickness 0), and the film's limits would
    // not be the base's F.
    float rp = (n2 * c1 - c2) / max(n2 * c1 + c2, 1e-30), rn = (c1 - n2 * c2) / max(c1 + n2 * c2, 1e-30);
    float r12 = 0.5 * (rp * rp + rn * rn), t121 = 1.0 - r12;
    // phase shifts at the interfaces: pi where light reflects off a denser medium
    float phi21 = BRDF_PI; // (phi12 = 0: the film is at least as dense as the outside)
    vec3 sf = sqrt(clamp(f0, vec3(0.0), vec3(0.9999)));
    vec3 n3 = (1.0 + sf) / (1.0 - sf);
    vec3 r1 = (n3 - n2) / (n3 + n2);
    vec3 r23 = brdf_fresnel_schlick(c2, r1 * r1, 1.0);
    vec3 phi = vec3(phi21) + mix(vec3(0.0), vec3(BRDF_PI), lessThan(n3, vec3(n2)));
    float opd = 2.0 * n2 * d * c2;
    vec3 r123 = clamp(r12 * r23, vec3(0.0), vec3(0.9999));
    vec3 rr = sqrt(r123);
    vec3 rs = t121 * t121 * r23 / (1.0 - r123);
    vec3 cm = (rs - t121) * rr; // the orders m = 1, 2 (unrolled: a loop costs llvmpipe passes)
    vec3 i = r12 + rs + cm * 2.0 * brdf_irid_sensitivity(opd, phi);
    cm *= rr;
    i += cm * 2.0 * brdf_irid_sensitivity(2.0 * opd, 2.0 * phi);
    return clamp(i, vec3(0.0), vec3(1.0));
}

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

float brdf_mean(vec3 v) { return (v.r + v.g + v.b) / 3.0; }

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
        pdf -= q * pd;
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
    if (GN_HAS(GN_FEAT_ROUGH_GLASS) && b.dielectric > 0.0 && b.shape >= BRDF_ALPHA_MIN) {
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
        if (GN_HAS(GN_FEAT_SMOOTH_GLASS) && b.shape < BRDF_ALPHA_MIN) {
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
#define BRDF_COAT_F0 0.04
#define BRDF_SHEEN_R_MIN 0.07 // tests/tool/sheen_table.c: a narrower sheen is too grazing to tabulate
// Below this cosine (0.06 degrees from grazing, under the table's first row but 0) the sheen
// is 0: its albedo there climbs to 3 before it falls to 0 at grazing, which no table row
// could follow.
#define BRDF_SHEEN_COS_MIN 0.001

bool brdf_has_layers(Bsdf b)
{
    return b.coat > 0.0 || any(greaterThan(b.sheen, vec3(0.0)));
}

float brdf_coat_fresnel(float c)
{
    return brdf_fresnel_schlick(c, vec3(BRDF_COAT_F0), 1.0).x;
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

float brdf_max3(vec3 v) { return max(v.r, max(v.g, v.b)); }

// E(cos theta, roughness) of the sheen lobe before its normalisation: bilinear in the table
// (rows at cos = (i / (N - 1))^2).
float brdf_sheen_table(float c, float r)
{
    vec2 x = vec2(sqrt(clamp(c, 0.0, 1.0)), clamp(r, 0.0, 1.0)) * float(SHEEN_N - 1);
    ivec2 i = min(ivec2(x), ivec2(SHEEN_N - 2));
    vec2 f = x - vec2(i);
    int k = i.x * SHEEN_N + i.y;
    return mix(mix(BRDF_SHEEN_FETCH(k), BRDF_SHEEN_FETCH(k + 1), f.y),
               mix(BRDF_SHEEN_FETCH(k + SHEEN_N), BRDF_SHEEN_FETCH(k + SHEEN_N + 1), f.y), f.x);
}

// The directional albedo of the (normalised) sheen lobe is at most min(E, 1).
float brdf_sheen_albedo(float c, float r)
{
    return min(brdf_sheen_table(c, r), 1.0);
}

float brdf_sheen_alpha(float r)
{
    r = max(r, BRDF_SHEEN_R_MIN);
    return r * r;
}

// Charlie: D = (2 + 1/alpha) sin^(1/alpha) / (2 pi) (Estevez & Kulla 2017); h unit, h.z > 0.
float brdf_d_charlie(vec3 h, float a)
{
    return (2.0 + 1.0 / a) * pow(max(dot(h.xy, h.xy), 0.0), 0.5 / a) / (2.0 * BRDF_PI);
}

// Estevez & Kulla's fit of Lambda for Charlie, as KHR_materials_sheen gives it.
float brdf_sheen_l(float x, float a)
{
    float t = (1.0 - a) * (1.0 - a);
    return mix(21.5473, 25.3245, t) / (1.0 + mix(3.82987, 3.32435, t) * pow(x, mix(0.19823, 0.16801, t))) +
           mix(-1.97760, -1.27393, t) * x + mix(-4.32054, -4.85967, t);
}

float brdf_sheen_lambda(float c, float a)
{
    return c < 0.5 ? exp(brdf_sheen_l(c, a)) : exp(2.0 * brdf_sheen_l(0.5, a) - brdf_sheen_l(1.0 - c, a));
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
    if (b.coat > 0.0 && b.coat_alpha >= BRDF_ALPHA_MIN) {
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
        if (b.coat_alpha < BRDF_ALPHA_MIN) {
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

// The layers on a base Bsdf: coat weight c, roughness cr, normal cn (local frame); sheen
// colour sc, roughness sr. c = 0 and sc = 0 leave b exactly as it is.
Bsdf bsdf_layers(Bsdf b, float c, float cr, vec3 cn, vec3 sc, float sr)
{
    b.coat = clamp(c, 0.0, 1.0);
    float a = clamp(cr, 0.0, 1.0);
    b.coat_alpha = a * a;
    b.coat_n = cn;
    b.sheen = clamp(sc, vec3(0.0), vec3(1.0));
    b.sheen_r = clamp(sr, 0.0, 1.0);
    return b;
}

vec3 bsdf_eval(Bsdf b, vec3 wo, vec3 wi)
{
    vec3 f;
    float pdf;
    bsdf_eval_pdf(b, wo, wi, f, pdf);
    return f;
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
    b.coat = 0.0;
    b.coat_n = vec3(0.0, 0.0, 1.0);
    b.coat_alpha = 0.0;
    b.sheen = vec3(0.0);
    b.sheen_r = 0.0;
    b.aniso_dir = vec2(1.0, 0.0);
    b.aniso_at = 0.0;
    b.irid = 0.0;
    b.irid_ior = 1.0;
    b.irid_d = 0.0;
    b.irid_wd = 0.0;
    b.irid_f0 = vec3(0.0);
    b.irid_wm = 0.0;
    b.irid_base = vec3(0.0);
    b.irid_avg = vec3(0.0);
    b.dt = vec3(0.0);
    return b;
}

// A model of brdf_models.h's table but glTF from a colour and four scalars, placed as its
// row's layout says; a microfacet lobe too narrow for float directions is the mirror.
Bsdf bsdf_from_model(uint model, vec3 color, vec4 params)
{
    Bsdf b = brdf_empty();
    uint place = BRDF_LAYOUT_GLTF;
// (the parameters are named apart from Bsdf's fields, which they would replace)
#define BRDF_X_ROW(id, name_, summary_, lobe_, fresnel_, layout_, lobe_feats_, feats_, params_) \
    if (model == id) {                                                                          \
        b.lobe = lobe_;                                                                         \
        b.fresnel = fresnel_;                                                                   \
        place = layout_;                                                                        \
    }
    BRDF_MODELS(BRDF_X_ROW)
#undef BRDF_X_ROW
    if (place == BRDF_LAYOUT_DIFFUSE) {
        b.diffuse = color;
    } else if (place == BRDF_LAYOUT_LOBE) {
        b.specular = color;
    } else if (place == BRDF_LAYOUT_LAYERED) {
        b.diffuse = color;
        b.specular = vec3(params[BRDF_P_SPECULAR]);
        b.shape = params[BRDF_P_SHAPE];
        b.ior = params[BRDF_P_IOR];
    } else if (place == BRDF_LAYOUT_CONDUCTOR) {
        b.specular = vec3(1.0);
        b.eta = color;
        b.k = params.xyz;
        b.shape = params[BRDF_P_ALPHA];
    } else if (place == BRDF_LAYOUT_DIELECTRIC) {
        b.dielectric = 1.0;
        b.tint = color;
        b.ior = params[BRDF_P_DIELECTRIC_IOR];
        b.shape = params[BRDF_P_DIELECTRIC_ALPHA];
    } else {
        b.lobe = BRDF_LOBE_NONE; // glTF has its own constructor; an unknown id is black
        b.fresnel = BRDF_FRESNEL_NONE;
    }
    if ((b.lobe == BRDF_LOBE_BECKMANN || b.lobe == BRDF_LOBE_GGX) && b.shape < BRDF_ALPHA_MIN)
        b.lobe = BRDF_LOBE_MIRROR;
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

// KHR_materials_anisotropy on a glTF base (bsdf_gltf): strength s in [0, 1] along dir (local
// xy, any length; none: the tangent) stretches the GGX of the specular, metal and
// transmission lobes to alpha_t = mix(alpha, 1, s^2) along dir, alpha_b = alpha across it.
// alpha_b is kept >= BRDF_ALPHA_MIN (a mirror across, rough along is still a GGX lobe); s = 0,
// or a lobe still too narrow along dir, leaves b exactly as it is.
Bsdf bsdf_anisotropy(Bsdf b, float strength, vec2 dir)
{
    float s = clamp(strength, 0.0, 1.0), at = mix(b.shape, 1.0, s * s);
    if (!GN_HAS(GN_FEAT_ANISO) || !(s > 0.0) || at < BRDF_ALPHA_MIN)
        return b;
    if (b.lobe == BRDF_LOBE_MIRROR)
        b.lobe = BRDF_LOBE_GGX;
    b.shape = max(b.shape, BRDF_ALPHA_MIN);
    b.aniso_at = at;
    b.aniso_dir = dot(dir, dir) > 1e-20 ? normalize(dir) : vec2(1.0, 0.0);
    return b;
}

// KHR_materials_iridescence and _diffuse_transmission on b = bsdf_gltf(...) of the same
// parameters: irid = (factor, the film's ior, its thickness in nm), dt = (colour, factor).
// - the film: the lobe's F = mix(F, F_film, factor), F_film of the dielectric's F0 and of the
//   metal's (the base colour) weighted as bsdf_gltf weights the two (brdf_irid_lobe); the
//   diffuse is coupled to that F (brdf_coupled), so its albedo stays kd (1 - F(wo));
// - the diffuse transmission: the diffuse weight kd = (1-m)(1-t) base colour becomes
//   (1 - factor) kd reflected and kt = factor (1-m)(1-t) colour transmitted (brdf_dt_eval_pdf).
// Factors of 0 leave b exactly as it is.
Bsdf bsdf_gltf_film(Bsdf b, vec3 base_color, float metallic, float specular, vec3 specular_color,
                    float ior, float transmission, vec3 irid, vec4 dt)
{
    float m = clamp(metallic, 0.0, 1.0), t = clamp(transmission, 0.0, 1.0);
    float wd = (1.0 - m) * (1.0 - t), k = clamp(dt.w, 0.0, 1.0);
    b.irid = clamp(irid.x, 0.0, 1.0);
    b.irid_ior = max(irid.y, 1.0);
    b.irid_d = max(irid.z, 0.0);
    b.irid_wd = wd * specular;
    b.irid_f0 = min(vec3(brdf_schlick_f0(ior)) * specular_color, vec3(1.0));
    b.irid_wm = m;
    b.irid_base = base_color;
    if (b.irid > 0.0) // (once here: it depends on the material only)
        b.irid_avg = brdf_irid_mean(b);
    if (k > 0.0) {
        b.dt = k * wd * clamp(dt.rgb, vec3(0.0), vec3(1.0));
        b.diffuse *= 1.0 - k;
    }
    return b;
}

#endif
