/* shared.h: the one definition of every struct, constant and binding that the C host and
 * the GLSL kernels share. C, C++ and GLSL all include this file; the C side checks sizes and
 * offsets with static asserts (see the end of the file), so a layout change that breaks
 * std430 fails the build instead of corrupting a buffer.
 *
 * Layout rule: std430, built only from vec4/uvec4, scalars, and "vec3 followed by one
 * 4-byte scalar" pairs, which have the same offsets in C and std430. No hand padding exists
 * in two places. */
#ifndef GONIO_SHARED_H
#define GONIO_SHARED_H

#ifdef VULKAN /* defined by glslang when compiling GLSL for Vulkan */
#define GN_STRUCT(name) struct name
#define GN_END(name)
/* GN_HAS(GN_FEAT_x): may this kernel meet feature x? A kernel specialised on features
 * defines it before including this header (path.comp); elsewhere everything may occur. */
#ifndef GN_HAS
#define GN_HAS(f) true
#endif
#else
#include <stdint.h>
typedef struct { float x, y; } vec2;
typedef struct { float x, y, z; } vec3;
typedef struct { float x, y, z, w; } vec4;
typedef struct { uint32_t x, y, z, w; } uvec4;
typedef uint32_t uint;
#define GN_STRUCT(name) typedef struct name
#define GN_END(name) name
#endif

/* ---- constants of the host and the kernels, each defined once --------------------------- */
#define GN_PI 3.14159265358979323846 /* a double in C, a float in GLSL (the same float either way) */
/* Rec. 709 luminance of linear RGB, the weights of the host's (src/core/vec.h: vec_luminance)
 * and the kernels' (glsl/kernels/path.comp: luminance) one definition */
#define GN_LUMA_R 0.2126
#define GN_LUMA_G 0.7152
#define GN_LUMA_B 0.0722
/* llvmpipe (lavapipe) ends an invocation's loops silently after this many iterations in
 * total (docs/architecture.md: The loop cap): the walk budgets and the path kernel's cap. */
#define GN_LLVMPIPE_LOOP_LIMIT 65535u
/* The most triangle pairs in a BVH leaf (src/accel/bvh.c splits a larger node even where the SAH
 * prefers a leaf; GnBvhNode's count field has room for 8). */
#define GN_BVH_MAX_LEAF 8
/* Loop passes one node visit of a walk can cost: the visit, and the two leaves it may open,
 * each one pass plus one a pair (src/render/render_limits.c: traversal_budget). */
#define GN_WALK_VISIT_PASSES (1u + 2u * (1u + GN_BVH_MAX_LEAF))

/* ---- descriptor bindings (set 0) of the render kernels -------------------------------- */
#define GN_BIND_FRAME 0u     /* GnFrame (a read-only storage buffer: see glsl/lib/scene.glsl) */
/* Bindings 1-5 are RGBA32UI uniform texel buffers (16 bytes a texel), read through
 * bvh_node, bvh_pair, prim_at, vertex_at and material_at (glsl/lib/bvh.glsl, glsl/lib/scene.glsl). */
#define GN_BIND_NODES 1u     /* GnBvhNode[] */
#define GN_BIND_TRIS 2u      /* GnTriPair[] (leaf order) */
#define GN_BIND_PRIMS 3u     /* GnPrim[] (BVH order) */
#define GN_BIND_VERTICES 4u  /* GnVertex[] */
#define GN_BIND_MATERIALS 5u /* GnMaterial[] */
#define GN_BIND_LIGHTS 6u    /* GnLight[] */
#define GN_BIND_TEXELS 7u    /* uint[]: RGBA8 texels of every image, packed */
#define GN_BIND_TEXTURES 8u  /* GnTexture[] */
#define GN_BIND_ACCUM 9u     /* vec4[] per pixel: sum of radiance samples, w = coverage */
#define GN_BIND_AOV 10u      /* vec4[3 * pixels]: normal, albedo, depth sums (GN_FRAME_AOV; else a dummy) */
#define GN_BIND_VCOLOR 11u   /* vec4[2] per vertex: Gouraud colours of the front and back side;
                                 the first one's w holds the vertex's material (uint bits) */
#define GN_BIND_EMITTERS 12u /* GnEmitter[]: emissive triangles for light sampling */
#define GN_BIND_STATUS 13u   /* uint[4]: [0] rays whose walk hit the traversal budget, [1] pixels pending (path) */
#define GN_BIND_SQUARES 14u  /* vec4[] per pixel: sum of squared radiance samples (variance) */
#define GN_BIND_ENV 15u      /* float[]: environment map and its sampling tables (path.comp) */
#define GN_BIND_PSTATE 16u   /* uint[]: per pixel, a path left unfinished by the loop cap (path.comp) */
#define GN_BIND_INSTANCES 17u /* GnInstance[] (RGBA32UI texels; a one-texel dummy in scenes without instances) */
#define GN_BIND_COUNT 18u

/* Work-group size of the 2D image kernels: 8x8 matches lavapipe's 8-wide SIMD rows and is a
 * good default for GPUs (64 threads = 2 warps / 1 wavefront). */
/* The most samples per pixel one dispatch of the path kernel takes (glsl/kernels/path.comp;
 * src/render/render_limits.c: path_samples picks the number for a scene). */
#define GN_PATH_SAMPLES 32u
/* Entries of a BVH walk's stack (glsl/lib/bvh.glsl: Walk), a sentinel and a spare included:
 * room for the 63 nodes a tree of the builder's 64 levels (src/accel/bvh.c) can put off. */
#define GN_WALK_STACK 66
/* The most stack entries a walk keeps in registers instead (specialization constant 2 of the
 * kernels that walk, GN_SPEC_WALK_REGS; glsl/lib/bvh.glsl: Walk): trees of up to this many
 * levels, whose walks put off at most one node per level. */
#define GN_WALK_REGS_MAX 8
#define GN_SPEC_WALK_REGS 2u
/* The path kernel's loop passes per SIMD group before its walks stop (specialization constant
 * 3; 0: none; glsl/lib/bvh.glsl: LOOP_CAP), set below llvmpipe's loop cap. */
#define GN_SPEC_LOOP_CAP 3u
/* The kernels that walk the scene are specialised on whether it has instances (specialization
 * constant 5, INSTANCES in glsl/lib/bvh.glsl; 0: one tree over world-space triangles, as
 * without it): the two-level walk and the instances' transforms compile away for scenes
 * without them. */
#define GN_SPEC_INSTANCES 5u
/* The path kernel's sampler (specialization constant 6, SAMPLER in glsl/kernels/path.comp):
 * where its random numbers come from (glsl/lib/sampling.glsl: sampler_get4; --sampler,
 * docs/path-tracing.md: "Samplers"). X(ID, value, name, help): GN_SAMPLER_<ID> = value,
 * list order is --sampler's, the first the default (render_settings.sampler 0). */
#define GN_SPEC_SAMPLER 6u
#define GN_SAMPLERS(X) \
    X(SOBOL, 0u, "sobol", "Owen-scrambled Sobol pairs, decorrelated per pixel (default)") \
    X(INDEPENDENT, 1u, "independent", "independent hashed random numbers")
#ifdef VULKAN
#define GN_SAMPLER_ID(id, value, name, help) const uint GN_SAMPLER_##id = value;
GN_SAMPLERS(GN_SAMPLER_ID)
#else
#define GN_SAMPLER_ID(id, value, name, help) GN_SAMPLER_##id = value,
enum { GN_SAMPLERS(GN_SAMPLER_ID) GN_SAMPLER_COUNT };
#endif
#undef GN_SAMPLER_ID
/* A path's saved state (glsl/kernels/path.comp: path_save, path_load; GN_BIND_PSTATE,
 * GnFrame.state_stride words a pixel): word 0, the pixel's samples still to take, then the
 * fields of GN_PATH_STATE in order, then the walk's stack; with instances, the last two words
 * of the stride are the hit's instance and the walk's. A row X(kind, variable, when) is a
 * variable of the kernel, saved and loaded where the kernel's condition `when` holds (the
 * host only counts the words). Kinds: U a uint, I an int, F a float, B a bool (a word each),
 * V a vec3 (three), M the media stack (GN_MEDIA_MAX). A field of the path is one row here. */
#define GN_MEDIA_MAX 4u /* media a path can be inside at once (path.comp: media) */
#define GN_PATH_STATE(X)                                                                     \
    X(U, phase, true) X(B, prev_delta, true) X(B, covered, true) X(B, alive, true)           \
    X(U, depth, true) X(V, o, true) X(V, d, true) X(F, tmin, true) X(V, radiance, true)      \
    X(V, beta, true) X(F, prev_pdf, true) X(V, normal, true) X(V, albedo, true)              \
    X(F, depth_aov, true) X(V, so, true) X(V, sd, true) X(F, smax, true) X(V, c, true)       \
    X(F, walk.hit.t, true) X(F, walk.hit.u, true) X(F, walk.hit.v, true)                     \
    X(U, walk.hit.tri, true) X(U, walk.hit.steps, true) X(U, walk.node, true)                \
    X(I, walk.sp, true)                                                                      \
    X(U, tr_k, GN_HAS(GN_FEAT_ALPHA) || GN_HAS(GN_FEAT_CULL))                                \
    X(F, tr_lo, GN_HAS(GN_FEAT_ALPHA) || GN_HAS(GN_FEAT_CULL))                               \
    X(F, tr_max, GN_HAS(GN_FEAT_ALPHA) || GN_HAS(GN_FEAT_CULL))                              \
    X(M, media, GN_HAS(GN_FEAT_VOLUME)) X(U, media_n, GN_HAS(GN_FEAT_VOLUME))                \
    X(U, channel, GN_HAS(GN_FEAT_VOLUME)) X(V, seg_from, GN_HAS(GN_FEAT_VOLUME))
#define GN_PS_WORDS_U 1u
#define GN_PS_WORDS_I 1u
#define GN_PS_WORDS_F 1u
#define GN_PS_WORDS_B 1u
#define GN_PS_WORDS_V 3u
#define GN_PS_WORDS_M GN_MEDIA_MAX
#define GN_PS_COUNT(kind, var, when) + GN_PS_WORDS_##kind
/* Words of a path's saved state before its walk's stack. */
#define GN_PATH_STATE_WORDS (1u GN_PATH_STATE(GN_PS_COUNT))
#define GN_TILE_X 8u
#define GN_TILE_Y 8u

/* ---- render modes: the one list -------------------------------------------------------
 * X(ID, value, kernel, flags, name, help): mode GN_MODE_<ID> = value (0, 1, ... in list
 * order: --mode's list, the help and the preview's number keys follow it), the kernel that
 * renders it, its GN_MODEF_* and, for the host only (src/render/render_modes.c; glslang drops
 * the unexpanded strings), its --mode name and its line of help. A mode of the local kernel
 * is one branch of glsl/kernels/local.comp's local_color: a new mode is an entry here and that branch
 * (docs/architecture.md, "Adding a render mode"). */
#define GN_KERNEL_PATH 0u  /* glsl/kernels/path.comp: GN_PATH_SAMPLES samples a dispatch, resumed past the loop cap */
#define GN_KERNEL_LOCAL 1u /* glsl/kernels/local.comp, specialised on the mode: one camera ray a sample */
#define GN_MODEF_LIT 1u          /* the Phong model's lights: ambient, shadows; a miss shows the environment */
#define GN_MODEF_VERTEX_LIGHT 2u /* the vertices are lit before the first dispatch (glsl/kernels/vertex.comp) */
#define GN_MODES(X) \
    X(PATH, 0u, GN_KERNEL_PATH, 0u, "path", "Monte Carlo path tracing of the rendering equation (default)") \
    X(PHONG, 1u, GN_KERNEL_LOCAL, GN_MODEF_LIT, "phong", "the Phong reflection model, shaded per pixel") \
    X(GOURAUD, 2u, GN_KERNEL_LOCAL, GN_MODEF_LIT | GN_MODEF_VERTEX_LIGHT, "gouraud", \
      "the Phong reflection model at the vertices, interpolated") \
    X(FLAT, 3u, GN_KERNEL_LOCAL, GN_MODEF_LIT, "flat", "the Phong reflection model, one colour a triangle") \
    X(NORMAL, 4u, GN_KERNEL_LOCAL, 0u, "normal", "the shading normal (PNG: 0.5 + 0.5 n)") \
    X(ALBEDO, 5u, GN_KERNEL_LOCAL, 0u, "albedo", "the surface's colour (base colour, or --brdf's)") \
    X(DEPTH, 6u, GN_KERNEL_LOCAL, 0u, "depth", "distance along the camera axis, 0 where nothing is hit") \
    X(COST, 7u, GN_KERNEL_LOCAL, 0u, "cost", "BVH nodes visited per primary ray (PNG: a colour map)")
#ifdef VULKAN
#define GN_MODE_ID(id, value, kernel, flags, name, help) const uint GN_MODE_##id = value;
GN_MODES(GN_MODE_ID)
#define GN_MODE_FLAGS(id, value, kernel, flags, name, help) if (mode == value) return flags;
uint mode_flags(uint mode) { GN_MODES(GN_MODE_FLAGS) return 0u; }
#else
#define GN_MODE_ID(id, value, kernel, flags, name, help) GN_MODE_##id = value,
enum { GN_MODES(GN_MODE_ID) GN_MODE_COUNT };
#endif
#undef GN_MODE_ID

#define GN_LIGHT_POINT 0u
#define GN_LIGHT_SPOT 1u
#define GN_LIGHT_DIRECTIONAL 2u
/* A small Lambertian emitter seen as a point: I(theta) = color * max(cos theta, 0) around
 * direction. Stands in for emissive geometry in the local modes (src/render/render_lights.c). */
#define GN_LIGHT_COSINE 3u

#define GN_INVALID 0xffffffffu

/* GnMaterial.flags */
#define GN_MAT_DOUBLE_SIDED 1u
#define GN_MAT_UNLIT 2u
#define GN_MAT_MASK 4u    /* glTF alphaMode MASK: cut away where alpha < alpha_cutoff */
#define GN_MAT_BLEND 8u   /* glTF alphaMode BLEND: stochastic transparency, opacity alpha */
/* KHR_materials_pbrSpecularGlossiness, read into the metallic-roughness fields (metallic 0,
 * F0 the specular colour at ior 0, the base colour the diffuse one): at a point, roughness =
 * 1 - glossiness and the base colour times 1 - max(specular colour), after the textures
 * (glsl/lib/material.glsl: material_eval) */
#define GN_MAT_SPEC_GLOSS 16u

/* GnFrame.flags */
#define GN_FRAME_AOV 1u       /* write normal/albedo/depth sums */
#define GN_FRAME_SHADOWS 2u   /* ray-traced shadows in the local modes */
#define GN_FRAME_LIGHT_ONLY 4u /* path: emitters reached only by light sampling (no MIS) */
#define GN_FRAME_BSDF_ONLY 8u  /* path: area lights and the environment only by BSDF sampling */
#define GN_FRAME_ENV_MAP 16u   /* path: the environment is the map in GN_BIND_ENV */
#define GN_FRAME_VERTEX_COLOR 32u /* the scene has vertex colours (GnVertex.color) */
#define GN_FRAME_ALPHA 64u     /* the scene has MASK or BLEND materials (surfaces cut away) */
#define GN_FRAME_VARIANCE 128u /* path: write the squares' sums (GN_BIND_SQUARES; else a dummy) */
#define GN_FRAME_CULL 256u     /* the scene has single-sided materials (camera rays pass their backs) */

/* GnEmitter.prim: a triangle (GnPrim index), a punctual light (this bit | GnLight index),
 * or the environment (GN_INVALID). */
#define GN_EMITTER_LIGHT 0x80000000u

/* Features of the path kernel: what a scene and a render can need. llvmpipe never jumps over
 * an `if` (both sides run, lanes masked), so code for a BRDF lobe, a light type or texturing
 * costs every path vertex whether or not any lane uses it; the host sets only the bits its
 * materials, lights and settings need, and the driver compiles the rest away. Each bit only
 * removes code that cannot change the result for a scene without the feature
 * (src/render/render_material.c: material_features; src/render/render.c: path_features).
 * 64 of them, half used: the host's GnFeatures (uint64_t) is two 32-bit specialization
 * constants (GN_SPEC_FEATURES: bits 0-31, GN_SPEC_FEATURES_HI: 32-63), a kernel's feature a
 * uvec2 (its bit in x or y) that GN_HAS tests; | combines features in both. */
#define GN_SPEC_FEATURES 1u
#define GN_SPEC_FEATURES_HI 4u
#ifdef VULKAN
#define GN_FEAT(n) uvec2((n) < 32 ? 1u << ((n) & 31) : 0u, (n) >= 32 ? 1u << ((n) & 31) : 0u)
#define GN_FEAT_NONE uvec2(0u)
#define GN_FEAT_ALL uvec2(0xffffffffu)
#else
typedef uint64_t GnFeatures;
#define GN_FEAT(n) ((GnFeatures)1 << (n))
#define GN_FEAT_NONE ((GnFeatures)0)
#define GN_FEAT_ALL (~(GnFeatures)0)
#endif
#define GN_FEAT_GLTF GN_FEAT(0)       /* glTF materials (bsdf_gltf) */
#define GN_FEAT_MODELS GN_FEAT(1)     /* BRDF-model overrides (bsdf_from_model) */
#define GN_FEAT_MIRROR GN_FEAT(2)     /* a Dirac mirror lobe */
#define GN_FEAT_PHONG GN_FEAT(3)      /* lobes: normalised Phong, */
#define GN_FEAT_BLINN GN_FEAT(4)      /* Blinn-Phong, */
#define GN_FEAT_TS GN_FEAT(5)         /* Torrance-Sparrow, */
#define GN_FEAT_BECKMANN GN_FEAT(6)   /* Beckmann, */
#define GN_FEAT_GGX GN_FEAT(7)        /* GGX */
#define GN_FEAT_FRESNEL_DIELECTRIC GN_FEAT(8)
#define GN_FEAT_FRESNEL_CONDUCTOR GN_FEAT(9)
#define GN_FEAT_FRESNEL_SCHLICK GN_FEAT(10)
#define GN_FEAT_COUPLED GN_FEAT(11)   /* a diffuse layer under a Schlick layer */
#define GN_FEAT_SMOOTH_GLASS GN_FEAT(12)
#define GN_FEAT_ROUGH_GLASS GN_FEAT(13)
#define GN_FEAT_TEXTURES GN_FEAT(14)  /* texture maps (glsl/lib/material.h: the TEX rows) */
#define GN_FEAT_NORMAL_MAP GN_FEAT(15)
#define GN_FEAT_UNLIT GN_FEAT(16)
#define GN_FEAT_EMISSIVE GN_FEAT(17)  /* emissive triangles */
#define GN_FEAT_PUNCTUAL GN_FEAT(18)  /* KHR_lights_punctual lights */
#define GN_FEAT_ENV GN_FEAT(19)       /* an environment (constant or map) */
#define GN_FEAT_ENV_MAP GN_FEAT(20)
#define GN_FEAT_LIGHT_SEARCH GN_FEAT(21) /* more than one light to choose from */
#define GN_FEAT_STRATEGY GN_FEAT(22)  /* light-only or BSDF-only estimators */
#define GN_FEAT_AOV GN_FEAT(23)
#define GN_FEAT_VERTEX_COLOR GN_FEAT(24) /* glTF COLOR_0 */
#define GN_FEAT_ALPHA GN_FEAT(25)     /* alphaMode MASK or BLEND (glsl/lib/bvh.glsl: trace_visible) */
#define GN_FEAT_VARIANCE GN_FEAT(26)  /* sums of squares (--aov variance) */
#define GN_FEAT_TEX_TRANSFORM GN_FEAT(27) /* KHR_texture_transform (GnTexture.transform) */
#define GN_FEAT_UV1 GN_FEAT(28)       /* textures reading TEXCOORD_1 (GN_TEX_UV1) */
#define GN_FEAT_LAYERS GN_FEAT(29)    /* KHR_materials_clearcoat, _sheen, _iridescence, _diffuse_transmission (brdf_material.glsl: bsdf_layers) */
#define GN_FEAT_VOLUME GN_FEAT(30)    /* KHR_materials_volume media, _dispersion */
#define GN_FEAT_ANISO GN_FEAT(31)     /* KHR_materials_anisotropy */
#define GN_FEAT_CULL GN_FEAT(32)      /* single-sided materials (doubleSided false): camera rays pass their
                                       * back faces (glsl/lib/bvh.glsl: trace_visible) */
/* (GN_FEAT_LOBES, every lobe a BRDF model can build: brdf_models.h, from its table) */
#define GN_FEAT_GLASS (GN_FEAT_SMOOTH_GLASS | GN_FEAT_ROUGH_GLASS)

/* ---- BVH: both children's boxes in one 64-byte node (Aila & Laine 2009, "Understanding
 * the efficiency of ray traversal on GPUs"): one fetch tests two boxes and the walk only
 * pushes the farther hit child. Node 0 holds the root's two children.
 * For child a (and likewise b):
 *   a_count > 0                       leaf: a_index = GN_BVH_LEAF | (a_count - 1) <<
 *                                     GN_BVH_COUNT_SHIFT | first, for the triangle pairs
 *                                     [first, first + a_count) of GnTriPair[]: the walk keeps
 *                                     child indices as they are, with no unpacking
 *   a_count == 0, a_index != INVALID  inner: GnBvhNode[a_index] (below GN_BVH_LEAF)
 *   a_count == 0, a_index == INVALID  empty (only b, when the whole scene is one leaf); its
 *                                     box is inverted (min FLT_MAX, max -FLT_MAX), so the
 *                                     walk's slab test never enters it and needs no check
 * Leaves hold at most GN_BVH_MAX_LEAF pairs and scenes at most 2^26 triangles
 * (src/scene/scene.h: SCENE_MAX_TRIANGLES), so first fits in 27 bits.
 * Two levels (a scene with instances, GN_SPEC_INSTANCES): the top tree's nodes come first
 * (node 0 is its root), then each mesh's tree, its indices offset to their place in the
 * node and pair arrays. A top-level leaf is one instance: a_count 1, a_index GN_BVH_LEAF |
 * GN_BVH_INSTANCE | its GnInstance index. The walk goes on at that instance's mesh's root
 * with the ray in the mesh's space, and first puts GN_BVH_RETURN on its stack: popping
 * it, once the mesh's tree is done, brings the walk back to world space. */
#define GN_BVH_LEAF 0x80000000u
#define GN_BVH_INSTANCE 0x40000000u
#define GN_BVH_COUNT_SHIFT 27
#define GN_BVH_COUNT_MASK 7u
#define GN_BVH_FIRST 0x07ffffffu
#define GN_BVH_RETURN (GN_BVH_LEAF | GN_BVH_INSTANCE | GN_BVH_FIRST) /* (so at most 2^27 - 1 instances) */
/* A slab test's far distance is scaled by this, so rounding never loses a box the triangle
 * test hits: 1 + 2 gamma(3) (Ize 2013; gamma(n) = n u / (1 - n u), u = 2^-24) is just above
 * 1 + 3 ulp, so 1 + 4 ulp (src/accel/bvh.c and glsl/lib/bvh.glsl, one value). */
#define GN_BVH_TFAR_SCALE 1.00000048f
/* A ray direction's component below this counts as parallel to its slabs (src/accel/bvh.c:
 * BVH_PARALLEL_DIR says why; glsl/lib/bvh.glsl: ray_pre). */
#define GN_BVH_PARALLEL_DIR 1e-30f
GN_STRUCT(GnBvhNode) {
    vec3 a_min; uint a_index;
    vec3 a_max; uint a_count;
    vec3 b_min; uint b_index;
    vec3 b_max; uint b_count;
} GN_END(GnBvhNode); /* 64 bytes */

/* The walk's leaf primitive: one triangle, or two that share an edge, for the watertight
 * test (Woop, Benthin & Wald 2013). Triangle A = (p0, p1, p2), triangle B = (p0, p2, p3):
 * B's edge (p0, p2) is A's, so the walk transforms four corners instead of six, computes
 * that edge's function once (negated for B: the very number B's own would be) and fetches
 * three texels for two triangles instead of six; texel fetches are most of what the walk
 * costs on lavapipe (docs/architecture.md). The pairs are neighbours in the index buffer
 * that share an edge, wound alike (src/accel/bvh.c: pairs_with_next); a triangle without a
 * partner has p3 = p2, a B that no ray can hit (its edge functions cancel exactly: det 0).
 * Pair i holds the BVH-order triangles 2i (A) and 2i + 1 (B; a hole in GnPrim[] and
 * tri_index for a lone triangle), whose corners are stored rotated: GnPrim lists each
 * one's vertices in the test's corner order (the same winding), so the walk's barycentrics
 * (u, v of p1, p2 for A; of p2, p3 for B) need no translation. No padding: 48 bytes, three
 * RGBA32UI texels. */
GN_STRUCT(GnTriPair) {
    vec3 p0; vec3 p1; vec3 p2; vec3 p3;
} GN_END(GnTriPair); /* 48 bytes */

/* An instance of a mesh (a bottom-level tree, in its own object space) in a scene with two
 * levels, shaped as a Vulkan acceleration-structure instance is (VkAccelerationStructure-
 * InstanceKHR): to_world is its 3x4 row-major object-to-world transform (the VkTransform-
 * MatrixKHR), mesh the bottom-level tree (the BLAS), custom the user's number for it
 * (instanceCustomIndex: gonio keeps the glTF node), flags GN_INSTANCE_*. The walk reads
 * to_object (the inverse, world to object) and root, its tree's root node; shading reads
 * to_world and to_object (normals by the inverse transpose). vcolor_offset: the Gouraud
 * colour of its vertex i is vcolor[2 (i + vcolor_offset)] (uint arithmetic); prim_base: its
 * mesh's first GnPrim (so a hit's GnPrim is prim_base + the triangle's place in the mesh's
 * own tree order, as a ray query's primitive index would give it). Eight RGBA32UI texels. */
GN_STRUCT(GnInstance) {
    vec4 to_object[3];
    uint root; uint mesh; uint custom; uint flags;
    vec4 to_world[3];
    uint vcolor_offset; uint prim_base; uint pad0; uint pad1;
} GN_END(GnInstance); /* 128 bytes */
/* GnInstance.flags: the transform's determinant is negative, so it mirrors: a triangle's
 * front (glTF: counter-clockwise in world space) is the side its object-space winding calls
 * back (Vulkan: VK_GEOMETRY_INSTANCE_TRIANGLE_FLIP_FACING_BIT_KHR). */
#define GN_INSTANCE_MIRROR 1u

/* Shading data of a triangle, in BVH order (2 per GnTriPair; the walk's hits count in it),
 * corners in the order the walk's test takes them (GnTriPair). */
GN_STRUCT(GnPrim) {
    uint i0; uint i1; uint i2; uint material;
} GN_END(GnPrim); /* 16 bytes */

GN_STRUCT(GnVertex) {
    vec3 position; float u;
    vec3 normal; float v;
    vec4 tangent; /* xyz tangent, w handedness; the loader generates them (MikkTSpace) for
                     normal maps without TANGENT; else all zero when the mesh has none */
    vec4 color;   /* glTF COLOR_0 (linear RGBA; 1 when the mesh has none), read only when
                     GnFrame.flags has GN_FRAME_VERTEX_COLOR */
    float u1; float v1; float pad0; float pad1; /* glTF TEXCOORD_1 (0 without), read only by
                     kernels with GN_FEAT_UV1 */
} GN_END(GnVertex); /* 80 bytes */

/* A material: glTF metallic-roughness with its extensions, the classic (OpenGL 1.x) Phong
 * parameters of the local shading modes, and an optional BRDF-model override for the path
 * tracer. Declared field by field in glsl/lib/material.h (GN_MATERIAL), which everything that
 * reads or writes one expands. Texture fields index GnTexture[], GN_INVALID when absent. */
#include "material.h"
GN_STRUCT(GnMaterial) {
    GN_MATERIAL(GN_MAT_DECL_PARAM, GN_MAT_DECL_TEX, GN_MAT_DECL_FIELD)
} GN_END(GnMaterial); /* 4 GN_MATERIAL_WORDS bytes (material.h) */

/* glTF KHR_lights_punctual light in world space. color = colour * intensity (W/sr for point
 * and spot, W/m^2 for directional: gonio reads photometric units as radiometric). direction
 * is where the light points (the node's -Z). range <= 0 means infinite. */
GN_STRUCT(GnLight) {
    vec3 position; uint type;
    vec3 direction; float range;
    vec3 color; float inner_cos;
    float outer_cos; float pad0; float pad1; float pad2;
} GN_END(GnLight); /* 64 bytes */

/* One light of the path tracer's light-selection table, chosen with probability pdf (cdf:
 * the running sum up to and including this entry). prim: see GN_EMITTER_LIGHT. */
GN_STRUCT(GnEmitter) {
    uint prim; float area; float cdf; float pdf; /* area: of the triangle, else 0 */
} GN_END(GnEmitter);

/* A material's use of an image in the packed texel buffer (RGBA8, rows top to bottom): its
 * sampler, the texture coordinate set it reads and its KHR_texture_transform. One per
 * (texture, texCoord, transform) that a material uses, so the material needs no more room.
 * transform holds the rows of the spec's 3x3 matrix T R S (its last row is 0 0 1):
 * uv' = (dot(row0.xyz, (u, v, 1)), dot(row1.xyz, (u, v, 1))); identity without the extension,
 * and read only by kernels with GN_FEAT_TEX_TRANSFORM. */
GN_STRUCT(GnTexture) {
    uint offset;   /* first texel (uint) in the texel buffer */
    uint width;
    uint height;
    uint flags;    /* bits 0-1 wrap S, 2-3 wrap T (0 repeat, 1 clamp, 2 mirror), 4 nearest,
                      5 TEXCOORD_1 */
    vec3 row0; float pad0;
    vec3 row1; float pad1;
} GN_END(GnTexture); /* 48 bytes */

#define GN_WRAP_REPEAT 0u
#define GN_WRAP_CLAMP 1u
#define GN_WRAP_MIRROR 2u
#define GN_TEX_NEAREST 16u
#define GN_TEX_UV1 32u

/* Camera in world space. Pixel (x, y) with y going down is at s = (2 (x+jx)/W - 1,
 * 1 - 2 (y+jy)/H) on the image plane. Perspective (ortho_half_height 0): the ray from
 * position along forward + s.x tan_half_fovy aspect right + s.y tan_half_fovy up.
 * Orthographic (glTF xmag/ymag): from position + h (s.x aspect right + s.y up) along
 * forward, h = ortho_half_height (ymag). */
GN_STRUCT(GnCamera) {
    vec3 position; float tan_half_fovy;
    vec3 right; float aspect;
    vec3 up; float znear;
    vec3 forward; float zfar;
    float ortho_half_height; float pad0; float pad1; float pad2;
} GN_END(GnCamera); /* 80 bytes */

/* Constant for a whole render (read-only storage buffer, std430). width x height is the
 * whole image, which the camera maps and whose pixel index feeds the random numbers; the
 * kernels run over its region (crop_x, crop_y) + crop_width x crop_height, whose pixels
 * the accumulation buffers hold, so a crop renders exactly the pixels of the whole image. */
GN_STRUCT(GnFrame) {
    GnCamera camera;
    uint width; uint height; uint seed; uint max_depth;
    uint num_lights; uint num_emitters; uint flags;
    uint traversal_budget;               /* max BVH steps per ray (docs/architecture.md: the loop cap) */
    vec3 ambient; float emitter_power;   /* ambient: global ambient light of the Phong model */
    vec3 env_color; float env_select;    /* constant environment radiance; env's selection probability */
    uint env_width; uint env_height;     /* GN_FRAME_ENV_MAP: the lat-long map's size */
    float env_cos; float env_sin;        /* the map turned by a about +Y (right-handed): cos a, -sin a */
    uint crop_x; uint crop_y;            /* the region's top-left pixel in the whole image */
    uint crop_width; uint crop_height;   /* the region's size: the dispatch and the buffers */
    uint loop_overhead; uint state_stride; /* path, LOOP_CAP > 0: loop passes a vertex costs besides its walks; words per pixel of GN_BIND_PSTATE */
    uint emitter_instances;              /* path, with instances: the first texel of GN_BIND_EMITTERS after the
                                            table, where emitter i's instance is texel + i (.x); 0 without */
    uint pad1;                           /* (std430 rounds the struct to 16 bytes) */
} GN_END(GnFrame); /* 192 bytes */

/* Per-dispatch values (push constants). */
GN_STRUCT(GnPush) {
    uint sample_index;   /* index of the (first) sample this pass takes in every pixel;
                            trace_test.comp: the number of rays */
    uint pass_flags;     /* vertex.comp: the side (0 front, 1 back); trace_test.comp: GN_PASS_* */
    uint samples;        /* path.comp: how many samples, sample_index on (0..GN_PATH_SAMPLES; 0: only finish those pending) */
    uint seed;           /* brdf_sphere.comp: the random numbers' seed */
} GN_END(GnPush);
#define GN_PASS_RESUME 1u  /* trace_test.comp: resume the walks the last dispatch saved */
#define GN_PASS_ANY_HIT 2u /* trace_test.comp: any hit ends a walk (shadow rays) */

/* ---- display kernel (glsl/kernels/display.comp): accumulated radiance -> 8-bit sRGB texels ----- */
#define GN_DISPLAY_BIND_ACCUM 0u /* vec4[] per pixel, as GN_BIND_ACCUM */
#define GN_DISPLAY_BIND_OUT 1u   /* uint[] per pixel: packed 8-bit texels */
#define GN_DISPLAY_BGRA 1u       /* GnDisplayPush.flags: pack B, G, R, A (byte order) */
/* Tonemaps, the values of image_tonemap (src/core/image.h). */
#define GN_TONEMAP_CLAMP 0u
#define GN_TONEMAP_ACES 1u
#define GN_TONEMAP_REINHARD 2u

GN_STRUCT(GnDisplayPush) {
    uint width; uint height; uint tonemap; uint flags;
    float inv_spp; float scale; uint pad0; uint pad1; /* scale = 2^exposure */
} GN_END(GnDisplayPush);

#ifndef VULKAN
#ifdef __cplusplus
#define GN_STATIC_ASSERT static_assert
#else
#define GN_STATIC_ASSERT _Static_assert
#endif
#include <stddef.h>
GN_STATIC_ASSERT(sizeof(GnBvhNode) == 64, "GnBvhNode layout");
GN_STATIC_ASSERT(GN_BVH_MAX_LEAF - 1 <= GN_BVH_COUNT_MASK &&
                     (GN_BVH_COUNT_MASK << GN_BVH_COUNT_SHIFT & (GN_BVH_LEAF | GN_BVH_INSTANCE | GN_BVH_FIRST)) == 0,
                 "a leaf's count fits its bits, apart from the instance bit");
GN_STATIC_ASSERT(sizeof(GnInstance) == 128 && offsetof(GnInstance, root) == 48 &&
                     offsetof(GnInstance, to_world) == 64 && offsetof(GnInstance, vcolor_offset) == 112,
                 "GnInstance layout");
GN_STATIC_ASSERT(offsetof(GnBvhNode, b_min) == 32, "GnBvhNode layout");
GN_STATIC_ASSERT(sizeof(GnTriPair) == 48, "GnTriPair layout");
GN_STATIC_ASSERT(sizeof(GnPrim) == 16, "GnPrim layout");
GN_STATIC_ASSERT(sizeof(GnVertex) == 80, "GnVertex layout");
GN_STATIC_ASSERT(offsetof(GnVertex, u1) == 64, "GnVertex layout");
GN_STATIC_ASSERT(sizeof(GnMaterial) == 4 * GN_MATERIAL_WORDS && GN_MATERIAL_WORDS == 4 * GN_MATERIAL_TEXELS,
                 "GnMaterial layout");
/* every row of GN_MATERIAL at its word, a vec3 or vec4 at the start of a texel */
#define GN_MAT_ALIGNED_float(word) 1
#define GN_MAT_ALIGNED_uint(word) 1
#define GN_MAT_ALIGNED_vec3(word) ((word) % 4 == 0)
#define GN_MAT_ALIGNED_vec4(word) ((word) % 4 == 0)
#define GN_MAT_ASSERT_FIELD(name, type, word) \
    GN_STATIC_ASSERT(offsetof(GnMaterial, name) == 4 * (word) && GN_MAT_ALIGNED_##type(word), \
                     "GnMaterial." #name " is not at word " #word " (glsl/lib/material.h)");
#define GN_MAT_ASSERT_PARAM(name, type, word, ext, json, def, lo, hi, rule, feat, brdf) GN_MAT_ASSERT_FIELD(name, type, word)
#define GN_MAT_ASSERT_TEX(name, word, ext, json, space, gate, uses) GN_MAT_ASSERT_FIELD(name, uint, word)
GN_MATERIAL(GN_MAT_ASSERT_PARAM, GN_MAT_ASSERT_TEX, GN_MAT_ASSERT_FIELD)
GN_STATIC_ASSERT(sizeof(GnLight) == 64, "GnLight layout");
GN_STATIC_ASSERT(sizeof(GnEmitter) == 16, "GnEmitter layout");
GN_STATIC_ASSERT(sizeof(GnTexture) == 48, "GnTexture layout");
GN_STATIC_ASSERT(offsetof(GnTexture, row1) == 32, "GnTexture layout");
GN_STATIC_ASSERT(sizeof(GnCamera) == 80, "GnCamera layout");
GN_STATIC_ASSERT(sizeof(GnFrame) == 192, "GnFrame layout");
GN_STATIC_ASSERT(offsetof(GnFrame, crop_x) == 160, "GnFrame layout");
GN_STATIC_ASSERT(offsetof(GnFrame, env_width) == 144, "GnFrame layout");
GN_STATIC_ASSERT(offsetof(GnFrame, ambient) == 112, "GnFrame layout");
GN_STATIC_ASSERT(sizeof(GnPush) == 16, "GnPush layout");
GN_STATIC_ASSERT(sizeof(GnDisplayPush) == 32, "GnDisplayPush layout");
#endif

#endif /* GONIO_SHARED_H */
