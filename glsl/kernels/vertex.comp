#version 450
// vertex.comp: the per-vertex lighting pass of Gouraud shading (Gouraud 1971, "Continuous
// shading of curved surfaces"): the Phong reflection model (glsl/lib/phong.glsl) once per vertex,
// with the vertex normal, the view direction from the vertex and shadow rays from the
// vertex, as an OpenGL 1.x vertex pipeline lights them. local.comp interpolates the colours.
//
// vcolor holds two vec4 per vertex: [2i] the side the normal points to, [2i+1] the other
// side (two-sided lighting: open meshes show both). The host stores the vertex's material
// index in the bits of vcolor[2i].w; this pass writes .rgb only. One dispatch per side
// (push.pass_flags = 0 or 1) keeps one invocation's shadow rays within the loop budget.
// With instances (INSTANCES), each instance's vertices have colours of their own, at
// GnInstance.vcolor_offset past the mesh's: the host puts the instance in [2i + 1].w.
// The dispatch is 2D when the vertices need more work groups than one axis may have
// (maxComputeWorkGroupCount[0]: 65,535 on lavapipe, 4.2 M vertices): rows of groups.
#extension GL_GOOGLE_include_directive : require

#include "phong.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = GN_BIND_VCOLOR) buffer VColorBlock { vec4 vcolor[]; };
layout(push_constant) uniform PushBlock { GnPush push; };

void main()
{
    uint i = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
    uint side = push.pass_flags;
    if (i >= uint(vcolor.length()) / 2u)
        return;
    GnVertex a;
    if (INSTANCES != 0u) { // an instance's copy of its mesh's vertex (its index rides in [2i + 1].w)
        uint inst = floatBitsToUint(vcolor[2u * i + 1u].w);
        a = xf_vertex(instance_xf(inst), vertex_at(i - texelFetch(instance_texels, int(8u * inst + 7u)).x));
    } else {
        a = vertex_at(i);
    }
    rng_pixel = i; // the BLEND test's random numbers in the shadow rays: per vertex
    rng_sample = side;
    uint material = floatBitsToUint(vcolor[2u * i].w);
    vec3 n = dot(a.normal, a.normal) > 1e-20 ? normalize(a.normal) : vec3(0.0);
    if (side == 1u)
        n = -n;
    vec3 v = camera_view(a.position);
    vec3 vc = vertex_colors() ? a.color.rgb : vec3(1.0);
    vcolor[2u * i + side].rgb = phong_shade(a.position, n, n, vertex_uv(a), vc, material, v);
}
