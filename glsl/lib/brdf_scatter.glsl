// brdf_scatter.glsl: the scattering maths the BSDFs of docs/brdf.md are made of, on numbers
// and directions in the local shading frame (normal = +z) only: the exact dielectric and
// conductor Fresnel equations and Schlick's approximation; Blinn's, Beckmann's and GGX's
// distributions with the V-cavity and height-correlated Smith masking (Cook & Torrance 1982,
// Heitz 2014), GGX's visible normals isotropic and stretched (Heitz 2018); refraction; the
// thin film of KHR_materials_iridescence (Belcour & Barla 2017) and the sheen's Charlie
// distribution (Estevez & Kulla 2017). brdf_bsdf.glsl sums them into a BSDF; docs/brdf.md
// derives each one and names the test that checks it.
#ifndef BRDF_SCATTER_GLSL
#define BRDF_SCATTER_GLSL

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

float brdf_mean(vec3 v) { return (v.r + v.g + v.b) / 3.0; }

// The layers' constants (brdf_bsdf.glsl: the layers): the coat's F0 (index 1.5) and the
// sheen's narrowest roughness.
#define BRDF_COAT_F0 0.04
#define BRDF_SHEEN_R_MIN 0.07 // tests/tool/sheen_table.c: a narrower sheen is too grazing to tabulate
// Below this cosine (0.06 degrees from grazing, under the table's first row but 0) the sheen
// is 0: its albedo there climbs to 3 before it falls to 0 at grazing, which no table row
// could follow.
#define BRDF_SHEEN_COS_MIN 0.001

float brdf_coat_fresnel(float c)
{
    return brdf_fresnel_schlick(c, vec3(BRDF_COAT_F0), 1.0).x;
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


#endif
