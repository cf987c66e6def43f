/* test_skin.c: skins and morph targets through scene_load, against poses computed here from
 * the glTF 2.0 specification's formulas ("Skins": the joint matrix is the joint's world
 * transform times its inverse bind matrix, a vertex moves by the weighted sum of its joints'
 * matrices, the skinned node's own transform is ignored; "Morph Targets": the base plus the
 * weighted displacements, before skinning; "Animations": LINEAR, STEP and the CUBICSPLINE
 * Hermite form). The test's own arithmetic: rotations from Rodrigues' formula (axis and
 * angle, not the loader's quaternion), translations added by hand, weights interpolated
 * here. The scenes are written here: a two-bone strip with two JOINTS/WEIGHTS sets (unsigned
 * byte joints and float weights, unsigned short joints and normalized weights), a quad
 * with two morph targets (one sparse), its weights from the mesh, the node and three
 * animations, and quads whose targets tilt flat normals and tangents. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "scene.h"
#include "scene_files.h"
#include "test.h"
#include "util.h"

/* ---- a glTF file built in memory ---------------------------------------------------------- */

typedef struct gltf_file {
    unsigned char bin[8192];
    size_t size;
    char views[4096], accessors[8192];
    int num_views, num_accessors;
} gltf_file;

static void app(char *dst, size_t cap, const char *fmt, ...)
{
    size_t n = strlen(dst);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(dst + n, cap - n, fmt, ap);
    va_end(ap);
}

/* Appends `bytes` as a buffer view (4-byte aligned) and returns its index. */
static int view(gltf_file *f, const void *bytes, size_t n)
{
    f->size = (f->size + 3) & ~(size_t)3;
    memcpy(f->bin + f->size, bytes, n);
    app(f->views, sizeof f->views, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", f->num_views ? "," : "",
        f->size, n);
    f->size += n;
    return f->num_views++;
}

/* An accessor of `count` elements of `type` over a new view of `bytes`; `extra` is more JSON
 * ("" or ",\"normalized\":true" or ",\"min\":...,\"max\":..."). */
static int accessor(gltf_file *f, const void *bytes, size_t n, int component, size_t count, const char *type,
                    const char *extra)
{
    int v = view(f, bytes, n);
    app(f->accessors, sizeof f->accessors, "%s{\"bufferView\":%d,\"componentType\":%d,\"count\":%zu,\"type\":\"%s\"%s}",
        f->num_accessors ? "," : "", v, component, count, type, extra);
    return f->num_accessors++;
}

/* A sparse accessor without a buffer view: zeros but for `n` elements (indices u16). */
static int sparse_vec3(gltf_file *f, size_t count, const uint16_t *idx, const float *values, int n)
{
    int vi = view(f, idx, sizeof *idx * (size_t)n), vv = view(f, values, 12 * (size_t)n);
    app(f->accessors, sizeof f->accessors,
        "%s{\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\",\"sparse\":{\"count\":%d,"
        "\"indices\":{\"bufferView\":%d,\"componentType\":5123},\"values\":{\"bufferView\":%d}}}",
        f->num_accessors ? "," : "", count, n, vi, vv);
    return f->num_accessors++;
}

/* The unit quad [0, 1]^2 at z = 0 facing +z, as a file's first accessors: 0 POSITION (with
 * its bounds), 1 NORMAL, 2 its indices. The scenes below morph and skin it. */
static const float quad_pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
static void quad_accessors(gltf_file *f)
{
    static const float nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    static const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    accessor(f, quad_pos, sizeof quad_pos, 5126, 4, "VEC3", ",\"min\":[0,0,0],\"max\":[1,1,0]");
    accessor(f, nrm, sizeof nrm, 5126, 4, "VEC3", "");
    accessor(f, idx, sizeof idx, 5123, 6, "SCALAR", "");
}

/* The quad's accessors and, after them, 3 JOINTS_0 (every vertex joint 0) and 4 WEIGHTS_0
 * (weight 1): the scenes below skin it with one joint. */
static void skinned_quad_accessors(gltf_file *f)
{
    static const uint8_t joints[16] = {0};
    static const float weights[16] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    quad_accessors(f);
    accessor(f, joints, sizeof joints, 5121, 4, "VEC4", "");
    accessor(f, weights, sizeof weights, 5126, 4, "VEC4", "");
}

/* Writes the file (`rest`: meshes, nodes, skins, animations, scenes) and loads it at time t
 * (< 0: the nodes' own transforms), its messages in load_log. */
static bool write_and_load(scene *s, const gltf_file *f, const char *rest, double t)
{
    const char *path = "/tmp/gonio_skin_test.gltf";
    char *b64 = base64(f->bin, f->size);
    FILE *out = fopen(path, "wb");
    fprintf(out, "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"data:application/octet-stream;base64,%s\","
            "\"byteLength\":%zu}],\"bufferViews\":[%s],\"accessors\":[%s],%s}", b64, f->size, f->views, f->accessors, rest);
    fclose(out);
    free(b64);
    scene_animation_time(t);
    bool ok = load(s, path);
    scene_animation_time(-1);
    return ok;
}

/* write_and_load at no animation time, a failure checked (its log printed): whether it loaded. */
static bool loads(scene *s, const gltf_file *f, const char *rest)
{
    bool ok = write_and_load(s, f, rest, -1);
    CHECKF(ok, "%s", load_log);
    return ok;
}

/* ---- the test's own arithmetic ------------------------------------------------------------ */

/* 3x3 rotation (row-major) by `deg` degrees about the unit axis a (Rodrigues). */
static void rotation(const double a[3], double deg, double r[3][3])
{
    double th = deg * M_PI / 180, c = cos(th), s = sin(th), C = 1 - c;
    r[0][0] = c + a[0] * a[0] * C;
    r[0][1] = a[0] * a[1] * C - a[2] * s;
    r[0][2] = a[0] * a[2] * C + a[1] * s;
    r[1][0] = a[1] * a[0] * C + a[2] * s;
    r[1][1] = c + a[1] * a[1] * C;
    r[1][2] = a[1] * a[2] * C - a[0] * s;
    r[2][0] = a[2] * a[0] * C - a[1] * s;
    r[2][1] = a[2] * a[1] * C + a[0] * s;
    r[2][2] = c + a[2] * a[2] * C;
}

static void mul3(const double m[3][3], const double v[3], double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
}

/* The inverse of m by Gauss-Jordan elimination with partial pivoting. */
static void inverse3(const double m[3][3], double inv[3][3])
{
    double a[3][6];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 6; j++)
            a[i][j] = j < 3 ? m[i][j] : (j - 3 == i);
    for (int col = 0; col < 3; col++) {
        int piv = col;
        for (int i = col + 1; i < 3; i++)
            if (fabs(a[i][col]) > fabs(a[piv][col]))
                piv = i;
        for (int j = 0; j < 6; j++) {
            double t = a[col][j];
            a[col][j] = a[piv][j];
            a[piv][j] = t;
        }
        double d = a[col][col];
        for (int j = 0; j < 6; j++)
            a[col][j] /= d;
        for (int i = 0; i < 3; i++)
            if (i != col) {
                double k = a[i][col];
                for (int j = 0; j < 6; j++)
                    a[i][j] -= k * a[col][j];
            }
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            inv[i][j] = a[i][j + 3];
}

static void normalize(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++)
        v[k] /= l;
}

static bool close3(vec3 got, const double want[3], double tol)
{
    return fabs(got.x - want[0]) <= tol && fabs(got.y - want[1]) <= tol && fabs(got.z - want[2]) <= tol;
}

/* ---- skins -------------------------------------------------------------------------------- */

/* The strip: 6 vertices (x in -0.5, 0.5; y in 0, 1, 2), normal +Z, tangent +X. Joint 0 (node 1)
 * at (0.25, 0, 0); joint 1 (node 2) its child at (0, 0.5, 0), rotated by `deg` about the
 * axis (1, 0, 1)/sqrt 2 (animated: 0 degrees at t 0, 90 at t 1, LINEAR). Row y 0 follows
 * joint 0, row 2 joint 1, row 1 both: 0.6 (set 0, float) and 0.4 (set 1, unsigned short
 * normalized). The skinned node (node 0) has a translation of (10, 0, 0) under a parent
 * scaled by 3, which glTF says to ignore. With ibm, the inverse bind matrices are those of
 * the joints at rest (deg 0); without, identity. */
static const double AXIS[3] = {0.70710678118654752, 0, 0.70710678118654752};

static bool load_strip(scene *s, double t, bool ibm, const char *joint1_rotation)
{
    gltf_file f = {0};
    const float pos[18] = {-0.5f, 0, 0, 0.5f, 0, 0, -0.5f, 1, 0, 0.5f, 1, 0, -0.5f, 2, 0, 0.5f, 2, 0};
    float nrm[18], tan[24];
    for (int v = 0; v < 6; v++) {
        memcpy(nrm + 3 * v, (float[3]){0, 0, 1}, 12);
        memcpy(tan + 4 * v, (float[4]){1, 0, 0, 1}, 16);
    }
    const uint16_t idx[12] = {0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4};
    const uint8_t j0[24] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    const float w0[24] = {1, 0, 0, 0, 1, 0, 0, 0, 0.6f, 0, 0, 0, 0.6f, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    const uint16_t j1[24] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    const uint16_t w1[24] = {0, 0, 0, 0, 0, 0, 0, 0, 26214, 0, 0, 0, 26214, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    const float ibms[32] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -0.25f, 0, 0, 1,
                            1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -0.25f, -0.5f, 0, 1};
    const float times[2] = {0, 1};
    const double h = sin(M_PI / 4); /* the quaternion of 90 degrees about AXIS: (sin 45 AXIS, cos 45) */
    const float quats[8] = {0, 0, 0, 1, (float)(h * AXIS[0]), 0, (float)(h * AXIS[2]), (float)h};
    accessor(&f, pos, sizeof pos, 5126, 6, "VEC3", ",\"min\":[-0.5,0,0],\"max\":[0.5,2,0]");
    accessor(&f, nrm, sizeof nrm, 5126, 6, "VEC3", "");
    accessor(&f, tan, sizeof tan, 5126, 6, "VEC4", "");
    accessor(&f, idx, sizeof idx, 5123, 12, "SCALAR", "");
    accessor(&f, j0, sizeof j0, 5121, 6, "VEC4", "");
    accessor(&f, w0, sizeof w0, 5126, 6, "VEC4", "");
    accessor(&f, j1, sizeof j1, 5123, 6, "VEC4", "");
    accessor(&f, w1, sizeof w1, 5123, 6, "VEC4", ",\"normalized\":true");
    accessor(&f, ibms, sizeof ibms, 5126, 2, "MAT4", "");
    accessor(&f, times, sizeof times, 5126, 2, "SCALAR", ",\"min\":[0],\"max\":[1]");
    accessor(&f, quats, sizeof quats, 5126, 2, "VEC4", "");
    char rest[2048];
    snprintf(rest, sizeof rest,
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TANGENT\":2,\"JOINTS_0\":4,"
             "\"WEIGHTS_0\":5,\"JOINTS_1\":6,\"WEIGHTS_1\":7},\"indices\":3}]}],"
             "\"nodes\":[{\"mesh\":0,\"skin\":0,\"translation\":[10,0,0]},{\"translation\":[0.25,0,0],\"children\":[2]},"
             "{\"translation\":[0,0.5,0]%s},{\"scale\":[3,3,3],\"children\":[0]}],"
             "\"skins\":[{\"joints\":[1,2]%s}],"
             "\"animations\":[{\"samplers\":[{\"input\":9,\"output\":10}],"
             "\"channels\":[{\"sampler\":0,\"target\":{\"node\":2,\"path\":\"rotation\"}}]}],"
             "\"scenes\":[{\"nodes\":[3,1]}]",
             joint1_rotation, ibm ? ",\"inverseBindMatrices\":8" : "");
    return write_and_load(s, &f, rest, t);
}

/* The strip's pose with joint 1 turned `deg` degrees, computed here: joint 0's matrix J0 is
 * T(0.25) x IBM0 and joint 1's J1 = T(0.25) T(0, 0.5) R x IBM1; a vertex p goes to
 * sum w J p, its normal by the inverse transpose of sum w J, its tangent by sum w J. */
static void check_strip(const scene *s, double deg, bool ibm, const char *what)
{
    CHECKF(s->num_vertices == 6 && s->num_triangles == 4, "%s: %u vertices", what, s->num_vertices);
    if (s->num_vertices != 6)
        return;
    double r[3][3];
    rotation(AXIS, deg, r);
    /* J0 and J1 as a 3x3 part and a translation */
    const double t0[3] = {ibm ? 0 : 0.25, 0, 0};
    double t1[3], ib1[3] = {ibm ? -0.25 : 0, ibm ? -0.5 : 0, 0}, rib[3];
    mul3(r, ib1, rib);
    for (int k = 0; k < 3; k++)
        t1[k] = (k == 0 ? 0.25 : k == 1 ? 0.5 : 0) + rib[k];
    const double id[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int v = 0; v < 6; v++) {
        const double p[3] = {v % 2 ? 0.5 : -0.5, v / 2, 0};
        const double wj1 = v / 2 == 0 ? 0 : v / 2 == 2 ? 1 : 26214 / 65535.0, wj0 = v / 2 == 1 ? 0.6 : 1 - wj1;
        double m[3][3], tr[3], want[3], n[3], tg[3];
        for (int i = 0; i < 3; i++) {
            for (int j = 0; j < 3; j++)
                m[i][j] = wj0 * id[i][j] + wj1 * r[i][j];
            tr[i] = wj0 * t0[i] + wj1 * t1[i];
        }
        mul3(m, p, want);
        for (int k = 0; k < 3; k++)
            want[k] += tr[k];
        double inv[3][3], invt[3][3];
        inverse3(m, inv);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                invt[i][j] = inv[j][i];
        mul3(invt, (double[3]){0, 0, 1}, n);
        normalize(n);
        mul3(m, (double[3]){1, 0, 0}, tg);
        normalize(tg);
        const GnVertex *g = &s->vertices[v];
        CHECKF(close3(g->position, want, 2e-5), "%s: vertex %d at (%g, %g, %g), expected (%g, %g, %g)", what, v,
               g->position.x, g->position.y, g->position.z, want[0], want[1], want[2]);
        CHECKF(close3(g->normal, n, 2e-5), "%s: vertex %d normal (%g, %g, %g), expected (%g, %g, %g)", what, v,
               g->normal.x, g->normal.y, g->normal.z, n[0], n[1], n[2]);
        CHECKF(close3((vec3){g->tangent.x, g->tangent.y, g->tangent.z}, tg, 2e-5) && g->tangent.w == 1,
               "%s: vertex %d tangent (%g, %g, %g, %g), expected (%g, %g, %g, 1)", what, v, g->tangent.x, g->tangent.y,
               g->tangent.z, g->tangent.w, tg[0], tg[1], tg[2]);
    }
}

/* Joint 1's own rotation (30 degrees about AXIS) without --at; the animation's slerp at
 * t 0.5 (45 degrees) and after its last key (90); identity inverse bind matrices. */
TEST(skin, two_bone_strip)
{
    scene s;
    char rot[128];
    const double h = sin(M_PI / 12); /* 30 degrees: (sin 15 AXIS, cos 15) */
    snprintf(rot, sizeof rot, ",\"rotation\":[%.17g,0,%.17g,%.17g]", h * AXIS[0], h * AXIS[2], cos(M_PI / 12));
    struct { double t, deg; bool ibm; const char *what; } cases[] = {
        {-1, 30, true, "own transforms"}, {0.5, 45, true, "t 0.5"}, {2, 90, true, "after the last key"},
        {0.25, 22.5, false, "no inverseBindMatrices"}};
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        bool ok = load_strip(&s, cases[i].t, cases[i].ibm, rot);
        CHECKF(ok, "%s: %s", cases[i].what, load_log);
        if (ok)
            check_strip(&s, cases[i].deg, cases[i].ibm, cases[i].what);
        CHECKF(!strstr(load_log, "skin") && !strstr(load_log, "warning"), "%s: %s", cases[i].what, load_log);
        scene_destroy(&s);
    }
}

/* ---- morph targets ------------------------------------------------------------------------ */

/* The quad (0,0,0) (1,0,0) (1,1,0) (0,1,0), normal +Z, with target 0 lifting every vertex by
 * (0, 0, 1) and tilting its normal by (0.5, 0, 0), and target 1 a sparse POSITION moving
 * vertex 2 by (0.5, 0.5, 0). Mesh weights (0.5, 0.25). Nodes: 0 the mesh's weights, at the
 * origin; 1 its own weights (1, 1) at x 5; 2, 3, 4 animated LINEAR, STEP and CUBICSPLINE at
 * x 10, 15, 20; 5 the same quad (mesh 1) skinned to joint node 6, scaled by 2 and moved by
 * (0, 0, -3), with mesh 1's weights (1, 0.5) (morphing comes first, then the skin).
 * Animation keys at t 0, 1, 2: LINEAR (0, 0) (1, 0.5) (0.5, 1); STEP the same; CUBICSPLINE
 * keys at 0 and 2, values (0, 0) and (1, 0.5), in-tangents (9, 9) and (-1, 2), out-tangents
 * (2, -1) and (9, 9). */
static bool load_quad(scene *s, double t)
{
    gltf_file f = {0};
    const float lift[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const float tilt[12] = {0.5f, 0, 0, 0.5f, 0, 0, 0.5f, 0, 0, 0.5f, 0, 0};
    const uint16_t sp_idx[1] = {2};
    const float sp_val[3] = {0.5f, 0.5f, 0};
    const uint8_t joints[16] = {0};
    const float weights[16] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    const float t3[3] = {0, 1, 2}, t2[2] = {0, 2};
    const float lin[6] = {0, 0, 1, 0.5f, 0.5f, 1};
    const float cub[12] = {9, 9, 0, 0, 2, -1, -1, 2, 1, 0.5f, 9, 9};
    quad_accessors(&f);                                                                  /* 0-2 */
    accessor(&f, lift, sizeof lift, 5126, 4, "VEC3", "");                                /* 3 */
    accessor(&f, tilt, sizeof tilt, 5126, 4, "VEC3", "");                                /* 4 */
    sparse_vec3(&f, 4, sp_idx, sp_val, 1);                                               /* 5 */
    accessor(&f, joints, sizeof joints, 5121, 4, "VEC4", "");                            /* 6 */
    accessor(&f, weights, sizeof weights, 5126, 4, "VEC4", "");                          /* 7 */
    accessor(&f, t3, sizeof t3, 5126, 3, "SCALAR", "");                                  /* 8 */
    accessor(&f, lin, sizeof lin, 5126, 6, "SCALAR", "");                                /* 9 */
    accessor(&f, t2, sizeof t2, 5126, 2, "SCALAR", "");                                  /* 10 */
    accessor(&f, cub, sizeof cub, 5126, 12, "SCALAR", "");                               /* 11 */
    const char *targets = "\"targets\":[{\"POSITION\":3,\"NORMAL\":4},{\"POSITION\":5}]";
    char rest[4096];
    snprintf(rest, sizeof rest,
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2,%s}],"
             "\"weights\":[0.5,0.25]},"
             "{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"JOINTS_0\":6,\"WEIGHTS_0\":7},\"indices\":2,"
             "%s}],\"weights\":[1,0.5]}],"
             "\"nodes\":[{\"mesh\":0},{\"mesh\":0,\"weights\":[1,1],\"translation\":[5,0,0]},"
             "{\"mesh\":0,\"translation\":[10,0,0]},{\"mesh\":0,\"translation\":[15,0,0]},"
             "{\"mesh\":0,\"translation\":[20,0,0]},{\"mesh\":1,\"skin\":0,\"translation\":[7,7,7]},"
             "{\"scale\":[2,2,2],\"translation\":[0,0,-3]}],"
             "\"skins\":[{\"joints\":[6]}],"
             "\"animations\":[{\"samplers\":[{\"input\":8,\"output\":9},{\"input\":8,\"output\":9,\"interpolation\":\"STEP\"},"
             "{\"input\":10,\"output\":11,\"interpolation\":\"CUBICSPLINE\"}],"
             "\"channels\":[{\"sampler\":0,\"target\":{\"node\":2,\"path\":\"weights\"}},"
             "{\"sampler\":1,\"target\":{\"node\":3,\"path\":\"weights\"}},"
             "{\"sampler\":2,\"target\":{\"node\":4,\"path\":\"weights\"}}]}],"
             "\"scenes\":[{\"nodes\":[0,1,2,3,4,5,6]}]",
             targets, targets);
    return write_and_load(s, &f, rest, t);
}

/* Quad vertex v of instance i (offset x, lift and joint as given) with weights w0, w1. */
static void check_quad_vertex(const scene *s, int inst, int v, double x, double w0, double w1, double scale,
                              double dz, const char *what)
{
    const double base[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    double p[3], n[3] = {0.5 * w0, 0, 1};
    for (int k = 0; k < 3; k++)
        p[k] = base[v][k] + w0 * (k == 2 ? 1 : 0) + w1 * (v == 2 && k < 2 ? 0.5 : 0);
    for (int k = 0; k < 3; k++)
        p[k] = p[k] * scale + (k == 0 ? x : k == 2 ? dz : 0);
    normalize(n);
    const GnVertex *g = &s->vertices[4 * inst + v];
    CHECKF(close3(g->position, p, 1e-5), "%s: instance %d vertex %d at (%g, %g, %g), expected (%g, %g, %g)", what, inst,
           v, g->position.x, g->position.y, g->position.z, p[0], p[1], p[2]);
    CHECKF(close3(g->normal, n, 1e-5), "%s: instance %d vertex %d normal (%g, %g, %g), expected (%g, %g, %g)", what,
           inst, v, g->normal.x, g->normal.y, g->normal.z, n[0], n[1], n[2]);
}

/* The animated weights at time t, interpolated here. */
static void anim_weights(double t, double lin[2], double step[2], double cub[2])
{
    const double k[3][2] = {{0, 0}, {1, 0.5}, {0.5, 1}};
    int i = t >= 2 ? 2 : t >= 1 ? 1 : 0;
    for (int j = 0; j < 2; j++) {
        double u = i == 2 ? 0 : t - i;
        lin[j] = i == 2 ? k[2][j] : (1 - u) * k[i][j] + u * k[i + 1][j];
        step[j] = k[i][j];
    }
    /* CUBICSPLINE over keys 0 and 2 (td = 2): p(u) = h00 v0 + h10 td b0 + h01 v1 + h11 td a1 */
    const double v0[2] = {0, 0}, b0[2] = {2, -1}, v1[2] = {1, 0.5}, a1[2] = {-1, 2};
    double u = t >= 2 ? 1 : t / 2, td = 2;
    double h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u, h01 = -2 * u * u * u + 3 * u * u,
           h11 = u * u * u - u * u;
    for (int j = 0; j < 2; j++)
        cub[j] = t >= 2 ? v1[j] : h00 * v0[j] + h10 * td * b0[j] + h01 * v1[j] + h11 * td * a1[j];
}

TEST(skin, morph_targets)
{
    const double times[] = {-1, 0.25, 1.5, 0.999, 3};
    for (size_t i = 0; i < sizeof times / sizeof *times; i++) {
        scene s;
        char what[64];
        snprintf(what, sizeof what, "t %g", times[i]);
        bool ok = load_quad(&s, times[i]);
        CHECKF(ok, "%s: %s", what, load_log);
        if (!ok)
            continue;
        CHECKF(s.num_vertices == 24, "%s: %u vertices", what, s.num_vertices);
        CHECKF(!strstr(load_log, "warning"), "%s: %s", what, load_log);
        if (s.num_vertices == 24) {
            double lin[2] = {0.5, 0.25}, step[2] = {0.5, 0.25}, cub[2] = {0.5, 0.25};
            if (times[i] >= 0)
                anim_weights(times[i], lin, step, cub);
            for (int v = 0; v < 4; v++) {
                check_quad_vertex(&s, 0, v, 0, 0.5, 0.25, 1, 0, what);
                check_quad_vertex(&s, 1, v, 5, 1, 1, 1, 0, what);
                check_quad_vertex(&s, 2, v, 10, lin[0], lin[1], 1, 0, what);
                check_quad_vertex(&s, 3, v, 15, step[0], step[1], 1, 0, what);
                check_quad_vertex(&s, 4, v, 20, cub[0], cub[1], 1, 0, what);
                check_quad_vertex(&s, 5, v, 0, 1, 0.5, 2, -3, what);
            }
        }
        scene_destroy(&s);
    }
}

/* The sample models' skins, joints and morph targets, as their JSON lists them (read with a
 * Python script when the test was written), loaded without a warning. */
TEST(skin, sample_models)
{
    static const struct {
        const char *path;
        uint32_t skins, joints, targets, morphed;
    } models[] = {
        {"gltf/RiggedSimple/glTF/RiggedSimple.gltf", 1, 2, 0, 0},
        {"gltf/SimpleSkin/glTF/SimpleSkin.gltf", 1, 2, 0, 0},
        {"gltf/CesiumMan/glTF/CesiumMan.gltf", 1, 19, 0, 0},
        {"gltf/AnimatedMorphCube/glTF/AnimatedMorphCube.gltf", 0, 0, 2, 1},
        {"gltf/SimpleMorph/glTF/SimpleMorph.gltf", 0, 0, 2, 1},
        {"gltf/MorphPrimitivesTest/glTF/MorphPrimitivesTest.gltf", 0, 0, 1, 1},
    };
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    for (size_t i = 0; i < sizeof models / sizeof *models; i++) {
        char path[4096];
        scene s;
        snprintf(path, sizeof path, "%s/%s", test_assets_dir(), models[i].path);
        for (int at = 0; at < 2; at++) {
            int w0 = util_warning_count();
            scene_animation_time(at ? 0.7 : -1);
            bool ok = scene_load(&s, path);
            scene_animation_time(-1);
            CHECKF(ok && util_warning_count() == w0, "%s at %s: loaded %d, %d warnings", models[i].path,
                   at ? "0.7 s" : "its own transforms", ok, util_warning_count() - w0);
            if (!ok)
                continue;
            CHECKF(s.num_skins == models[i].skins && s.num_joints == models[i].joints &&
                       s.num_morph_targets == models[i].targets && s.num_morphed_meshes == models[i].morphed,
                   "%s: %u skins, %u joints, %u morph targets in %u meshes", models[i].path, s.num_skins,
                   s.num_joints, s.num_morph_targets, s.num_morphed_meshes);
            scene_destroy(&s);
        }
    }
}

/* A morphed quad without NORMAL gets the flat normals of its posed triangles (its corners
 * lifted by 0, 0.4, 1 and 0.2), and a TANGENT target moves tangents as a NORMAL target moves
 * normals (weight 0.5: normal (0, 0, 1) + 0.5 (0.5, 0, 0), tangent (1, 0, 0) + 0.5 (0, 0, -0.5)). */
TEST(skin, morph_flat_normals_and_tangents)
{
    gltf_file f = {0};
    const float tan[16] = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1};
    const float lift[12] = {0, 0, 0, 0, 0, 0.4f, 0, 0, 1, 0, 0, 0.2f};
    const float dn[12] = {0.5f, 0, 0, 0.5f, 0, 0, 0.5f, 0, 0, 0.5f, 0, 0};
    const float dt[12] = {0, 0, -0.5f, 0, 0, -0.5f, 0, 0, -0.5f, 0, 0, -0.5f};
    quad_accessors(&f);                                   /* 0-2 */
    accessor(&f, tan, sizeof tan, 5126, 4, "VEC4", "");   /* 3 */
    accessor(&f, lift, sizeof lift, 5126, 4, "VEC3", ""); /* 4 */
    accessor(&f, dn, sizeof dn, 5126, 4, "VEC3", "");     /* 5 */
    accessor(&f, dt, sizeof dt, 5126, 4, "VEC3", "");     /* 6 */
    const char *rest =
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":2,\"targets\":[{\"POSITION\":4}]}],"
        "\"weights\":[1]},"
        "{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TANGENT\":3},\"indices\":2,"
        "\"targets\":[{\"NORMAL\":5,\"TANGENT\":6}]}],\"weights\":[0.5]}],"
        "\"nodes\":[{\"mesh\":0},{\"mesh\":1,\"translation\":[5,0,0]}],\"scenes\":[{\"nodes\":[0,1]}]";
    scene s;
    if (!loads(&s, &f, rest))
        return;
    CHECKF(s.num_vertices == 10, "%u vertices", s.num_vertices);
    const int tris[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (int t = 0; t < 2 && s.num_vertices == 10; t++) {
        double p[3][3], e1[3], e2[3], n[3];
        for (int k = 0; k < 3; k++)
            for (int j = 0; j < 3; j++)
                p[k][j] = quad_pos[3 * tris[t][k] + j] + lift[3 * tris[t][k] + j];
        for (int j = 0; j < 3; j++) {
            e1[j] = p[1][j] - p[0][j];
            e2[j] = p[2][j] - p[0][j];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        normalize(n);
        for (int k = 0; k < 3; k++) {
            const GnVertex *g = &s.vertices[3 * t + k];
            CHECKF(close3(g->position, p[k], 1e-6) && close3(g->normal, n, 1e-5),
                   "flat triangle %d corner %d: (%g, %g, %g) normal (%g, %g, %g), expected (%g, %g, %g) normal "
                   "(%g, %g, %g)", t, k, g->position.x, g->position.y, g->position.z, g->normal.x, g->normal.y,
                   g->normal.z, p[k][0], p[k][1], p[k][2], n[0], n[1], n[2]);
        }
    }
    double n[3] = {0.25, 0, 1}, t[3] = {1, 0, -0.25};
    normalize(n);
    normalize(t);
    for (int v = 6; v < 10 && s.num_vertices == 10; v++) {
        const GnVertex *g = &s.vertices[v];
        CHECKF(close3(g->normal, n, 1e-6) && close3((vec3){g->tangent.x, g->tangent.y, g->tangent.z}, t, 1e-6) &&
                   g->tangent.w == 1,
               "vertex %d: normal (%g, %g, %g) tangent (%g, %g, %g, %g)", v, g->normal.x, g->normal.y, g->normal.z,
               g->tangent.x, g->tangent.y, g->tangent.z, g->tangent.w);
    }
    scene_destroy(&s);
}

/* A joint that mirrors (scale -1 on x) turns the skinned quad's triangles around: their
 * corner order must be reversed, as a node's mirroring transform reverses it, so that the
 * winding's normal and the shading normal agree and face +z, as the quad did (a mirror in x
 * keeps a plane facing +z; a one-sided material stays seen from the side it faces). With
 * NORMAL (mesh 0) and without (mesh 1: flat normals, made after posing); node 1 mirrors a
 * plain quad by its own transform, the reference. */
TEST(skin, mirroring_joint_keeps_the_winding)
{
    gltf_file f = {0};
    skinned_quad_accessors(&f); /* 0-4 */
    const char *rest =
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"JOINTS_0\":3,\"WEIGHTS_0\":4},"
        "\"indices\":2}]},"
        "{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"JOINTS_0\":3,\"WEIGHTS_0\":4},\"indices\":2}]},"
        "{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}],"
        "\"nodes\":[{\"mesh\":0,\"skin\":0},{\"mesh\":2,\"scale\":[-1,1,1],\"translation\":[0,3,0]},"
        "{\"scale\":[-1,1,1]},{\"mesh\":1,\"skin\":1},{\"scale\":[-1,1,1],\"translation\":[0,-3,0]}],"
        "\"skins\":[{\"joints\":[2]},{\"joints\":[4]}],\"scenes\":[{\"nodes\":[0,1,2,3,4]}]";
    scene s;
    if (!loads(&s, &f, rest))
        return;
    CHECKF(s.num_triangles == 6, "%u triangles", s.num_triangles);
    for (uint32_t t = 0; t < s.num_triangles; t++) {
        const GnVertex *v[3];
        for (int k = 0; k < 3; k++)
            v[k] = &s.vertices[s.indices[3 * t + k]];
        double e1[3] = {v[1]->position.x - v[0]->position.x, v[1]->position.y - v[0]->position.y,
                        v[1]->position.z - v[0]->position.z};
        double e2[3] = {v[2]->position.x - v[0]->position.x, v[2]->position.y - v[0]->position.y,
                        v[2]->position.z - v[0]->position.z};
        double gz = e1[0] * e2[1] - e1[1] * e2[0]; /* the winding's normal: along z only */
        for (int k = 0; k < 3; k++)
            CHECKF(gz > 0 && v[k]->normal.z > 0 && v[k]->position.x >= -1 && v[k]->position.x <= 0,
                   "triangle %u (at y %g) corner %d: winding's normal z %g, shading normal z %g, x %g", t,
                   v[0]->position.y, k, gz, v[k]->normal.z, v[k]->position.x);
    }
    scene_destroy(&s);
}

/* Morph targets displace TEXCOORD_0, TEXCOORD_1 and COLOR_0 too (glTF 2.0, "Morph Targets"):
 * the base plus the weighted displacements, as for positions; a VEC3 colour displacement
 * leaves alpha, a normalized unsigned byte one reads as k / 255, and the colour is clamped
 * to [0, 1]. Two targets at weights 0.5 and 0.25; a target's TEXCOORD_3 (a set gonio does
 * not read) changes nothing and is no warning. */
TEST(skin, morph_texcoords_and_colors)
{
    gltf_file f = {0};
    const float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1}, uv1[8] = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
    const float col[16] = {0.2f, 0.4f, 0.6f, 1, 0.2f, 0.4f, 0.6f, 1, 0.2f, 0.4f, 0.6f, 1, 0.2f, 0.4f, 0.6f, 0.5f};
    const float duv[8] = {0.2f, 0, 0.2f, 0, 0.2f, 0, 0.2f, -0.4f}, duv1[8] = {0, 0.4f, 0, 0.4f, 0, 0.4f, 0, 0.4f};
    const float dcol[12] = {0.4f, 0, 0, 0.4f, 0, 0, 0.4f, 0, 0, 2, -2, 0}; /* vertex 3: clamped */
    const uint8_t dcol2[16] = {0, 0, 255, 0, 0, 0, 255, 0, 0, 0, 255, 0, 0, 0, 255, 204};
    quad_accessors(&f);                                                   /* 0-2 */
    accessor(&f, uv, sizeof uv, 5126, 4, "VEC2", "");                     /* 3 */
    accessor(&f, uv1, sizeof uv1, 5126, 4, "VEC2", "");                   /* 4 */
    accessor(&f, col, sizeof col, 5126, 4, "VEC4", "");                   /* 5 */
    accessor(&f, duv, sizeof duv, 5126, 4, "VEC2", "");                   /* 6 */
    accessor(&f, duv1, sizeof duv1, 5126, 4, "VEC2", "");                 /* 7 */
    accessor(&f, dcol, sizeof dcol, 5126, 4, "VEC3", "");                 /* 8 */
    accessor(&f, dcol2, sizeof dcol2, 5121, 4, "VEC4", ",\"normalized\":true"); /* 9 */
    const char *rest =
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":3,\"TEXCOORD_1\":4,"
        "\"COLOR_0\":5},\"indices\":2,\"targets\":[{\"TEXCOORD_0\":6,\"TEXCOORD_1\":7,\"COLOR_0\":8},"
        "{\"COLOR_0\":9,\"TEXCOORD_3\":6}]}],\"weights\":[0.5,0.25]}],"
        "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]";
    scene s;
    int w0 = util_warning_count();
    if (!loads(&s, &f, rest))
        return;
    CHECKF(util_warning_count() == w0, "%s", load_log);
    CHECKF(s.num_vertices == 4, "%u vertices", s.num_vertices);
    for (int v = 0; v < 4 && s.num_vertices == 4; v++) {
        const GnVertex *g = &s.vertices[v];
        double want_uv[2] = {uv[2 * v] + 0.5 * duv[2 * v], uv[2 * v + 1] + 0.5 * duv[2 * v + 1]};
        double want_uv1[2] = {0.5, 0.5 + 0.5 * 0.4};
        double want[4];
        for (int k = 0; k < 4; k++) {
            double x = col[4 * v + k] + (k < 3 ? 0.5 * dcol[3 * v + k] : 0) + 0.25 * dcol2[4 * v + k] / 255.0;
            want[k] = x < 0 ? 0 : x > 1 ? 1 : x;
        }
        CHECKF(fabs(g->u - want_uv[0]) < 1e-6 && fabs(g->v - want_uv[1]) < 1e-6 && fabs(g->u1 - want_uv1[0]) < 1e-6 &&
                   fabs(g->v1 - want_uv1[1]) < 1e-6,
               "vertex %d: uv (%g, %g) uv1 (%g, %g), expected (%g, %g) (%g, %g)", v, g->u, g->v, g->u1, g->v1,
               want_uv[0], want_uv[1], want_uv1[0], want_uv1[1]);
        CHECKF(fabs(g->color.x - want[0]) < 1e-6 && fabs(g->color.y - want[1]) < 1e-6 &&
                   fabs(g->color.z - want[2]) < 1e-6 && fabs(g->color.w - want[3]) < 1e-6,
               "vertex %d: colour (%g, %g, %g, %g), expected (%g, %g, %g, %g)", v, g->color.x, g->color.y, g->color.z,
               g->color.w, want[0], want[1], want[2], want[3]);
    }
    scene_destroy(&s);
}

/* An inverse bind matrix that is singular (all zeros) is no inverse of a bind matrix: the
 * mesh is drawn as the file says (flattened) with one warning naming the skin and joint. */
TEST(skin, singular_inverse_bind_matrix)
{
    gltf_file f = {0};
    const float zero[32] = {0};
    skinned_quad_accessors(&f);                           /* 0-4 */
    accessor(&f, zero, sizeof zero, 5126, 2, "MAT4", ""); /* 5 */
    const char *rest =
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"JOINTS_0\":3,\"WEIGHTS_0\":4},"
        "\"indices\":2}]},{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":2}]}],"
        "\"nodes\":[{\"mesh\":0,\"skin\":0},{},{},{\"mesh\":1,\"translation\":[3,0,0]}],"
        "\"skins\":[{\"joints\":[1,2],\"inverseBindMatrices\":5}],\"scenes\":[{\"nodes\":[0,1,2,3]}]";
    scene s;
    int w0 = util_warning_count();
    if (!loads(&s, &f, rest))
        return;
    CHECKF(util_warning_count() - w0 == 1 && strstr(load_log, "skins[0].inverseBindMatrices: joint 0's matrix is singular"),
           "%s", load_log);
    scene_destroy(&s);
}
