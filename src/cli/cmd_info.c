/* cmd_info.c: `gonio info`, a scene's contents and BVH statistics. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bvh.h"
#include "cli.h"
#include "image_decode.h"
#include "render_geometry.h"
#include "scene.h"
#include "util.h"

/* The keys' column: "triangles      ", "camera 0       " (names and values start after it). */
#define INFO_KEY_WIDTH 14

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
    for (uint32_t i = 0; i < sc->num_instances; i++) { /* each instance's, as placed */
        const scene_instanced_mesh *im = &sc->instanced_meshes[sc->instances[i].mesh];
        for (uint32_t t = 0; t < im->num_triangles; t++) {
            const GnMaterial *m = &sc->materials[im->tri_material[t]];
            double c[3];
            if (!(m->emissive.x > 0 || m->emissive.y > 0 || m->emissive.z > 0) || (m->flags & GN_MAT_UNLIT))
                continue;
            scene_instance_triangle_cross(sc, i, t, c);
            if (!(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] > 0))
                continue;
            tris++;
            mats += count[im->tri_material[t]]++ == 0;
        }
    }
    printf("emissive       %u triangles in %u material(s)", tris, mats);
    for (uint32_t m = 0, n = 0; m < sc->num_materials; m++)
        if (count[m])
            printf("%s%s (%u)", n++ ? ", " : ": ", shown(sc->material_names[m]),
                   count[m]);
    printf("\n");
    free(count);
}

/* The lines the loader's extensions add (scene.h: scene_material_line), grouped by extension in
 * the table's order: one a material that uses it, its label and index filling the column that
 * the other lines' keys fill. */
static void print_material_lines(const scene *sc)
{
    const scene_material_line *l;
    char text[512];
    for (size_t k = 0; (l = scene_material_line_at(k)); k++)
        for (uint32_t i = 0; i < sc->num_materials; i++)
            if (l->text(&sc->materials[i], text, sizeof text)) {
                int w = INFO_KEY_WIDTH - (int)strlen(l->label) - 1;
                printf("%s %-*u \"%s\" %s\n", l->label, w > 1 ? w : 1, i, shown(sc->material_names[i]), text);
            }
}

/* The images' encodings (WebP: EXT_texture_webp, KTX2: KHR_texture_basisu), one count each. */
static void print_image_formats(const scene *sc)
{
    uint32_t count[TEXTURE_FORMAT_COUNT] = {0};
    for (uint32_t i = 0; i < sc->num_images; i++)
        count[sc->images[i].format < TEXTURE_FORMAT_COUNT ? sc->images[i].format : TEXTURE_FORMAT_UNKNOWN]++;
    if (!sc->num_images)
        return;
    printf("image formats ");
    for (int f = 0, n = 0; f < TEXTURE_FORMAT_COUNT; f++)
        if (count[f])
            printf("%s %u %s", n++ ? "," : "", count[f], texture_format_name((texture_format)f));
    printf("\n");
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

#define INFO_INTRO                                                                              \
    "Prints the scene's contents and its BVH statistics: the emissive triangles (the path\n"      \
    "tracer's area lights) and the materials that emit, the skins (and their joints) and the\n"  \
    "morph targets (and the meshes that have them), the load's time (and the part posing\n"      \
    "skinned and morphed meshes took), and one line per camera (index, name,\n"                  \
    "position, forward direction, vertical field of view or orthographic width x height;\n"      \
    "the first is the one gonio render uses by default), the KHR_materials_variants\n"           \
    "variants by index and name (for --variant), the images' formats (PNG, JPEG, WebP for\n"     \
    "EXT_texture_webp, KTX2 for KHR_texture_basisu), one line per extension the file lists:\n"   \
    "whether gonio supports it, partly (and what it leaves out) or not (and why); and for\n"     \
    "each of these extensions, one line per material that uses it (index, name, what gonio\n"   \
    "reads of it):\n"

/* INFO_INTRO and the lines of the loader's extensions (scene_material_line), listed as the
 * options are. */
static const char *info_intro(void)
{
    static char text[8192];
    const scene_material_line *l;
    FILE *f = fmemopen(text, sizeof text, "w");
    if (!f)
        return INFO_INTRO;
    fputs(INFO_INTRO, f);
    for (size_t k = 0; (l = scene_material_line_at(k)); k++)
        cli_help_item(f, l->label, l->help);
    fclose(f);
    return text;
}

int cmd_info(int argc, char **argv)
{
    bool outside = false, strict = false;
    const cli_option options[] = {CLI_OPT_ALLOW_OUTSIDE_FILES(&outside), CLI_OPT_STRICT(&strict)};
    const cli_command cmd = {
        .name = "info", .synopsis = "SCENE.gltf|.glb [--allow-outside-files] [--strict]",
        .intro = info_intro(),
        CLI_OPTIONS(options), .min_args = 1, .max_args = 1, .missing = "no scene given",
        .complete_args = "*.gltf *.glb"};
    cli_args args;
    scene sc = {0};
    render_geometry geo;
    int rc = cli_parse(&cmd, argc, argv, &args);
    if (rc >= 0)
        return rc;
    const char *path = args.arg[0];
    scene_allow_outside_files(outside);
    int since = cli_strict_begin(strict);
    double t0 = util_now();
    if (!scene_load(&sc, path))
        return 1;
    double load_seconds = util_now() - t0;
    if (!cli_strict_ok(since, path)) {
        scene_destroy(&sc);
        return 1;
    }
    if (!render_geometry_build(&geo, &sc)) {
        scene_destroy(&sc);
        return 1;
    }
    printf("scene          %s\n", shown(path));
    if (sc.num_instances) {
        uint64_t stored = sc.num_triangles, verts = sc.num_vertices;
        for (uint32_t m = 0; m < sc.num_instanced_meshes; m++) {
            stored += sc.instanced_meshes[m].num_triangles;
            verts += sc.instanced_meshes[m].num_vertices;
        }
        printf("triangles      %llu placed, %llu stored (%u in world space, the rest once per instanced mesh)\n",
               (unsigned long long)scene_placed_triangles(&sc), (unsigned long long)stored, sc.num_triangles);
        printf("vertices       %llu stored\n", (unsigned long long)verts);
        printf("instances      %u of %u mesh(es) (meshes several nodes use, or EXT_mesh_gpu_instancing places)\n",
               sc.num_instances, sc.num_instanced_meshes);
    } else {
        printf("triangles      %u\n", sc.num_triangles);
        printf("vertices       %u\n", sc.num_vertices);
    }
    printf("meshes         %u (primitive instances; %u glTF meshes, %u nodes)\n", sc.num_meshes,
           sc.num_gltf_meshes, sc.num_nodes);
    printf("skins          %u (%u joints), morph targets %u (in %u mesh(es))\n", sc.num_skins, sc.num_joints,
           sc.num_morph_targets, sc.num_morphed_meshes);
    printf("load           %.2f ms (posing skinned and morphed meshes %.2f ms)\n", load_seconds * 1e3,
           sc.pose_seconds * 1e3);
    printf("materials      %u\n", sc.num_materials);
    printf("variants       %u\n", sc.num_variants);
    for (uint32_t i = 0; i < sc.num_variants; i++)
        printf("variant %-6u \"%s\"\n", i, shown(sc.variant_names[i]));
    print_extensions(&sc);
    printf("textures       %u (%u images)\n", sc.num_textures, sc.num_images);
    print_image_formats(&sc);
    printf("lights         %u\n", sc.num_lights);
    if (sc.environment.num_channels)
        printf("environment    %s (a %dx%d lat-long map)\n", shown(sc.environment_what), sc.environment.width,
               sc.environment.height);
    print_emitters(&sc);
    print_material_lines(&sc);
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
    render_geometry_bytes mem = render_geometry_size(&geo);
    if (geo.two_levels) {
        /* two levels (src/render/render_geometry.h): a tree per mesh, one over the instances */
        uint32_t tris = 0, pairs = 0, leaf = 0, depth = 0;
        double sah = 0;
        for (uint32_t m = 0; m < geo.num_meshes; m++) {
            const bvh *b = &geo.meshes[m];
            tris += b->num_tris;
            pairs += b->num_pairs;
            leaf = b->max_leaf_size > leaf ? b->max_leaf_size : leaf;
            depth = b->depth > depth ? b->depth : depth;
            sah = b->sah_cost > sah ? b->sah_cost : sah;
        }
        printf("bvh trees      %u mesh tree(s)%s and a top tree over %u instances\n", geo.num_meshes,
               geo.first_instance ? " (the first: the triangles in world space)" : "", geo.top.num_instances);
        printf("bvh nodes      %u (%zu bytes each; the top tree's %u)\n", geo.num_nodes, sizeof(GnBvhNode),
               geo.top.tree.num_nodes);
        printf("bvh leaf prims %u (%u triangle pairs sharing an edge, %u single triangles)\n", pairs,
               tris - pairs, 2 * pairs - tris);
        printf("bvh depth      %u (stack entries of a walk: the top tree's %u levels, one to enter a mesh, "
               "the deepest mesh tree's %u)\n", geo.depth, geo.top.tree.depth, depth);
        printf("bvh max leaf   %u triangle pairs\n", leaf);
        printf("bvh sah cost   %.2f (the top tree's; the costliest mesh tree's %.2f)\n", geo.top.tree.sah_cost, sah);
        printf("bvh build      %.2f ms (%.2f M triangles/s; the top tree %.3f ms)\n", geo.build_seconds * 1e3,
               geo.build_seconds > 0 ? tris / geo.build_seconds * 1e-6 : 0.0, geo.top_seconds * 1e3);
    } else {
        const bvh *b = &geo.world;
        printf("bvh nodes      %u (%zu bytes each)\n", b->num_nodes, sizeof(GnBvhNode));
        printf("bvh leaf prims %u (%u triangle pairs sharing an edge, %u single triangles)\n",
               b->num_pairs, b->num_tris - b->num_pairs, 2 * b->num_pairs - b->num_tris);
        printf("bvh depth      %u\n", b->depth);
        printf("bvh max leaf   %u triangle pairs\n", b->max_leaf_size);
        printf("bvh sah cost   %.2f\n", b->sah_cost);
        printf("bvh build      %.2f ms (%.2f M triangles/s)\n", b->build_seconds * 1e3,
               b->build_seconds > 0 ? sc.num_triangles / b->build_seconds * 1e-6 : 0.0);
    }
    printf("scene memory   %.3f MB (BVH nodes %.3f, triangle pairs %.3f, shading %.3f, vertices %.3f, instances "
           "%.3f)\n", (mem.nodes + mem.pairs + mem.prims + mem.vertices + mem.instances) * 1e-6, mem.nodes * 1e-6,
           mem.pairs * 1e-6, mem.prims * 1e-6, mem.vertices * 1e-6, mem.instances * 1e-6);
    render_geometry_destroy(&geo);
    scene_destroy(&sc);
    return 0;
}
