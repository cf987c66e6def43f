// phong.glsl: the Phong reflection model (Phong 1975; OpenGL 1.x's lighting
// equation): L = emission + ambient_light * ka + sum over lights of E (kd (n.l) + ks (r.v)^s),
// r = 2 (n.l) n - l, with ray-traced shadows. One function serves the three shading
// algorithms, which differ only in where they call it: once per triangle (flat), once per
// vertex (Gouraud, glsl/kernels/vertex.comp) or once per pixel (Phong shading, glsl/kernels/local.comp).
#ifndef GONIO_PHONG_GLSL
#define GONIO_PHONG_GLSL

#include "bvh.glsl"

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

// ng: the normal to offset the shadow ray's origin along (the side being lit).
// dim: the first random dimension of its crossings of BLEND surfaces (trace_visible).
bool shadowed(vec3 p, vec3 ng, vec3 wi, float dist, uint dim)
{
    if ((frame.flags & GN_FRAME_SHADOWS) == 0u)
        return false;
    // Offset scaled to the position's magnitude, so the ray does not hit its own triangle.
    float eps = 1e-4 * max(1.0, max(abs(p.x), max(abs(p.y), abs(p.z))));
    Hit h = trace_visible(p + ng * eps, wi, 0.0, dist * (1.0 - 1e-4), true, false, frame.traversal_budget, dim);
    return h.tri != GN_INVALID;
}

// The Phong reflection model at p with shading normal n (unit, or zero: then no light but
// ambient and emission), geometric normal ng on the same side (light below it is cut off),
// texture coordinates uv (both sets: vertex_uv) and vertex colour vcolor (1 without), seen from direction v (unit,
// towards the viewer).
vec3 phong_shade(vec3 p, vec3 n, vec3 ng, vec4 uv, vec3 vcolor, uint material, vec3 v)
{
    GnMaterial m = material_at(material);
    // The glTF base-colour texture and vertex colours modulate the classic colours, as they
    // do glTF's base colour, so textured and painted models look right.
    vec3 tex = m.tex_base != GN_INVALID ? texture_sample(m.tex_base, uv, true).rgb : vec3(1.0);
    tex *= vcolor;
    vec3 kd = m.phong_diffuse * tex;
    vec3 ka = m.phong_ambient * tex;
    vec3 ks = m.phong_specular;
    vec3 c = m.phong_emission;
    if (m.tex_emissive != GN_INVALID)
        c *= texture_sample(m.tex_emissive, uv, true).rgb;
    float occlusion = 1.0;
    if (m.tex_occlusion != GN_INVALID)
        occlusion = 1.0 + m.occlusion_strength * (texture_sample(m.tex_occlusion, uv, false).r - 1.0);
    c += frame.ambient * ka * occlusion;
    for (uint i = 0u; i < frame.num_lights; i++) {
        vec3 wi;
        float dist;
        vec3 E = light_incident(lights[i], p, wi, dist);
        float ndl = dot(n, wi);
        if (ndl <= 0.0 || dot(ng, wi) <= 0.0 || dot(E, E) == 0.0)
            continue;
        if (shadowed(p, ng, wi, dist, DIM_ALPHA + DIM_ALPHA_RAY * (1u + i)))
            continue;
        vec3 r = 2.0 * ndl * n - wi; // the mirror direction r(w_i)
        // OpenGL's 0^0 = 1; GLSL leaves pow(0, 0) undefined.
        float spec = m.phong_shininess > 0.0 ? pow(max(dot(r, v), 0.0), m.phong_shininess) : 1.0;
        c += E * (kd * ndl + ks * spec);
    }
    return c;
}

#endif
