/* test_tangent.c: src/scene/tangent.c on meshes whose tangents follow from the glTF convention by
 * hand: bitangent = cross(normal, tangent.xyz) * w must point toward decreasing v (glTF's
 * uv origin is the image's top left, and a normal map's +Y is up in the image). */
#include <math.h>
#include <stdlib.h>

#include "tangent.h"
#include "test.h"

static void cross(const float *a, const float *b, double *out)
{
    out[0] = (double)a[1] * b[2] - (double)a[2] * b[1];
    out[1] = (double)a[2] * b[0] - (double)a[0] * b[2];
    out[2] = (double)a[0] * b[1] - (double)a[1] * b[0];
}

/* Output vertex v: tangent within tol of (x, y, z), w == sign, the bitangent along (bx, by,
 * bz), all unit and orthogonal to the normal. */
static void check_vertex(const float *nrm, const uint32_t *remap, const float *tan, size_t v,
                         const double t[3], float sign, const double b[3], double tol)
{
    const float *n = &nrm[3 * remap[v]], *tv = &tan[4 * v];
    double bt[3];
    cross(n, tv, bt);
    for (int k = 0; k < 3; k++)
        bt[k] *= tv[3];
    CHECKF(fabs(tv[0] - t[0]) <= tol && fabs(tv[1] - t[1]) <= tol && fabs(tv[2] - t[2]) <= tol,
           "vertex %zu: tangent (%g %g %g), expected (%g %g %g)", v, tv[0], tv[1], tv[2], t[0], t[1], t[2]);
    CHECKF(tv[3] == sign, "vertex %zu: w %g, expected %g", v, tv[3], sign);
    CHECKF(fabs(bt[0] - b[0]) <= tol && fabs(bt[1] - b[1]) <= tol && fabs(bt[2] - b[2]) <= tol,
           "vertex %zu: bitangent (%g %g %g), expected (%g %g %g)", v, bt[0], bt[1], bt[2], b[0], b[1], b[2]);
}

/* The quad of the glTF Asset Generator's Mesh_PrimitiveAttribute_06 (which supplies tangent
 * (1, 0, 0, 1)): normal +Z, u along +X, v along -Y. The image's up is +Y, so the bitangent
 * is +Y and w = +1. With u mirrored (u along -X) the tangent is -X and w = -1: the
 * bitangent stays +Y. */
TEST(tangent, plane)
{
    const float pos[] = {0.5f, -0.5f, 0, -0.5f, -0.5f, 0, -0.5f, 0.5f, 0, 0.5f, 0.5f, 0};
    const float nrm[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const float uv[] = {1, 1, 0, 1, 0, 0, 1, 0};
    const float uv_mirror[] = {0, 1, 1, 1, 1, 0, 0, 0};
    const double up[3] = {0, 1, 0}, px[3] = {1, 0, 0}, nx[3] = {-1, 0, 0};
    for (int mirror = 0; mirror < 2; mirror++) {
        uint32_t idx[] = {1, 0, 3, 1, 3, 2}, *remap;
        float *tan;
        size_t n = tangent_generate(4, pos, nrm, mirror ? uv_mirror : uv, 2, idx, &remap, &tan);
        CHECKF(n == 4, "mirror %d: %zu vertices, expected 4 (nothing to split)", mirror, n);
        for (size_t v = 0; v < n; v++)
            check_vertex(nrm, remap, tan, v, mirror ? nx : px, mirror ? -1.0f : 1.0f, up, 1e-6);
        free(remap);
        free(tan);
    }
}

/* Two quads side by side sharing the edge x = 1, the right one a mirror image of the left in
 * uv (u = x, then u = 2 - x; the shared vertices have one uv): the seam's two vertices are
 * split, the left side keeps tangent +X and w = +1, the right gets -X and w = -1. */
TEST(tangent, mirror_seam)
{
    const float pos[] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 1, 1, 0, 2, 1, 0};
    const float nrm[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const float uv[] = {0, 1, 1, 1, 0, 1, 0, 0, 1, 0, 0, 0}; /* v = 1 - y */
    uint32_t idx[] = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4}, *remap;
    const uint32_t orig[12] = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4};
    const double up[3] = {0, 1, 0}, px[3] = {1, 0, 0}, nx[3] = {-1, 0, 0};
    float *tan;
    size_t n = tangent_generate(6, pos, nrm, uv, 4, idx, &remap, &tan);
    CHECKF(n == 8, "%zu vertices, expected 8 (the seam's two split)", n);
    for (size_t c = 0; c < 12 && n == 8; c++) {
        bool right = c >= 6;
        CHECK(remap[idx[c]] == orig[c]);
        check_vertex(nrm, remap, tan, idx[c], right ? nx : px, right ? -1.0f : 1.0f, up, 1e-6);
    }
    free(remap);
    free(tan);
}

/* An open cylinder around +Y, outward normals, u = phi / 2pi around it (the seam's columns
 * duplicated, as uv maps have them), v = 1 - y. At every vertex the tangent is dP/du's
 * direction (-sin phi, 0, cos phi): by symmetry the angle-weighted chords of the two
 * neighbouring faces average to it, and a seam vertex's one chord projects onto it. Seen from
 * outside, u runs right to left (a mirrored mapping), so w = -1 with the bitangent +Y. */
TEST(tangent, cylinder)
{
    enum { N = 12 };
    float pos[2 * (N + 1) * 3], nrm[2 * (N + 1) * 3], uv[2 * (N + 1) * 2];
    uint32_t idx[6 * N], *remap;
    const double up[3] = {0, 1, 0};
    float *tan;
    for (int i = 0; i <= N; i++)
        for (int j = 0; j < 2; j++) {
            int v = 2 * i + j;
            double phi = 2 * M_PI * i / N;
            pos[3 * v] = (float)cos(phi), pos[3 * v + 1] = (float)j, pos[3 * v + 2] = (float)sin(phi);
            nrm[3 * v] = (float)cos(phi), nrm[3 * v + 1] = 0, nrm[3 * v + 2] = (float)sin(phi);
            uv[2 * v] = (float)i / N, uv[2 * v + 1] = (float)(1 - j);
        }
    for (int i = 0; i < N; i++) {
        uint32_t b0 = 2 * i, t0 = b0 + 1, b1 = b0 + 2, t1 = b0 + 3;
        uint32_t q[6] = {b0, t1, b1, b0, t0, t1}; /* wound outward */
        for (int k = 0; k < 6; k++)
            idx[6 * i + k] = q[k];
    }
    size_t n = tangent_generate(2 * (N + 1), pos, nrm, uv, 2 * N, idx, &remap, &tan);
    CHECKF(n == 2 * (N + 1), "%zu vertices, expected %d", n, 2 * (N + 1));
    for (size_t v = 0; v < n; v++) {
        const float *p = &pos[3 * remap[v]];
        double phi = atan2(p[2], p[0]), t[3] = {-sin(phi), 0, cos(phi)};
        check_vertex(nrm, remap, tan, v, t, -1.0f, up, 1e-5);
    }
    free(remap);
    free(tan);
}

/* A triangle with no uv area still gets a unit tangent orthogonal to its normal, and one
 * beside a good triangle takes that one's tangent. */
TEST(tangent, degenerate)
{
    const float pos[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    const float nrm[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const float uv0[] = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
    const float uv1[] = {0, 1, 1, 1, 0, 0, 1, 0}; /* good for (0 1 3), the other: */
    float uv1b[8];
    for (int k = 0; k < 8; k++)
        uv1b[k] = uv1[k];
    uv1b[4] = 0.5f, uv1b[5] = 0.5f; /* vertex 2 between 0 and 3 in uv: (0 3 2) has no uv area */
    for (int c = 0; c < 2; c++) {
        uint32_t idx[] = {0, 1, 3, 0, 3, 2}, *remap;
        float *tan;
        size_t n = tangent_generate(4, pos, nrm, c ? uv1b : uv0, 2, idx, &remap, &tan);
        CHECK(n >= 4);
        for (size_t v = 0; v < n; v++) {
            const float *t = &tan[4 * v];
            double len = sqrt((double)t[0] * t[0] + (double)t[1] * t[1] + (double)t[2] * t[2]);
            CHECKF(fabs(len - 1) < 1e-6 && fabs(t[2]) < 1e-6 && fabs(t[3]) == 1,
                   "case %d vertex %zu: tangent (%g %g %g %g)", c, v, t[0], t[1], t[2], t[3]);
        }
        if (c == 1) /* vertex 0 and 3 of the degenerate triangle: the good one's +X */
            for (int k = 3; k < 6; k++)
                if (remap[idx[k]] != 2)
                    CHECKF(tan[4 * idx[k]] > 0.999f, "corner %d: tangent x %g", k, tan[4 * idx[k]]);
        free(remap);
        free(tan);
    }
}
