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
// (GnPrim = 1), vertices (GnVertex = 5), materials (GnMaterial = GN_MATERIAL_TEXELS), textures (GnTexture =
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

// The corners of BVH-order triangle i (the walk's GnTriPairs hold them too, but a pair has
// no index by triangle).
void tri_corners(uint i, out vec3 a, out vec3 b, out vec3 c)
{
    GnPrim pr = prim_at(i);
    a = vertex_at(pr.i0).position; // (the unused texels of a vertex are never fetched)
    b = vertex_at(pr.i1).position;
    c = vertex_at(pr.i2).position;
}

// Does the scene have vertex colours (glTF COLOR_0)? Without, GnVertex.color is not read.
bool vertex_colors() { return GN_HAS(GN_FEAT_VERTEX_COLOR) && (frame.flags & GN_FRAME_VERTEX_COLOR) != 0u; }

// Material i, each field from its word (glsl/lib/material.h); fields a kernel does not read are
// never fetched: the compiler drops unused texel loads.
GnMaterial material_at(uint i)
{
    uint k = GN_MATERIAL_TEXELS * i;
    GnMaterial m;
    GN_MATERIAL(GN_MAT_READ_PARAM, GN_MAT_READ_TEX, GN_MAT_READ_FIELD)
    return m;
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

// The material at a hit (glsl/lib/material.glsl), its textures read by texture_sample.
#define MATERIAL_TEXTURE(index, uv, srgb) texture_sample(index, uv, srgb)
#include "material.glsl"

struct Surface {
    vec3 p;           // world position
    vec3 ng;          // geometric normal, facing the incoming ray
    vec4 uv;          // TEXCOORD_0 (xy) and TEXCOORD_1 (zw)
    vec3 vcolor;      // the interpolated vertex colour (1 without COLOR_0)
    uint material;
    bool front;       // the ray hit the side the triangle's winding calls front
    Shading sh;       // the material there (material_eval); its normals sh.n (the shading
                      // normal: interpolated, normal-mapped) and sh.coat_n (GN_FEAT_LAYERS)
                      // turned to ng's side and bent by shading_normal_valid
};

// tri: BVH-order triangle index; (u, v): barycentrics of v1 and v2; d: ray direction.
Surface surface_at(uint tri, float t, float u, float v, vec3 o, vec3 d)
{
    Surface s;
    GnPrim pr = prim_at(tri);
    GnVertex a = vertex_at(pr.i0), b = vertex_at(pr.i1), c = vertex_at(pr.i2);
    float w = 1.0 - u - v;
    s.p = o + t * d;
    vec3 e1 = b.position - a.position, e2 = c.position - a.position;
    vec3 ng = normalize(cross(e1, e2));
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
    s.material = pr.material;
    vec4 vc = vec4(1.0);
    if (vertex_colors())
        vc = w * a.color + u * b.color + v * c.color;
    s.vcolor = vc.rgb;
    MaterialHit h;
    h.uv = s.uv;
    h.color = vc;
    h.n = n;
    h.tangent = w * a.tangent + u * b.tangent + v * c.tangent;
    s.sh = material_eval(material_at(pr.material), h);
    // (occlusion maps: the local modes' ambient term only, glsl/lib/phong.glsl)
    if (GN_HAS(GN_FEAT_LAYERS))
        s.sh.coat_n = shading_normal_valid(flip ? -s.sh.coat_n : s.sh.coat_n, ng, -d);
    s.sh.n = shading_normal_valid(flip ? -s.sh.n : s.sh.n, ng, -d);
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
