// scene.glsl: the scene buffers of the render kernels, camera rays, the per-sample random
// numbers and the shading data at a hit (interpolated normal, uv, textured material).
// Include after "#version 450" and the extensions; bvh.glsl builds on it.
#ifndef GONIO_SCENE_GLSL
#define GONIO_SCENE_GLSL

#include "shared.h"
#include "wrap.glsl"
#include "sampling.glsl"

// GnFrame is read from a storage buffer, not a uniform buffer: lavapipe inlines uniform
// values that steer loops and re-specializes the shader whenever they change, a cost per
// dispatch larger than a small render (docs/performance.md).
layout(std430, binding = GN_BIND_FRAME) readonly buffer FrameBlock { GnFrame frame; };
// The BVH nodes (GnBvhNode = 4 texels), triangle pairs (GnTriPair = 3), shading triangles
// (GnPrim = 1), vertices (GnVertex = 5), materials (GnMaterial = 21), textures (GnTexture =
// 1; their RGBA8 images: R32UI) and path.comp's lights (GnEmitter = 1) are read from texel
// buffers, not storage buffers: llvmpipe fetches a storage buffer with per-lane offsets one
// lane and one component at a time, branching on each lane's mask, a texel buffer with
// one load per lane and no branches, which makes the walk several times faster there;
// GPUs read both at full speed.
// They are textureBuffers, images without a sampler (texelFetch needs none): SPIR-V deprecates
// a sampler combined with a buffer image, and Mesa 25 warns at every such binding.
#extension GL_EXT_samplerless_texture_functions : require
// An integer format passes every bit through (a float format may flush the denormals that
// small integers stored as floats are); floats come back with uintBitsToFloat.
layout(binding = GN_BIND_NODES) uniform utextureBuffer node_texels;
layout(binding = GN_BIND_TRIS) uniform utextureBuffer tri_texels;
layout(binding = GN_BIND_PRIMS) uniform utextureBuffer prim_texels;
layout(binding = GN_BIND_VERTICES) uniform utextureBuffer vertex_texels;
layout(binding = GN_BIND_MATERIALS) uniform utextureBuffer material_texels;
layout(std430, binding = GN_BIND_LIGHTS) readonly buffer LightBlock { GnLight lights[]; };
layout(binding = GN_BIND_TEXELS) uniform utextureBuffer texels; // R32UI: one RGBA8 texel each
layout(binding = GN_BIND_TEXTURES) uniform utextureBuffer texture_texels; // GnTexture[]
layout(binding = GN_BIND_INSTANCES) uniform utextureBuffer instance_texels; // GnInstance[] (bvh.glsl: INSTANCES)

#define PI GN_PI // (the name path.comp and bench.comp use)

vec4 texel_f(utextureBuffer b, uint i) { return uintBitsToFloat(texelFetch(b, int(i))); }

GnPrim prim_at(uint i)
{
    uvec4 t = texelFetch(prim_texels, int(i));
    return GnPrim(t.x, t.y, t.z, t.w);
}

GnVertex vertex_at(uint i)
{
    vec4 a = texel_f(vertex_texels, 5u * i), b = texel_f(vertex_texels, 5u * i + 1u);
    vec4 e = texel_f(vertex_texels, 5u * i + 4u);
    return GnVertex(a.xyz, a.w, b.xyz, b.w, texel_f(vertex_texels, 5u * i + 2u),
                    texel_f(vertex_texels, 5u * i + 3u), e.x, e.y, e.z, e.w);
}

// ---- instances -------------------------------------------------------------------------------
// INSTANCES != 0: the scene has two levels (glsl/lib/shared.h: a top tree over instances of
// meshes, each in its own object space); 0 (scenes without instances): one tree over world-
// space triangles, and all that instances need compiles away (the host sets it:
// src/render/render.c). A hit in an instance has its mesh's vertices, which shading moves to
// world space as the loader bakes a mesh used once (src/scene: positions by the transform,
// normals by its inverse transpose, tangents by the transform with their sign mirrored, each
// renormalised), so an instance is shaded as its flattened copy would be.
layout(constant_id = GN_SPEC_INSTANCES) const uint INSTANCES = 0u;

struct InstanceXf {
    vec4 w0, w1, w2;   // object to world (GnInstance.to_world), rows
    vec3 o0, o1, o2;   // world to object's 3x3 (to_object), rows: normals go by its transpose
    bool mirror;       // GN_INSTANCE_MIRROR
};

InstanceXf instance_xf(uint i)
{
    InstanceXf x;
    x.o0 = texel_f(instance_texels, 8u * i).xyz;
    x.o1 = texel_f(instance_texels, 8u * i + 1u).xyz;
    x.o2 = texel_f(instance_texels, 8u * i + 2u).xyz;
    x.mirror = (texelFetch(instance_texels, int(8u * i + 3u)).w & GN_INSTANCE_MIRROR) != 0u;
    x.w0 = texel_f(instance_texels, 8u * i + 4u);
    x.w1 = texel_f(instance_texels, 8u * i + 5u);
    x.w2 = texel_f(instance_texels, 8u * i + 6u);
    return x;
}

vec3 xf_point(InstanceXf x, vec3 p)
{
    return vec3(dot(x.w0.xyz, p) + x.w0.w, dot(x.w1.xyz, p) + x.w1.w, dot(x.w2.xyz, p) + x.w2.w);
}

GnVertex xf_vertex(InstanceXf x, GnVertex a)
{
    a.position = xf_point(x, a.position);
    a.normal = normalize(x.o0 * a.normal.x + x.o1 * a.normal.y + x.o2 * a.normal.z);
    vec3 t = vec3(dot(x.w0.xyz, a.tangent.xyz), dot(x.w1.xyz, a.tangent.xyz), dot(x.w2.xyz, a.tangent.xyz));
    if (dot(t, t) > 0.0) // (a mesh without tangents keeps its zeros)
        a.tangent = vec4(normalize(t), x.mirror ? -a.tangent.w : a.tangent.w);
    return a;
}

// The corners of BVH-order triangle i (the walk's GnTriPairs hold them too, but a pair has
// no index by triangle), in world space: inst is its instance (GN_INVALID: none). With a
// mirroring instance the corners' winding is the opposite of the world's (instance_mirrors).
void tri_corners(uint i, uint inst, out vec3 a, out vec3 b, out vec3 c)
{
    GnPrim pr = prim_at(i);
    a = vertex_at(pr.i0).position; // (the unused texels of a vertex are never fetched)
    b = vertex_at(pr.i1).position;
    c = vertex_at(pr.i2).position;
    if (INSTANCES != 0u && inst != GN_INVALID) {
        InstanceXf x = instance_xf(inst);
        a = xf_point(x, a);
        b = xf_point(x, b);
        c = xf_point(x, c);
    }
}

// Does instance inst mirror (a negative determinant)? Then the front of its triangles (glTF:
// counter-clockwise in world space) is the side their corners' cross product points away
// from. False without instances.
bool instance_mirrors(uint inst)
{
    return INSTANCES != 0u && inst != GN_INVALID &&
           (texelFetch(instance_texels, int(8u * inst + 3u)).w & GN_INSTANCE_MIRROR) != 0u;
}

// Does the scene have vertex colours (glTF COLOR_0)? Without, GnVertex.color is not read.
bool vertex_colors() { return GN_HAS(GN_FEAT_VERTEX_COLOR) && (frame.flags & GN_FRAME_VERTEX_COLOR) != 0u; }

// Fields a kernel does not read are never fetched: the compiler drops unused texel loads.
GnMaterial material_at(uint i)
{
    uint k = 21u * i;
    vec4 t0 = texel_f(material_texels, k), t1 = texel_f(material_texels, k + 1u);
    vec4 t2 = texel_f(material_texels, k + 2u), t3 = texel_f(material_texels, k + 3u);
    uvec4 t4 = texelFetch(material_texels, int(k + 4u)), t5 = texelFetch(material_texels, int(k + 5u));
    uvec4 t6 = texelFetch(material_texels, int(k + 6u));
    vec4 t7 = texel_f(material_texels, k + 7u), t8 = texel_f(material_texels, k + 8u);
    vec4 t9 = texel_f(material_texels, k + 9u), t10 = texel_f(material_texels, k + 10u);
    vec4 t11 = texel_f(material_texels, k + 11u), t12 = texel_f(material_texels, k + 12u);
    uvec4 t13 = texelFetch(material_texels, int(k + 13u));
    uvec4 t14 = texelFetch(material_texels, int(k + 14u)), t15 = texelFetch(material_texels, int(k + 15u));
    vec4 t16 = texel_f(material_texels, k + 16u);
    uvec4 t17 = texelFetch(material_texels, int(k + 17u)), t18 = texelFetch(material_texels, int(k + 18u));
    uvec4 t19 = texelFetch(material_texels, int(k + 19u)), t20 = texelFetch(material_texels, int(k + 20u));
    return GnMaterial(t0, t1.xyz, t1.w, t2.xyz, t2.w, t3.x, t3.y, t3.z, t3.w,
                      uintBitsToFloat(t4.x), uintBitsToFloat(t4.y), t4.z, t4.w,
                      t5.x, t5.y, t5.z, t5.w, t6.x, t6.y, t6.z, t6.w,
                      t7, t8.xyz, t8.w, t9.xyz, t9.w, t10.xyz, t10.w, t11.xyz, t11.w,
                      t12.xyz, t12.w, uintBitsToFloat(t13.x), uintBitsToFloat(t13.y), t13.z,
                      uintBitsToFloat(t13.w),
                      uintBitsToFloat(t14.x), uintBitsToFloat(t14.y), t14.z, t14.w,
                      t15.x, uintBitsToFloat(t15.y), t15.z, t15.w, t16.xyz, t16.w,
                      uintBitsToFloat(t17.x), uintBitsToFloat(t17.y), t17.z, uintBitsToFloat(t17.w),
                      uintBitsToFloat(t18.x), uintBitsToFloat(t18.y), uintBitsToFloat(t18.z),
                      uintBitsToFloat(t18.w), t19.x, t19.y, uintBitsToFloat(t19.z), t19.w,
                      uintBitsToFloat(t20.xyz), t20.w);
}

// ---- random numbers that depend only on (pixel, sample, dimension, seed) ---------------
// Random numbers are rng_pcg4d hashes (sampling.glsl; Jarzynski & Olano, "Hash Functions
// for GPU Rendering", JCGT 2020) of (pixel, sample, dimension, seed): a hash, not a
// sequence, so any sample of any pixel is computed independently (reproducible, splittable
// across processes by seed).

// Two independent uniforms in [0, 1) for dimensions (2 dim2, 2 dim2 + 1).
vec2 rand2(uint pixel, uint sample_index, uint dim2)
{
    return rng_uniform4(pixel, sample_index, dim2, frame.seed).xy;
}

// ---- camera ------------------------------------------------------------------------------
// The camera ray through image position p in pixels (y down), see GnCamera: origin o, unit
// direction d, and the distance along it to the near plane.
void camera_ray(vec2 p, out vec3 o, out vec3 d, out float tnear)
{
    GnCamera c = frame.camera;
    vec2 s = vec2(2.0 * p.x / float(frame.width) - 1.0, 1.0 - 2.0 * p.y / float(frame.height));
    if (c.ortho_half_height > 0.0) {
        o = c.position + c.ortho_half_height * (s.x * c.aspect * c.right + s.y * c.up);
        d = c.forward;
        tnear = c.znear;
    } else {
        o = c.position;
        d = normalize(c.forward + s.x * c.tan_half_fovy * c.aspect * c.right +
                      s.y * c.tan_half_fovy * c.up);
        tnear = c.znear / dot(d, c.forward);
    }
}

// Unit vector from p toward the viewer.
vec3 camera_view(vec3 p)
{
    return frame.camera.ortho_half_height > 0.0 ? -frame.camera.forward
                                                : normalize(frame.camera.position - p);
}

// ---- textures: RGBA8 texels packed in one buffer (lavapipe has no descriptor indexing,
// so an arbitrary number of textures cannot be bound as samplers), filtered here ----------
vec4 texel_fetch(GnTexture t, ivec2 p)
{
    uint c = texelFetch(texels, int(t.offset + uint(p.y) * t.width + uint(p.x))).x;
    return vec4(c & 255u, (c >> 8u) & 255u, (c >> 16u) & 255u, c >> 24u) * (1.0 / 255.0);
}

vec4 srgb_to_linear(vec4 c)
{
    vec3 lo = c.rgb / 12.92, hi = pow((c.rgb + 0.055) / 1.055, vec3(2.4));
    return vec4(mix(hi, lo, lessThanEqual(c.rgb, vec3(0.04045))), c.a);
}

// Both texture coordinate sets of a vertex: TEXCOORD_0 in xy, TEXCOORD_1 in zw.
vec4 vertex_uv(GnVertex a) { return vec4(a.u, a.v, a.u1, a.v1); }

// Bilinear (or nearest) lookup of texture `index` at its set of uv (vertex_uv), moved by its
// KHR_texture_transform; srgb decodes before filtering, as GPUs do. Kernels without
// GN_FEAT_UV1 or GN_FEAT_TEX_TRANSFORM never fetch what those need.
vec4 texture_sample(uint index, vec4 uv, bool srgb)
{
    uvec4 tt = texelFetch(texture_texels, int(3u * index));
    GnTexture t;
    t.offset = tt.x; t.width = tt.y; t.height = tt.z; t.flags = tt.w;
    int w = int(t.width), h = int(t.height);
    uint ws = t.flags & 3u, wt = (t.flags >> 2u) & 3u;
    vec2 st = GN_HAS(GN_FEAT_UV1) && (t.flags & GN_TEX_UV1) != 0u ? uv.zw : uv.xy;
    if (GN_HAS(GN_FEAT_TEX_TRANSFORM)) {
        vec3 r0 = texel_f(texture_texels, 3u * index + 1u).xyz;
        vec3 r1 = texel_f(texture_texels, 3u * index + 2u).xyz;
        st = vec2(dot(r0, vec3(st, 1.0)), dot(r1, vec3(st, 1.0)));
    }
    vec2 p = st * vec2(w, h) - 0.5;
    if ((t.flags & GN_TEX_NEAREST) != 0u) {
        ivec2 q = ivec2(floor(p + 0.5));
        vec4 c = texel_fetch(t, ivec2(tex_wrap(q.x, w, ws), tex_wrap(q.y, h, wt)));
        return srgb ? srgb_to_linear(c) : c;
    }
    ivec2 q = ivec2(floor(p));
    vec2 f = p - vec2(q);
    int x0 = tex_wrap(q.x, w, ws), x1 = tex_wrap(q.x + 1, w, ws);
    int y0 = tex_wrap(q.y, h, wt), y1 = tex_wrap(q.y + 1, h, wt);
    vec4 c00 = texel_fetch(t, ivec2(x0, y0)), c10 = texel_fetch(t, ivec2(x1, y0));
    vec4 c01 = texel_fetch(t, ivec2(x0, y1)), c11 = texel_fetch(t, ivec2(x1, y1));
    if (srgb) {
        c00 = srgb_to_linear(c00); c10 = srgb_to_linear(c10);
        c01 = srgb_to_linear(c01); c11 = srgb_to_linear(c11);
    }
    return mix(mix(c00, c10, f.x), mix(c01, c11, f.x), f.y);
}

// ---- surface data at a hit ---------------------------------------------------------------
// A shading normal n (unit) such that the mirror reflection of wo (unit, toward the viewer)
// about it lies above the geometric surface ng (which faces wo): a normal map or normals
// interpolated near a silhouette can turn n so far that the viewer is below it or its
// reflection below the surface, which every BSDF then reads as black. As Cycles does
// (ensure_valid_reflection), n is bent toward ng, in the plane of n and ng, just far enough
// that the reflection's height above the surface reaches t = min(0.9 (wo.ng), 0.01).
// With n = (sin a, cos a) in the basis (x, ng) and wo = (ix, iz), the reflection's height is
// ix sin 2a + iz cos 2a = t: two solutions for 2a, of which the nearer to n's is taken.
vec3 shading_normal_valid(vec3 n, vec3 ng, vec3 wo)
{
    float iz = dot(wo, ng), t = min(0.9 * iz, 0.01);
    if (2.0 * dot(n, wo) * dot(n, ng) - iz >= t)
        return n;
    vec3 x = n - ng * dot(n, ng);
    float lx = length(x);
    if (lx < 1e-7)
        return ng;
    x /= lx;
    float ix = dot(wo, x), a2 = ix * ix + iz * iz, r = sqrt(max(a2 - t * t, 0.0));
    // The two solutions 2a = phi +- acos(t / |wo|), phi = atan(ix, iz), as cos and sin.
    vec2 hi = vec2(t * iz - ix * r, t * ix + iz * r) / a2;
    vec2 lo = vec2(t * iz + ix * r, t * ix - iz * r) / a2;
    // n's own 2a (cos 2a = 2 nz^2 - 1, sin 2a = 2 nx nz) lies beyond the upper one when
    // sin(2a - phi) > 0: the nearer solution is then the upper one.
    float nz = dot(n, ng), nx = dot(n, x);
    vec2 s = 2.0 * nx * nz * iz - (2.0 * nz * nz - 1.0) * ix > 0.0 ? hi : lo;
    // back from 2a to a: cos a = sqrt((1 + cos 2a) / 2), sin a = sin 2a / (2 cos a)
    float ca = sqrt(max(0.5 * (1.0 + s.x), 0.0));
    float sa = ca > 1e-7 ? s.y / (2.0 * ca) : 1.0;
    return normalize(sa * x + ca * ng);
}

struct Surface {
    vec3 p;           // world position
    vec3 ng;          // geometric normal, facing the incoming ray
    vec3 n;           // shading normal (interpolated, normal-mapped, bent by
                      // shading_normal_valid), same side as ng
    vec4 uv;          // TEXCOORD_0 (xy) and TEXCOORD_1 (zw)
    vec3 base;        // linear base colour (factor * texture * vertex colour)
    vec3 vcolor;      // the interpolated vertex colour (1 without COLOR_0)
    float metallic;
    float roughness;
    vec3 emission;
    uint material;
    bool front;       // the ray hit the side the triangle's winding calls front
    // KHR_materials_clearcoat and _sheen (GN_FEAT_LAYERS; else 0): the coat's weight,
    // roughness and normal (the mesh's, or its own normal map's: never normalTexture's),
    // the sheen's colour and roughness
    float coat;
    float coat_roughness;
    vec3 coat_n;
    vec3 sheen;
    float sheen_roughness;
    // KHR_materials_anisotropy (GN_FEAT_ANISO; else 0): the strength and the direction in
    // world space (the tangent frame's, rotated; 0 where the mesh has no tangents)
    float aniso;
    vec3 aniso_t;
    // KHR_materials_iridescence (factor, film ior, thickness in nm) and _diffuse_transmission
    // (colour, factor), textures applied (GN_FEAT_LAYERS; else factors 0)
    vec3 irid;
    vec4 dt;
};

// KHR_materials_iridescence: factor x texture R, thickness mix(min, max, texture G) (max
// without one); KHR_materials_diffuse_transmission: factor x texture A, colour x texture RGB.
void surface_film(inout Surface s, GnMaterial m)
{
    s.irid = vec3(m.iridescence, m.iridescence_ior, m.iridescence_thickness_max);
    if (GN_HAS(GN_FEAT_TEXTURES) && s.irid.x > 0.0 && m.tex_iridescence != GN_INVALID)
        s.irid.x *= texture_sample(m.tex_iridescence, s.uv, false).r;
    if (GN_HAS(GN_FEAT_TEXTURES) && s.irid.x > 0.0 && m.tex_iridescence_thickness != GN_INVALID)
        s.irid.z = mix(m.iridescence_thickness_min, m.iridescence_thickness_max,
                       texture_sample(m.tex_iridescence_thickness, s.uv, false).g);
    s.dt = vec4(m.diffuse_transmission_color, m.diffuse_transmission);
    if (GN_HAS(GN_FEAT_TEXTURES) && s.dt.w > 0.0 && m.tex_diffuse_transmission != GN_INVALID)
        s.dt.w *= texture_sample(m.tex_diffuse_transmission, s.uv, false).a;
    if (GN_HAS(GN_FEAT_TEXTURES) && s.dt.w > 0.0 && m.tex_diffuse_transmission_color != GN_INVALID)
        s.dt.rgb *= texture_sample(m.tex_diffuse_transmission_color, s.uv, true).rgb;
}

// tri: BVH-order triangle index; inst: its instance (Hit.inst); (u, v): barycentrics of v1
// and v2; d: ray direction.
Surface surface_at(uint tri, uint inst, float t, float u, float v, vec3 o, vec3 d)
{
    Surface s;
    GnPrim pr = prim_at(tri);
    GnVertex a = vertex_at(pr.i0), b = vertex_at(pr.i1), c = vertex_at(pr.i2);
    bool mirror = false;
    if (INSTANCES != 0u && inst != GN_INVALID) {
        InstanceXf x = instance_xf(inst);
        a = xf_vertex(x, a);
        b = xf_vertex(x, b);
        c = xf_vertex(x, c);
        mirror = x.mirror;
    }
    float w = 1.0 - u - v;
    s.p = o + t * d;
    vec3 e1 = b.position - a.position, e2 = c.position - a.position;
    vec3 ng = normalize(cross(e1, e2));
    if (mirror) // (the loader reverses a mirrored mesh's corners: the same front)
        ng = -ng;
    s.front = dot(ng, d) < 0.0;
    vec3 n = w * a.normal + u * b.normal + v * c.normal;
    n = dot(n, n) > 1e-20 ? normalize(n) : ng;
    // Shade the side the ray sees: the geometric normal faces the viewer, and the shading
    // normal is kept on its side (meshes whose winding disagrees with their normals exist).
    // The normal map bends the normal of the side the mesh's normals are on; the other side
    // of the sheet gets the opposite of that whole normal (flip below).
    if (!s.front) ng = -ng;
    bool flip = dot(n, ng) < 0.0;
    s.ng = ng;
    s.uv = w * vertex_uv(a) + u * vertex_uv(b) + v * vertex_uv(c);

    GnMaterial m = material_at(pr.material);
    s.material = pr.material;
    vec4 base = m.base_color;
    if (GN_HAS(GN_FEAT_TEXTURES) && m.tex_base != GN_INVALID)
        base *= texture_sample(m.tex_base, s.uv, true);
    vec4 vc = vec4(1.0);
    if (vertex_colors())
        vc = w * a.color + u * b.color + v * c.color;
    base *= vc;
    s.vcolor = vc.rgb;
    s.base = base.rgb;
    s.metallic = m.metallic;
    s.roughness = m.roughness;
    if (GN_HAS(GN_FEAT_TEXTURES) && m.tex_mr != GN_INVALID) {
        vec4 mr = texture_sample(m.tex_mr, s.uv, false);
        s.roughness *= mr.g;
        s.metallic *= mr.b;
    }
    s.emission = m.emissive;
    if (GN_HAS(GN_FEAT_TEXTURES) && m.tex_emissive != GN_INVALID)
        s.emission *= texture_sample(m.tex_emissive, s.uv, true).rgb;
    // (occlusion maps: the local modes' ambient term only, glsl/lib/phong.glsl)
    s.coat = 0.0;
    s.coat_roughness = 0.0;
    s.coat_n = n;
    s.sheen = vec3(0.0);
    s.sheen_roughness = 0.0;
    s.irid = vec3(0.0);
    s.dt = vec4(0.0);
    vec4 tg = w * a.tangent + u * b.tangent + v * c.tangent;
    if (GN_HAS(GN_FEAT_LAYERS)) {
        s.coat = m.clearcoat;
        s.coat_roughness = m.clearcoat_roughness;
        if (GN_HAS(GN_FEAT_TEXTURES) && m.tex_clearcoat != GN_INVALID)
            s.coat *= texture_sample(m.tex_clearcoat, s.uv, false).r;
        if (GN_HAS(GN_FEAT_TEXTURES) && m.tex_clearcoat_roughness != GN_INVALID)
            s.coat_roughness *= texture_sample(m.tex_clearcoat_roughness, s.uv, false).g;
        s.sheen = m.sheen_color;
        s.sheen_roughness = m.sheen_roughness;
        if (GN_HAS(GN_FEAT_TEXTURES) && m.tex_sheen_color != GN_INVALID)
            s.sheen *= texture_sample(m.tex_sheen_color, s.uv, true).rgb;
        if (GN_HAS(GN_FEAT_TEXTURES) && m.tex_sheen_roughness != GN_INVALID)
            s.sheen_roughness *= texture_sample(m.tex_sheen_roughness, s.uv, false).a;
        if (GN_HAS(GN_FEAT_TEXTURES) && s.coat > 0.0 && m.tex_clearcoat_normal != GN_INVALID) {
            vec3 tangent = tg.xyz - n * dot(n, tg.xyz);
            if (dot(tangent, tangent) > 1e-20) {
                tangent = normalize(tangent);
                vec3 bitangent = (tg.w < 0.0 ? -1.0 : 1.0) * cross(n, tangent);
                vec3 tn = texture_sample(m.tex_clearcoat_normal, s.uv, false).xyz * 2.0 - 1.0;
                tn.xy *= m.clearcoat_normal_scale;
                vec3 nm = tn.x * tangent + tn.y * bitangent + tn.z * n;
                if (dot(nm, nm) > 1e-20)
                    s.coat_n = normalize(nm);
            }
        }
        s.coat_n = shading_normal_valid(flip ? -s.coat_n : s.coat_n, ng, -d);
        surface_film(s, m);
    }
    s.aniso = 0.0;
    s.aniso_t = vec3(0.0);
    if (GN_HAS(GN_FEAT_ANISO) && m.anisotropy_strength > 0.0) {
        // The extension's direction: (1, 0) or the texture's RG in [-1, 1], rotated by the
        // rotation from the tangent toward the bitangent; its B scales the strength.
        vec2 dir = vec2(1.0, 0.0);
        s.aniso = m.anisotropy_strength;
        if (GN_HAS(GN_FEAT_TEXTURES) && m.tex_anisotropy != GN_INVALID) {
            vec3 ta = texture_sample(m.tex_anisotropy, s.uv, false).rgb;
            dir = ta.rg * 2.0 - 1.0;
            s.aniso *= ta.b;
        }
        float cr = cos(m.anisotropy_rotation), sr = sin(m.anisotropy_rotation);
        dir = vec2(cr * dir.x - sr * dir.y, sr * dir.x + cr * dir.y);
        vec3 tangent = tg.xyz - n * dot(n, tg.xyz);
        if (dot(tangent, tangent) > 1e-20) {
            tangent = normalize(tangent);
            vec3 bitangent = (tg.w < 0.0 ? -1.0 : 1.0) * cross(n, tangent);
            s.aniso_t = dir.x * tangent + dir.y * bitangent;
        }
    }
    if (GN_HAS(GN_FEAT_NORMAL_MAP) && m.tex_normal != GN_INVALID) {
        // The vertex tangents: the mesh's TANGENT or the loader's MikkTSpace ones, which
        // glTF asks for (src/scene/tangent.c); bitangent = cross(normal, tangent) w, toward -v.
        vec3 tangent = tg.xyz - n * dot(n, tg.xyz);
        if (dot(tangent, tangent) > 1e-20) {
            tangent = normalize(tangent);
            vec3 bitangent = (tg.w < 0.0 ? -1.0 : 1.0) * cross(n, tangent);
            vec3 tn = texture_sample(m.tex_normal, s.uv, false).xyz * 2.0 - 1.0;
            tn.xy *= m.normal_scale; // glTF: the scale applies to X and Y of the sampled normal
            vec3 nm = tn.x * tangent + tn.y * bitangent + tn.z * n;
            if (dot(nm, nm) > 1e-20)
                n = normalize(nm);
        }
    }
    if (flip) n = -n;
    s.n = shading_normal_valid(n, ng, -d);
    return s;
}

// ---- alphaMode: surfaces cut away -----------------------------------------------------------
// The opacity of triangle tri at barycentrics (u, v): 1 for OPAQUE; MASK: 1 where alpha >=
// alphaCutoff, else 0; BLEND: alpha. alpha = base colour factor x texture x vertex colour
// alpha, as glTF defines it.
float surface_opacity(uint tri, float u, float v)
{
    GnPrim pr = prim_at(tri);
    GnMaterial m = material_at(pr.material);
    if ((m.flags & (GN_MAT_MASK | GN_MAT_BLEND)) == 0u)
        return 1.0;
    GnVertex a = vertex_at(pr.i0), b = vertex_at(pr.i1), c = vertex_at(pr.i2);
    float w = 1.0 - u - v, alpha = m.base_color.a;
    if (GN_HAS(GN_FEAT_TEXTURES) && m.tex_base != GN_INVALID)
        alpha *= texture_sample(m.tex_base, w * vertex_uv(a) + u * vertex_uv(b) + v * vertex_uv(c), false).a;
    if (vertex_colors())
        alpha *= w * a.color.a + u * b.color.a + v * c.color.a;
    if ((m.flags & GN_MAT_MASK) != 0u)
        return alpha >= m.alpha_cutoff ? 1.0 : 0.0;
    return clamp(alpha, 0.0, 1.0);
}

// The pixel of this invocation. lavapipe runs a work group as SIMD groups of 8 consecutive
// invocations; laid out as 4x2 blocks of the 8x8 tile (not rows of 8), the rays of a SIMD
// group start closer together and walk more of the same nodes.
uvec2 tile_pixel()
{
    uint l = gl_LocalInvocationIndex, c = l >> 3u, j = l & 7u;
    return gl_WorkGroupID.xy * uvec2(GN_TILE_X, GN_TILE_Y) +
           uvec2((c & 1u) * 4u + (j & 3u), (c >> 1u) * 2u + (j >> 2u));
}

#endif
