#version 450
// path.comp: Monte Carlo path tracing of the lecture's rendering equation
// L_o = L_e + integral f L_i cos, one path sample per pixel per dispatch. At every vertex:
// next-event estimation (one light from the power-proportional table, area sampling on
// triangles, the lat-long environment map by its luminance) and a BSDF sample from
// brdf.glsl, combined by multiple importance sampling with the power heuristic (Veach &
// Guibas 1995, "Optimally combining sampling techniques"); Dirac lobes and punctual lights
// take their one strategy exactly; Russian roulette after ROULETTE_DEPTH bounces.
// docs/path-tracing.md derives the estimator and names the tests that check it.
#extension GL_GOOGLE_include_directive : require

// Specialised on the scene's features (GN_FEAT_* in shared.h): code no lane can need is
// compiled away, which llvmpipe (running both sides of every branch) needs most.
#define GN_HAS(f) ((FEATURES & (f)) != 0u)
#include "shared.h"
layout(constant_id = 1) const uint FEATURES = GN_FEAT_ALL;

#include "bvh.glsl"
// The sheen's albedo table heads the texel buffer in scenes with layers (src/render.c).
#define BRDF_SHEEN_FETCH(i) uintBitsToFloat(texelFetch(texels, (i)).x)
#include "brdf.glsl"

layout(local_size_x = GN_TILE_X, local_size_y = GN_TILE_Y) in;

layout(std430, binding = GN_BIND_ACCUM) buffer AccumBlock { vec4 accum[]; };
layout(std430, binding = GN_BIND_AOV) buffer AovBlock { vec4 aov[]; };
// GnEmitter[] as one RGBA32UI texel each (a storage buffer read with per-lane indices costs
// llvmpipe a scalar load per lane and component: scene.glsl).
layout(binding = GN_BIND_EMITTERS) uniform usamplerBuffer emitter_texels;
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
layout(binding = GN_BIND_ENV) uniform usamplerBuffer env_texels;
uint envdata(uint i) { return texelFetch(env_texels, int(i)).x; }
layout(push_constant) uniform PushBlock { GnPush push; };

#define ROULETTE_DEPTH 3u
// A ray's own loop iterations besides its walk (light selection, map searches), in node
// visits (a visit costs up to 19 iterations): charged so the whole path stays under
// llvmpipe's loop cap with frame.traversal_budget node visits per path.
#define TRACE_OVERHEAD 4u

uint budget;    // node visits left to this path
bool truncated; // a walk ran out of budget: the path was cut short

uint sample_now; // the sample index of the path being traced
vec4 rng(uint pixel, uint dim)
{
    return rng_uniform4(pixel, sample_now, dim, frame.seed);
}

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

float power_heuristic(float a, float b) { return a * a / (a * a + b * b); }

// dim: the first random dimension of the ray's crossings of BLEND surfaces (trace_visible).
Hit trace(vec3 o, vec3 d, float tmin, float tmax, bool any_hit, uint dim)
{
    trace_visible(o, d, tmin, tmax, any_hit, budget, dim);
    budget -= min(walk.hit.steps + TRACE_OVERHEAD, budget);
    truncated = truncated || walk.hit.truncated;
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
        vec3 c0, c1, c2;
        tri_corners(e.prim, c0, c1, c2);
        float su = sqrt(u.y), b1 = 1.0 - su, b2 = u.z * su;
        vec3 q = (1.0 - b1 - b2) * c0 + b1 * c1 + b2 * c2;
        vec3 ng = normalize(cross(c1 - c0, c2 - c0));
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
Bsdf material_bsdf(Surface s, GnMaterial m)
{
    if (GN_HAS(GN_FEAT_MODELS) && (!GN_HAS(GN_FEAT_GLTF) || m.brdf != BRDF_GLTF)) // the colour of a conductor is its index, never a texture's
        return bsdf_from_model(m.brdf, m.brdf == BRDF_CONDUCTOR ? m.base_color.rgb : s.base, m.brdf_params);
    Bsdf b = bsdf_gltf(s.base, s.metallic, s.roughness, m.specular, m.specular_color, m.ior, m.transmission);
    if (GN_HAS(GN_FEAT_LAYERS)) // the coat's normal in the local frame: main() sets it
        b = bsdf_layers(b, s.coat, s.coat_roughness, vec3(0.0, 0.0, 1.0), s.sheen, s.sheen_roughness);
    return b;
}

// Does b have a part that light sampling can reach (anything but Dirac lobes)?
bool bsdf_has_smooth(Bsdf b)
{
    return any(greaterThan(b.diffuse, vec3(0.0))) ||
           (b.lobe != BRDF_LOBE_NONE && b.lobe != BRDF_LOBE_MIRROR) ||
           (b.dielectric > 0.0 && b.shape >= BRDF_ALPHA_MIN) ||
           (GN_HAS(GN_FEAT_LAYERS) && (any(greaterThan(b.sheen, vec3(0.0))) ||
                                       (b.coat > 0.0 && b.coat_alpha >= BRDF_ALPHA_MIN)));
}

// Offset of a ray origin off the surface, to the side of w (scaled to the coordinates'
// magnitude so float rounding of the hit point cannot put it behind the surface).
vec3 offset_origin(vec3 p, vec3 ng, vec3 w)
{
    float eps = 1e-4 * max(1.0, max(abs(p.x), max(abs(p.y), abs(p.z))));
    return p + ng * (dot(ng, w) >= 0.0 ? eps : -eps);
}

// ---- the paths of an invocation --------------------------------------------------------------
// An invocation takes push.pad0 samples of its pixel (sample indices push.sample_index on),
// starting the next path as soon as one ends ("regeneration"). The 8 lanes of a SIMD group
// run in step until the longest of their paths ends, and roulette makes path lengths vary
// a lot; a lane that starts its next path at once, instead of idling, keeps the group busy.
// Every sample is still the same function of (pixel, sample index, dimension).
//
// After each vertex path_step adds up a finished sample and starts the next path; the loop
// ends once this invocation has taken all its samples.
uvec2 px;
uint pixel;
uint samples, taken;
vec4 sum;
vec3 sum_sq, sum_n, sum_a;
float sum_depth;
// The current path.
uint depth;
vec3 o, d, radiance, beta, normal, albedo;
float tmin, prev_pdf, depth_aov;
bool prev_delta, covered, ended;

void path_start()
{
    sample_now = push.sample_index + taken;
    rng_sample = sample_now;
    budget = frame.traversal_budget;
    depth = 0u;
    camera_ray(vec2(px) + rng(pixel, 0u).xy, o, d, tmin);
    radiance = vec3(0.0);
    beta = vec3(1.0);
    prev_pdf = 0.0;
    prev_delta = true; // the camera ray: what it sees has one strategy only
    covered = false;
    normal = vec3(0.0);
    albedo = vec3(0.0);
    depth_aov = 0.0;
    ended = false;
}

// After a path vertex: the next vertex, or (the path ended) the sample added up and the
// next path started.
uint path_step()
{
    if (!ended) {
        depth++;
        return taken;
    }
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
    return taken;
}

void main()
{
    px = tile_pixel();
    if (px.x >= frame.crop_width || px.y >= frame.crop_height)
        return;
    uint slot = px.y * frame.crop_width + px.x; // in the region's buffers
    px += uvec2(frame.crop_x, frame.crop_y);    // in the whole image
    pixel = px.y * frame.width + px.x;
    rng_pixel = pixel;
    bool light_only = GN_HAS(GN_FEAT_STRATEGY) && (frame.flags & GN_FRAME_LIGHT_ONLY) != 0u;
    bool bsdf_only = GN_HAS(GN_FEAT_STRATEGY) && (frame.flags & GN_FRAME_BSDF_ONLY) != 0u;
    truncated = false;
    samples = max(push.pad0, 1u);
    taken = 0u;
    // The sums go on from the buffers, one sample at a time in sample order, so a pixel's
    // sum is the same float whichever dispatches (or runs: --resume) took its samples.
    bool aov_on = GN_HAS(GN_FEAT_AOV) && (frame.flags & GN_FRAME_AOV) != 0u;
    // Without them the aov and squares buffers are 16-byte dummies: never indexed.
    bool squares_on = GN_HAS(GN_FEAT_VARIANCE) && (frame.flags & GN_FRAME_VARIANCE) != 0u;
    sum = accum[slot];
    sum_sq = squares_on ? squares[slot].rgb : vec3(0.0);
    sum_n = aov_on ? aov[3u * slot + 0u].xyz : vec3(0.0);
    sum_a = aov_on ? aov[3u * slot + 1u].xyz : vec3(0.0);
    sum_depth = aov_on ? aov[3u * slot + 2u].x : 0.0;

    path_start();
    while (true) {
        // One path vertex, in a loop of one iteration: a path's end is a `break` out of it.
        // (llvmpipe masks lanes for a break cheaply; a continue or an early return masks
        // every later statement again and cost a third of the speed.)
        ended = true;
        do {
            Hit h = trace(o, d, tmin, 1e30, false, DIM_ALPHA + DIM_ALPHA_RAY * 2u * depth);
            tmin = 0.0;
            if (h.truncated)
                break;
            if (h.tri == GN_INVALID) {
                vec3 le = env_radiance(d);
                float w = 1.0;
                if (GN_HAS(GN_FEAT_ENV) && !prev_delta && frame.env_select > 0.0)
                    w = light_only ? 0.0 : bsdf_only ? 1.0 : power_heuristic(prev_pdf, env_pdf(d));
                radiance += beta * le * w;
                break;
            }
            Surface s = surface_at(h.tri, h.t, h.u, h.v, o, d);
            GnMaterial m = material_at(s.material);
            covered = covered || depth == 0u;
            if (GN_HAS(GN_FEAT_AOV) && depth == 0u) {
                normal = s.n;
                albedo = s.base;
                depth_aov = h.t * dot(d, frame.camera.forward);
            }
            if (GN_HAS(GN_FEAT_UNLIT) && (m.flags & GN_MAT_UNLIT) != 0u) { // KHR_materials_unlit: the colour is the radiance
                radiance += beta * s.base;
                break;
            }
            if (GN_HAS(GN_FEAT_EMISSIVE) && (s.front || (m.flags & GN_MAT_DOUBLE_SIDED) != 0u) &&
                luminance(m.emissive) > 0.0) {
                float w = 1.0;
                if (!prev_delta) {
                    float pl = luminance(m.emissive) * area_sides(m) / frame.emitter_power * h.t * h.t /
                               abs(dot(s.ng, d));
                    w = light_only ? 0.0 : bsdf_only ? 1.0 : power_heuristic(prev_pdf, pl);
                }
                radiance += beta * s.emission * w;
            }
            if (frame.max_depth != 0u && depth >= frame.max_depth)
                break;

            Bsdf b = material_bsdf(s, m);
            // A transmitting surface needs the side: brdf.glsl's normal points outside.
            bool flip = b.dielectric > 0.0 && !s.front;
            vec3 n = flip ? -s.n : s.n, ng = flip ? -s.ng : s.ng, tx, ty;
            sampling_basis(n, tx, ty);
            vec3 wo = vec3(dot(-d, tx), dot(-d, ty), dot(-d, n));
            if (GN_HAS(GN_FEAT_LAYERS)) {
                vec3 cn = flip ? -s.coat_n : s.coat_n;
                b.coat_n = normalize(vec3(dot(cn, tx), dot(cn, ty), dot(cn, n)));
            }
            vec4 ul = rng(pixel, 1u + 2u * depth), ub = rng(pixel, 2u + 2u * depth);

            if (frame.num_emitters > 0u && bsdf_has_smooth(b)) {
                LightSample ls = light_sample(s.p, ul.xyz);
                vec3 wi = vec3(dot(ls.wi, tx), dot(ls.wi, ty), dot(ls.wi, n));
                // The shading and geometric normals must agree on the side of wi (no light leaks).
                if (ls.pdf > 0.0 && !(bsdf_only && !ls.delta) && dot(ng, ls.wi) * wi.z > 0.0 &&
                    luminance(ls.L) > 0.0) {
                    vec3 f;
                    float pb;
                    bsdf_eval_pdf(b, wo, wi, f, pb);
                    float w = ls.delta || light_only ? 1.0 : power_heuristic(ls.pdf, pb);
                    vec3 c = beta * f * abs(wi.z) * ls.L * (w / ls.pdf);
                    if (luminance(c) > 0.0) {
                        Hit sh = trace(offset_origin(s.p, ng, ls.wi), ls.wi, 0.0, ls.dist * (1.0 - 1e-3), true,
                                       DIM_ALPHA + DIM_ALPHA_RAY * (2u * depth + 1u));
                        if (sh.tri == GN_INVALID && !sh.truncated)
                            radiance += c;
                    }
                }
            }

            BsdfSample bs = bsdf_sample(b, wo, ub.xyz);
            if (bs.flags == 0u)
                break;
            vec3 wi = bs.wi.x * tx + bs.wi.y * ty + bs.wi.z * n;
            if (dot(ng, wi) * bs.wi.z <= 0.0)
                break;
            beta *= bs.weight;
            prev_delta = (bs.flags & BRDF_FLAG_DELTA) != 0u;
            prev_pdf = bs.pdf;
            o = offset_origin(s.p, ng, wi);
            d = wi;
            if (depth + 1u >= ROULETTE_DEPTH) {
                float q = min(max(beta.r, max(beta.g, beta.b)), 0.95);
                if (ul.w >= q)
                    break;
                beta /= q;
            }
            ended = false;
        } while (false);
        if (path_step() == samples)
            break;
    }
    // Fewer samples than asked for: llvmpipe's loop cap ended the loop (the rest count 0).
    if (truncated || taken < samples)
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
