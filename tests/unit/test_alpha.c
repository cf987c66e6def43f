/* test_alpha.c: alphaMode MASK and BLEND on scenes with known answers, written here. A quad
 * of base colour alpha a in front of an emitter of radiance 1 (camera rays), or between a
 * directional light and a Lambertian floor (shadow rays), that reflects nothing itself
 * (black, KHR_materials_specular 0): opaque, it reads 0; MASKed out (alpha < cutoff) it lets
 * everything through; MASK with alpha >= cutoff is opaque; BLEND passes 1 - a of the light.
 * Two BLEND quads pass (1 - a)^2: a shadow ray that took any hit and went on past it could
 * skip the nearer one. Each BLEND sample is a Bernoulli trial of probability p (the passing
 * fraction), so the image mean over P pixels of N samples has standard error
 * sqrt(p (1 - p) / (N P)) (times the unblocked value): with a = 0.3, N = 64 and P = 32 x 32
 * that is 0.0018 for one quad, 0.0020 for two, and the tests allow 5 of them. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "gltf_write.h"
#include "gpu.h"
#include "image.h"
#include "render.h"
#include "scene.h"
#include "test.h"

enum { SIZE = 32, SPP = 64 };
#define ALPHA 0.3

typedef struct alpha_case {
    const char *name, *mode; /* mode: NULL (opaque), "MASK" or "BLEND" */
    float alpha, cutoff;
    double pass;             /* the fraction of the light that gets through */
    int layers;              /* quads one behind the other */
} alpha_case;

static const alpha_case cases[] = {
    {"opaque", NULL, ALPHA, 0, 0, 1},
    {"mask-cut", "MASK", ALPHA, 0.5f, 1, 1},
    {"mask-kept", "MASK", 0.7f, 0.5f, 0, 1},
    {"blend", "BLEND", ALPHA, 0, 1 - ALPHA, 1},
    {"blend-twice", "BLEND", ALPHA, 0, (1 - ALPHA) * (1 - ALPHA), 2},
};
#define NUM_CASES (sizeof cases / sizeof *cases)

/* A square in the plane axis = at (0: z, 1: y) of half size h, facing +axis. */
static void square(float *pos, float *nrm, int axis, float at, float h)
{
    const float c[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int i = 0; i < 4; i++) {
        float *p = &pos[3 * i], *n = &nrm[3 * i];
        if (axis == 0) /* x, y in the plane z = at, counter-clockwise from +z */
            p[0] = h * c[i][0], p[1] = h * c[i][1], p[2] = at, n[0] = 0, n[1] = 0, n[2] = 1;
        else /* x, -z in the plane y = at, counter-clockwise from +y */
            p[0] = h * c[i][0], p[1] = at, p[2] = -h * c[i][1], n[0] = 0, n[1] = 1, n[2] = 0;
    }
}

/* shadow = false: emitter at z = -1, the quad at z = 0 (the second at 0.5), camera at z = 3 looking down -Z.
 * shadow = true: floor at y = 0, the quad at y = 1.5 (the second at 1), a directional light of irradiance pi
 * shining down -Y, camera at y = 0.5 looking down at the floor (the quad above it unseen). */
static void write_scene(const char *path, bool shadow, const alpha_case *k)
{
    static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    float pos[3][12], nrm[3][12];
    const float rot_down[4] = {-0.70710678f, 0, 0, 0.70710678f}; /* -Z -> -Y */
    gltf_write_material mats[2] = {
        {.name = "back", .base_color = {1, 1, 1, 1}, .roughness = 1, .has_specular = true},
        {.name = "quad", .base_color = {0, 0, 0, k->alpha}, .roughness = 1, .has_specular = true,
         .alpha_mode = k->mode, .alpha_cutoff = k->cutoff},
    };
    if (shadow) {
        mats[0].base_color[0] = mats[0].base_color[1] = mats[0].base_color[2] = 0.8f;
    } else {
        mats[0].emissive[0] = mats[0].emissive[1] = mats[0].emissive[2] = 1;
    }
    square(pos[0], nrm[0], shadow, shadow ? 0 : -1, 5);
    /* (the farther quad from the floor first: a walk that takes any hit meets it first) */
    square(pos[1], nrm[1], shadow, shadow ? 1.5f : 0, 3);
    square(pos[2], nrm[2], shadow, shadow ? 1 : 0.5f, 3);
    gltf_write_mesh meshes[3] = {
        {.num_vertices = 4, .positions = pos[0], .normals = nrm[0], .num_indices = 6, .indices = idx, .material = 0},
        {.num_vertices = 4, .positions = pos[1], .normals = nrm[1], .num_indices = 6, .indices = idx, .material = 1},
        {.num_vertices = 4, .positions = pos[2], .normals = nrm[2], .num_indices = 6, .indices = idx, .material = 1},
    };
    gltf_write_camera cam = {.yfov = 0.5f, .aspect = 1};
    gltf_write_light sun = {.type = GLTF_WRITE_DIRECTIONAL, .intensity = (float)M_PI};
    gltf_write_node nodes[5] = {{.kind = GLTF_WRITE_NODE_CAMERA, .translation = {0, 0, 3}},
                                {.kind = GLTF_WRITE_NODE_MESH, .index = 0},
                                {.kind = GLTF_WRITE_NODE_MESH, .index = 1},
                                {.kind = GLTF_WRITE_NODE_MESH, .index = 2}};
    uint32_t n = 2 + (uint32_t)k->layers;
    if (shadow) {
        nodes[0].translation[2] = 0, nodes[0].translation[1] = 0.5f;
        memcpy(nodes[0].rotation, rot_down, sizeof rot_down);
        nodes[n++] = (gltf_write_node){.kind = GLTF_WRITE_NODE_LIGHT, .rotation = {-0.70710678f, 0, 0, 0.70710678f}};
    }
    gltf_write_desc d = {.meshes = meshes, .num_meshes = 3, .materials = mats, .num_materials = 2,
                         .cameras = &cam, .num_cameras = 1, .lights = &sun, .num_lights = shadow ? 1 : 0,
                         .nodes = nodes, .num_nodes = n};
    CHECK(gltf_write_file(path, &d));
}

/* The mean of channel 0 over the image (every pixel sees the back surface or the floor). */
static bool render_mean(gpu *g, const char *path, uint32_t mode, double *mean)
{
    scene sc = {0};
    renderer r = {0};
    render_stats st;
    image img = {0};
    render_settings s = {.mode = mode, .width = SIZE, .height = SIZE, .spp = SPP, .camera = 0, .seed = 7,
                         .ambient_set = true};
    bool ok = scene_load(&sc, path);
    if (ok) {
        renderer_create(&r, g, &sc);
        ok = renderer_render(&r, &s, &img, &st);
        CHECKF(st.truncated == 0, "%u rays ran out of BVH budget", st.truncated);
        renderer_destroy(&r);
    }
    scene_destroy(&sc);
    CHECKF(ok, "rendering %s failed", path);
    double sum = 0;
    for (int p = 0; ok && p < SIZE * SIZE; p++) {
        sum += img.planes[0][p];
        CHECKF(img.planes[3][p] == 1.0f, "pixel %d not covered", p);
    }
    *mean = sum / (SIZE * SIZE);
    image_destroy(&img);
    return ok;
}

/* Checks mean = pass * full within 5 standard errors of the BLEND estimate (exact otherwise,
 * up to float rounding). */
static void check_pass(const char *what, const alpha_case *k, double mean, double full)
{
    double se = full * sqrt(k->pass * (1 - k->pass) / ((double)SPP * SIZE * SIZE));
    double tol = k->pass > 0 && k->pass < 1 ? 5 * se : 1e-4 * (full > 1 ? full : 1);
    CHECKF(fabs(mean - k->pass * full) <= tol, "%s, %s: mean %.5f, expected %.5f +- %.5f", what, k->name, mean,
           k->pass * full, tol);
}

static void run(bool shadow)
{
    char path[256];
    gpu g = {0};
    double unshadowed_phong = -1;
    if (!test_open_gpu(&g))
        return;
    snprintf(path, sizeof path, "/tmp/gonio-test-alpha-%d.gltf", (int)getpid());
    /* mask-cut first: in the local shadow test its render is the unshadowed reference */
    static const int order[NUM_CASES] = {1, 0, 2, 3, 4};
    for (size_t i = 0; i < NUM_CASES; i++) {
        const alpha_case *k = &cases[order[i]];
        double m;
        write_scene(path, shadow, k);
        /* path tracing: the emitter's radiance 1, or the floor's 0.8 (albedo 0.8 / pi x pi) */
        if (render_mean(&g, path, GN_MODE_PATH, &m))
            check_pass(shadow ? "path, shadow rays" : "path, camera rays", k, m, shadow ? 0.8 : 1.0);
        if (!shadow && render_mean(&g, path, GN_MODE_ALBEDO, &m)) /* the back's albedo 1, the quad's 0 */
            check_pass("albedo (local), camera rays", k, m, 1.0);
        if (shadow && render_mean(&g, path, GN_MODE_PHONG, &m)) {
            if (order[i] == 1) {
                unshadowed_phong = m;
                CHECKF(m > 0.1, "the unshadowed Phong floor reads %g", m);
            }
            check_pass("phong (local), shadow rays", k, m, unshadowed_phong);
        }
    }
    unlink(path);
    gpu_destroy(&g);
}

TEST(alpha, camera_rays) { run(false); }
TEST(alpha, shadow_rays) { run(true); }
