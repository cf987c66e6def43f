/* cmd_info.c: `gonio info`, a scene's contents and BVH statistics. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "bvh.h"
#include "cli.h"
#include "scene.h"
#include "util.h"

/* A name from the file, as printed: control characters escaped, "(unnamed)" when empty. Four
 * buffers in turn, for the printf calls that print up to four names. */
static const char *shown(const char *name)
{
    static char buf[4][512];
    static int next;
    char *b = buf[next++ & 3];
    return name[0] ? util_escape(name, b, sizeof buf[0]) : "(unnamed)";
}

/* The area lights as the path tracer sees them (src/render/render_lights.c: build_emitters):
 * triangles of non-zero area whose material emits and is not unlit; prints the materials by
 * name. */
static void print_emitters(const scene *sc)
{
    uint32_t tris = 0, mats = 0;
    uint32_t *count = util_calloc(sc->num_materials, sizeof *count);
    for (uint32_t t = 0; t < sc->num_triangles; t++) {
        const GnMaterial *m = &sc->materials[sc->tri_material[t]];
        double c[3];
        if (!(m->emissive.x > 0 || m->emissive.y > 0 || m->emissive.z > 0) || (m->flags & GN_MAT_UNLIT))
            continue;
        scene_triangle_cross(sc, t, c);
        if (!(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] > 0))
            continue;
        tris++;
        mats += count[sc->tri_material[t]]++ == 0;
    }
    printf("emissive       %u triangles in %u material(s)", tris, mats);
    for (uint32_t m = 0, n = 0; m < sc->num_materials; m++)
        if (count[m])
            printf("%s%s (%u)", n++ ? ", " : ": ", shown(sc->material_names[m]),
                   count[m]);
    printf("\n");
    free(count);
}

/* The materials with a medium or dispersion, as the path tracer reads them (glsl/kernels/path.comp:
 * sigma_a = -ln(attenuation colour) / attenuation distance). */
static void print_media(const scene *sc)
{
    for (uint32_t i = 0; i < sc->num_materials; i++) {
        const GnMaterial *m = &sc->materials[i];
        const float *c = &m->attenuation_color.x;
        double sigma[3];
        if (!m->volume && !(m->dispersion > 0))
            continue;
        for (int k = 0; k < 3; k++)
            sigma[k] = c[k] >= 1 ? 0 : -log(c[k] > 1e-30f ? c[k] : 1e-30f) / m->attenuation_distance;
        printf("medium %-7u \"%s\" %s attenuation (%g, %g, %g) distance %g (sigma_a %g, %g, %g), "
               "thickness %g, ior %g, dispersion %g\n", i, shown(sc->material_names[i]),
               m->volume ? "volume" : "thin-walled", c[0], c[1], c[2], m->attenuation_distance, sigma[0], sigma[1],
               sigma[2], m->thickness, m->ior, m->dispersion);
    }
}

/* The materials with KHR_materials_anisotropy, as bsdf_anisotropy reads them. */
static void print_anisotropy(const scene *sc)
{
    for (uint32_t i = 0; i < sc->num_materials; i++) {
        const GnMaterial *m = &sc->materials[i];
        if (!(m->anisotropy_strength > 0) && m->tex_anisotropy == GN_INVALID)
            continue;
        printf("anisotropy %-3u \"%s\" strength %g, rotation %g deg%s\n", i,
               shown(sc->material_names[i]), m->anisotropy_strength,
               m->anisotropy_rotation * 180 / M_PI, m->tex_anisotropy != GN_INVALID ? ", textured" : "");
    }
}

/* KHR_materials_iridescence and _diffuse_transmission: one line per material that has them. */
static void print_films(const scene *sc)
{
    for (uint32_t i = 0; i < sc->num_materials; i++) {
        const GnMaterial *m = &sc->materials[i];
        const char *name = shown(sc->material_names[i]);
        if (m->iridescence > 0 && m->tex_iridescence_thickness != GN_INVALID)
            printf("iridescence %-3u \"%s\" factor %g%s, film ior %g, thickness %g - %g nm (texture G)\n", i, name,
                   m->iridescence, m->tex_iridescence != GN_INVALID ? " x texture" : "", m->iridescence_ior,
                   m->iridescence_thickness_min, m->iridescence_thickness_max);
        else if (m->iridescence > 0)
            printf("iridescence %-3u \"%s\" factor %g%s, film ior %g, thickness %g nm\n", i, name, m->iridescence,
                   m->tex_iridescence != GN_INVALID ? " x texture" : "", m->iridescence_ior,
                   m->iridescence_thickness_max);
        if (m->diffuse_transmission > 0)
            printf("diffuse transmission %-3u \"%s\" factor %g%s, colour (%g, %g, %g)%s\n", i, name,
                   m->diffuse_transmission, m->tex_diffuse_transmission != GN_INVALID ? " x texture" : "",
                   m->diffuse_transmission_color.x, m->diffuse_transmission_color.y, m->diffuse_transmission_color.z,
                   m->tex_diffuse_transmission_color != GN_INVALID ? " x texture" : "");
    }
}

/* The extensions the file lists, one line each: how gonio handles it (scene.h: scene_extension). */
static void print_extensions(const scene *sc)
{
    static const char *const support[] = {[SCENE_UNSUPPORTED] = "unsupported (ignored)", [SCENE_PARTLY] = "partly",
                                          [SCENE_SUPPORTED] = "supported"};
    printf("extensions     %u\n", sc->num_extensions);
    for (uint32_t i = 0; i < sc->num_extensions; i++) {
        const scene_extension *e = &sc->extensions[i];
        printf("extension      %s%s: %s: %s\n", shown(e->name), e->required ? " (required)" : "", support[e->support],
               e->how);
    }
}

int cmd_info(int argc, char **argv)
{
    bool outside = false;
    const cli_option options[] = {CLI_OPT_ALLOW_OUTSIDE_FILES(&outside)};
    const cli_command cmd = {
        .name = "info", .synopsis = "SCENE.gltf|.glb [--allow-outside-files]",
        .intro = "Prints the scene's contents and its BVH statistics: the emissive triangles (the path\n"
                 "tracer's area lights) and the materials that emit, and one line per camera (index, name,\n"
                 "position, forward direction, vertical field of view or orthographic width x height;\n"
                 "the first is the one gonio render uses by default), the KHR_materials_variants\n"
                 "variants by index and name (for --variant), and one line per material that bounds a\n"
                 "medium (KHR_materials_volume) or disperses (KHR_materials_dispersion): attenuation\n"
                 "colour and distance, the absorption coefficient they give, thickness (unused by the\n"
                 "path tracer), IOR and dispersion; one line per anisotropic material\n"
                 "(KHR_materials_anisotropy): strength, rotation and whether a texture sets them;\n"
                 "and one line per material with an iridescent film (KHR_materials_iridescence:\n"
                 "factor, film IOR, thickness) or a diffuse transmission\n"
                 "(KHR_materials_diffuse_transmission: factor, colour); and one line per extension the\n"
                 "file lists: whether gonio supports it, partly (and what it leaves out) or not (and why).\n",
        CLI_OPTIONS(options), .min_args = 1, .max_args = 1, .missing = "no scene given",
        .complete_args = "*.gltf *.glb"};
    cli_args args;
    scene sc = {0};
    bvh b = {0};
    int rc = cli_parse(&cmd, argc, argv, &args);
    if (rc >= 0)
        return rc;
    const char *path = args.arg[0];
    scene_allow_outside_files(outside);
    if (!scene_load(&sc, path))
        return 1;
    bvh_build(&b, &sc.vertices[0].position.x, sizeof(GnVertex) / sizeof(float), sc.indices,
              sc.num_triangles);
    printf("scene          %s\n", shown(path));
    printf("triangles      %u\n", sc.num_triangles);
    printf("vertices       %u\n", sc.num_vertices);
    printf("meshes         %u (primitive instances; %u glTF meshes, %u nodes)\n", sc.num_meshes,
           sc.num_gltf_meshes, sc.num_nodes);
    printf("materials      %u\n", sc.num_materials);
    printf("variants       %u\n", sc.num_variants);
    for (uint32_t i = 0; i < sc.num_variants; i++)
        printf("variant %-6u \"%s\"\n", i, shown(sc.variant_names[i]));
    print_extensions(&sc);
    printf("textures       %u (%u images)\n", sc.num_textures, sc.num_images);
    printf("lights         %u\n", sc.num_lights);
    print_emitters(&sc);
    print_media(&sc);
    print_anisotropy(&sc);
    print_films(&sc);
    printf("cameras        %u\n", sc.num_cameras);
    for (uint32_t i = 0; i < sc.num_cameras; i++) {
        const scene_camera *c = &sc.cameras[i];
        printf("camera %-7u \"%s\" position (%g, %g, %g) forward (%g, %g, %g) ", i, shown(c->name), c->position[0],
               c->position[1], c->position[2], c->forward[0], c->forward[1], c->forward[2]);
        if (c->ortho_half_height > 0)
            printf("orthographic %g x %g\n", 2 * c->ortho_half_height * c->aspect, 2 * c->ortho_half_height);
        else
            printf("yfov %.4g deg\n", c->yfov * 180 / M_PI);
    }
    printf("bounds         (%g, %g, %g) - (%g, %g, %g)\n", sc.bounds_min[0], sc.bounds_min[1],
           sc.bounds_min[2], sc.bounds_max[0], sc.bounds_max[1], sc.bounds_max[2]);
    printf("bvh nodes      %u (%zu bytes each)\n", b.num_nodes, sizeof(GnBvhNode));
    printf("bvh leaf prims %u (%u triangle pairs sharing an edge, %u single triangles)\n",
           b.num_pairs, b.num_tris - b.num_pairs, 2 * b.num_pairs - b.num_tris);
    printf("bvh depth      %u\n", b.depth);
    printf("bvh max leaf   %u triangle pairs\n", b.max_leaf_size);
    printf("bvh sah cost   %.2f\n", b.sah_cost);
    printf("bvh build      %.2f ms (%.2f M triangles/s)\n", b.build_seconds * 1e3,
           b.build_seconds > 0 ? sc.num_triangles / b.build_seconds * 1e-6 : 0.0);
    bvh_destroy(&b);
    scene_destroy(&sc);
    return 0;
}
