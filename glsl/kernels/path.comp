#version 450
// path.comp: Monte Carlo path tracing of the rendering equation (docs/path-tracing.md)
// L_o = L_e + integral f L_i cos, several path samples a pixel per dispatch. At every vertex:
// next-event estimation (one light from the power-proportional table, area sampling on
// triangles, the lat-long environment map by its luminance) and a BSDF sample from
// brdf_bsdf.glsl, combined by multiple importance sampling with the power heuristic (Veach &
// Guibas 1995, "Optimally combining sampling techniques"); Dirac lobes and punctual lights
// take their one strategy exactly; Russian roulette after ROULETTE_DEPTH bounces.
// docs/path-tracing.md derives the estimator and names the tests that check it.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require

// Specialised on the scene's features (GN_FEAT_* in shared.h): code no lane can need is
// compiled away, which llvmpipe (running both sides of every branch) needs most.
#define GN_HAS(f) (((FEATURES & (f).x) | (FEATURES_HI & (f).y)) != 0u)
#include "shared.h"
layout(constant_id = GN_SPEC_FEATURES) const uint FEATURES = 0xffffffffu;    // GN_FEAT_* bits 0-31
layout(constant_id = GN_SPEC_FEATURES_HI) const uint FEATURES_HI = 0xffffffffu; // ... 32-63

#include "bvh.glsl"
// The sheen's albedo table heads the texel buffer in scenes with layers (src/render/render.c).
#define BRDF_SHEEN_FETCH(i) uintBitsToFloat(texelFetch(texels, (i)).x)
#include "brdf_material.glsl"

layout(local_size_x = GN_TILE_X, local_size_y = GN_TILE_Y) in;

layout(std430, binding = GN_BIND_ACCUM) buffer AccumBlock { vec4 accum[]; };
layout(std430, binding = GN_BIND_AOV) buffer AovBlock { vec4 aov[]; };
// GnEmitter[] as one RGBA32UI texel each (a storage buffer read with per-lane indices costs
// llvmpipe a scalar load per lane and component: scene.glsl).
layout(binding = GN_BIND_EMITTERS) uniform utextureBuffer emitter_texels;
GnEmitter emitter_at(uint i)
{
    uvec4 t = texelFetch(emitter_texels, int(i));
    return GnEmitter(t.x, uintBitsToFloat(t.y), uintBitsToFloat(t.z), uintBitsToFloat(t.w));
}
layout(std430, binding = GN_BIND_STATUS) buffer StatusBlock { uint status[]; };
layout(std430, binding = GN_BIND_SQUARES) buffer SquaresBlock { vec4 squares[]; };
// Lat-long map: 2 words (RGB as half floats) per texel, rows top (+Y) to bottom, then the
// marginal CDF of the rows (env_height floats), then each row's conditional CDF.
// (An R32UI texel buffer: a storage buffer's per-lane reads cost llvmpipe a branch per lane.)
layout(binding = GN_BIND_ENV) uniform utextureBuffer env_texels;
uint envdata(uint i) { return texelFetch(env_texels, int(i)).x; }
layout(push_constant) uniform PushBlock { GnPush push; };

#define ROULETTE_DEPTH 3u
// Rays that leave the scene end their paths; where there is an environment they are the
// rule (a frame mostly background, an object lit by the sky), and a lane then starts its
// next path at once (main): mostly-background frame +10-15%, furnace +7% (CPU time). Not
// in scenes without one: the loop around the walk made the closed Cornell box 15% slower.
#define RETRACE (GN_HAS(GN_FEAT_ENV) ? 6u : 0u)
layout(std430, binding = GN_BIND_PSTATE) buffer StateBlock { uint pstate[]; };

// The sampler (GN_SAMPLER_*). Its dimensions, four numbers each (sampling.glsl:
// sampler_get4, .yz a 2D pair): 0 the film position (.yz); per bounce d, 1 + 2d the light
// choice (.x), the point on the light (.yz) and roulette (.w), 2 + 2d the BSDF's lobe choice
// (.x), its direction (.yz) and the medium boundary's choice (.w). The alpha tests' numbers
// (DIM_ALPHA, bvh.glsl) stay independent.
layout(constant_id = GN_SPEC_SAMPLER) const uint SAMPLER = GN_SAMPLER_SOBOL;
uint sample_now; // the sample index of the path being traced
vec4 rng(uint pixel, uint dim)
{
    return sampler_get4(SAMPLER, pixel, sample_now, dim, frame.seed);
}

float luminance(vec3 c) { return dot(c, vec3(GN_LUMA_R, GN_LUMA_G, GN_LUMA_B)); }

float power_heuristic(float a, float b) { return a * a / (a * a + b * b); }

// ---- resumable rays --------------------------------------------------------------------------
// A ray is traced in steps that resume `walk` (glsl/lib/bvh.glsl) until it is over: with
// LOOP_CAP > 0 a walk stops when its SIMD group has used its loop passes, and the path is
// then saved whole (path_save) and resumed by the next dispatch. trace_visible's crossings of
// surfaces cut away are resumable too: tr_lo is the walk's tmin (the last surface crossed)
// and tr_k the crossings so far.
float tr_lo, tr_max;
uint tr_k;
bool suspended; // this lane's walk stopped unfinished: the path waits for the next dispatch

void trace_begin(float tmin, float tmax)
{
    walk_start(tmax);
    if (GN_HAS(GN_FEAT_ALPHA) || GN_HAS(GN_FEAT_CULL)) {
        tr_lo = tmin;
        tr_max = tmax;
        tr_k = 0u;
    }
}

// Goes on with the ray of trace_begin where `on`; the same hit as trace_visible(o, d, tmin, tmax, any_hit,
// cull, dim) once the walk is over, whatever number of calls that took.
Hit trace_resume(bool on, vec3 o, vec3 d, float tmin, bool any_hit, bool cull, uint dim)
{
    // (without crossings tr_lo is the ray's own tmin: one value less kept live)
    if (!GN_HAS(GN_FEAT_ALPHA) && !GN_HAS(GN_FEAT_CULL))
        tr_lo = tmin;
    bool alpha = GN_HAS(GN_FEAT_ALPHA) && (frame.flags & GN_FRAME_ALPHA) != 0u;
    cull = cull && GN_HAS(GN_FEAT_CULL) && (frame.flags & GN_FRAME_CULL) != 0u;
    RayPre r = ray_pre(o, d);
    // (off: the loop conditions see GN_INVALID, so no visit, and the lane's walk is kept)
    uint node = walk.node;
    walk.node = on ? node : GN_INVALID;
    bvh_walk(r, tr_lo, any_hit && !alpha && !cull, 1u << 30);
    if (GN_HAS(GN_FEAT_ALPHA) || GN_HAS(GN_FEAT_CULL)) {
        while (on && (alpha || cull) && walk.node == GN_INVALID && walk.hit.tri != GN_INVALID &&
               surface_passed(walk.hit, d, alpha, cull, dim + (tr_k & (DIM_ALPHA_RAY - 1u)))) {
            // (t > the hit's own t: the watertight test gives the same t for the same ray and
            // triangle, so the surface just crossed is not found again)
            uint steps = walk.hit.steps;
            tr_lo = walk.hit.t;
            walk_start(tr_max);
            walk.hit.steps = steps;
            tr_k++;
            loop_left -= min(loop_left, 1u); // (the loop's test: in loop_overhead)
            bvh_walk(r, tr_lo, false, 1u << 30);
        }
    }
    if (!on)
        walk.node = node;
    suspended = suspended || (on && walk.node != GN_INVALID);
    return walk.hit;
}

// ---- the environment -------------------------------------------------------------------
// Lat-long mapping: u = atan(d.z, d.x) / 2pi + 1/2, v = acos(d.y) / pi (+Y up, v = 0 at the
// top row), so dOmega = 2 pi^2 sin(theta) du dv; d is first turned about +Y by minus the
// map's rotation (env_cos, env_sin), so the map turns by plus it.
ivec2 env_texel(vec3 d, out float sin_theta)
{
    d.xz = vec2(frame.env_cos * d.x + frame.env_sin * d.z, frame.env_cos * d.z - frame.env_sin * d.x);
    float v = acos(clamp(d.y, -1.0, 1.0)) / PI, u = atan(d.z, d.x) / (2.0 * PI) + 0.5;
    sin_theta = sqrt(max(0.0, 1.0 - d.y * d.y));
    return ivec2(min(uint(u * float(frame.env_width)), frame.env_width - 1u),
                 min(uint(v * float(frame.env_height)), frame.env_height - 1u));
}

float env_cdf(uint i) { return uintBitsToFloat(envdata(i)); }

// Density (over the unit square) of the map's sampler in texel xy: exactly the mass the
// CDFs give the texel, times the texel count.
float env_pdf_uv(ivec2 xy)
{
    uint m = 2u * frame.env_width * frame.env_height, c = m + frame.env_height + uint(xy.y) * frame.env_width;
    float pm = env_cdf(m + uint(xy.y)) - (xy.y > 0 ? env_cdf(m + uint(xy.y) - 1u) : 0.0);
    float pc = env_cdf(c + uint(xy.x)) - (xy.x > 0 ? env_cdf(c + uint(xy.x) - 1u) : 0.0);
    return pm * pc * float(frame.env_width * frame.env_height);
}

vec3 env_radiance(vec3 d)
{
    if (!GN_HAS(GN_FEAT_ENV))
        return vec3(0.0);
    if (!GN_HAS(GN_FEAT_ENV_MAP) || (frame.flags & GN_FRAME_ENV_MAP) == 0u)
        return frame.env_color;
    float st;
    ivec2 xy = env_texel(d, st);
    uint i = 2u * (uint(xy.y) * frame.env_width + uint(xy.x));
    return vec3(unpackHalf2x16(envdata(i)), unpackHalf2x16(envdata(i + 1u)).x);
}

// Solid-angle density with which light sampling picks direction d toward the environment.
float env_pdf(vec3 d)
{
    if (!GN_HAS(GN_FEAT_ENV_MAP) || (frame.flags & GN_FRAME_ENV_MAP) == 0u)
        return frame.env_select / (4.0 * PI);
    float st;
    ivec2 xy = env_texel(d, st);
    return st > 0.0 ? frame.env_select * env_pdf_uv(xy) / (2.0 * PI * PI * st) : 0.0;
}

// First index in [first, first + n) whose CDF value exceeds u (the last when none does).
uint cdf_search(uint first, uint n, float u)
{
    uint lo = 0u, hi = n - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (env_cdf(first + mid) > u) hi = mid; else lo = mid + 1u;
    }
    return lo;
}

// A direction from the map's piecewise-constant density; pdf excludes env_select.
vec3 env_sample(vec2 u, out float pdf)
{
    uint w = frame.env_width, h = frame.env_height, m = 2u * w * h;
    uint y = cdf_search(m, h, u.x);
    float y0 = y > 0u ? env_cdf(m + y - 1u) : 0.0, y1 = env_cdf(m + y);
    uint c = m + h + y * w;
    uint x = cdf_search(c, w, u.y);
    float x0 = x > 0u ? env_cdf(c + x - 1u) : 0.0, x1 = env_cdf(c + x);
    float fu = (float(x) + clamp((u.y - x0) / max(x1 - x0, 1e-30), 0.0, 1.0)) / float(w);
    float fv = (float(y) + clamp((u.x - y0) / max(y1 - y0, 1e-30), 0.0, 1.0)) / float(h);
    float theta = fv * PI, phi = (fu - 0.5) * 2.0 * PI, st = sin(theta);
    pdf = st > 0.0 ? (y1 - y0) * (x1 - x0) * float(w * h) / (2.0 * PI * PI * st) : 0.0;
    vec2 xz = st * vec2(cos(phi), sin(phi));
    return vec3(frame.env_cos * xz.x - frame.env_sin * xz.y, cos(theta),
                frame.env_sin * xz.x + frame.env_cos * xz.y);
}

// ---- lights ---------------------------------------------------------------------------------
struct LightSample {
    vec3 wi;     // toward the light
    float dist;  // to the light point (1e30: at infinity)
    vec3 L;      // incident radiance; for a punctual light its irradiance at normal incidence
    float pdf;   // solid-angle density, selection included; punctual: the selection probability
    bool delta;  // punctual: no other strategy can find it
};

float area_sides(GnMaterial m) { return (m.flags & GN_MAT_DOUBLE_SIDED) != 0u ? 2.0 : 1.0; }

// Emitted radiance of triangle `prim` at barycentrics (u, v) toward -d, 0 from the back of a
// single-sided material (glTF: back faces are culled).
vec3 tri_emission(uint prim, float u, float v, vec3 d, vec3 ng)
{
    GnPrim pr = prim_at(prim);
    GnMaterial m = material_at(pr.material);
    if (dot(ng, d) >= 0.0 && (m.flags & GN_MAT_DOUBLE_SIDED) == 0u)
        return vec3(0.0);
    vec3 e = m.emissive;
    if (GN_HAS(GN_FEAT_TEXTURES) && m.tex_emissive != GN_INVALID) {
        GnVertex a = vertex_at(pr.i0), b = vertex_at(pr.i1), c = vertex_at(pr.i2);
        vec4 uv = (1.0 - u - v) * vertex_uv(a) + u * vertex_uv(b) + v * vertex_uv(c);
        e *= texture_sample(m.tex_emissive, uv, true).rgb;
    }
    return e;
}

// KHR_lights_punctual: irradiance at p from light l (range window and spot cone as the
// extension recommends), direction and distance.
vec3 punctual_incident(GnLight l, vec3 p, out vec3 wi, out float dist)
{
    if (l.type == GN_LIGHT_DIRECTIONAL) {
        wi = -l.direction;
        dist = 1e30;
        return l.color;
    }
    vec3 to = l.position - p;
    float d2 = max(dot(to, to), 1e-12);
    dist = sqrt(d2);
    wi = to / dist;
    float atten = 1.0 / d2;
    if (l.range > 0.0) {
        float x = dist / l.range, win = clamp(1.0 - x * x * x * x, 0.0, 1.0);
        atten *= win * win;
    }
    if (l.type == GN_LIGHT_SPOT)
        atten *= smoothstep(l.outer_cos, l.inner_cos, dot(l.direction, -wi));
    return l.color * atten;
}

LightSample light_sample(vec3 p, vec3 u)
{
    LightSample s;
    s.pdf = 0.0;
    s.delta = false;
    s.L = vec3(0.0);
    uint lo = 0u, hi = frame.num_emitters - 1u;
    while (GN_HAS(GN_FEAT_LIGHT_SEARCH) && lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (emitter_at(mid).cdf > u.x) hi = mid; else lo = mid + 1u;
    }
    GnEmitter e = emitter_at(lo);
    if (GN_HAS(GN_FEAT_ENV) && e.prim == GN_INVALID) {
        float pdf = 1.0 / (4.0 * PI);
        if (GN_HAS(GN_FEAT_ENV_MAP) && (frame.flags & GN_FRAME_ENV_MAP) != 0u)
            s.wi = env_sample(u.yz, pdf);
        else
            s.wi = sampling_uniform_sphere(u.yz);
        s.dist = 1e30;
        s.L = env_radiance(s.wi);
        s.pdf = e.pdf * pdf;
    } else if (GN_HAS(GN_FEAT_PUNCTUAL) && (e.prim & GN_EMITTER_LIGHT) != 0u) {
        s.L = punctual_incident(lights[e.prim & ~GN_EMITTER_LIGHT], p, s.wi, s.dist);
        s.pdf = e.pdf;
        s.delta = true;
    } else if (GN_HAS(GN_FEAT_EMISSIVE)) {
        // (with instances the table lists each instance's triangles, the instance after the table)
        uint inst = INSTANCES != 0u ? texelFetch(emitter_texels, int(frame.emitter_instances + lo)).x : GN_INVALID;
        vec3 c0, c1, c2;
        tri_corners(e.prim, inst, c0, c1, c2);
        float su = sqrt(u.y), b1 = 1.0 - su, b2 = u.z * su;
        vec3 q = (1.0 - b1 - b2) * c0 + b1 * c1 + b2 * c2;
        vec3 ng = normalize(cross(c1 - c0, c2 - c0));
        if (instance_mirrors(inst))
            ng = -ng;
        vec3 to = q - p;
        float d2 = dot(to, to);
        s.dist = sqrt(d2);
        s.wi = to / s.dist;
        float c = abs(dot(ng, s.wi));
        if (c > 0.0 && d2 > 0.0) {
            s.L = tri_emission(e.prim, b1, b2, s.wi, ng);
            // A BSDF ray finds an emitter of opacity a only a of the time: so does light sampling.
            if (GN_HAS(GN_FEAT_ALPHA))
                s.L *= surface_opacity(e.prim, b1, b2);
            s.pdf = e.pdf / e.area * d2 / c;
        }
    }
    return s;
}

// ---- materials ------------------------------------------------------------------------------
// Does b have a part that light sampling can reach (anything but Dirac lobes)?
bool bsdf_has_smooth(Bsdf b)
{
    return any(greaterThan(b.diffuse, vec3(0.0))) || (GN_HAS(GN_FEAT_LAYERS) && brdf_has_dt(b)) ||
           (b.lobe != BRDF_LOBE_NONE && b.lobe != BRDF_LOBE_MIRROR) ||
           (b.dielectric > 0.0 && !lobes_smooth(b.shape)) ||
           (GN_HAS(GN_FEAT_LAYERS) && (any(greaterThan(b.sheen, vec3(0.0))) ||
                                       (b.coat > 0.0 && !lobes_smooth(b.coat_alpha))));
}

// ---- media: KHR_materials_volume and _dispersion (GN_FEAT_VOLUME) --------------------------
// The media a path is inside, innermost last, as material ids: a closed transmissive mesh
// with a volume is entered by a transmission through a front face and left by one through a
// back face, so nested and touching media (a glass of water: water inside glass) have the
// right one on top, and the index at an interface is the ratio of the two sides' media.
// Paths start in vacuum (index 1, no absorption); a fifth nested medium is not entered.
#define MEDIA_MAX GN_MEDIA_MAX
uint media[MEDIA_MAX];
uint media_n;
vec3 seg_from; // where the path's current segment starts: the vertex, not the offset origin
uint channel; // dispersion: the colour channel the path carries since its first dispersive
              // interface (3: all of them)

void media_start()
{
    media_n = 0u;
    channel = 3u;
}

uint medium_top() { return media_n > 0u ? media[media_n - 1u] : GN_INVALID; }

// Does material m bound a medium? (a BRDF-model override shades it as it is, without)
bool medium_of(GnMaterial m) { return m.volume != 0u && m.brdf == BRDF_GLTF; }

// Beer-Lambert transmittance over distance t in medium `id`: exp(-sigma_a t), sigma_a =
// -ln(attenuation colour) / attenuation distance (colour floored so that black stays finite).
vec3 medium_transmittance(uint id, float t)
{
    if (id == GN_INVALID)
        return vec3(1.0);
    GnMaterial m = material_at(id);
    vec3 sigma = -log(max(m.attenuation_color, vec3(1e-30))) / m.attenuation_distance;
    return exp(-sigma * t);
}

// The index of material m in the path's channel (at least 1: KHR_materials_ior's 0, a
// mirror's F0 of 1, has no refraction to take a ratio of). Dispersion as glTF defines it: n(lambda) =
// max(n_d + (n_d - 1) / V (523655 / lambda^2 - 1.5168), 1), V = 20 / dispersion, at the
// Fraunhofer lines C (656.3 nm) for red, d (587.56 nm, where n = n_d) for green and F
// (486.1 nm) for blue.
float medium_ior(GnMaterial m)
{
    if (m.dispersion <= 0.0 || channel > 2u || m.ior < 1.0)
        return max(m.ior, 1.0);
    float k = channel == 0u ? 523655.0 / (656.3 * 656.3) - 1.5168
            : channel == 2u ? 523655.0 / (486.1 * 486.1) - 1.5168 : 0.0;
    return max(m.ior + (m.ior - 1.0) * m.dispersion / 20.0 * k, 1.0);
}

float medium_ior_of(uint id) { return id == GN_INVALID ? 1.0 : medium_ior(material_at(id)); }

// At a hit on material m (surface s) with a dielectric part or a diffuse transmission: picks
// the path's channel at its first dispersive interface (u: uniform; the throughput of the one
// channel times 3, its selection's inverse probability) and sets b.ior to the interface's
// ratio (the back side's medium over the front side's). Returns the medium on the far side of
// the interface, which a shadow ray through it crosses.
uint medium_interface(Surface s, GnMaterial m, inout Bsdf b, float u, inout vec3 throughput)
{
    uint top = medium_top();
    if (b.dielectric <= 0.0 && !(GN_HAS(GN_FEAT_LAYERS) && brdf_has_dt(b)))
        return top;
    if (b.dielectric > 0.0 && m.dispersion > 0.0 && channel > 2u && m.brdf == BRDF_GLTF) {
        channel = min(uint(u * 3.0), 2u);
        throughput *= vec3(channel == 0u, channel == 1u, channel == 2u) * 3.0;
    }
    if (!medium_of(m)) { // no medium: glass against vacuum, as without the extension
        if (m.brdf == BRDF_GLTF)
            b.ior = max(medium_ior(m), 1.01);
        return top;
    }
    float inner, outer;
    uint far = top;
    if (s.front) {
        inner = medium_ior(m);
        outer = medium_ior_of(top);
        far = s.material;
    } else {
        // Leaving m: outside is what is left when m's innermost entry goes (m not entered,
        // as for a camera inside it: the medium the path is in).
        int j = -1;
        for (uint i = 0u; i < media_n; i++)
            if (media[i] == s.material) j = int(i);
        if (j >= 0) {
            far = int(media_n) - 1 == j ? (j > 0 ? media[j - 1] : GN_INVALID) : top;
            inner = medium_ior_of(top);
        } else {
            inner = medium_ior(m);
        }
        outer = medium_ior_of(far);
    }
    float eta = inner / outer;
    // The rough BTDF collapses to a Dirac at 1 (bsdf_gltf): kept as far off it as there.
    if (!lobes_smooth(b.shape))
        eta = eta >= 1.0 ? max(eta, 1.01) : min(eta, 1.0 / 1.01);
    b.ior = eta;
    return far;
}

// After a transmission through material `id`: the medium entered (front) or left (back).
void medium_cross(uint id, bool front)
{
    if (front) {
        if (media_n < MEDIA_MAX)
            media[media_n++] = id;
        return;
    }
    bool found = false;
    for (int i = int(media_n) - 1; i >= 0; i--)
        if (!found && media[i] == id) {
            found = true;
            for (uint k = uint(i); k + 1u < media_n; k++)
                media[k] = media[k + 1u];
        }
    if (found)
        media_n--;
}

// Offset of a ray origin off the surface, to the side of w (scaled to the coordinates'
// magnitude so float rounding of the hit point cannot put it behind the surface).
vec3 offset_origin(vec3 p, vec3 ng, vec3 w)
{
    float eps = 1e-4 * max(1.0, max(abs(p.x), max(abs(p.y), abs(p.z))));
    return p + ng * (dot(ng, w) >= 0.0 ? eps : -eps);
}

// ---- the paths of an invocation --------------------------------------------------------------
// An invocation takes push.samples samples of its pixel (sample indices push.sample_index on),
// starting the next path as soon as one ends ("regeneration"). The 8 lanes of a SIMD group
// run in step until the longest of their paths ends, and roulette makes path lengths vary
// a lot; a lane that starts its next path at once, instead of idling, keeps the group busy.
// Every sample is still the same function of (pixel, sample index, dimension).
//
// Under llvmpipe's loop cap (LOOP_CAP > 0) a path whose walk runs out of the group's loop
// passes is saved whole in pstate (path_save) with the samples after it, and the next
// dispatch of the kernel, in the same or the next submission, finishes those first
// (path_load): the pixel's samples are still added up one at a time in sample order, so the
// bits do not depend on where a path was interrupted. The host dispatches again, taking no
// new samples, until no pixel is pending (status[1]; src/render/render.c: renderer_finish).
uvec2 px;
uint pixel;
uint samples, taken;
uint pstate_behind = 0u; // samples pending from the last dispatch (0: none), the first one saved
vec4 sum;
vec3 sum_sq, sum_n, sum_a;
float sum_depth;
// The current path: its ray (o, d from tmin) and, in phase PHASE_SHADOW, the shadow ray
// (so, sd up to smax) whose contribution c it adds if nothing blocks it; alive: the path goes
// on after this vertex (o, d already the next ray).
#define PHASE_RAY 0u
#define PHASE_SHADOW 1u
uint depth, phase;
vec3 o, d, radiance, beta, normal, albedo, so, sd, c;
float tmin, prev_pdf, depth_aov, smax;
bool prev_delta, covered, ended, alive;

void path_start()
{
    sample_now = push.sample_index - pstate_behind + taken;
    rng_sample = sample_now;
    depth = 0u;
    camera_ray(vec2(px) + rng(pixel, 0u).yz, o, d, tmin);
    radiance = vec3(0.0);
    beta = vec3(1.0);
    prev_pdf = 0.0;
    prev_delta = true; // the camera ray: what it sees has one strategy only
    covered = false;
    normal = vec3(0.0);
    albedo = vec3(0.0);
    depth_aov = 0.0;
    ended = false;
    phase = PHASE_RAY;
    trace_begin(tmin, 1e30);
    if (GN_HAS(GN_FEAT_VOLUME))
        media_start();
    seg_from = o;
}

// The path's sample added up and the next path started, if the pixel has one.
void path_end()
{
    // A NaN or infinity from a degenerate configuration would poison the pixel for good.
    if (any(isnan(radiance)) || any(isinf(radiance)))
        radiance = vec3(0.0);
    sum += vec4(radiance, covered ? 1.0 : 0.0);
    if (GN_HAS(GN_FEAT_VARIANCE))
        sum_sq += radiance * radiance;
    sum_n += normal;
    sum_a += albedo;
    sum_depth += depth_aov;
    taken++;
    if (taken < samples)
        path_start();
}

// After a path vertex: the next vertex, or (the path ended) the sample added up and the
// next path started.
uint path_step()
{
    if (!ended) {
        depth++;
        return taken;
    }
    path_end();
    return taken;
}

// What a ray that left the scene (h: its walk's miss) adds to the path, which it ends.
void path_miss(Hit h, bool light_only, bool bsdf_only)
{
    if (GN_HAS(GN_FEAT_VOLUME)) // absorption by the medium the segment crossed
        beta *= medium_transmittance(medium_top(), h.t);
    vec3 le = env_radiance(d);
    float w = 1.0;
    if (GN_HAS(GN_FEAT_ENV) && !prev_delta && frame.env_select > 0.0)
        w = light_only ? 0.0 : bsdf_only ? 1.0 : power_heuristic(prev_pdf, env_pdf(d));
    radiance += beta * le * w;
}

// ---- a path's saved state (GN_BIND_PSTATE: frame.state_stride words a pixel) -----------------
// Word 0: the pixel's samples still to take, the saved one included (0: none pending); then
// the fields of GN_PATH_STATE (glsl/lib/shared.h), each saved and loaded by the expansions
// below at word ps_k, and the walk's stack. Read and written only by LOOP_CAP kernels.
uint ps_base, ps_k;
#define PS_AT(i) pstate[ps_base + ps_k + (i)]
#define PS_SAVE_U(v) PS_AT(0u) = v;
#define PS_SAVE_I(v) PS_AT(0u) = uint(v);
#define PS_SAVE_F(v) PS_AT(0u) = floatBitsToUint(v);
#define PS_SAVE_B(v) PS_AT(0u) = v ? 1u : 0u;
#define PS_SAVE_V(v) PS_AT(0u) = floatBitsToUint(v.x); PS_AT(1u) = floatBitsToUint(v.y); \
                     PS_AT(2u) = floatBitsToUint(v.z);
#define PS_SAVE_M(v) for (uint m = 0u; m < GN_MEDIA_MAX; m++) PS_AT(m) = v[m];
#define PS_LOAD_U(v) v = PS_AT(0u);
#define PS_LOAD_I(v) v = int(PS_AT(0u));
#define PS_LOAD_F(v) v = uintBitsToFloat(PS_AT(0u));
#define PS_LOAD_B(v) v = PS_AT(0u) != 0u;
#define PS_LOAD_V(v) v = vec3(uintBitsToFloat(PS_AT(0u)), uintBitsToFloat(PS_AT(1u)), uintBitsToFloat(PS_AT(2u)));
#define PS_LOAD_M(v) for (uint m = 0u; m < GN_MEDIA_MAX; m++) v[m] = PS_AT(m);
#define PS_SAVE(kind, var, when) if (when) { PS_SAVE_##kind(var) } ps_k += GN_PS_WORDS_##kind;
#define PS_LOAD(kind, var, when) if (when) { PS_LOAD_##kind(var) } ps_k += GN_PS_WORDS_##kind;

void path_save(uint behind)
{
    pstate[ps_base] = behind;
    ps_k = 1u;
    GN_PATH_STATE(PS_SAVE)
    if (WALK_REGS > 0u) {
        for (uint k = 0u; k < WALK_REGS; k++)
            pstate[ps_base + GN_PATH_STATE_WORDS + k] = walk.regs[k];
    } else {
        for (int k = 1; k < walk.sp; k++)
            pstate[ps_base + GN_PATH_STATE_WORDS + uint(k)] = walk.stack[k];
    }
    if (INSTANCES != 0u) { // the instances' two words close a pixel's state, after the stack
        pstate[ps_base + frame.state_stride - 2u] = walk.hit.inst;
        pstate[ps_base + frame.state_stride - 1u] = walk.inst;
    }
}

void path_load()
{
    ps_k = 1u;
    GN_PATH_STATE(PS_LOAD)
    walk.hit.truncated = false;
    if (WALK_REGS > 0u) {
        for (uint k = 0u; k < WALK_REGS; k++)
            walk.regs[k] = pstate[ps_base + GN_PATH_STATE_WORDS + k];
    } else {
        walk.stack[0] = GN_INVALID;
        for (int k = 1; k < walk.sp; k++)
            walk.stack[k] = pstate[ps_base + GN_PATH_STATE_WORDS + uint(k)];
    }
    walk.hit.inst = INSTANCES != 0u ? pstate[ps_base + frame.state_stride - 2u] : GN_INVALID;
    walk.inst = INSTANCES != 0u ? pstate[ps_base + frame.state_stride - 1u] : GN_INVALID;
    sample_now = push.sample_index - pstate_behind;
    rng_sample = sample_now;
    ended = false;
}

// ---- a pixel's work: its sums, its paths' vertices, what it leaves to the next dispatch -----

// The strategies of the estimator ablations (--estimator light|bsdf); MIS otherwise.
bool light_only, bsdf_only;
// The pixel's sums in the region's buffers; without their AOVs the aov and squares buffers
// are 16-byte dummies, never indexed.
uint slot;
bool aov_on, squares_on;

// The pixel's state at the dispatch's start: the samples it takes (those pending from the
// last dispatch first) and its sums so far. The sums go on from the buffers, one sample at a
// time in sample order, so a pixel's sum is the same float whichever dispatches (or runs:
// --resume) took its samples.
void pixel_begin()
{
    slot = px.y * frame.crop_width + px.x; // in the region's buffers
    px += uvec2(frame.crop_x, frame.crop_y); // in the whole image
    pixel = px.y * frame.width + px.x;
    rng_pixel = pixel;
    light_only = GN_HAS(GN_FEAT_STRATEGY) && (frame.flags & GN_FRAME_LIGHT_ONLY) != 0u;
    bsdf_only = GN_HAS(GN_FEAT_STRATEGY) && (frame.flags & GN_FRAME_BSDF_ONLY) != 0u;
    suspended = false;
    ps_base = slot * frame.state_stride;
    if (LOOP_CAP > 0u)
        pstate_behind = pstate[ps_base];
    samples = pstate_behind + push.samples;
    taken = 0u;
    aov_on = GN_HAS(GN_FEAT_AOV) && (frame.flags & GN_FRAME_AOV) != 0u;
    squares_on = GN_HAS(GN_FEAT_VARIANCE) && (frame.flags & GN_FRAME_VARIANCE) != 0u;
    sum = accum[slot];
    sum_sq = squares_on ? squares[slot].rgb : vec3(0.0);
    sum_n = aov_on ? aov[3u * slot + 0u].xyz : vec3(0.0);
    sum_a = aov_on ? aov[3u * slot + 1u].xyz : vec3(0.0);
    sum_depth = aov_on ? aov[3u * slot + 2u].x : 0.0;
}

// The walk of the path's ray. With RETRACE, a lane whose ray leaves the scene ends its path
// and walks its next path's camera ray at once, up to RETRACE times, so that fewer lanes idle
// through the shading and the shadow ray below. The same samples in the same order: the same
// bits.
Hit vertex_walk()
{
    Hit h;
    if (RETRACE == 0u) {
        h = trace_resume(true, o, d, tmin, false, depth == 0u, DIM_ALPHA + DIM_ALPHA_RAY * 2u * depth);
    } else {
        bool again = true;
        for (uint k = 0u; again; k++) {
            if (LOOP_CAP > 0u && k > 0u) // (a pass counts as a vertex: its walk's loop tests and this loop's)
                loop_left -= min(loop_left, frame.loop_overhead);
            h = trace_resume(true, o, d, tmin, false, depth == 0u, DIM_ALPHA + DIM_ALPHA_RAY * 2u * depth);
            again = !suspended && h.tri == GN_INVALID && k < RETRACE && taken + 1u < samples;
            if (again) {
                path_miss(h, light_only, bsdf_only);
                path_end();
                ended = true; // (path_start's false is for path_step, after the vertex)
            }
        }
    }
    return h;
}

// The first hit's coverage and AOVs.
void vertex_seen(Surface s, Hit h)
{
    covered = covered || depth == 0u;
    if (GN_HAS(GN_FEAT_AOV) && depth == 0u) {
        normal = s.sh.n;
        albedo = s.sh.m.base_color.rgb;
        depth_aov = h.t * dot(d, frame.camera.forward);
    }
}

// The light the surface emits toward the path, MIS-weighted against the light sample of the
// vertex before.
void vertex_emission(Surface s, GnMaterial m, Hit h)
{
    if (GN_HAS(GN_FEAT_EMISSIVE) && (s.front || (m.flags & GN_MAT_DOUBLE_SIDED) != 0u) && luminance(m.emissive) > 0.0) {
        float w = 1.0;
        if (!prev_delta) {
            float pl = luminance(m.emissive) * area_sides(m) / frame.emitter_power * h.t * h.t / abs(dot(s.ng, d));
            w = light_only ? 0.0 : bsdf_only ? 1.0 : power_heuristic(prev_pdf, pl);
        }
        radiance += beta * s.sh.m.emissive * w;
    }
}

// The vertex's scattering: its Bsdf, a light sample (its shadow ray set up, walked after the
// next ray is chosen: the state a walk that stops leaves to save is then the two rays, c and
// the path's sums), and the next ray with roulette (alive: the path goes on).
void vertex_scatter(Surface s, GnMaterial m)
{
    Bsdf b = bsdf_material(s.sh);
    // A transmitting surface needs the side: a Bsdf's normal points outside.
    bool flip = b.dielectric > 0.0 && !s.front;
    vec3 n = flip ? -s.sh.n : s.sh.n, ng = flip ? -s.ng : s.ng, tx, ty;
    sampling_basis(n, tx, ty);
    vec3 wo = vec3(dot(-d, tx), dot(-d, ty), dot(-d, n));
    vec3 cn = flip ? -s.sh.coat_n : s.sh.coat_n; // (the anisotropy's direction on the shading plane)
    b = bsdf_orient(b, s.sh, normalize(vec3(dot(cn, tx), dot(cn, ty), dot(cn, n))),
                    vec2(dot(s.sh.aniso_t, tx), dot(s.sh.aniso_t, ty)));
    vec4 ul = rng(pixel, 1u + 2u * depth), ub = rng(pixel, 2u + 2u * depth);
    uint far = GN_INVALID; // the medium beyond a transmitting surface
    if (GN_HAS(GN_FEAT_VOLUME))
        far = medium_interface(s, m, b, ub.w, beta);

    bool shadow = false;
    if (frame.num_emitters > 0u && bsdf_has_smooth(b)) {
        LightSample ls = light_sample(s.p, ul.xyz);
        vec3 wi = vec3(dot(ls.wi, tx), dot(ls.wi, ty), dot(ls.wi, n));
        // The shading and geometric normals must agree on the side of wi (no light leaks).
        if (ls.pdf > 0.0 && !(bsdf_only && !ls.delta) && dot(ng, ls.wi) * wi.z > 0.0 && luminance(ls.L) > 0.0) {
            vec3 f;
            float pb;
            bsdf_eval_pdf(b, wo, wi, f, pb);
            float w = ls.delta || light_only ? 1.0 : power_heuristic(ls.pdf, pb);
            c = beta * f * abs(wi.z) * ls.L * (w / ls.pdf);
            if (GN_HAS(GN_FEAT_VOLUME))
                c *= medium_transmittance(wi.z * wo.z > 0.0 ? medium_top() : far, ls.dist);
            if (luminance(c) > 0.0) {
                shadow = true;
                so = offset_origin(s.p, ng, ls.wi);
                sd = ls.wi;
                smax = ls.dist * (1.0 - 1e-3);
            }
        }
    }

    BsdfSample bs = bsdf_sample(b, wo, ub.xyz);
    vec3 wi = bs.wi.x * tx + bs.wi.y * ty + bs.wi.z * n;
    alive = bs.flags != 0u && dot(ng, wi) * bs.wi.z > 0.0;
    if (alive) {
        beta *= bs.weight;
        if (GN_HAS(GN_FEAT_VOLUME) && (bs.flags & BRDF_FLAG_TRANSMISSION) != 0u && medium_of(m))
            medium_cross(s.material, s.front);
        prev_delta = (bs.flags & BRDF_FLAG_DELTA) != 0u;
        prev_pdf = bs.pdf;
        o = offset_origin(s.p, ng, wi);
        seg_from = s.p;
        d = wi;
        if (depth + 1u >= ROULETTE_DEPTH) {
            float q = min(max(beta.r, max(beta.g, beta.b)), 0.95);
            alive = ul.w < q;
            if (alive)
                beta /= q;
        }
    }
    if (shadow) {
        phase = PHASE_SHADOW;
        trace_begin(0.0, smax);
    }
}

// The pixel's sums written back, and what it leaves pending to the next dispatch (the rest of
// its samples, and the path it stopped in) saved and counted (status[1]); status[0] counts
// what only a bug gives: llvmpipe's own cap stopping a walk or the loop.
void pixel_end()
{
    uint behind = suspended ? samples - taken : 0u;
    if (LOOP_CAP > 0u) {
        if (suspended)
            path_save(behind);
        else if (pstate_behind > 0u)
            pstate[ps_base] = 0u;
        if ((behind > 0u) != (pstate_behind > 0u))
            atomicAdd(status[1], behind > 0u ? 1u : ~0u);
        // A walk stopped with passes left: llvmpipe's own cap stopped it, the count is wrong.
        if (suspended && loop_left > 0u)
            atomicAdd(status[0], 1u);
    }
    // Fewer samples than asked for and nothing pending: llvmpipe's loop cap ended the loop.
    if (!suspended && taken < samples)
        atomicAdd(status[0], 1u);
    accum[slot] = sum;
    if (squares_on)
        squares[slot] = vec4(sum_sq, 0.0);
    if (aov_on) {
        aov[3u * slot + 0u] = vec4(sum_n, 0.0);
        aov[3u * slot + 1u] = vec4(sum_a, 0.0);
        aov[3u * slot + 2u] = vec4(sum_depth, 0.0, 0.0, 0.0);
    }
}

void main()
{
    px = tile_pixel();
    if (px.x >= frame.crop_width || px.y >= frame.crop_height)
        return;
    pixel_begin();
    if (pstate_behind > 0u)
        path_load();
    else if (samples > 0u)
        path_start();
    // One path vertex an iteration: the walk of its ray, the vertex shaded (its light sample
    // and next ray chosen), the walk of its shadow ray, in that order; a path resumed in its
    // shadow ray's walk starts at the third.
    loop_left = LOOP_CAP / gl_SubgroupSize;
    while (samples > 0u) {
        ended = true;
        if (LOOP_CAP > 0u) // (the vertex's loops other than its walks)
            loop_left -= min(loop_left, frame.loop_overhead);
        // One vertex, in a loop of one iteration: a path's end is a `break` out of it.
        // (llvmpipe masks lanes for a break cheaply; a continue or an early return masks
        // every later statement again, which is slower: docs/performance.md.)
        do {
            if (phase == PHASE_RAY) {
                Hit h = vertex_walk();
                if (suspended)
                    break;
                if (GN_HAS(GN_FEAT_VOLUME) && h.tri != GN_INVALID) // absorption by the medium the segment crossed
                    beta *= medium_transmittance(medium_top(), distance(seg_from, o + h.t * d));
                alive = false;
                tmin = 0.0;
                if (h.tri == GN_INVALID) {
                    path_miss(h, light_only, bsdf_only);
                    break;
                }
                Surface s = surface_at(h.tri, h.inst, h.t, h.u, h.v, o, d);
                GnMaterial m = material_at(s.material);
                vertex_seen(s, h);
                if (GN_HAS(GN_FEAT_UNLIT) && (m.flags & GN_MAT_UNLIT) != 0u) { // KHR_materials_unlit: the colour is the radiance
                    radiance += beta * s.sh.m.base_color.rgb;
                    break;
                }
                vertex_emission(s, m, h);
                if (frame.max_depth != 0u && depth >= frame.max_depth)
                    break;
                vertex_scatter(s, m);
            }
            if (phase == PHASE_SHADOW) {
                Hit sh = trace_resume(true, so, sd, 0.0, true, false, DIM_ALPHA + DIM_ALPHA_RAY * (2u * depth + 1u));
                if (suspended)
                    break;
                if (sh.tri == GN_INVALID)
                    radiance += c;
                phase = PHASE_RAY;
            }
            // A path's vertex is over when its rays are: alive, it goes on with the next ray.
            if (!alive)
                break;
            ended = false;
            trace_begin(0.0, 1e30);
        } while (false);
        if (suspended || path_step() == samples)
            break;
    }
    pixel_end();
}
