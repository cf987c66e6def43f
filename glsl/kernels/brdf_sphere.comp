#version 450
// brdf_sphere.comp: the material ball of `gonio brdf --sphere`: a unit sphere lit by a
// directional light (evaluated directly: Lo += f E cos, the point-light integral)
// and a constant environment (reached by BSDF sampling, bounces through glass included),
// one path per pixel per dispatch, accumulated. Uses the renderer's brdf_material.glsl.
#extension GL_GOOGLE_include_directive : require

// Specialised on its material's features (src/cli/cmd_brdf.c: material_features), as the
// renderer's kernels are: llvmpipe runs both sides of every branch and compiles all of them.
#define GN_HAS(f) (((FEATURES & (f).x) | (FEATURES_HI & (f).y)) != 0u)
#include "shared.h"
layout(constant_id = GN_SPEC_FEATURES) const uint FEATURES = 0xffffffffu;    // GN_FEAT_* bits 0-31
layout(constant_id = GN_SPEC_FEATURES_HI) const uint FEATURES_HI = 0xffffffffu; // ... 32-63

// The ball's material has no textures (every slot GN_INVALID): no lookup is ever made.
#define MATERIAL_TEXTURE(index, uv, srgb) vec4(1.0)
#include "brdf_material.glsl"

layout(local_size_x = GN_TILE_X, local_size_y = GN_TILE_Y) in;

layout(std430, binding = 0) readonly buffer SceneBlock { BrdfSphere scene; };
layout(std430, binding = 1) buffer AccumBlock { vec4 accum[]; };
layout(push_constant) uniform PushBlock { GnPush push; }; // sample_index, seed

#define SPHERE_CAMERA_Z 4.0
#define SPHERE_TAN_HALF_FOV 0.3 // the ball fills ~80% of the frame height

// Distance along d (unit) from o to the sphere, the nearest beyond a small epsilon; -1: miss.
float sphere_hit(vec3 o, vec3 d)
{
    float b = dot(o, d), c = dot(o, o) - 1.0, disc = b * b - c;
    if (disc < 0.0)
        return -1.0;
    float s = sqrt(disc);
    if (-b - s > 1e-4)
        return -b - s;
    return -b + s > 1e-4 ? -b + s : -1.0;
}

void main()
{
    uvec2 px = gl_GlobalInvocationID.xy;
    if (px.x >= scene.width || px.y >= scene.height)
        return;
    uint pixel = px.y * scene.width + px.x;
    // The ball's tangent runs along its parallels (about the vertical axis), as on a
    // lathe-brushed part: each hit gives it, in its shading frame, to material_eval, which
    // turns it by the anisotropy's rotation toward the bitangent n x t.
    MaterialHit mh;
    mh.uv = vec4(0.0);
    mh.color = vec4(1.0);
    mh.n = vec3(0.0, 0.0, 1.0);
    mh.tangent = vec4(1.0, 0.0, 0.0, 1.0);
    Bsdf b0 = bsdf_material(material_eval(scene.material, mh)), b = b0;
    vec4 jitter = rng_uniform4(pixel, push.sample_index, 0u, push.seed);
    float aspect = float(scene.width) / float(scene.height);
    vec2 ndc = vec2(2.0 * (float(px.x) + jitter.x) / float(scene.width) - 1.0,
                    1.0 - 2.0 * (float(px.y) + jitter.y) / float(scene.height));
    vec3 o = vec3(0.0, 0.0, SPHERE_CAMERA_Z);
    vec3 d = normalize(vec3(ndc.x * aspect * SPHERE_TAN_HALF_FOV, ndc.y * SPHERE_TAN_HALF_FOV, -1.0));
    vec3 radiance = vec3(0.0), throughput = vec3(1.0);
    for (uint depth = 0u; depth < scene.max_depth; depth++) {
        float t = sphere_hit(o, d);
        if (t < 0.0) {
            radiance += throughput * scene.env;
            break;
        }
        vec3 p = o + t * d, n = normalize(p), tx, ty;
        sampling_basis(n, tx, ty);
        vec3 wo = vec3(dot(-d, tx), dot(-d, ty), dot(-d, n));
        if (scene.material.anisotropy_strength > 0.0) {
            vec3 t = cross(vec3(0.0, 1.0, 0.0), n);
            t = dot(t, t) > 1e-12 ? normalize(t) : tx;
            mh.tangent = vec4(dot(t, tx), dot(t, ty), 0.0, 1.0);
            Shading sh = material_eval(scene.material, mh);
            b = bsdf_orient(b0, sh, vec3(0.0, 0.0, 1.0), sh.aniso_t.xy);
        }
        // The light reaches only the outside (the sphere is convex: no shadow ray needed).
        vec3 wl = vec3(dot(scene.light_dir, tx), dot(scene.light_dir, ty), dot(scene.light_dir, n));
        if (wo.z > 0.0 && wl.z > 0.0)
            radiance += throughput * bsdf_eval(b, wo, wl) * scene.light_irradiance * wl.z;
        BsdfSample s = bsdf_sample(b, wo, rng_uniform4(pixel, push.sample_index, depth + 1u, push.seed).xyz);
        if (s.flags == 0u)
            break;
        throughput *= s.weight;
        d = normalize(s.wi.x * tx + s.wi.y * ty + s.wi.z * n);
        o = p + n * (s.wi.z > 0.0 ? 1e-4 : -1e-4);
    }
    accum[pixel] += vec4(radiance, 1.0);
}
