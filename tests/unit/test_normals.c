/* test_normals.c: normal maps on files the project did not write (the glTF Asset Generator's
 * Mesh_PrimitiveAttribute set and Khronos's NormalTangentTest, from the test assets): the
 * tangents the loader generates where TANGENT is absent against the ones a file supplies,
 * normal-mapped cells against the real geometry they imitate, and no black where a strong
 * normal map turns the shading normal away from the viewer. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gpu.h"
#include "image.h"
#include "render.h"
#include "scene.h"
#include "test.h"

/* A camera at (0, 0, z) looking down -Z, +Y up. */
static GnCamera front_camera(float z, float tan_half_fovy)
{
    return (GnCamera){.position = {0, 0, z}, .tan_half_fovy = tan_half_fovy, .right = {1, 0, 0},
                      .aspect = 1, .up = {0, 1, 0}, .znear = 0.01f, .forward = {0, 0, -1}, .zfar = 1e30f};
}

/* Loads an asset (path under the assets directory), lets `edit` change it, renders it. */
static bool render_asset(gpu *g, const char *rel, uint32_t mode, int size, int spp, const GnCamera *cam,
                         void (*edit)(scene *), image *out)
{
    const char *dir = test_assets_dir();
    char path[1024];
    scene sc = {0};
    renderer r = {0};
    render_stats st;
    render_settings s = {.mode = mode, .width = size, .height = size, .spp = spp, .camera = -1,
                         .env = {1, 1, 1}, .seed = 1, .camera_override = cam};
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    bool ok = scene_load(&sc, path);
    CHECKF(ok, "cannot load %s", path);
    if (ok) {
        if (edit)
            edit(&sc);
        renderer_create(&r, g, &sc);
        ok = renderer_render(&r, &s, out, &st);
        CHECKF(ok, "rendering %s failed", path);
        renderer_destroy(&r);
    }
    scene_destroy(&sc);
    return ok;
}

static bool open_assets(gpu *g)
{
    if (!test_assets_dir()) {
        test_skip("the test assets are absent");
        return false;
    }
    return test_open_gpu(g);
}

/* Mesh_PrimitiveAttribute_05 is _06 without its TANGENT accessor (tangent (1, 0, 0, 1) on a
 * quad of normal +Z, u along +X, v along -Y): the generated tangents must give the same
 * normals. (Before the loader generated them, per-triangle uv tangents of the opposite
 * handedness gave RMSE 0.24.) */
TEST(normals, generated_tangents)
{
    const char *dir = "asset-generator/Mesh_PrimitiveAttribute";
    char a[256], b[256];
    GnCamera cam = front_camera(1.3f, 0.45f); /* the set's Manifest.json camera */
    image ia = {0}, ib = {0};
    gpu g = {0};
    if (!open_assets(&g))
        return;
    snprintf(a, sizeof a, "%s/Mesh_PrimitiveAttribute_05.gltf", dir);
    snprintf(b, sizeof b, "%s/Mesh_PrimitiveAttribute_06.gltf", dir);
    if (render_asset(&g, a, GN_MODE_NORMAL, 96, 1, &cam, NULL, &ia) &&
        render_asset(&g, b, GN_MODE_NORMAL, 96, 1, &cam, NULL, &ib)) {
        double se = 0, bent = 0;
        int n = 0;
        for (int p = 0; p < 96 * 96; p++) {
            if (ib.planes[3][p] != 1.0f)
                continue;
            for (int c = 0; c < 3; c++) {
                double d = (double)ia.planes[c][p] - ib.planes[c][p];
                se += d * d;
            }
            bent += 1 - ib.planes[2][p];
            n++;
        }
        double rmse = n ? sqrt(se / (3.0 * n)) : 1;
        CHECKF(n > 2000, "only %d pixels cover the quad", n);
        /* the map must do something, or equal images prove nothing */
        CHECKF(n && bent / n > 0.02, "the normal map bends the normals by only %g on average", n ? bent / n : 0);
        CHECKF(rmse < 0.02, "normals of _05 (generated tangents) and _06 (its own) differ: RMSE %g", rmse);
    }
    image_destroy(&ia);
    image_destroy(&ib);
    gpu_destroy(&g);
}

/* NormalTangentTest (no TANGENT): 15 pairs of cells, real bumps of radius ~0.1 on the left,
 * a flat quad with their normal map 0.32 to the right (the layout of its README's
 * screenshot; cells in columns at x = -0.96, -0.16, 0.64, rows at y = -0.8 ... 0.8). Seen
 * from the front, each mapped cell's normals must be its geometric twin's, and on both the
 * upper half of a bump faces up (+Y) and the right half right: the pattern that a flipped
 * green channel or wrong handedness turns around. */
TEST(normals, tangent_test_layout)
{
    enum { S = 480 };
    const float dist = 6, th = 1.25f / 6; /* the frame spans [-1.25, 1.25] at z = 0 */
    GnCamera cam = front_camera(dist, th);
    image img = {0};
    gpu g = {0};
    if (!open_assets(&g))
        return;
    if (render_asset(&g, "gltf/NormalTangentTest/glTF/NormalTangentTest.gltf", GN_MODE_NORMAL, S, 1, &cam,
                     NULL, &img)) {
        const double cx[3] = {-0.96, -0.16, 0.64}, cy[5] = {-0.8, -0.4, 0, 0.4, 0.8}, shift = 0.32;
        double worst = 0;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 5; j++) {
                double se = 0, up = 0, right = 0;
                int n = 0;
                /* pixels of the bump's disc (r < 0.08) in the geometric cell; the mapped twin is
                 * `shift` to the right, in pixels shift / (2 th dist / S) */
                for (int y = 0; y < S; y++)
                    for (int x = 0; x < S; x++) {
                        double wx = (2.0 * (x + 0.5) / S - 1) * th * dist, wy = (1 - 2.0 * (y + 0.5) / S) * th * dist;
                        double rx = wx - cx[i], ry = wy - cy[j];
                        if (rx * rx + ry * ry > 0.08 * 0.08)
                            continue;
                        int xm = x + (int)lround(shift / (2.0 * th * dist / S));
                        int p = y * S + x, q = y * S + xm;
                        for (int c = 0; c < 3; c++) {
                            double d = (double)img.planes[c][p] - img.planes[c][q];
                            se += d * d;
                        }
                        up += (ry > 0 ? 1 : -1) * img.planes[1][q];
                        right += (rx > 0 ? 1 : -1) * img.planes[0][q];
                        n++;
                    }
                double rmse = n ? sqrt(se / (3.0 * n)) : 1;
                worst = rmse > worst ? rmse : worst;
                CHECKF(n > 200 && up / n > 0.1 && right / n > 0.1,
                       "cell (%d, %d): the mapped bump leans the wrong way (up %g, right %g over %d pixels)",
                       i, j, n ? up / n : 0, n ? right / n : 0, n);
                CHECKF(rmse < 0.12, "cell (%d, %d): mapped normals differ from the geometry's: RMSE %g", i, j, rmse);
            }
        printf("    worst cell RMSE %.3f\n", worst);
    }
    image_destroy(&img);
    gpu_destroy(&g);
}

static void scale_normals(scene *sc)
{
    for (uint32_t i = 0; i < sc->num_materials; i++)
        sc->materials[i].normal_scale = 8;
}

/* Mesh_PrimitiveAttribute_06 with its normal map scaled 8 times, path traced under a white
 * environment at grazing view: where the shading normal would turn away from the viewer, a
 * BSDF sees the viewer below the surface and gives black; bent back (surface_at), every
 * pixel of the quad is lit. */
TEST(normals, strong_scale)
{
    const float ang = 1.2f; /* 69 degrees from the normal, looking down at the quad */
    GnCamera cam = front_camera(0, 0.2f);
    image img = {0};
    gpu g = {0};
    if (!open_assets(&g))
        return;
    cam.position = (vec3){0, -1.5f * sinf(ang), 1.5f * cosf(ang)};
    cam.forward = (vec3){0, sinf(ang), -cosf(ang)};
    cam.up = (vec3){0, cosf(ang), sinf(ang)};
    if (render_asset(&g, "asset-generator/Mesh_PrimitiveAttribute/Mesh_PrimitiveAttribute_06.gltf", GN_MODE_PATH,
                     64, 16, &cam, scale_normals, &img)) {
        int n = 0, dark = 0;
        for (int p = 0; p < 64 * 64; p++)
            if (img.planes[3][p] == 1.0f) {
                n++;
                dark += img.planes[0][p] + img.planes[1][p] + img.planes[2][p] < 0.01f;
            }
        CHECKF(n > 1000, "only %d pixels cover the quad", n);
        CHECKF(dark == 0, "%d of %d pixels are black", dark, n);
    }
    image_destroy(&img);
    gpu_destroy(&g);
}
