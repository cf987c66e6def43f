/* test_path.c: the path tracer (glsl/kernels/path.comp) against answers it does not compute itself:
 * furnaces (a closed convex object of albedo a under a constant environment of radiance 1
 * shows a), the three estimators (MIS, light only, BSDF only) against each other, the error
 * falling as 1/sqrt(spp), the Cornell box against a brute-force CPU path tracer written
 * here (BSDF sampling only, no MIS, double precision), bit-identical reruns and exact
 * merging. Comparisons are z-tests with the renders' own variance channels, of renders of
 * independent numbers (--sampler independent), for which those are honest; the Sobol
 * sampler's unbiasedness is tested by the spread of independent seeds (furnace_sobol). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "gltf_write.h"
#include "gpu.h"
#include "image.h"
#include "meshgen.h"
#include "render.h"
#include "render_material.h"
#include "scene.h"
#include "test.h"

#define Z_MAX 5.0 /* |z| above this fails: 1 in 1.7 million for a true Gaussian statistic */

/* Renders a scene file with the path tracer; brdf as for render_material_overrides. */
static bool render_file(gpu *g, const char *path, const char *brdf, render_settings s, image *out)
{
    scene sc = {0};
    renderer r = {0};
    render_stats st;
    bool ok = scene_load(&sc, path) && render_material_overrides(&sc, brdf);
    s.mode = GN_MODE_PATH;
    s.aov |= RENDER_AOV_VARIANCE;
    if (ok) {
        renderer_create(&r, g, &sc);
        ok = renderer_render(&r, &s, out, &st);
        CHECKF(st.truncated == 0, "%u paths ran out of BVH budget", st.truncated);
        renderer_destroy(&r);
    }
    scene_destroy(&sc);
    CHECKF(ok, "rendering %s failed", path);
    return ok;
}

/* A flat-shaded (no NORMAL: shading = geometric normal, so the furnace is exact) unit sphere
 * at the origin seen by a camera at z = 3, with one material. */
static void write_sphere(const char *path, const gltf_write_material *mat)
{
    const float c[3] = {0, 0, 0};
    meshgen_mesh m = meshgen_uv_sphere(c, 1, 24, 12);
    gltf_write_mesh mesh = {.num_vertices = m.num_vertices, .positions = m.positions,
                            .num_indices = 3 * m.num_triangles, .indices = m.indices};
    gltf_write_camera cam = {.yfov = 0.8f, .aspect = 1};
    gltf_write_node nodes[] = {{.kind = GLTF_WRITE_NODE_MESH},
                               {.kind = GLTF_WRITE_NODE_CAMERA, .translation = {0, 0, 3}}};
    gltf_write_desc d = {.meshes = &mesh, .num_meshes = 1, .materials = mat, .num_materials = 1,
                         .cameras = &cam, .num_cameras = 1, .nodes = nodes, .num_nodes = 2};
    CHECK(gltf_write_file(path, &d));
    meshgen_destroy(&m);
}

/* Mean of channel c over the pixels every sample of which hit the object (A = 1), and the
 * standard error of that mean from the variance channel. */
static double covered_mean(const image *img, int c, double *se, int *count)
{
    int a = image_channel(img, "A"), v = image_channel(img, "variance.R") + c;
    double sum = 0, var = 0;
    int n = 0;
    for (int p = 0; p < img->width * img->height; p++)
        if (img->planes[a][p] == 1.0f) {
            sum += img->planes[c][p];
            var += img->planes[v][p];
            n++;
        }
    *count = n;
    *se = n ? sqrt(var) / n : 0;
    return n ? sum / n : 0;
}

static void tmp_file(char *out, size_t cap, const char *name)
{
    snprintf(out, cap, "/tmp/gonio-test-path-%d-%s", (int)getpid(), name);
}

/* The white furnace: a sphere under a unit environment returns the light it receives: an
 * albedo of 1 gives 1, a Lambertian of 0.5 gives 0.5 (within Z_MAX standard errors), a lossy
 * material at most 1; background pixels show the environment exactly. The fast tier has the
 * exact cases and two lossy ones (a rough conductor, the glTF layers together); the slow tier
 * the other lossy materials, each render as before. */
static void furnace(bool slow)
{
    static const struct {
        const char *extras; /* NULL: glTF Lambertian (specular 0) of albedo 0.5 */
        double expect;      /* < 0: lossy, at most 1 */
        bool slow;          /* in the slow tier */
    } cases[] = {
        {NULL, 0.5, false},
        {"{\"gonio\":{\"brdf\":\"lambert\",\"diffuse\":1}}", 1, false},
        {"{\"gonio\":{\"brdf\":\"mirror\",\"reflectance\":1}}", 1, false},
        {"{\"gonio\":{\"brdf\":\"dielectric\",\"tint\":1,\"ior\":1.5}}", 1, false},
        {"{\"gonio\":{\"brdf\":\"dielectric\",\"tint\":1,\"ior\":1.5,\"alpha\":0.3}}", -1, true}, /* single scattering */
        {"{\"gonio\":{\"brdf\":\"conductor\",\"alpha\":0.3}}", -1, false},
        {"{\"gonio\":{\"brdf\":\"ggx\",\"diffuse\":0.5,\"specular\":0.5,\"alpha\":0.5}}", -1, true},
        {"{\"gonio\":{\"brdf\":\"torrance-sparrow\",\"diffuse\":0.5,\"specular\":0.5}}", -1, true},
        {"{\"gonio\":{\"brdf\":\"phong\",\"diffuse\":0.5,\"specular\":0.5}}", -1, true},
        /* glTF layers over a white base: a smooth and a rough coat, a sheen, all three */
        {"{\"gonio\":{\"brdf\":\"gltf\",\"base-color\":1,\"clearcoat\":1}}", -1, true},
        {"{\"gonio\":{\"brdf\":\"gltf\",\"base-color\":1,\"clearcoat\":1,\"clearcoat-roughness\":0.4}}", -1, true},
        {"{\"gonio\":{\"brdf\":\"gltf\",\"base-color\":1,\"sheen-color\":1,\"sheen-roughness\":0.3}}", -1, true},
        {"{\"gonio\":{\"brdf\":\"gltf\",\"base-color\":1,\"metallic\":1,\"roughness\":0.2,\"clearcoat\":1,"
         "\"clearcoat-roughness\":0.1,\"sheen-color\":1}}", -1, false},
    };
    char path[256];
    gpu g = {0};
    if (!test_open_gpu(&g))
        return;
    tmp_file(path, sizeof path, "furnace.gltf");
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        if (cases[i].slow != slow)
            continue;
        gltf_write_material mat = {.base_color = {0.5f, 0.5f, 0.5f, 1}, .roughness = 1,
                                   .has_specular = true, .specular_color = {1, 1, 1},
                                   .extras = cases[i].extras};
        render_settings s = {.width = 32, .height = 32, .spp = 64, .camera = 0,
                             .env = {1, 1, 1}, .seed = 1, .sampler = GN_SAMPLER_INDEPENDENT};
        image img = {0};
        write_sphere(path, &mat);
        if (!render_file(&g, path, NULL, s, &img))
            continue;
        for (int c = 0; c < 3; c++) {
            int n, bg = 0, bad = 0;
            double se, mean = covered_mean(&img, c, &se, &n);
            CHECKF(n > 300, "case %zu: only %d covered pixels", i, n);
            /* a pixel no camera ray hits shows the environment, exactly: every sample is 1
             * (a lane that misses starts its next path at once: path.comp, RETRACE) */
            for (int p = 0, a = image_channel(&img, "A"); p < img.width * img.height; p++)
                if (img.planes[a][p] == 0.0f)
                    bg++, bad += img.planes[c][p] != 1.0f;
            CHECKF(bg > 0 && bad == 0, "case %zu: %d of %d background pixels are not exactly 1", i, bad, bg);
            if (cases[i].expect > 0)
                CHECKF(fabs(mean - cases[i].expect) <= Z_MAX * se + 1e-4,
                       "case %zu (%s): furnace gives %.5f +- %.5f, expected %.3f", i,
                       cases[i].extras ? cases[i].extras : "gltf", mean, se, cases[i].expect);
            else
                CHECKF(mean <= 1 + Z_MAX * se + 1e-4 && mean > 0.1,
                       "case %zu (%s): lossy furnace gives %.5f +- %.5f, expected (0.1, 1]", i,
                       cases[i].extras, mean, se);
        }
        image_destroy(&img);
    }
    unlink(path);
    gpu_destroy(&g);
}
TEST(path, furnace) { furnace(false); }
TEST_SLOW(path, furnace_more_materials) { furnace(true); }

/* The Sobol sampler is unbiased too: the Lambertian furnace (0.5) as the mean of R renders
 * of independent seeds (independent scrambles), its standard error from their spread, since
 * the variance channel overstates a Sobol mean's error (the z-tests here take independent
 * numbers for that reason). */
TEST(path, furnace_sobol)
{
    enum { R = 8 };
    char path[256];
    gpu g = {0};
    double m[R], mean = 0, var = 0;
    if (!test_open_gpu(&g))
        return;
    tmp_file(path, sizeof path, "furnace-sobol.gltf");
    gltf_write_material mat = {.base_color = {0.5f, 0.5f, 0.5f, 1}, .roughness = 1, .has_specular = true,
                               .specular_color = {1, 1, 1}};
    write_sphere(path, &mat);
    for (int r = 0; r < R; r++) {
        render_settings s = {.width = 32, .height = 32, .spp = 8, .camera = 0, .env = {1, 1, 1},
                             .seed = 40 + (uint32_t)r, .sampler = GN_SAMPLER_SOBOL};
        image img = {0};
        double se;
        int n;
        if (!render_file(&g, path, NULL, s, &img))
            break;
        m[r] = covered_mean(&img, 0, &se, &n);
        mean += m[r] / R;
        image_destroy(&img);
    }
    for (int r = 0; r < R; r++)
        var += (m[r] - mean) * (m[r] - mean) / (R - 1);
    double se = sqrt(var / R);
    printf("    Sobol furnace: %.5f +- %.5f over %d seeds (expected 0.5)\n", mean, se, R);
    CHECKF(se > 0 && fabs(mean - 0.5) <= Z_MAX * se + 1e-4, "Sobol furnace gives %.5f +- %.5f, expected 0.5", mean, se);
    unlink(path);
    gpu_destroy(&g);
}

/* KHR_materials_unlit: the base colour is the radiance the surface sends, whatever lights
 * it, and it reflects nothing: an unlit sphere seen by camera rays under no, a unit and a
 * bright (20) environment shows exactly its base colour in every pixel it covers. */
TEST(path, unlit)
{
    const float base[3] = {0.2f, 0.5f, 0.8f};
    char path[256];
    gpu g = {0};
    if (!test_open_gpu(&g))
        return;
    tmp_file(path, sizeof path, "unlit.gltf");
    gltf_write_material mat = {.base_color = {base[0], base[1], base[2], 1}, .roughness = 0.5f, .unlit = true};
    write_sphere(path, &mat);
    const float envs[3] = {0, 1, 20};
    for (int e = 0; e < 3; e++) {
        render_settings s = {.width = 24, .height = 24, .spp = 8, .camera = 0,
                             .env = {envs[e], envs[e], envs[e]}, .seed = 3};
        image img = {0};
        if (!render_file(&g, path, NULL, s, &img))
            continue;
        int a = image_channel(&img, "A"), covered = 0, bad = 0;
        for (int p = 0; p < img.width * img.height; p++) {
            if (img.planes[a][p] != 1.0f)
                continue;
            covered++;
            for (int c = 0; c < 3; c++)
                bad += fabsf(img.planes[c][p] - base[c]) > 1e-6f;
        }
        CHECKF(covered > 100, "env %g: only %d covered pixels", envs[e], covered);
        CHECKF(bad == 0, "env %g: %d pixel values differ from the base colour", envs[e], bad);
        image_destroy(&img);
    }
    unlink(path);
    gpu_destroy(&g);
}

/* A lat-long map under which the sphere is lit: constant 1 (the furnace again, through map
 * sampling), and a bright band, where MIS and BSDF sampling only must agree. */
TEST(path, env_map)
{
    char scene_path[256], map_path[256];
    const char *names[] = {"R", "G", "B"};
    gpu g = {0};
    image map = {0}, a = {0}, b = {0};
    gltf_write_material mat = {.base_color = {0.5f, 0.5f, 0.5f, 1}, .roughness = 1,
                               .has_specular = true, .specular_color = {1, 1, 1}};
    render_settings s = {.width = 32, .height = 32, .spp = 64, .camera = 0, .seed = 3,
                         .sampler = GN_SAMPLER_INDEPENDENT};
    int n;
    double se, mean;
    if (!test_open_gpu(&g))
        return;
    tmp_file(scene_path, sizeof scene_path, "env.gltf");
    tmp_file(map_path, sizeof map_path, "env.exr");
    write_sphere(scene_path, &mat);
    image_create(&map, 32, 16, 3, names);
    for (int p = 0; p < 32 * 16; p++)
        map.planes[0][p] = map.planes[1][p] = map.planes[2][p] = 1;
    s.env_map = &map;
    if (render_file(&g, scene_path, NULL, s, &a)) {
        mean = covered_mean(&a, 0, &se, &n);
        CHECKF(fabs(mean - 0.5) <= Z_MAX * se + 1e-3, "constant map: %.5f +- %.5f, expected 0.5", mean, se);
    }
    image_destroy(&a);
    /* A band 10x brighter, above and to one side (rows 3-5, columns 20-27), plus a dim rest. */
    for (int y = 0; y < 16; y++)
        for (int x = 0; x < 32; x++)
            map.planes[0][y * 32 + x] = map.planes[1][y * 32 + x] = map.planes[2][y * 32 + x] =
                y >= 3 && y <= 5 && x >= 20 && x <= 27 ? 20.0f : 0.2f;
    s.spp = 128;
    if (render_file(&g, scene_path, NULL, s, &a)) {
        s.strategy = GN_FRAME_BSDF_ONLY;
        s.seed = 4;
        if (render_file(&g, scene_path, NULL, s, &b)) {
            double ma, mb, sa, sb;
            ma = covered_mean(&a, 1, &sa, &n);
            mb = covered_mean(&b, 1, &sb, &n);
            CHECKF(fabs(ma - mb) <= Z_MAX * sqrt(sa * sa + sb * sb),
                   "map: MIS %.5f +- %.5f vs BSDF only %.5f +- %.5f", ma, sa, mb, sb);
            CHECKF(sa < sb, "map importance sampling should reduce noise: %.5f vs %.5f", sa, sb);
        }
    }
    image_destroy(&a);
    image_destroy(&b);
    image_destroy(&map);
    unlink(scene_path);
    gpu_destroy(&g);
}

/* z statistics of a - b in blocks of bs x bs pixels over R, G, B: the largest |z| of any
 * block and channel. */
static double max_block_z(const image *a, const image *b, int bs)
{
    double zmax = 0;
    for (int c = 0; c < 3; c++) {
        int va = image_channel(a, "variance.R") + c, vb = image_channel(b, "variance.R") + c;
        for (int by = 0; by < a->height / bs; by++)
            for (int bx = 0; bx < a->width / bs; bx++) {
                double d = 0, v = 0;
                for (int y = by * bs; y < (by + 1) * bs; y++)
                    for (int x = bx * bs; x < (bx + 1) * bs; x++) {
                        int p = y * a->width + x;
                        d += (double)a->planes[c][p] - b->planes[c][p];
                        v += (double)a->planes[va][p] + b->planes[vb][p];
                    }
                if (v > 0 && fabs(d) / sqrt(v) > zmax)
                    zmax = fabs(d) / sqrt(v);
                else if (v == 0 && fabs(d) > 1e-5)
                    zmax = 1e9;
            }
    }
    return zmax;
}

/* The Cornell box with glossy (GGX) walls, and again with layered glTF walls (a rough coat
 * and a sheen: KHR_materials_clearcoat, _sheen): MIS, light sampling only and BSDF sampling
 * only converge to the same image; and the test notices a missing bounce. 256 spp: BSDF
 * sampling finds the small light rarely, and below that its variance estimates run low (at
 * 128 spp the z of a correct render reaches 9). The fast tier has the GGX walls, the slow
 * tier the layered ones, each at its 256 spp as before. */
static void estimators(int k)
{
    static const uint32_t strategies[] = {0, GN_FRAME_LIGHT_ONLY, GN_FRAME_BSDF_ONLY};
    static const char *brdfs[] = {"ggx:alpha=0.25:specular=0.3",
                                  "gltf:roughness=0.6:clearcoat=1:clearcoat-roughness=0.3:sheen-color=0.8,0.5,0.3:"
                                  "sheen-roughness=0.5"};
    gpu g = {0};
    if (!test_open_gpu(&g))
        return;
    {
        const char *brdf = brdfs[k];
        image img[3] = {{0}}, direct = {0};
        render_settings s = {.width = 32, .height = 32, .spp = 256, .camera = 0,
                             .sampler = GN_SAMPLER_INDEPENDENT};
        for (int i = 0; i < 3; i++) {
            s.strategy = strategies[i];
            s.seed = 10 + (uint32_t)i;
            render_file(&g, "scenes/cornell.gltf", brdf, s, &img[i]);
        }
        s.strategy = 0;
        s.max_depth = 1;
        render_file(&g, "scenes/cornell.gltf", brdf, s, &direct);
        if (img[0].planes[0] && img[1].planes[0] && img[2].planes[0] && direct.planes[0]) {
            double z01 = max_block_z(&img[0], &img[1], 4), z02 = max_block_z(&img[0], &img[2], 4);
            double z12 = max_block_z(&img[1], &img[2], 4), zd = max_block_z(&img[0], &direct, 4);
            CHECKF(z01 < Z_MAX, "%s: MIS vs light sampling: max block |z| = %.2f", brdf, z01);
            CHECKF(z02 < Z_MAX, "%s: MIS vs BSDF sampling: max block |z| = %.2f", brdf, z02);
            CHECKF(z12 < Z_MAX, "%s: light vs BSDF sampling: max block |z| = %.2f", brdf, z12);
            CHECKF(zd > 2 * Z_MAX, "%s: the test cannot tell direct light only from MIS: |z| = %.2f", brdf, zd);
        }
        for (int i = 0; i < 3; i++)
            image_destroy(&img[i]);
        image_destroy(&direct);
    }
    gpu_destroy(&g);
}
TEST(path, estimators) { estimators(0); }
TEST_SLOW(path, estimators_layers) { estimators(1); }

static double rmse_rgb(const image *a, const image *b)
{
    double s = 0;
    int n = a->width * a->height;
    for (int c = 0; c < 3; c++)
        for (int p = 0; p < n; p++) {
            double d = (double)a->planes[c][p] - b->planes[c][p];
            s += d * d;
        }
    return sqrt(s / (3.0 * n));
}

/* The log-log slope of the RMSE against ref (less its own noise, ref_var) of renders of s at
 * 4, 16 and 64 spp with `sampler`; NAN when a render fails. */
static double rmse_slope(gpu *g, render_settings s, uint32_t sampler, const image *ref, double ref_var)
{
    double x[3], y[3], sx = 0, sy = 0, sxx = 0, sxy = 0;
    s.sampler = sampler;
    for (int i = 0; i < 3; i++) {
        image img = {0};
        s.spp = 4 << (2 * i);
        s.seed = 200 + (uint32_t)i;
        if (!render_file(g, "scenes/cornell.gltf", NULL, s, &img))
            return NAN;
        x[i] = log(s.spp);
        y[i] = 0.5 * log(fmax(pow(rmse_rgb(&img, ref), 2) - ref_var, 1e-30));
        image_destroy(&img);
        sx += x[i], sy += y[i], sxx += x[i] * x[i], sxy += x[i] * y[i];
    }
    return (3 * sxy - sx * sy) / (3 * sxx - sx * sx);
}

/* RMSE against a 512 spp render of independent samples falls as 1/sqrt(spp) with
 * independent samples: the fitted log-log slope over 4..64 spp is -1/2, once the
 * reference's own noise (its variance channel, honest for independent samples) is taken
 * out. With the Sobol sampler it falls measurably faster (the image is not smooth: edges
 * and visibility keep it above the smooth integrand's n^-1.4 of tests/unit/test_sampler.c). */
TEST(path, convergence)
{
    gpu g = {0};
    image ref = {0};
    render_settings s = {.width = 32, .height = 32, .spp = 512, .camera = 0, .seed = 100,
                         .sampler = GN_SAMPLER_INDEPENDENT};
    double ref_var = 0, slope, sobol;
    if (!test_open_gpu(&g))
        return;
    if (!render_file(&g, "scenes/cornell.gltf", NULL, s, &ref)) {
        gpu_destroy(&g);
        return;
    }
    for (int c = 0; c < 3; c++)
        for (int p = 0; p < 32 * 32; p++)
            ref_var += ref.planes[image_channel(&ref, "variance.R") + c][p] / (3.0 * 32 * 32);
    slope = rmse_slope(&g, s, GN_SAMPLER_INDEPENDENT, &ref, ref_var);
    sobol = rmse_slope(&g, s, GN_SAMPLER_SOBOL, &ref, ref_var);
    printf("    RMSE ~ spp^%.3f (independent), spp^%.3f (sobol)\n", slope, sobol);
    CHECKF(fabs(slope + 0.5) < 0.1, "RMSE ~ spp^%.3f, expected spp^-0.5", slope);
    CHECKF(sobol < -0.8, "Sobol's RMSE ~ spp^%.3f: not measurably faster than spp^-0.5", sobol);
    image_destroy(&ref);
    gpu_destroy(&g);
}

/* ---- an independent reference: brute-force CPU path tracing of the Cornell box --------- */

static double rnd(uint64_t *s) /* splitmix64 -> [0, 1) */
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return (double)((z ^ (z >> 31)) >> 11) * (1.0 / 9007199254740992.0);
}

static void sub3(double *o, const float *a, const float *b)
{
    for (int k = 0; k < 3; k++)
        o[k] = (double)a[k] - b[k];
}
static void cross3(double *o, const double *a, const double *b)
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Closest triangle hit by Moller-Trumbore over every triangle; -1 on a miss. */
static int ref_hit(const scene *sc, const double *o, const double *d, double *tbest)
{
    int best = -1;
    *tbest = 1e300;
    for (uint32_t t = 0; t < sc->num_triangles; t++) {
        const float *p0 = &sc->vertices[sc->indices[3 * t]].position.x;
        double e1[3], e2[3], pv[3], tv[3], qv[3], det, u, v, dist, o0[3];
        sub3(e1, &sc->vertices[sc->indices[3 * t + 1]].position.x, p0);
        sub3(e2, &sc->vertices[sc->indices[3 * t + 2]].position.x, p0);
        cross3(pv, d, e2);
        det = dot3(e1, pv);
        if (fabs(det) < 1e-14)
            continue;
        for (int k = 0; k < 3; k++)
            o0[k] = p0[k];
        for (int k = 0; k < 3; k++)
            tv[k] = o[k] - o0[k];
        u = dot3(tv, pv) / det;
        if (u < 0 || u > 1)
            continue;
        cross3(qv, tv, e1);
        v = dot3(d, qv) / det;
        if (v < 0 || u + v > 1)
            continue;
        dist = dot3(e2, qv) / det;
        if (dist > 1e-9 && dist < *tbest) {
            *tbest = dist;
            best = (int)t;
        }
    }
    return best;
}

/* Radiance along one camera ray: Lambertian BRDFs sampled by the cosine, emission added
 * where a path happens to hit a lit front face, roulette after three bounces. */
static void ref_radiance(const scene *sc, double *o, double *d, uint64_t *rng, double L[3])
{
    double beta[3] = {1, 1, 1};
    L[0] = L[1] = L[2] = 0;
    for (int depth = 0; depth < 1000; depth++) {
        double t, e1[3], e2[3], n[3], len, tx[3], ty[3], r, phi, z, q;
        int tri = ref_hit(sc, o, d, &t);
        const GnMaterial *m;
        if (tri < 0)
            return;
        m = &sc->materials[sc->tri_material[tri]];
        sub3(e1, &sc->vertices[sc->indices[3 * tri + 1]].position.x, &sc->vertices[sc->indices[3 * tri]].position.x);
        sub3(e2, &sc->vertices[sc->indices[3 * tri + 2]].position.x, &sc->vertices[sc->indices[3 * tri]].position.x);
        cross3(n, e1, e2);
        len = sqrt(dot3(n, n));
        for (int k = 0; k < 3; k++)
            n[k] /= len;
        if (dot3(n, d) < 0 || (m->flags & GN_MAT_DOUBLE_SIDED))
            for (int k = 0; k < 3; k++)
                L[k] += beta[k] * (&m->emissive.x)[k];
        if (dot3(n, d) > 0)
            for (int k = 0; k < 3; k++)
                n[k] = -n[k];
        for (int k = 0; k < 3; k++) {
            o[k] += t * d[k] + 1e-6 * n[k];
            beta[k] *= (&m->base_color.x)[k];
        }
        /* a cosine-distributed direction about n */
        tx[0] = fabs(n[0]) > 0.5 ? 0 : 1;
        tx[1] = fabs(n[0]) > 0.5 ? 1 : 0;
        tx[2] = 0;
        cross3(ty, n, tx);
        len = sqrt(dot3(ty, ty));
        for (int k = 0; k < 3; k++)
            ty[k] /= len;
        cross3(tx, ty, n);
        r = sqrt(rnd(rng));
        phi = 2 * M_PI * rnd(rng);
        z = sqrt(fmax(0, 1 - r * r));
        for (int k = 0; k < 3; k++)
            d[k] = r * cos(phi) * tx[k] + r * sin(phi) * ty[k] + z * n[k];
        if (depth >= 2) {
            q = fmin(fmax(beta[0], fmax(beta[1], beta[2])), 0.95);
            if (rnd(rng) >= q)
                return;
            for (int k = 0; k < 3; k++)
                beta[k] /= q;
        }
    }
}

TEST(path, cornell_reference)
{
    enum { W = 32, H = 32, SPP = 256 };
    const char *names[] = {"R", "G", "B", "variance.R", "variance.G", "variance.B"};
    gpu g = {0};
    scene sc = {0};
    image gpu_img = {0}, ref = {0};
    render_settings s = {.width = W, .height = H, .spp = SPP, .camera = 0, .seed = 5,
                         .sampler = GN_SAMPLER_INDEPENDENT};
    uint64_t rng = 12345;
    if (!scene_load(&sc, "scenes/cornell.gltf")) {
        CHECK(!"scenes/cornell.gltf loads");
        return;
    }
    image_create(&ref, W, H, 6, names);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const scene_camera *c = &sc.cameras[0];
            double sum[3] = {0}, sq[3] = {0}, th = tan(0.5 * c->yfov);
            for (int i = 0; i < SPP; i++) {
                double nx = 2 * (x + rnd(&rng)) / W - 1, ny = 1 - 2 * (y + rnd(&rng)) / H;
                double o[3], d[3], len = 0, L[3];
                for (int k = 0; k < 3; k++) {
                    o[k] = c->position[k];
                    d[k] = c->forward[k] + nx * th * c->right[k] + ny * th * c->up[k];
                    len += d[k] * d[k];
                }
                for (int k = 0; k < 3; k++)
                    d[k] /= sqrt(len);
                ref_radiance(&sc, o, d, &rng, L);
                for (int k = 0; k < 3; k++) {
                    sum[k] += L[k];
                    sq[k] += L[k] * L[k];
                }
            }
            for (int k = 0; k < 3; k++) {
                double m = sum[k] / SPP;
                ref.planes[k][y * W + x] = (float)m;
                ref.planes[3 + k][y * W + x] = (float)fmax(0, (sq[k] / SPP - m * m) / (SPP - 1));
            }
        }
    scene_destroy(&sc);
    if (test_open_gpu(&g) && render_file(&g, "scenes/cornell.gltf", NULL, s, &gpu_img)) {
        double z = max_block_z(&gpu_img, &ref, 4), mg = 0, mr = 0;
        for (int p = 0; p < W * H; p++)
            mg += gpu_img.planes[1][p], mr += ref.planes[1][p];
        CHECKF(z < Z_MAX, "Cornell box vs the CPU reference: max block |z| = %.2f (mean G %.4f vs %.4f)",
               z, mg / (W * H), mr / (W * H));
    }
    image_destroy(&gpu_img);
    image_destroy(&ref);
    gpu_destroy(&g);
}

/* The bits do not depend on how long batches took: renderer_render grows its batches by the
 * clock, but its dispatches start at multiples of the kernel's samples per dispatch, so it
 * must give exactly the image of the same samples taken one dispatch per submission. (With
 * batches of 1, 2, 4... samples, the sums of a pixel's samples were grouped differently.) */
TEST(path, batching)
{
    gpu g = {0};
    scene sc = {0};
    renderer r = {0};
    image a = {0}, b = {0};
    render_stats st;
    GnFrame frame;
    const int spp = 40;
    render_settings s = {.width = 24, .height = 24, .spp = spp, .camera = 0, .seed = 3,
                         .mode = GN_MODE_PATH};
    if (!test_open_gpu(&g))
        return;
    if (scene_load(&sc, "scenes/cornell.gltf")) {
        renderer_create(&r, &g, &sc);
        if (renderer_render(&r, &s, &a, &st) && renderer_begin(&r, &s, &frame)) {
            uint32_t per = r.path_samples;
            bool same = true;
            for (uint32_t i = 0; i < (uint32_t)spp; i += per) {
                VkCommandBuffer cmd = gpu_begin(&g);
                renderer_record_samples(&r, cmd, GN_MODE_PATH, i, spp - i < per ? spp - i : per);
                gpu_submit_wait(&g, cmd);
                renderer_finish(&r, GN_MODE_PATH, spp - i < per ? (uint32_t)spp : i + per);
            }
            renderer_resolve(&r, spp, false, &b);
            for (int c = 0; same && c < 4; c++)
                same = !memcmp(a.planes[c], b.planes[c], sizeof(float) * 24 * 24);
            CHECKF(same, "renderer_render differs from one dispatch of %u samples per submission", per);
        }
        renderer_destroy(&r);
    }
    scene_destroy(&sc);
    image_destroy(&a);
    image_destroy(&b);
    gpu_destroy(&g);
}

/* The same settings twice give the same bits. */
TEST(path, determinism)
{
    gpu g = {0};
    image a = {0}, b = {0};
    render_settings s = {.width = 24, .height = 24, .spp = 8, .camera = 0, .seed = 9, .aov = RENDER_AOV_GPU};
    if (!test_open_gpu(&g))
        return;
    if (render_file(&g, "scenes/cornell.gltf", NULL, s, &a) &&
        render_file(&g, "scenes/cornell.gltf", NULL, s, &b)) {
        bool same = a.num_channels == b.num_channels;
        for (int c = 0; same && c < a.num_channels; c++)
            same = !memcmp(a.planes[c], b.planes[c], sizeof(float) * 24 * 24);
        CHECKF(same, "two renders with the same settings differ");
    }
    image_destroy(&a);
    image_destroy(&b);
    gpu_destroy(&g);
}

/* gonio merge on hand-made files: means weight by spp, variances by the sums of squares
 * they imply (computed here by hand for two pixels of two samples each). */
TEST(path, merge)
{
    const char *names[] = {"R", "variance.R"};
    char a_path[256], b_path[256], o_path[256];
    image a = {0}, b = {0}, o = {0};
    image_attr attr_a[] = {{"gonio:spp", IMAGE_ATTR_INT, NULL, 1, 0, NULL}, {"gonio:seed", IMAGE_ATTR_INT, NULL, 1, 0, NULL}};
    image_attr attr_b[] = {{"gonio:spp", IMAGE_ATTR_INT, NULL, 3, 0, NULL}, {"gonio:seed", IMAGE_ATTR_INT, NULL, 2, 0, NULL}};
    tmp_file(a_path, sizeof a_path, "a.exr");
    tmp_file(b_path, sizeof b_path, "b.exr");
    tmp_file(o_path, sizeof o_path, "o.exr");
    image_create(&a, 1, 1, 2, names);
    image_create(&b, 1, 1, 2, names);
    /* a: one sample, 2. b: three samples 1, 2, 6: mean 3, variance of the mean
     * (sum (x - 3)^2 / 2) / 3 = (4 + 1 + 9) / 6 = 7/3. All four: 2, 1, 2, 6: mean 11/4,
     * sample variance (sum x^2 - 4 m^2) / 3 = (45 - 30.25) / 3, of the mean / 4. */
    a.planes[0][0] = 2;
    b.planes[0][0] = 3;
    b.planes[1][0] = 7.0f / 3;
    CHECK(image_write_exr(&a, a_path, attr_a, 2) && image_write_exr(&b, b_path, attr_b, 2));
    {
        char *argv[] = {"merge", a_path, b_path, "-o", o_path, NULL};
        CHECK(cmd_merge(5, argv) == 0);
    }
    if (image_read_exr(&o, o_path)) {
        double spp = 0;
        CHECKF(fabs(o.planes[0][0] - 2.75) < 1e-6, "merged mean %g, expected 2.75", o.planes[0][0]);
        CHECKF(fabs(o.planes[1][0] - (45 - 30.25) / 3 / 4) < 1e-5, "merged variance %g, expected %g",
               o.planes[1][0], (45 - 30.25) / 3 / 4);
        CHECK(image_exr_attr_double(o_path, "gonio:spp", &spp) && spp == 4);
    }
    image_destroy(&a);
    image_destroy(&b);
    image_destroy(&o);
    unlink(a_path);
    unlink(b_path);
    unlink(o_path);
}

/* gonio merge refuses sample counts that are not positive integers (whatever type the
 * header stores them as), a total past the header's int, and a repeated seed (unless
 * --force); each refusal exits 1 and writes nothing. */
TEST(path, merge_checks)
{
    const char *names[] = {"R"};
    static const struct { image_attr_type type; int i; double d; const char *what; } bad[] = {
        {IMAGE_ATTR_DOUBLE, 0, INFINITY, "inf"},     {IMAGE_ATTR_DOUBLE, 0, 1e300, "1e300"},
        {IMAGE_ATTR_DOUBLE, 0, 1.5, "1.5"},          {IMAGE_ATTR_DOUBLE, 0, NAN, "nan"},
        {IMAGE_ATTR_DOUBLE, 0, 4294967296.0, "2^32"}, {IMAGE_ATTR_INT, 0, 0, "0"},
        {IMAGE_ATTR_INT, -5, 0, "-5"}};
    char a_path[256], b_path[256], o_path[256];
    image a = {0};
    tmp_file(a_path, sizeof a_path, "ca.exr");
    tmp_file(b_path, sizeof b_path, "cb.exr");
    tmp_file(o_path, sizeof o_path, "co.exr");
    image_create(&a, 2, 2, 1, names);
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
        image_attr attr_a[] = {{"gonio:spp", bad[k].type, NULL, bad[k].i, bad[k].d, NULL},
                               {"gonio:seed", IMAGE_ATTR_INT, NULL, 1, 0, NULL}};
        image_attr attr_b[] = {{"gonio:spp", IMAGE_ATTR_INT, NULL, 3, 0, NULL}, {"gonio:seed", IMAGE_ATTR_INT, NULL, 2, 0, NULL}};
        char *argv[] = {"merge", b_path, a_path, "-o", o_path, NULL};
        unlink(o_path);
        CHECK(image_write_exr(&a, a_path, attr_a, 2) && image_write_exr(&a, b_path, attr_b, 2));
        CHECKF(cmd_merge(5, argv) == 1, "merge took gonio:spp %s", bad[k].what);
        CHECKF(access(o_path, F_OK) != 0, "merge wrote an output for gonio:spp %s", bad[k].what);
    }
    {
        /* 2^31 - 1 twice: the total wraps in 32 bits. */
        image_attr attr_a[] = {{"gonio:spp", IMAGE_ATTR_INT, NULL, INT32_MAX, 0, NULL}, {"gonio:seed", IMAGE_ATTR_INT, NULL, 1, 0, NULL}};
        image_attr attr_b[] = {{"gonio:spp", IMAGE_ATTR_INT, NULL, INT32_MAX, 0, NULL}, {"gonio:seed", IMAGE_ATTR_INT, NULL, 2, 0, NULL}};
        char *argv[] = {"merge", a_path, b_path, "-o", o_path, NULL};
        CHECK(image_write_exr(&a, a_path, attr_a, 2) && image_write_exr(&a, b_path, attr_b, 2));
        CHECKF(cmd_merge(5, argv) == 1, "merge took a total of 2^32 - 2 samples");
        CHECK(access(o_path, F_OK) != 0);
    }
    {
        /* Seed 4 in both (once as a merge's list): refused, and merged with --force. */
        image_attr attr_a[] = {{"gonio:spp", IMAGE_ATTR_INT, NULL, 2, 0, NULL}, {"gonio:seed", IMAGE_ATTR_INT, NULL, 4, 0, NULL}};
        image_attr attr_b[] = {{"gonio:spp", IMAGE_ATTR_INT, NULL, 6, 0, NULL}, {"gonio:seeds", IMAGE_ATTR_STRING, "3,4,5", 0, 0, NULL}};
        char *argv[] = {"merge", a_path, b_path, "-o", o_path, NULL};
        char *forced[] = {"merge", "--force", a_path, b_path, "-o", o_path, NULL};
        char seeds[64] = "";
        CHECK(image_write_exr(&a, a_path, attr_a, 2) && image_write_exr(&a, b_path, attr_b, 2));
        CHECKF(cmd_merge(5, argv) == 1, "merge took seed 4 twice");
        CHECK(access(o_path, F_OK) != 0);
        CHECK(cmd_merge(6, forced) == 0);
        CHECK(image_exr_attr_string(o_path, "gonio:seeds", seeds, sizeof seeds) && !strcmp(seeds, "4,3,4,5"));
    }
    image_destroy(&a);
    unlink(a_path);
    unlink(b_path);
    unlink(o_path);
}

/* A path longer than one invocation may run: camera rays down the axis of the comb (50,000
 * teeth whose boxes all hold the axis, src/scene/meshgen.c) visit every node before they reach the
 * triangle across its far end, far more loop iterations than llvmpipe lets an invocation
 * run. Every surface emits radiance 1 (both sides) and reflects nothing (black, no specular),
 * so each sample is exactly 1 whatever happens after the first hit: the image must be 1
 * everywhere. A path cut short would give 0 (the answer before paths were resumed), one
 * dropped or added twice a sum that is not spp. */
TEST(path, loop_cap)
{
    char path[256];
    gpu g = {0};
    scene sc = {0};
    renderer r = {0};
    image img = {0};
    render_stats st = {0};
    meshgen_mesh m = meshgen_comb(50000);
    gltf_write_mesh mesh = {.num_vertices = m.num_vertices, .positions = m.positions,
                            .num_indices = 3 * m.num_triangles, .indices = m.indices};
    gltf_write_material mat = {.base_color = {0, 0, 0, 1}, .roughness = 1, .emissive = {1, 1, 1},
                               .has_specular = true, .double_sided = true};
    /* (half a degree's hundredth: the rays stay within 0.3 of the axis, off every tooth, and
     * all meet the far triangle) */
    gltf_write_camera cam = {.yfov = 1.2e-5f, .aspect = 1};
    gltf_write_node nodes[] = {{.kind = GLTF_WRITE_NODE_MESH},
                               {.kind = GLTF_WRITE_NODE_CAMERA, .translation = {0, 0, -1},
                                .rotation = {0, 1, 0, 0}}};
    gltf_write_desc d = {.meshes = &mesh, .num_meshes = 1, .materials = &mat, .num_materials = 1,
                         .cameras = &cam, .num_cameras = 1, .nodes = nodes, .num_nodes = 2};
    render_settings s = {.width = 8, .height = 8, .spp = 3, .camera = 0, .seed = 1,
                         .mode = GN_MODE_PATH};
    tmp_file(path, sizeof path, "comb.gltf");
    CHECK(gltf_write_file(path, &d));
    meshgen_destroy(&m);
    if (!test_open_gpu(&g))
        return;
    if (scene_load(&sc, path)) {
        renderer_create(&r, &g, &sc);
        if (renderer_render(&r, &s, &img, &st)) {
            int wrong = 0;
            for (int p = 0; p < 64; p++)
                for (int c = 0; c < 4; c++)
                    wrong += img.planes[c][p] != 1.0f;
            CHECKF(wrong == 0, "%d of 256 values are not exactly 1 (pixel 0: %g %g %g %g)", wrong,
                   img.planes[0][0], img.planes[1][0], img.planes[2][0], img.planes[3][0]);
            CHECKF(st.truncated == 0, "%u pixel passes were cut short", st.truncated);
            if (strstr(g.props.deviceName, "llvmpipe"))
                CHECKF(st.resumes > 0, "no path needed resuming on %s: the test tests nothing",
                       g.props.deviceName);
            printf("    comb: %u dispatch(es) finished interrupted paths\n", st.resumes);
        } else {
            CHECKF(false, "rendering the comb failed");
        }
        renderer_destroy(&r);
    } else {
        CHECKF(false, "loading %s failed", path);
    }
    image_destroy(&img);
    scene_destroy(&sc);
    gpu_destroy(&g);
}
