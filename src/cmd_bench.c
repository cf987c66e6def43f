/* cmd_bench.c: `gonio bench`: BVH build rate, primary and diffuse-bounce ray throughput
 * of the GLSL traversal, and the time from start to the first finished pixel. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stdint.h>

#include "bench.h" /* spv_bench: glsl/bench.comp compiled by the build */
#include "cli.h"
#include "meshgen.h"
#include "render.h"
#include "scene.h"
#include "scene_mesh.h"
#include "util.h"

static const char bench_usage[] =
    "usage: gonio bench [SCENE.gltf | --generate N] [options]\n"
    "\n"
    "Prints the BVH build time (best of 3), the time from start to the first finished\n"
    "pixel (load, build, upload, shader compile, one pass), and the throughput of\n"
    "primary (camera) rays and diffuse bounce rays (cosine-distributed from the primary\n"
    "hits) through the GPU traversal. Default scene: scenes/cornell.gltf.\n"
    "\n"
    "  --generate N     a procedural mesh of about N triangles instead of a scene\n"
    "  --size WxH       rays per pass (default 512x512)\n"
    "  --seconds S      measure each rate for about S seconds (default 3)\n"
    "  --device N       Vulkan device index\n"
    "  --validate       enable the Vulkan validation layer\n";

static bool build_scene(scene *sc, const char *path, long generate)
{
    meshgen_mesh m;
    if (!generate)
        return scene_load(sc, path);
    m = meshgen_bench_mesh((uint32_t)generate);
    scene_from_mesh(sc, "generated", m.num_vertices, m.positions, m.normals, m.num_triangles,
                    m.indices);
    meshgen_destroy(&m);
    /* A three-quarter view from above, so nearly every camera ray meets the spheres or the
     * ground, as in a real image (the framing camera sees the ground edge-on). */
    {
        scene_camera *c = sc->cameras = util_calloc(1, sizeof *sc->cameras);
        float ctr[3], ext = 0, f[3], len = 0, r[3], u[3];
        for (int k = 0; k < 3; k++) {
            ctr[k] = 0.5f * (sc->bounds_min[k] + sc->bounds_max[k]);
            ext = fmaxf(ext, sc->bounds_max[k] - sc->bounds_min[k]);
        }
        c->position[0] = ctr[0];
        c->position[1] = ctr[1] + 0.45f * ext;
        c->position[2] = ctr[2] + 0.45f * ext;
        for (int k = 0; k < 3; k++) {
            f[k] = ctr[k] - c->position[k];
            len += f[k] * f[k];
        }
        for (int k = 0; k < 3; k++)
            c->forward[k] = f[k] / sqrtf(len);
        r[0] = -c->forward[2], r[1] = 0, r[2] = c->forward[0]; /* forward x (0,1,0) */
        len = sqrtf(r[0] * r[0] + r[2] * r[2]);
        for (int k = 0; k < 3; k++)
            c->right[k] = r[k] / len;
        u[0] = c->right[1] * c->forward[2] - c->right[2] * c->forward[1];
        u[1] = c->right[2] * c->forward[0] - c->right[0] * c->forward[2];
        u[2] = c->right[0] * c->forward[1] - c->right[1] * c->forward[0];
        memcpy(c->up, u, sizeof u);
        c->yfov = 0.8f;
        c->znear = 1e-3f * ext;
        snprintf(c->name, sizeof c->name, "bench");
        sc->num_cameras = 1;
    }
    return true;
}

int cmd_bench(int argc, char **argv)
{
    const double t_start = util_now();
    const char *path = "scenes/cornell.gltf";
    long generate = 0, v;
    float seconds = 3;
    int device = -1, w = 512, h = 512;
    bool validate = false;
    scene sc = {0};
    gpu g = {0};
    renderer r = {0};
    gpu_pipeline pipes[2] = {{0}};
    render_settings s = {.mode = GN_MODE_PHONG, .camera = -1};
    GnFrame frame;
    double best_build = 1e30, t_first = 0, t_primary = 0, t_diffuse = 0;
    uint64_t n_primary = 0, n_diffuse = 0;
    int passes = 0;

    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *val;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(bench_usage, stdout);
            return 0;
        } else if (!strcmp(a, "--validate")) {
            validate = true;
        } else if (a[0] == '-' && a[1]) {
            if (!(val = cli_value(argc, argv, &i)))
                return 2;
            if (!strcmp(a, "--generate")) {
                if (!util_parse_int(val, 1, 50000000, &generate))
                    return cli_usage_error("bench", "--generate '%s': expected a triangle count", val);
            } else if (!strcmp(a, "--size")) {
                if (!util_parse_size(val, &w, &h))
                    return cli_usage_error("bench", "--size '%s': expected WxH", val);
            } else if (!strcmp(a, "--seconds")) {
                if (!util_parse_float(val, &seconds) || seconds <= 0)
                    return cli_usage_error("bench", "--seconds '%s': expected a number > 0", val);
            } else if (!strcmp(a, "--device")) {
                if (!util_parse_int(val, 0, 64, &v))
                    return cli_usage_error("bench", "--device '%s': expected an index", val);
                device = (int)v;
            } else {
                return cli_usage_error("bench", "unknown option '%s'", a);
            }
        } else {
            path = a;
        }
    }

    if (!build_scene(&sc, path, generate))
        return 1;
    if (!cli_gpu_create(&g, device, validate)) {
        scene_destroy(&sc);
        return 1;
    }
    renderer_create(&r, &g, &sc);
    s.width = w;
    s.height = h;
    s.camera = sc.num_cameras ? 0 : -1;
    s.shadows = false;
    if (!renderer_begin(&r, &s, &frame)) {
        renderer_destroy(&r);
        gpu_destroy(&g);
        scene_destroy(&sc);
        return 1;
    }
    for (uint32_t mode = 0; mode < 2; mode++) {
        gpu_binding b[GN_BIND_COUNT];
        renderer_spec spec;
        gpu_pipeline_desc pd = {.name = "bench", .code = spv_bench, .code_size = sizeof spv_bench,
                                .local_size = {GN_TILE_X, GN_TILE_Y, 1},
                                .push_size = sizeof(GnPush), .bindings = b,
                                .num_bindings = renderer_bindings(&r, b),
                                .specialization = renderer_specialize(&r, mode, &spec)};
        gpu_pipeline_create(&g, &pipes[mode], &pd);
    }

    /* Pass 0 is the warm-up (shader compilation) and defines time to first pixel. */
    for (uint32_t pass = 0;; pass++) {
        GnPush push = {pass, 0, 0, 0};
        double t0 = util_now(), t1, t2;
        VkCommandBuffer cmd = gpu_begin(&g);
        gpu_dispatch(cmd, &pipes[0], &push, (uint32_t)w, (uint32_t)h, 1);
        gpu_submit_wait(&g, cmd);
        t1 = util_now();
        cmd = gpu_begin(&g);
        gpu_dispatch(cmd, &pipes[1], &push, (uint32_t)w, (uint32_t)h, 1);
        gpu_submit_wait(&g, cmd);
        t2 = util_now();
        if (pass == 0) {
            t_first = t1 - t_start;
            continue;
        }
        {
            const float *rays = r.aov.mapped;
            for (int p = 0; p < w * h; p++)
                n_diffuse += rays[8 * p + 7] >= 0.0f;
        }
        n_primary += (uint64_t)w * h;
        t_primary += t1 - t0;
        t_diffuse += t2 - t1;
        passes++;
        if (t_primary + t_diffuse >= 2.0 * seconds && passes >= 2)
            break;
    }
    for (int i = 0; i < 3; i++) {
        bvh b = {0};
        bvh_build(&b, &sc.vertices[0].position.x, sizeof(GnVertex) / sizeof(float), sc.indices,
                  sc.num_triangles);
        if (b.build_seconds < best_build)
            best_build = b.build_seconds;
        bvh_destroy(&b);
    }

    printf("scene              %s\n", generate ? "generated mesh" : path);
    printf("device             %s\n", g.props.deviceName);
    printf("triangles          %u\n", sc.num_triangles);
    printf("bvh nodes          %u (depth %u, SAH cost %.1f)\n", r.tree.num_nodes, r.tree.depth,
           r.tree.sah_cost);
    printf("bvh build          %.2f ms (%.2f M triangles/s)\n", best_build * 1e3,
           sc.num_triangles / best_build * 1e-6);
    printf("first pixel        %.3f s after start\n", t_first);
    printf("primary rays       %.2f Mrays/s (%dx%d, %d passes)\n", n_primary / t_primary * 1e-6,
           w, h, passes);
    printf("diffuse rays       %.2f Mrays/s (%.0f%% of pixels hit)\n",
           n_diffuse / t_diffuse * 1e-6, 100.0 * n_diffuse / n_primary);
    for (int i = 0; i < 2; i++)
        gpu_pipeline_destroy(&g, &pipes[i]);
    renderer_destroy(&r);
    scene_destroy(&sc);
    return cli_gpu_finish(&g) ? 0 : 1;
}
