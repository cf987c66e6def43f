#version 450
// local.comp: one sample per pixel per dispatch of the non-path-traced modes: the Phong
// reflection model of the lecture (L_o = ambient + emission + diffuse + specular, summed
// over the punctual lights, with ray-traced shadows), and the debug images normal, albedo,
// depth and BVH cost. The mode is a specialization constant, so each mode compiles to its
// own lean kernel.
#extension GL_GOOGLE_include_directive : require

#include "bvh.glsl"

layout(local_size_x = GN_TILE_X, local_size_y = GN_TILE_Y) in;
layout(constant_id = 0) const uint MODE = GN_MODE_PHONG;

layout(std430, binding = GN_BIND_ACCUM) buffer AccumBlock { vec4 accum[]; };
layout(std430, binding = GN_BIND_AOV) buffer AovBlock { vec4 aov[]; };
layout(std430, binding = GN_BIND_VCOLOR) readonly buffer VColorBlock { vec4 vcolor[]; };
layout(std430, binding = GN_BIND_STATUS) buffer StatusBlock { uint status[]; };
layout(push_constant) uniform PushBlock { GnPush push; };

// Light arriving at p from light l: direction to the light, distance, and the irradiance
// scale (colour already in l.color) for a surface facing it.
vec3 light_incident(GnLight l, vec3 p, out vec3 wi, out float dist)
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
    if (l.range > 0.0) { // KHR_lights_punctual's recommended window
        float x = dist / l.range;
        atten *= clamp(1.0 - x * x * x * x, 0.0, 1.0) * clamp(1.0 - x * x * x * x, 0.0, 1.0);
    }
    if (l.type == GN_LIGHT_COSINE)
        atten *= max(dot(l.direction, -wi), 0.0);
    if (l.type == GN_LIGHT_SPOT) {
        float cd = dot(l.direction, -wi);
        atten *= smoothstep(l.outer_cos, l.inner_cos, cd);
    }
    return l.color * atten;
}

bool shadowed(Surface s, vec3 wi, float dist)
{
    if ((frame.flags & GN_FRAME_SHADOWS) == 0u)
        return false;
    // Offset along the geometric normal, scaled to the position's magnitude, so the
    // shadow ray does not hit its own triangle.
    float eps = 1e-4 * max(1.0, max(abs(s.p.x), max(abs(s.p.y), abs(s.p.z))));
    vec3 o = s.p + s.ng * eps;
    Hit h = bvh_trace(o, wi, 0.0, dist * (1.0 - 1e-4), true);
    return h.tri != GN_INVALID;
}

// The Phong reflection model at s seen from direction v (towards the viewer).
vec3 phong_shade(Surface s, vec3 v)
{
    GnMaterial m = materials[s.material];
    // The glTF textures modulate the classic colours, so textured models look right.
    vec3 tex = m.tex_base != GN_INVALID ? texture_sample(m.tex_base, s.uv, true).rgb : vec3(1.0);
    vec3 kd = m.phong_diffuse * tex;
    vec3 ka = m.phong_ambient * tex;
    vec3 ks = m.phong_specular;
    vec3 c = m.phong_emission;
    if (m.tex_emissive != GN_INVALID)
        c *= texture_sample(m.tex_emissive, s.uv, true).rgb;
    c += frame.ambient * ka * s.occlusion;
    for (uint i = 0u; i < frame.num_lights; i++) {
        GnLight l = lights[i];
        vec3 wi;
        float dist;
        vec3 E = light_incident(l, s.p, wi, dist);
        float ndl = dot(s.n, wi);
        if (ndl <= 0.0 || dot(s.ng, wi) <= 0.0 || dot(E, E) == 0.0)
            continue;
        if (shadowed(s, wi, dist))
            continue;
        vec3 r = 2.0 * ndl * s.n - wi; // the lecture's r(w_i)
        float spec = pow(max(dot(r, v), 0.0), m.phong_shininess);
        c += E * (kd * ndl + ks * spec);
    }
    return c;
}

void main()
{
    uvec2 px = gl_GlobalInvocationID.xy;
    if (px.x >= frame.width || px.y >= frame.height)
        return;
    uint pixel = px.y * frame.width + px.x;
    vec2 jitter = push.sample_index == 0u ? vec2(0.5) : rand2(pixel, push.sample_index, 0u);
    vec3 o = frame.camera.position;
    vec3 d = camera_dir(vec2(px) + jitter);
    Hit h = bvh_trace(o, d, frame.camera.znear / dot(d, frame.camera.forward), 1e30, false);

    vec3 color = vec3(0.0);
    vec3 normal = vec3(0.0), albedo = vec3(0.0);
    float depth = 0.0;
    if (h.tri != GN_INVALID) {
        Surface s = surface_at(h.tri, h.t, h.u, h.v, o, d);
        normal = s.n;
        albedo = s.base;
        depth = h.t * dot(d, frame.camera.forward);
        if (MODE == GN_MODE_NORMAL) color = normal;
        else if (MODE == GN_MODE_ALBEDO) color = albedo;
        else if (MODE == GN_MODE_DEPTH) color = vec3(depth);
        else if (MODE == GN_MODE_PHONG) color = phong_shade(s, -d);
    } else {
        color = MODE == GN_MODE_PHONG ? frame.env_color : vec3(0.0);
    }
    if (MODE == GN_MODE_COST) color = vec3(float(h.steps));
    accum[pixel] += vec4(color, h.tri != GN_INVALID ? 1.0 : 0.0); // w: coverage
    if (h.truncated)
        atomicAdd(status[0], 1u);
    if ((frame.flags & GN_FRAME_AOV) != 0u) {
        aov[3u * pixel + 0u] += vec4(normal, 0.0);
        aov[3u * pixel + 1u] += vec4(albedo, 0.0);
        aov[3u * pixel + 2u] += vec4(depth, 0.0, 0.0, 0.0);
    }
}
