/* cmd_scene.c: `gonio scene cornell|teapot` and `gonio teapot`: the project's own scenes as
 * glTF. The Cornell box follows the Cornell Program of Computer Graphics' published
 * measurements (graphics.cornell.edu/online/box/data.html); the teapot scene is the
 * classic OpenGL 1.x example (red diffuse, white specular, shininess 128, light from
 * (1,1,1)). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "cli.h"
#include "gltf_write.h"
#include "scene.h"
#include "teapot.h"
#include "util.h"
#include "vec.h"

#define SCENE_TEAPOT_LEVEL 8
#define SCENE_TEAPOT_MAX_LEVEL 256 /* 4.2 M triangles: far past any use */

/* Rotation of a node whose -Z (view or light direction) is turned to the direction
 * (-cos(pitch) sin(yaw), -sin(pitch), -cos(pitch) cos(yaw)): q = q_y(yaw) q_x(-pitch). */
static void yaw_pitch_quat(double yaw, double pitch, float q[4])
{
    double sy = sin(yaw / 2), cy = cos(yaw / 2), sx = sin(-pitch / 2), cx = cos(-pitch / 2);
    q[0] = (float)(cy * sx);
    q[1] = (float)(cx * sy);
    q[2] = (float)(-sy * sx);
    q[3] = (float)(cy * cx);
}

/* ---- Cornell box -------------------------------------------------------------------------
 * Quads in the published frame (millimetres, right-handed, Y up, the camera at
 * (278, 273, -800) looking along +z, so +x is on its LEFT). A rotation by 180 degrees about
 * Y (x -> 278 - x, z -> -z, then metres) turns the camera to look down glTF's -Z from
 * (0, 0.273, 0.8) with the red wall (x ~ 556) on its left at x' = -0.278, as in the
 * photographs. A rotation keeps the scene's handedness; a mirror of z alone would swap the
 * walls. */
typedef float cornell_quad[4][3];

static const cornell_quad cornell_floor[] = {
    {{552.8f, 0, 0}, {0, 0, 0}, {0, 0, 559.2f}, {549.6f, 0, 559.2f}}};
static const cornell_quad cornell_ceiling[] = {
    {{556, 548.8f, 0}, {556, 548.8f, 559.2f}, {0, 548.8f, 559.2f}, {0, 548.8f, 0}}};
static const cornell_quad cornell_back[] = {
    {{549.6f, 0, 559.2f}, {0, 0, 559.2f}, {0, 548.8f, 559.2f}, {556, 548.8f, 559.2f}}};
static const cornell_quad cornell_red[] = {
    {{552.8f, 0, 0}, {549.6f, 0, 559.2f}, {556, 548.8f, 559.2f}, {556, 548.8f, 0}}};
static const cornell_quad cornell_green[] = {
    {{0, 0, 559.2f}, {0, 0, 0}, {0, 548.8f, 0}, {0, 548.8f, 559.2f}}};
/* The published light is at the ceiling's height (548.8); 0.1 mm lower keeps the two
 * surfaces apart, as pbrt's and Mitsuba's versions do. */
static const cornell_quad cornell_light[] = {
    {{343, 548.7f, 227}, {343, 548.7f, 332}, {213, 548.7f, 332}, {213, 548.7f, 227}}};
static const cornell_quad cornell_short[] = {
    {{130, 165, 65}, {82, 165, 225}, {240, 165, 272}, {290, 165, 114}},
    {{290, 0, 114}, {290, 165, 114}, {240, 165, 272}, {240, 0, 272}},
    {{130, 0, 65}, {130, 165, 65}, {290, 165, 114}, {290, 0, 114}},
    {{82, 0, 225}, {82, 165, 225}, {130, 165, 65}, {130, 0, 65}},
    {{240, 0, 272}, {240, 165, 272}, {82, 165, 225}, {82, 0, 225}}};
static const cornell_quad cornell_tall[] = {
    {{423, 330, 247}, {265, 330, 296}, {314, 330, 456}, {472, 330, 406}},
    {{423, 0, 247}, {423, 330, 247}, {472, 330, 406}, {472, 0, 406}},
    {{472, 0, 406}, {472, 330, 406}, {314, 330, 456}, {314, 0, 456}},
    {{314, 0, 456}, {314, 330, 456}, {265, 330, 296}, {265, 0, 296}},
    {{265, 0, 296}, {265, 330, 296}, {423, 330, 247}, {423, 0, 247}}};

enum { CORNELL_WHITE, CORNELL_RED, CORNELL_GREEN, CORNELL_LIGHT, CORNELL_MATERIALS };
#define CORNELL_MAX_QUADS 5

typedef struct cornell_part {
    const char *name;
    const cornell_quad *quads;
    int num_quads;
    uint32_t material;
    bool outward; /* block faces face out of the block; walls and light into the box */
} cornell_part;

typedef struct cornell_mesh {
    float positions[CORNELL_MAX_QUADS * 4 * 3], normals[CORNELL_MAX_QUADS * 4 * 3];
    uint32_t indices[CORNELL_MAX_QUADS * 6];
} cornell_mesh;

static void cornell_to_gltf(const float p[3], float out[3])
{
    out[0] = (278.0f - p[0]) * 0.001f;
    out[1] = p[1] * 0.001f;
    out[2] = 0.0f - p[2] * 0.001f; /* 0 - x: no "-0" in the file */
}

/* Flat-shaded quads, two triangles each, wound counter-clockwise about the side they face:
 * into the box (towards its centre) or out of a block (away from the block's centre). */
static void cornell_build(const cornell_part *part, cornell_mesh *m)
{
    static const float box_centre[3] = {278, 274.4f, 279.6f};
    static const uint32_t corners[6] = {0, 1, 2, 0, 2, 3};
    float centre[3] = {0, 0, 0};
    const float *ref = box_centre;
    if (part->outward) { /* the top quad is first: its middle, at half the block's height */
        for (int c = 0; c < 4; c++)
            for (int k = 0; k < 3; k++)
                centre[k] += part->quads[0][c][k] / 4;
        centre[1] /= 2;
        ref = centre;
    }
    for (int q = 0; q < part->num_quads; q++) {
        float p[4][3], d0[3], d1[3], n[3], to_ref[3], ref_g[3], len;
        bool flip;
        for (int c = 0; c < 4; c++)
            cornell_to_gltf(part->quads[q][c], p[c]);
        cornell_to_gltf(ref, ref_g);
        vec_sub(p[2], p[0], d0);
        vec_sub(p[3], p[1], d1);
        vec_cross(d0, d1, n); /* the quad's normal for its vertex order (diagonals' cross) */
        vec_sub(ref_g, p[0], to_ref);
        flip = (n[0] * to_ref[0] + n[1] * to_ref[1] + n[2] * to_ref[2] > 0) == part->outward;
        len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) * (flip ? -1.0f : 1.0f);
        for (int c = 0; c < 4; c++) {
            int src = flip ? (4 - c) % 4 : c;
            for (int k = 0; k < 3; k++) {
                m->positions[(4 * q + c) * 3 + k] = p[src][k];
                m->normals[(4 * q + c) * 3 + k] = n[k] / len;
            }
        }
        for (int t = 0; t < 6; t++)
            m->indices[6 * q + t] = 4 * (uint32_t)q + corners[t];
    }
}

static bool write_cornell(const char *path)
{
    static const cornell_part parts[] = {
        {"floor", cornell_floor, 1, CORNELL_WHITE, false},
        {"ceiling", cornell_ceiling, 1, CORNELL_WHITE, false},
        {"back_wall", cornell_back, 1, CORNELL_WHITE, false},
        {"left_wall_red", cornell_red, 1, CORNELL_RED, false},
        {"right_wall_green", cornell_green, 1, CORNELL_GREEN, false},
        {"short_block", cornell_short, 5, CORNELL_WHITE, true},
        {"tall_block", cornell_tall, 5, CORNELL_WHITE, true},
        {"light", cornell_light, 1, CORNELL_LIGHT, false},
    };
    enum { NUM_PARTS = sizeof parts / sizeof *parts };
    /* Reflectances and the light's radiance (17, 12, 4): RGB fits of the measured spectra
     * as in Benedikt Bitterli's Rendering Resources (Mitsuba/pbrt/Tungsten "cornell-box"),
     * all Lambertian: specularFactor 0 removes the glTF dielectric's specular layer. The
     * emissive factor must lie in [0, 1], so the strength carries the 17. */
#define CORNELL_LAMBERT(nm, r, g, b) \
    {.name = nm, .base_color = {r, g, b, 1}, .roughness = 1, .has_specular = true, \
     .specular_color = {1, 1, 1}}
    gltf_write_material materials[CORNELL_MATERIALS] = {
        [CORNELL_WHITE] = CORNELL_LAMBERT("white", 0.725f, 0.71f, 0.68f),
        [CORNELL_RED] = CORNELL_LAMBERT("red", 0.63f, 0.065f, 0.05f),
        [CORNELL_GREEN] = CORNELL_LAMBERT("green", 0.14f, 0.45f, 0.091f),
        [CORNELL_LIGHT] = CORNELL_LAMBERT("light", 0.78f, 0.78f, 0.78f),
    };
#undef CORNELL_LAMBERT
    cornell_mesh built[NUM_PARTS];
    gltf_write_mesh meshes[NUM_PARTS];
    gltf_write_node nodes[NUM_PARTS + 1];
    /* The published camera: 35 mm focal length, 25 x 25 mm film. */
    gltf_write_camera camera = {
        .name = "camera", .yfov = (float)(2 * atan(12.5 / 35.0)), .aspect = 1, .znear = 0.01f};
    gltf_write_desc desc = {.meshes = meshes, .num_meshes = NUM_PARTS,
                            .materials = materials, .num_materials = CORNELL_MATERIALS,
                            .cameras = &camera, .num_cameras = 1,
                            .nodes = nodes, .num_nodes = NUM_PARTS + 1};
    materials[CORNELL_LIGHT].emissive[0] = 1;
    materials[CORNELL_LIGHT].emissive[1] = 12.0f / 17.0f;
    materials[CORNELL_LIGHT].emissive[2] = 4.0f / 17.0f;
    materials[CORNELL_LIGHT].emissive_strength = 17;
    for (int i = 0; i < NUM_PARTS; i++) {
        cornell_build(&parts[i], &built[i]);
        meshes[i] = (gltf_write_mesh){.name = parts[i].name,
                                      .num_vertices = 4 * (uint32_t)parts[i].num_quads,
                                      .positions = built[i].positions,
                                      .normals = built[i].normals,
                                      .num_indices = 6 * (uint32_t)parts[i].num_quads,
                                      .indices = built[i].indices,
                                      .material = parts[i].material};
        nodes[i] = (gltf_write_node){.name = parts[i].name, .index = (uint32_t)i};
    }
    nodes[NUM_PARTS] = (gltf_write_node){.name = "camera", .kind = GLTF_WRITE_NODE_CAMERA,
                                         .translation = {0, 0.273f, 0.8f}};
    return gltf_write_file(path, &desc);
}

/* ---- the OpenGL 1.x teapot ---------------------------------------------------------------
 * glMaterial: diffuse (1,0,0), specular (1,1,1), shininess 128 (and OpenGL's default ambient
 * 0.2), kept verbatim in extras for the Phong modes. For the path tracer, the roughness
 * whose Phong-equivalent exponent 2/alpha^2 - 2 (Walter et al. 2007) is 128, alpha =
 * roughness^2. The light: glLightfv(GL_POSITION, {1,1,1,0}), a directional light from
 * (1,1,1), i.e. shining along -(1,1,1)/sqrt(3): yaw 45 degrees, pitch asin(1/sqrt(3)). */
/* --instances N: the teapot placed N times by EXT_mesh_gpu_instancing, a square grid 4 units
 * apart, each turned about +Y and scaled 0.8 to 1.2 (a golden-ratio sequence), seen from above
 * one corner; the camera node is replaced. (gonio bench's scene of instances.) */
static void teapot_grid(int n, gltf_write_node *teapot, gltf_write_node *camera, float **buf)
{
    int side = (int)ceil(sqrt((double)n));
    float *t = *buf = util_malloc(10 * sizeof *t * (size_t)n), *q = t + 3 * (size_t)n, *sc = q + 4 * (size_t)n;
    for (int i = 0; i < n; i++) {
        double a = fmod(i * 0.6180339887, 1.0), angle = 2 * M_PI * a, scale = 0.8 + 0.4 * fmod(i * 0.7548776662, 1.0);
        t[3 * i] = (float)(4.0 * (i % side - 0.5 * (side - 1)));
        t[3 * i + 1] = 0;
        t[3 * i + 2] = (float)(4.0 * (i / side - 0.5 * (side - 1)));
        q[4 * i] = 0, q[4 * i + 1] = (float)sin(angle / 2), q[4 * i + 2] = 0, q[4 * i + 3] = (float)cos(angle / 2);
        sc[3 * i] = sc[3 * i + 1] = sc[3 * i + 2] = (float)scale;
    }
    teapot->num_instances = (uint32_t)n;
    teapot->instance_translation = t;
    teapot->instance_rotation = q;
    teapot->instance_scale = sc;
    const double yaw = 30 * M_PI / 180, pitch = 25 * M_PI / 180, dist = 0.35 * 4.0 * side + 6;
    camera->translation[0] = (float)(dist * cos(pitch) * sin(yaw));
    camera->translation[1] = (float)(dist * sin(pitch));
    camera->translation[2] = (float)(dist * cos(pitch) * cos(yaw));
    yaw_pitch_quat(yaw, pitch, camera->rotation);
}

static bool write_teapot(const char *path, int level, int instances)
{
    teapot_mesh t;
    bool ok;
    gltf_write_mesh mesh;
    gltf_write_material material = {
        .name = "red_plastic", .base_color = {1, 0, 0, 1}, .metallic = 0,
        .roughness = powf(2.0f / 130.0f, 0.25f),
        .double_sided = true, /* the mesh is open (teapot.h): the spout's inside is seen */
        .extras = "{\"gonio\":{\"phong\":{\"diffuse\":[1,0,0],\"specular\":[1,1,1],"
                  "\"shininess\":128,\"ambient\":[0.2,0.2,0.2]}}}"};
    gltf_write_light light = {.name = "sun", .type = GLTF_WRITE_DIRECTIONAL, .intensity = 1};
    /* Front-right and a little above; the target centres the teapot in the frame. */
    const double yaw = 30 * M_PI / 180, pitch = 20 * M_PI / 180, dist = 3.4;
    const float target[3] = {0.19f, 0.45f, -0.07f};
    gltf_write_camera camera = {.name = "camera", .yfov = (float)(30 * M_PI / 180),
                                .aspect = 4.0f / 3.0f, .znear = 0.05f};
    gltf_write_node nodes[3] = {
        {.name = "teapot", .kind = GLTF_WRITE_NODE_MESH},
        {.name = "sun", .kind = GLTF_WRITE_NODE_LIGHT},
        {.name = "camera", .kind = GLTF_WRITE_NODE_CAMERA,
         .translation = {target[0] + (float)(dist * cos(pitch) * sin(yaw)),
                         target[1] + (float)(dist * sin(pitch)),
                         target[2] + (float)(dist * cos(pitch) * cos(yaw))}}};
    gltf_write_desc desc = {.meshes = &mesh, .num_meshes = 1, .materials = &material,
                            .num_materials = 1, .cameras = &camera, .num_cameras = 1,
                            .lights = &light, .num_lights = 1, .nodes = nodes, .num_nodes = 3};
    yaw_pitch_quat(M_PI / 4, asin(1 / sqrt(3.0)), nodes[1].rotation);
    yaw_pitch_quat(yaw, pitch, nodes[2].rotation);
    float *grid = NULL;
    if (instances > 0)
        teapot_grid(instances, &nodes[0], &nodes[2], &grid);
    teapot_tessellate(&t, level);
    mesh = (gltf_write_mesh){.name = "teapot", .num_vertices = t.num_vertices,
                             .positions = t.positions, .normals = t.normals,
                             .num_indices = 3 * t.num_triangles, .indices = t.indices};
    ok = gltf_write_file(path, &desc);
    teapot_destroy(&t);
    free(grid);
    return ok;
}

/* gonio scene NAME and gonio teapot: one option table; `teapot` is the second's name. */
static int run(int argc, char **argv, bool teapot_command)
{
    const char *out = NULL;
    int level = SCENE_TEAPOT_LEVEL, instances = 0;
    const cli_option options[] = {
        {NULL, NULL, "  cornell             the Cornell box (published measurements, metres, one area light)\n"
                     "  teapot              the Utah teapot as in the classic OpenGL 1.x example\n",
         CLI_TEXT, NULL, 0, 0, NULL, NULL, NULL},
        {"-o, --output", "FILE", "the file to write, in the format its name says: .gltf JSON with\n"
                                 "the buffer embedded, .glb binary glTF (any other name is a usage error)",
         CLI_STRING, CLI_AS(const char *, &out), 0, 0, NULL, NULL, "*.gltf *.glb"},
        {"--level", "N", "teapot: N x N grid cells per Bezier patch, 1..256 (default 8);\n"
                         "64 N^2 - 8 N triangles",
         CLI_INT, CLI_AS(int, &level), 1, SCENE_TEAPOT_MAX_LEVEL, "an integer 1..256", NULL, NULL},
        {"--instances", "N", "teapot: N teapots on a square grid, placed by EXT_mesh_gpu_instancing\n"
                             "(one mesh, N transforms), seen from above a corner",
         CLI_INT, CLI_AS(int, &instances), 1, 1 << 20, "an integer 1..1048576", NULL, NULL},
    };
    const cli_command cmd = {
        .name = teapot_command ? "teapot" : "scene",
        .synopsis = teapot_command ? "[--level N] [--instances N] -o FILE.gltf|FILE.glb"
                                   : "cornell -o FILE.gltf|FILE.glb\n"
                                     "       gonio scene teapot [--level N] [--instances N] -o FILE.gltf|FILE.glb",
        .intro = "Writes one of gonio's own scenes as a self-contained glTF 2.0 file.\n",
        /* gonio teapot has no scene names to list */
        .options = options + teapot_command, .num_options = (int)(sizeof options / sizeof *options) - teapot_command,
        .min_args = teapot_command ? 0 : 1, .max_args = teapot_command ? 0 : 1,
        .missing = "which scene? (cornell or teapot)", .complete_args = teapot_command ? NULL : "cornell teapot"};
    cli_args args;
    int rc = cli_parse(&cmd, argc, argv, &args);
    if (rc >= 0)
        return rc;
    const char *name = teapot_command ? "teapot" : args.arg[0];
    bool teapot = !strcmp(name, "teapot");
    if (!teapot && strcmp(name, "cornell"))
        return cli_usage_error(cmd.name, "unknown scene '%s' (cornell or teapot)", name);
    if (!teapot && cli_given(&cmd, &args, "--level"))
        return cli_usage_error(cmd.name, "--level is for the teapot");
    if (!teapot && cli_given(&cmd, &args, "--instances"))
        return cli_usage_error(cmd.name, "--instances is for the teapot");
    if (!out)
        return cli_usage_error(cmd.name, "missing -o FILE.gltf");
    {
        const char *dot = strrchr(out, '.');
        if (!dot || (strcasecmp(dot, ".gltf") && strcasecmp(dot, ".glb")))
            return cli_usage_error(cmd.name, "-o '%s': expected a .gltf (JSON) or .glb (binary glTF) name", out);
    }
    if (!util_check_output(out))
        return 1;
    return (teapot ? write_teapot(out, level, instances) : write_cornell(out)) ? 0 : 1;
}

int cmd_scene(int argc, char **argv) { return run(argc, argv, false); }

int cmd_teapot(int argc, char **argv) { return run(argc, argv, true); }

bool cli_load_builtin_scene(scene *out, const char *name)
{
    const char *base = getenv("TMPDIR");
    char dir[4096], path[4200];
    bool ok;
    snprintf(dir, sizeof dir, "%s/gonio-XXXXXX", base && *base ? base : "/tmp");
    if (!mkdtemp(dir)) {
        util_error("%s: cannot create a temporary directory: %s", dir, strerror(errno));
        return false;
    }
    snprintf(path, sizeof path, "%s/%s.gltf", dir, name);
    ok = (!strcmp(name, "teapot") ? write_teapot(path, SCENE_TEAPOT_LEVEL, 0) : write_cornell(path)) &&
         scene_load(out, path);
    unlink(path);
    rmdir(dir);
    if (ok) /* messages name the scene, not a file that is gone */
        snprintf(out->path, sizeof out->path, "%s (built in)", name);
    return ok;
}
