/* cmd_bench.c: `gonio bench`: BVH build rate, primary and diffuse-bounce ray throughput
 * of the GLSL traversal, the time from start to the first finished pixel, and (--paths)
 * the path tracer's paths per second and time to reach an RMSE against a reference. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stdint.h>

#include "bench.h" /* spv_bench: glsl/kernels/bench.comp compiled by the build */
#include "cli.h"
#include "denoise.h"
#include "meshgen.h"
#include "render.h"
#include "scene.h"
#include "scene_mesh.h"
#include "util.h"

static bool build_scene(scene *sc, const char *path, int generate)
{
    meshgen_mesh m;
    if (!generate)
        return path ? scene_load(sc, path) : cli_load_builtin_scene(sc, "cornell");
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

/* The BVH build time, best of 7 (after the timed passes: it must not delay the first pixel).
 * The build is threaded, so on a 2-core machine one run can lose a core to anything else;
 * the fastest of several is the figure noise cannot inflate. */
static void print_build(const scene *sc)
{
    double best = 1e30, top = 1e30;
    uint64_t stored = sc->num_triangles;
    for (int i = 0; i < 7; i++) {
        render_geometry g;
        if (!render_geometry_build(&g, sc))
            return;
        best = g.build_seconds < best ? g.build_seconds : best;
        top = g.top_seconds < top ? g.top_seconds : top;
        render_geometry_destroy(&g);
    }
    for (uint32_t m = 0; m < sc->num_instanced_meshes; m++)
        stored += sc->instanced_meshes[m].num_triangles;
    printf("bvh build          %.2f ms (%.2f M triangles/s)\n", best * 1e3, stored / best * 1e-6);
    if (sc->num_instances)
        printf("top tree build     %.3f ms (%u instances: what an animated frame rebuilds)\n", top * 1e3,
               sc->num_instances);
}

/* Samples [first, first + count) of every pixel of r's current image, as `gonio render`
 * takes them (GN_PATH_SAMPLES per dispatch); returns the seconds. */
static double path_pass(renderer *r, uint32_t first, uint32_t count)
{
    double t0 = util_now();
    VkCommandBuffer cmd = gpu_begin(r->g);
    renderer_record_samples(r, cmd, GN_MODE_PATH, first, count);
    gpu_submit_wait(r->g, cmd);
    renderer_finish(r, GN_MODE_PATH, first + count);
    return util_now() - t0;
}

static const double bench_thresholds[] = {0.05, 0.02};

/* A progressive render of s (seed 0) against ref: the render time and spp at which its RMSE,
 * less the reference's own noise, first falls below each of bench_thresholds (spp 0: not
 * within ref_spp). With denoise, the image at each pass is denoised (src/core/denoise.h)
 * first, each time as `render --denoise` would, its filters made anew, and the time of
 * that denoise is added; the render then takes the albedo and normal it needs. False when
 * renderer_begin or the denoiser fails. */
static bool paths_to_rmse(renderer *r, render_settings *s, const image *ref, double ref_noise, int ref_spp,
                          bool denoise, double times[2], int spps[2], double rmses[2], double denoise_seconds[2])
{
    GnFrame frame;
    double t_run = 0, rmse;
    int k = 0;
    const uint32_t aov = denoise ? RENDER_AOV_ALBEDO | RENDER_AOV_NORMAL : 0;
    s->seed = 0;
    s->aov = RENDER_AOV_VARIANCE | aov;
    /* The kernel with the guides is another specialization: compiled before the timing,
     * as the warm-up pass compiled the first. */
    if (!renderer_begin(r, s, &frame))
        return false;
    if (denoise) {
        path_pass(r, 0, 1);
        if (!renderer_begin(r, s, &frame))
            return false;
    }
    spps[0] = spps[1] = 0;
    /* Passes of 1, 1, 2, 4, ... samples up to the renderer's own per dispatch: the first
     * thresholds may be met at a few spp, the denoised ones especially. */
    for (int spp = 0, n = 1; spp < ref_spp && k < 2; n = spp < (int)r->path_samples ? spp : (int)r->path_samples) {
        image img = {0};
        image_metrics m;
        denoise_info dn = {0};
        if (n > ref_spp - spp)
            n = ref_spp - spp;
        t_run += path_pass(r, (uint32_t)spp, (uint32_t)n);
        spp += n;
        renderer_resolve(r, spp, aov, &img);
        if (denoise) {
            denoise_channels ch = {{0, 1, 2}, {7, 8, 9}, {4, 5, 6}}; /* R G B A normal.XYZ albedo.RGB */
            denoise_shutdown();
            if (!denoise_image(&img, &ch, true, &dn, "bench")) {
                image_destroy(&img);
                return false;
            }
        }
        image_compare(&img, ref, &m);
        image_destroy(&img);
        rmse = sqrt(fmax(0.0, m.rmse * m.rmse - ref_noise));
        for (; k < 2 && rmse < bench_thresholds[k]; k++) {
            times[k] = t_run + dn.seconds + dn.setup_seconds;
            denoise_seconds[k] = dn.seconds + dn.setup_seconds;
            spps[k] = spp;
            rmses[k] = rmse;
        }
    }
    for (; k < 2; k++)
        times[k] = t_run;
    return true;
}

/* --paths: prints the path tracer's first pixel, paths/s at s's size and the time to reach
 * each RMSE against a reference of ref_w x ref_h at ref_spp (seed 1; the timed render uses
 * seed 0); with denoise, the same for the denoised image and the speed-up at equal RMSE.
 * False when renderer_begin fails. */
static bool bench_paths(renderer *r, render_settings *s, double t_start, float seconds,
                        int ref_w, int ref_h, int ref_spp, bool denoise)
{
    GnFrame frame;
    image ref = {0};
    double t_first, t_paths = 0, t_ref, ref_noise = 0;
    double times[2][2], rmses[2][2] = {{0}}, dn_seconds[2][2] = {{0}};
    int samples = 0, spps[2][2];

    if (!renderer_begin(r, s, &frame))
        return false;
    /* Sample 0 compiles the kernel and defines time to first pixel. */
    path_pass(r, 0, 1);
    t_first = util_now() - t_start;
    for (uint32_t first = 1; t_paths < seconds || samples < 2 * (int)r->path_samples;
         first += r->path_samples, samples += (int)r->path_samples)
        t_paths += path_pass(r, first, r->path_samples);
    printf("first pixel        %.3f s after start (path, %dx%d)\n", t_first, s->width, s->height);
    printf("paths              %.3f M paths/s (%dx%d, %d spp, unbounded depth, MIS, %s sampler)\n",
           (double)s->width * s->height * samples / t_paths * 1e-6, s->width, s->height, samples,
           render_sampler_name(s->sampler));
    fflush(stdout);

    /* The reference by independent samples (seed 1): their variance estimates its noise
     * below (a low-discrepancy sampler's mean errs less than its samples' variance says). */
    const uint32_t sampler = s->sampler;
    s->width = ref_w;
    s->height = ref_h;
    s->seed = 1;
    s->sampler = GN_SAMPLER_INDEPENDENT;
    if (!renderer_begin(r, s, &frame))
        return false;
    t_ref = util_now();
    path_pass(r, 0, (uint32_t)ref_spp);
    t_ref = util_now() - t_ref;
    renderer_resolve(r, ref_spp, false, &ref);
    /* The reference's own noise: the mean over pixels and RGB of its estimated variance
     * (sum x^2 / n - mean^2) / (n - 1), subtracted from each squared RMSE below, so the
     * figures estimate the error against the converged image. */
    for (int p = 0; ref_spp > 1 && p < ref_w * ref_h; p++)
        for (int c = 0; c < 3; c++) {
            double m = ref.planes[c][p], sq = ((const float *)r->accum.squares.mapped)[4 * p + c];
            ref_noise += (sq / ref_spp - m * m) / (ref_spp - 1);
        }
    ref_noise /= 3.0 * ref_w * ref_h;
    s->sampler = sampler;
    printf("reference          %dx%d, %d spp in %.1f s (its own rmse %.4f)\n", ref_w, ref_h,
           ref_spp, t_ref, sqrt(ref_noise));

    /* The progressive render stops at the reference's spp: beyond it the error left is
     * below the reference's own, and only the noise estimate subtracted stands for it. */
    for (int d = 0; d < 1 + denoise; d++) {
        if (!paths_to_rmse(r, s, &ref, ref_noise, ref_spp, d, times[d], spps[d], rmses[d], dn_seconds[d])) {
            image_destroy(&ref);
            return false;
        }
        for (int k = 0; k < 2; k++) {
            if (!spps[d][k])
                printf("%s < %.2f%snot reached in %d spp (%.2f s)\n", d ? "denoised rmse" : "rmse",
                       bench_thresholds[k], d ? " " : "        ", ref_spp, times[d][k]);
            else if (!d)
                printf("rmse < %.2f        %.2f s (%d spp, rmse %.4f, %dx%d)\n", bench_thresholds[k], times[d][k],
                       spps[d][k], rmses[d][k], ref_w, ref_h);
            else
                printf("denoised rmse < %.2f %.2f s (%d spp + denoise %.2f s, rmse %.4f, %dx%d)\n",
                       bench_thresholds[k], times[d][k], spps[d][k], dn_seconds[d][k], rmses[d][k], ref_w, ref_h);
        }
    }
    if (denoise) {
        for (int k = 0; k < 2; k++)
            if (spps[0][k] && spps[1][k])
                printf("denoise speed-up   %.1fx at rmse %.2f (%d spp in %.2f s, denoised %d spp in %.2f s)\n",
                       times[0][k] / times[1][k], bench_thresholds[k], spps[0][k], times[0][k], spps[1][k],
                       times[1][k]);
            else
                printf("denoise speed-up   at rmse %.2f: not measured (a run did not reach it)\n",
                       bench_thresholds[k]);
        denoise_shutdown();
    }
    image_destroy(&ref);
    return true;
}

typedef struct reference_option {
    int *w, *h, *spp;
} reference_option;

/* --reference WxH:SPP */
static bool take_reference(const char *cmd, const char *opt, const char *val, void *dest)
{
    (void)cmd, (void)opt;
    reference_option *r = dest;
    char size[64];
    long v;
    const char *colon = strchr(val, ':');
    if (!colon || colon - val >= (long)sizeof size)
        return false;
    snprintf(size, sizeof size, "%.*s", (int)(colon - val), val);
    if (!util_parse_size(size, r->w, r->h) || !util_parse_int(colon + 1, 1, 1 << 20, &v))
        return false;
    *r->spp = (int)v;
    return true;
}

/* The scene's load time, its trees and their memory. */
static void print_scene(const renderer *r, const scene *sc, const char *name, double t_load)
{
    printf("scene              %s\n", name);
    printf("device             %s\n", r->g->props.deviceName);
    printf("scene load         %.3f s (the file read and checked, meshes decoded; then the trees' build\n"
           "                   and upload took %.3f s)\n", t_load, r->setup_seconds);
    const render_geometry *geo = &r->geo;
    render_geometry_bytes mem = render_geometry_size(geo);
    if (geo->two_levels) {
        uint32_t tris = 0;
        for (uint32_t m = 0; m < geo->num_meshes; m++)
            tris += geo->meshes[m].num_tris;
        printf("triangles          %llu placed, %u stored (%u instances of %u meshes)\n",
               (unsigned long long)scene_placed_triangles(sc), tris, geo->top.num_instances, geo->num_meshes);
        printf("bvh leaf prims     %u\n", geo->num_pairs);
        printf("bvh nodes          %u (top tree %u, depth %u; walks up to %u levels)\n", geo->num_nodes,
               geo->top.tree.num_nodes, geo->top.tree.depth, geo->depth);
    } else {
        printf("triangles          %u\n", sc->num_triangles);
        printf("bvh leaf prims     %u (%u triangle pairs, %u single triangles)\n", geo->world.num_pairs,
               geo->world.num_tris - geo->world.num_pairs, 2 * geo->world.num_pairs - geo->world.num_tris);
        printf("bvh nodes          %u (depth %u, SAH cost %.1f)\n", geo->world.num_nodes, geo->world.depth,
               geo->world.sah_cost);
    }
    printf("scene memory       %.2f MB (nodes %.2f, triangles %.2f, shading %.2f, vertices %.2f, instances %.2f)\n",
           (mem.nodes + mem.pairs + mem.prims + mem.vertices + mem.instances) * 1e-6, mem.nodes * 1e-6,
           mem.pairs * 1e-6, mem.prims * 1e-6, mem.vertices * 1e-6, mem.instances * 1e-6);
    fflush(stdout);
}

/* The rates of bench.comp's primary and diffuse rays through the renderer's buffers, for
 * about `seconds` each after a warm-up pass (shader compilation), which defines the time to
 * the first pixel. False when renderer_begin fails. */
static bool bench_rays(renderer *r, const render_settings *s, double t_start, float seconds)
{
    GnFrame frame;
    gpu_pipeline pipes[2] = {{0}};
    double t_first = 0, t_primary = 0, t_diffuse = 0;
    uint64_t n_primary = 0, n_diffuse = 0;
    const int w = s->width, h = s->height;
    int passes = 0;
    if (!renderer_begin(r, s, &frame))
        return false;
    for (uint32_t mode = 0; mode < 2; mode++) {
        gpu_binding b[GN_BIND_COUNT];
        render_spec spec;
        gpu_pipeline_desc pd = {.name = "bench", .code = spv_bench, .code_size = sizeof spv_bench,
                                .local_size = {GN_TILE_X, GN_TILE_Y, 1},
                                .push_size = sizeof(GnPush), .bindings = b,
                                .num_bindings = renderer_bindings(r, b),
                                .specialization = renderer_specialize(r, mode, &spec)};
        gpu_pipeline_create(r->g, &pipes[mode], &pd);
    }
    for (uint32_t pass = 0;; pass++) {
        GnPush push = {pass, 0, 0, 0};
        double t0 = util_now(), t1, t2;
        VkCommandBuffer cmd = gpu_begin(r->g);
        gpu_dispatch(cmd, &pipes[0], &push, (uint32_t)w, (uint32_t)h, 1);
        gpu_submit_wait(r->g, cmd);
        t1 = util_now();
        cmd = gpu_begin(r->g);
        gpu_dispatch(cmd, &pipes[1], &push, (uint32_t)w, (uint32_t)h, 1);
        gpu_submit_wait(r->g, cmd);
        t2 = util_now();
        if (pass == 0) {
            t_first = t1 - t_start;
            continue;
        }
        const float *rays = r->accum.aov.mapped; /* (bench.comp writes its rays into the AOV buffer) */
        for (int p = 0; p < w * h; p++)
            n_diffuse += rays[8 * p + 7] >= 0.0f;
        n_primary += (uint64_t)w * h;
        t_primary += t1 - t0;
        t_diffuse += t2 - t1;
        passes++;
        if (t_primary + t_diffuse >= 2.0 * seconds && passes >= 2)
            break;
    }
    printf("first pixel        %.3f s after start\n", t_first);
    printf("primary rays       %.2f Mrays/s (%dx%d, %d passes)\n", n_primary / t_primary * 1e-6, w, h, passes);
    printf("diffuse rays       %.2f Mrays/s (%.0f%% of pixels hit)\n", n_diffuse / t_diffuse * 1e-6,
           100.0 * n_diffuse / n_primary);
    for (int i = 0; i < 2; i++)
        gpu_pipeline_destroy(r->g, &pipes[i]);
    return true;
}

int cmd_bench(int argc, char **argv)
{
    const double t_start = util_now();
    const char *path = NULL; /* the built-in Cornell box */
    int generate = 0;
    float seconds = 3;
    env_option env = {0};
    int device = -1, size[2] = {0, 0}, ref_w = 128, ref_h = 128, ref_spp = 512;
    bool validate = false, paths = false, denoise = false;
    uint32_t sampler = GN_SAMPLER_SOBOL;
    reference_option ref = {&ref_w, &ref_h, &ref_spp};
    const cli_option options[] = {
        /* meshgen_bench_mesh's 16 spheres and ground need about 1000 triangles. */
        {"--generate", "N", "a procedural mesh of about N triangles (1000..50000000) instead of a scene",
         CLI_INT, CLI_AS(int, &generate), 1000, 50000000, "a triangle count 1000..50000000", NULL, NULL},
        CLI_OPT_SIZE(size, "rays per pass (default 512x512; --paths: 256x256)"),
        {"--seconds", "S", "measure each rate for about S seconds (default 3)", CLI_FLOAT, CLI_AS(float, &seconds),
         FLT_MIN, 1e6, "a number > 0", NULL, NULL},
        {"--paths", NULL, "measure the path tracer", CLI_FLAG, CLI_AS(bool, &paths), 0, 0, NULL, NULL, NULL},
        CLI_OPT_ENV(&env, "--paths: the environment, as gonio render's (default 0: black)"),
        CLI_OPT_SAMPLER(&sampler), /* (--paths: its help is the render's) */
        {"--reference", "WxH:SPP", "--paths: the RMSE reference (default 128x128:512)", CLI_CALL, &ref,
         0, 0, "WxH:SPP", take_reference, NULL},
        CLI_OPT_DENOISE(&denoise, "--paths: also the time to each RMSE of the denoised image (render\n"
                                  "--denoise: OIDN guided by albedo and normal) and the speed-up"),
        CLI_OPT_DEVICE(&device),
        CLI_OPT_VALIDATE(&validate),
    };
    const cli_command command = {
        .name = "bench", .synopsis = "[SCENE.gltf | --generate N] [options]",
        .intro =
            "Prints the BVH build time (best of 7), the time from start to the first finished\n"
            "pixel (load, build, upload, shader compile, one pass), and the throughput of\n"
            "primary (camera) rays and diffuse bounce rays (cosine-distributed from the primary\n"
            "hits) through the GPU traversal. Default scene: the Cornell box (gonio scene cornell).\n"
            "\n"
            "With --paths, the path tracer instead (--mode path: unbounded depth, MIS): the time to\n"
            "the first finished path pass, paths per second, and the time and spp at which a\n"
            "progressive render's RMSE (linear RGB) against a high-spp reference (with the\n"
            "reference's own estimated noise removed) first falls below 0.05 and 0.02 (times count\n"
            "the passes, not the RMSE checks).\n",
        CLI_OPTIONS(options), .max_args = 1, .complete_args = "*.gltf *.glb"};
    cli_args args;
    int rc;
    scene sc = {0};
    gpu g = {0};
    renderer r = {0};

    if ((rc = cli_parse(&command, argc, argv, &args)) >= 0)
        return rc;
    if (args.num_args)
        path = args.arg[0];
    if (denoise && !paths)
        return cli_usage_error("bench", "--denoise is for --paths");
    if (denoise && !denoise_load())
        return 1;
    double t_load = util_now();
    if (!build_scene(&sc, path, generate))
        return 1;
    t_load = util_now() - t_load;
    if (!cli_gpu_create(&g, device, validate)) {
        scene_destroy(&sc);
        return 1;
    }
    bool ok = renderer_create(&r, &g, &sc);
    if (ok) {
        print_scene(&r, &sc, generate ? "generated mesh" : path ? path : "cornell (built in)", t_load);
        /* bench.comp writes its rays into the AOV buffer, which is allocated only when asked for;
         * --paths: the reference's own noise needs its squares. */
        render_settings s = {.mode = paths ? GN_MODE_PATH : GN_MODE_PHONG, .camera = sc.num_cameras ? 0 : -1,
                             .aov = paths ? RENDER_AOV_VARIANCE : RENDER_AOV_GPU, .no_shadows = true,
                             .width = size[0] ? size[0] : paths ? 256 : 512,
                             .height = size[0] ? size[1] : paths ? 256 : 512, .sampler = sampler};
        render_lighting light = {0};
        if (!paths)
            ok = bench_rays(&r, &s, t_start, seconds);
        else if (!env.given || render_light_begin(&env, &sc, true, &s, &light))
            ok = bench_paths(&r, &s, t_start, seconds, ref_w, ref_h, ref_spp, denoise);
        else
            ok = false;
        render_lighting_destroy(&light);
        if (ok || paths)
            print_build(&sc);
    }
    renderer_destroy(&r);
    scene_destroy(&sc);
    return cli_gpu_finish(&g) && ok ? 0 : 1;
}
