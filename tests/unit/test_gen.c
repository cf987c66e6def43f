/* test_gen.c: the scene generators: gltf_write read back through scene_load (tinygltf), the
 * Utah teapot's tessellation against properties derived by hand from Newell's control
 * points, and the Cornell box and teapot scenes written by `gonio scene`. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gltf_write.h"
#include "scene.h"
#include "teapot.h"
#include "test.h"
#include "util.h"

int cmd_scene(int argc, char **argv);  /* cli.h */
int cmd_teapot(int argc, char **argv); /* cli.h */

static const char *tmp_file(const char *name)
{
    static char path[256];
    snprintf(path, sizeof path, "/tmp/gonio_test_gen_%ld_%s", (long)getpid(), name);
    return path;
}

static bool near3(vec3 a, double x, double y, double z, double tol)
{
    return fabs(a.x - x) <= tol && fabs(a.y - y) <= tol && fabs(a.z - z) <= tol;
}

static bool has_vertex(const scene *s, double x, double y, double z)
{
    for (uint32_t i = 0; i < s->num_vertices; i++)
        if (near3(s->vertices[i].position, x, y, z, 1e-5))
            return true;
    return false;
}

static int material_named(const scene *s, const char *name)
{
    for (uint32_t i = 0; i < s->num_materials; i++)
        if (!strcmp(s->material_names[i], name))
            return (int)i;
    return -1;
}

static vec3 sub(vec3 a, vec3 b) { return (vec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static vec3 cross(vec3 a, vec3 b)
{
    return (vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static double dot(vec3 a, vec3 b)
{
    return (double)a.x * b.x + (double)a.y * b.y + (double)a.z * b.z;
}
static vec3 v3(const float *p) { return (vec3){p[0], p[1], p[2]}; }

/* Face normal (unnormalised) from the winding, and the centroid, of scene triangle t. */
static vec3 tri_normal(const scene *s, uint32_t t, vec3 *centroid)
{
    vec3 p[3];
    for (int k = 0; k < 3; k++)
        p[k] = s->vertices[s->indices[3 * t + k]].position;
    if (centroid)
        *centroid = (vec3){(p[0].x + p[1].x + p[2].x) / 3, (p[0].y + p[1].y + p[2].y) / 3,
                           (p[0].z + p[1].z + p[2].z) / 3};
    return cross(sub(p[1], p[0]), sub(p[2], p[0]));
}

/* ---- gltf_write ------------------------------------------------------------------------ */

TEST(gen, gltf_roundtrip)
{
    static const float quad_p[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    static const float quad_n[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    static const float quad_uv[] = {0, 0, 1, 0, 1, 1, 0, 1};
    static const uint32_t quad_i[] = {0, 1, 2, 0, 2, 3};
    static const float tri_p[] = {0, 0, 0, 2, 0, 0, 0, 0, -1};
    static const uint32_t tri_i[] = {0, 1, 2};
    /* diag(3, 1, 1) then translate (0, 0, -5), column-major */
    static const float matrix[16] = {3, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -5, 1};
    const float h = (float)sqrt(0.5);
    gltf_write_mesh meshes[2] = {
        {.name = "quad", .num_vertices = 4, .positions = quad_p, .normals = quad_n,
         .uvs = quad_uv, .num_indices = 6, .indices = quad_i, .material = 1},
        {.name = "tri", .num_vertices = 3, .positions = tri_p, .num_indices = 3,
         .indices = tri_i, .material = 0}};
    gltf_write_material materials[2] = {
        {.name = "plain", .base_color = {0.5f, 0.25f, 0.125f, 1}, .metallic = 0.75f,
         .roughness = 0.3f},
        {.name = "fancy \"quoted\"", .base_color = {0.2f, 0.4f, 0.6f, 1}, .roughness = 0.5f,
         .emissive = {1, 0.5f, 0.25f}, .emissive_strength = 4, .has_specular = true,
         .specular = 0.7f, .specular_color = {0.9f, 0.8f, 0.7f}, .ior = 1.33f,
         .transmission = 0.6f, .double_sided = true,
         .extras = "{\"gonio\":{\"sigma\":0.25,\"phong\":{\"diffuse\":[0.1,0.2,0.3],"
                   "\"specular\":[0.4,0.5,0.6],\"shininess\":42,\"ambient\":[0.05,0.06,0.07]}}}"}};
    gltf_write_camera camera = {.name = "cam", .yfov = 0.8f, .aspect = 1.5f, .znear = 0.1f,
                                .zfar = 100};
    gltf_write_light lights[3] = {
        {.name = "bulb", .type = GLTF_WRITE_POINT, .color = {1, 0.5f, 0.25f}, .intensity = 10,
         .range = 5},
        {.name = "spot", .type = GLTF_WRITE_SPOT, .intensity = 2, .inner_cone = 0.2f,
         .outer_cone = 0.5f},
        {.name = "sun", .type = GLTF_WRITE_DIRECTIONAL}};
    gltf_write_node nodes[6] = {
        {.name = "q", .kind = GLTF_WRITE_NODE_MESH, .index = 0, .translation = {1, 2, 3},
         .rotation = {0, h, 0, h}, .scale = {2, 2, 2}},
        {.name = "t", .kind = GLTF_WRITE_NODE_MESH, .index = 1, .matrix = matrix},
        {.kind = GLTF_WRITE_NODE_CAMERA, .index = 0, .translation = {0, 1, 10}},
        {.kind = GLTF_WRITE_NODE_LIGHT, .index = 0, .translation = {1, 1, 1}},
        {.kind = GLTF_WRITE_NODE_LIGHT, .index = 1, .rotation = {-h, 0, 0, h}},
        {.kind = GLTF_WRITE_NODE_LIGHT, .index = 2}};
    gltf_write_desc desc = {.meshes = meshes, .num_meshes = 2, .materials = materials,
                            .num_materials = 2, .cameras = &camera, .num_cameras = 1,
                            .lights = lights, .num_lights = 3, .nodes = nodes, .num_nodes = 6};
    const char *path = tmp_file("roundtrip.gltf");
    char *text, *used;
    scene s = {0};
    int fancy, plain;

    CHECK(gltf_write_file(path, &desc));
    text = util_read_file(path, NULL);
    CHECK(text != NULL);
    if (!text)
        return;
    /* extensionsUsed lists exactly the five extensions used, on its one line */
    used = strstr(text, "\"extensionsUsed\": [");
    CHECK(used != NULL);
    if (used) {
        char line[512];
        int n = 0;
        snprintf(line, sizeof line, "%.*s", (int)strcspn(used, "\n"), used);
        for (const char *p = line; (p = strstr(p, "\"KHR_")); p++)
            n++;
        CHECK(n == 5);
        CHECK(strstr(line, "\"KHR_lights_punctual\"") && strstr(line, "\"KHR_materials_ior\"") &&
              strstr(line, "\"KHR_materials_emissive_strength\"") &&
              strstr(line, "\"KHR_materials_specular\"") &&
              strstr(line, "\"KHR_materials_transmission\""));
    }
    /* POSITION bounds (glTF requires them), buffer-view targets, buffer length:
     * quad 48 + 48 + 32 + 24, triangle 36 + 12 */
    CHECK(strstr(text, "\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]") != NULL);
    CHECK(strstr(text, "\"type\":\"VEC3\",\"min\":[0,0,-1],\"max\":[2,0,0]") != NULL);
    CHECK(strstr(text, "\"target\":34962") && strstr(text, "\"target\":34963"));
    CHECK(strstr(text, "\"byteLength\":200,") != NULL);
    free(text);

    CHECK(scene_load(&s, path));
    unlink(path);
    if (!s.num_triangles)
        return;
    CHECK(s.num_triangles == 3 && s.num_gltf_meshes == 2 && s.num_nodes == 6);
    CHECK(s.num_materials == 2 && s.num_cameras == 1 && s.num_lights == 3);

    /* quad: scale 2, then 90 degrees about +Y ((x,y,z) -> (z,y,-x)), then (1,2,3) */
    CHECK(has_vertex(&s, 1, 2, 3) && has_vertex(&s, 1, 2, 1) && has_vertex(&s, 1, 4, 1) &&
          has_vertex(&s, 1, 4, 3));
    /* triangle: x scaled by 3, moved to z - 5 */
    CHECK(has_vertex(&s, 0, 0, -5) && has_vertex(&s, 6, 0, -5) && has_vertex(&s, 0, 0, -6));
    fancy = material_named(&s, "fancy \"quoted\"");
    plain = material_named(&s, "plain");
    CHECK(fancy >= 0 && plain >= 0);
    if (fancy < 0 || plain < 0)
        goto done;
    for (uint32_t t = 0; t < s.num_triangles; t++) {
        const GnVertex *v = &s.vertices[s.indices[3 * t]];
        if (s.tri_material[t] == (uint32_t)fancy)
            CHECK(near3(v->normal, 1, 0, 0, 1e-6)); /* (0,0,1) turned about +Y */
    }
    {
        const GnMaterial *m = &s.materials[fancy], *p = &s.materials[plain];
        /* %.9g round-trips floats exactly */
        CHECK(p->base_color.x == 0.5f && p->base_color.y == 0.25f && p->metallic == 0.75f &&
              p->roughness == 0.3f);
        CHECK(!(p->flags & GN_MAT_DOUBLE_SIDED) && (m->flags & GN_MAT_DOUBLE_SIDED));
        CHECK(m->base_color.x == 0.2f && m->base_color.y == 0.4f && m->base_color.z == 0.6f &&
              m->metallic == 0 && m->roughness == 0.5f);
        CHECK(m->emissive.x == 4 && m->emissive.y == 2 && m->emissive.z == 1);
        CHECK(m->specular == 0.7f && m->specular_color.x == 0.9f && m->specular_color.z == 0.7f);
        CHECK(m->ior == 1.33f && m->transmission == 0.6f);
        CHECK(near3(m->phong_diffuse, 0.1, 0.2, 0.3, 1e-7) &&
              near3(m->phong_specular, 0.4, 0.5, 0.6, 1e-7) &&
              near3(m->phong_ambient, 0.05, 0.06, 0.07, 1e-7) && m->phong_shininess == 42);
        CHECK(s.material_extras[fancy].has_phong && s.material_extras[fancy].num_params == 1 &&
              !strcmp(s.material_extras[fancy].param_names[0], "sigma") &&
              s.material_extras[fancy].param_values[0] == 0.25f);
    }
    {
        const scene_camera *c = &s.cameras[0];
        CHECK(!strcmp(c->name, "cam") && c->yfov == 0.8f && c->aspect == 1.5f &&
              c->znear == 0.1f && c->zfar == 100);
        CHECK(c->position[0] == 0 && c->position[1] == 1 && c->position[2] == 10);
        CHECK(c->forward[2] == -1 && c->up[1] == 1 && c->right[0] == 1);
    }
    for (uint32_t i = 0; i < s.num_lights; i++) {
        const GnLight *l = &s.lights[i];
        if (l->type == GN_LIGHT_POINT)
            CHECK(near3(l->position, 1, 1, 1, 0) && near3(l->color, 10, 5, 2.5, 0) &&
                  l->range == 5);
        else if (l->type == GN_LIGHT_SPOT)
            CHECK(near3(l->direction, 0, -1, 0, 1e-6) && near3(l->color, 2, 2, 2, 0) &&
                  fabs(l->inner_cos - cos(0.2)) < 1e-6 && fabs(l->outer_cos - cos(0.5)) < 1e-6);
        else
            CHECK(l->type == GN_LIGHT_DIRECTIONAL && near3(l->direction, 0, 0, -1, 0) &&
                  near3(l->color, 1, 1, 1, 0) && l->range <= 0);
    }
done:
    scene_destroy(&s);
}

/* The other base64 tail: 136 bytes = 3 * 45 + 1 ends in "==" (the round trip above has
 * 200 = 3 * 66 + 2, one '='). Also: no materials, lights or extensions. */
TEST(gen, gltf_base64_padding)
{
    static const float p[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0.5f, 1.5f, 0, 0, 1, 0};
    static const float uv[] = {0, 0, 1, 0, 1, 1, 0.5f, 1.5f, 0, 1};
    static const uint32_t idx[] = {0, 1, 2, 0, 2, 3, 0, 3, 4};
    gltf_write_mesh mesh = {.num_vertices = 5, .positions = p, .uvs = uv, .num_indices = 9,
                            .indices = idx};
    gltf_write_node node = {.kind = GLTF_WRITE_NODE_MESH};
    gltf_write_desc desc = {.meshes = &mesh, .num_meshes = 1, .nodes = &node, .num_nodes = 1};
    const char *path = tmp_file("pad.gltf");
    char *text;
    scene s = {0};
    CHECK(gltf_write_file(path, &desc));
    text = util_read_file(path, NULL);
    CHECK(text && strstr(text, "\"byteLength\":136,") && strstr(text, "==\"}]") &&
          !strstr(text, "extensionsUsed") && !strstr(text, "materials"));
    free(text);
    CHECK(scene_load(&s, path));
    unlink(path);
    CHECK(s.num_triangles == 3);
    for (uint32_t t = 0; t < s.num_triangles && s.num_triangles == 3; t++)
        for (int k = 0; k < 3; k++) {
            const GnVertex *v = &s.vertices[s.indices[3 * t + k]];
            uint32_t i = idx[3 * t + k];
            CHECK(near3(v->position, p[3 * i], p[3 * i + 1], p[3 * i + 2], 0));
            CHECK(v->u == uv[2 * i] && v->v == uv[2 * i + 1]);
        }
    scene_destroy(&s);
}

/* A write that cannot be committed (the destination is a directory) fails, names the file
 * and leaves no temporary file behind. */
TEST(gen, gltf_unwritable)
{
    static const float p[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    static const uint32_t idx[] = {0, 1, 2};
    gltf_write_mesh mesh = {.num_vertices = 3, .positions = p, .num_indices = 3, .indices = idx};
    gltf_write_desc desc = {.meshes = &mesh, .num_meshes = 1};
    char dir[256], dest[300];
    DIR *d;
    struct dirent *e;
    int entries = 0;
    snprintf(dir, sizeof dir, "%s", tmp_file("dir"));
    snprintf(dest, sizeof dest, "%s/out.gltf", dir);
    CHECK(mkdir(dir, 0700) == 0 && mkdir(dest, 0700) == 0);
    fprintf(stderr, "    (expected error follows)\n");
    CHECK(!gltf_write_file(dest, &desc));
    CHECK(!gltf_write_file("/nonexistent-gonio-dir/x.gltf", &desc));
    d = opendir(dir);
    CHECK(d != NULL);
    while (d && (e = readdir(d)))
        entries += e->d_name[0] != '.' || strstr(e->d_name, ".tmp-") != NULL;
    if (d)
        closedir(d);
    CHECK(entries == 1); /* just out.gltf/ */
    rmdir(dest);
    rmdir(dir);
}

/* ---- teapot ---------------------------------------------------------------------------- */

static double signed_volume(const teapot_mesh *m)
{
    double v = 0;
    for (uint32_t t = 0; t < m->num_triangles; t++) {
        vec3 a = v3(&m->positions[3 * m->indices[3 * t]]);
        vec3 b = v3(&m->positions[3 * m->indices[3 * t + 1]]);
        vec3 c = v3(&m->positions[3 * m->indices[3 * t + 2]]);
        v += dot(a, cross(b, c)) / 6;
    }
    return v;
}

/* Each of the 32 patches gives 2 N^2 triangles; the 8 patches with a pole (lid top and
 * bottom: 4 each) lose the N triangles of the collapsed row. Zero-area triangles: only at
 * level 1, where the spout tip's 2 patches have collinear corners (4 triangles). */
TEST(gen, teapot_counts)
{
    static const int levels[] = {1, 2, 3, 5, 8};
    for (int l = 0; l < 5; l++) {
        int n = levels[l];
        teapot_mesh m;
        uint32_t bad = 0;
        teapot_tessellate(&m, n);
        CHECKF(m.num_triangles == (uint32_t)(64 * n * n - 8 * n), "level %d: %u triangles", n,
               m.num_triangles);
        for (uint32_t t = 0; t < m.num_triangles; t++) {
            const uint32_t *i = &m.indices[3 * t];
            vec3 f;
            if (i[0] >= m.num_vertices || i[1] >= m.num_vertices || i[2] >= m.num_vertices) {
                bad++;
                continue;
            }
            f = cross(sub(v3(&m.positions[3 * i[1]]), v3(&m.positions[3 * i[0]])),
                      sub(v3(&m.positions[3 * i[2]]), v3(&m.positions[3 * i[0]])));
            bad += dot(f, f) <= 0;
        }
        CHECKF(bad == (n == 1 ? 4u : 0u), "level %d: %u triangles out of range or of zero area",
               n, bad);
        teapot_destroy(&m);
    }
}

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Consistent winding: every directed edge occurs once (so an edge has at most 2 triangles,
 * traversed in opposite directions). The open boundary is, in grid edges: the lid's outer
 * edge and the rim's inner edge (4 patches each), both ends of the handle and of the spout
 * (2 patches each): 16 N. */
TEST(gen, teapot_topology)
{
    for (int n = 5; n <= 8; n += 3) {
        teapot_mesh m;
        uint64_t *edges;
        uint32_t count, dup = 0, boundary = 0;
        teapot_tessellate(&m, n);
        count = 3 * m.num_triangles;
        edges = util_malloc(count * sizeof *edges);
        for (uint32_t t = 0; t < m.num_triangles; t++)
            for (int k = 0; k < 3; k++)
                edges[3 * t + k] =
                    (uint64_t)m.indices[3 * t + k] << 32 | m.indices[3 * t + (k + 1) % 3];
        qsort(edges, count, sizeof *edges, compare_u64);
        for (uint32_t i = 0; i < count; i++) {
            uint64_t rev = edges[i] >> 32 | edges[i] << 32;
            dup += i > 0 && edges[i] == edges[i - 1];
            boundary += !bsearch(&rev, edges, count, sizeof *edges, compare_u64);
        }
        CHECKF(dup == 0, "level %d: %u directed edges repeated", n, dup);
        CHECKF(boundary == (uint32_t)(16 * n), "level %d: %u boundary edges, expected %d", n,
               boundary, 16 * n);
        free(edges);
        teapot_destroy(&m);
    }
}

TEST(gen, teapot_normals)
{
    teapot_mesh m;
    uint32_t not_unit = 0, disagree = 0;
    teapot_tessellate(&m, 8);
    for (uint32_t i = 0; i < m.num_vertices; i++) {
        vec3 n = v3(&m.normals[3 * i]);
        not_unit += fabs(sqrt(dot(n, n)) - 1) > 1e-5;
    }
    /* Smooth normals agree with the winding's face normal at every corner. */
    for (uint32_t t = 0; t < m.num_triangles; t++) {
        const uint32_t *i = &m.indices[3 * t];
        vec3 f = cross(sub(v3(&m.positions[3 * i[1]]), v3(&m.positions[3 * i[0]])),
                       sub(v3(&m.positions[3 * i[2]]), v3(&m.positions[3 * i[0]])));
        for (int k = 0; k < 3; k++)
            if (dot(f, v3(&m.normals[3 * i[k]])) <= 0) {
                disagree++;
                break;
            }
    }
    CHECKF(not_unit == 0, "%u normals not unit length", not_unit);
    CHECKF(disagree == 0, "%u of %u triangles have a corner normal against the face", disagree,
           m.num_triangles);
    CHECK(signed_volume(&m) > 0); /* outward winding */
    /* Poles: the bottom centre (0,0,0) points straight down, the lid's top straight up. */
    for (uint32_t i = 0; i < m.num_vertices; i++) {
        vec3 p = v3(&m.positions[3 * i]), n = v3(&m.normals[3 * i]);
        if (p.x == 0 && p.z == 0 && p.y == 0)
            CHECK(near3(n, 0, -1, 0, 1e-4));
        if (p.x == 0 && p.z == 0 && p.y == 1)
            CHECK(near3(n, 0, 1, 0, 1e-4));
    }
    teapot_destroy(&m);
}

TEST(gen, teapot_convergence)
{
    teapot_mesh a, b;
    double va, vb;
    teapot_tessellate(&a, 32);
    teapot_tessellate(&b, 64);
    va = signed_volume(&a);
    vb = signed_volume(&b);
    CHECKF(vb > 0 && fabs(va - vb) < 1e-3 * vb, "volume %g at level 32, %g at 64", va, vb);
    /* The body alone (a solid of revolution up to radius 2, 2.4 high, in units of 3.15)
     * bounds the volume from above by pi 2^2 2.4 / 3.15^3 and, inscribed, from below by
     * a cylinder of radius 1.5 and height 2.4. */
    CHECK(vb < M_PI * 4 * 2.4 * 1.01 * 1.01 / pow(3.15, 3) + 0.05);
    CHECK(vb > M_PI * 1.5 * 1.5 * 2.4 / pow(3.15, 3));
    teapot_destroy(&a);
    teapot_destroy(&b);
}

/* Extents from the control points (original units, Z up), scaled by 1/3.15 into Y up:
 * - spout tip: the y = 0 edge of the tip patch has x control values 3.3, 3.525, 3.45, 3.2;
 *   its maximum over the curve is found here by dense sampling;
 * - handle: the patch corner (-3, 0, 1.8) where the tangent is vertical: min x = -3;
 * - height: bottom pole z = 0, lid knob pole z = 3.15;
 * - depth: the body's widest row (z = 0.9) has the corner (0, -2) of a quarter circle whose
 *   y control values 0, -1.12, -2, -2 are monotone: |y| <= 2, reached at the corner. (Its
 *   radius peaks at 45 degrees, 2 sqrt(2) (1/8 + 3/8 + 3/8 0.56) = 2.008, but there |y| is
 *   only 1.42.) */
TEST(gen, teapot_bounds)
{
    const double s = 1 / 3.15, c[4] = {3.3, 3.525, 3.45, 3.2};
    const double depth = 2;
    double xmax = 0;
    float lo[3] = {1e9f, 1e9f, 1e9f}, hi[3] = {-1e9f, -1e9f, -1e9f};
    teapot_mesh m;
    for (int i = 0; i <= 100000; i++) {
        double t = i / 100000.0, u = 1 - t;
        xmax = fmax(xmax, u * u * u * c[0] + 3 * t * u * u * c[1] + 3 * t * t * u * c[2] +
                              t * t * t * c[3]);
    }
    CHECKF(fabs(xmax - 3.434) < 1e-3, "spout tip at x = %.5f", xmax);
    teapot_tessellate(&m, 32);
    for (uint32_t i = 0; i < m.num_vertices; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fminf(lo[k], m.positions[3 * i + k]);
            hi[k] = fmaxf(hi[k], m.positions[3 * i + k]);
        }
    /* grid points lie on the surface, so the mesh's extent is within the true one */
    CHECKF(hi[0] <= xmax * s + 1e-6 && hi[0] > (xmax - 1e-3) * s, "max x %.6f vs %.6f", hi[0],
           xmax * s);
    CHECKF(fabs(lo[0] + 3 * s) < 1e-6, "min x %.7f", lo[0]);
    CHECK(fabs(lo[1]) < 1e-6 && fabs(hi[1] - 1) < 1e-6);
    CHECKF(fabs(hi[2] - depth * s) < 1e-6 && fabs(lo[2] + depth * s) < 1e-6,
           "z in [%.7f, %.7f], expected +-%.7f", lo[2], hi[2], depth * s);
    teapot_destroy(&m);
}

/* ---- the scenes of `gonio scene` --------------------------------------------------------- */

static bool run_command(int (*cmd)(int, char **), int expect, int argc, const char **argv)
{
    char *args[8];
    for (int i = 0; i < argc; i++)
        args[i] = (char *)argv[i];
    args[argc] = NULL;
    return cmd(argc, args) == expect;
}

TEST(gen, cornell)
{
    const char *path = tmp_file("cornell.gltf");
    const char *argv[] = {"scene", "cornell", "-o", path};
    /* middles of the blocks' tops, from the published corners: x -> 0.278 - x, z -> -z */
    const double short_c[2] = {0.278 - 0.1855, -0.169}, tall_c[2] = {0.278 - 0.3685, -0.35125};
    scene s = {0};
    int red, green, white, light;
    double light_area = 0;
    uint32_t wrong_side = 0, light_tris = 0;
    CHECK(run_command(cmd_scene, 0, 4, argv));
    CHECK(scene_load(&s, path));
    unlink(path);
    if (!s.num_triangles)
        return;
    CHECK(s.num_triangles == 32 && s.num_cameras == 1 && s.num_lights == 0 &&
          s.num_materials == 4);
    red = material_named(&s, "red");
    green = material_named(&s, "green");
    white = material_named(&s, "white");
    light = material_named(&s, "light");
    CHECK(red >= 0 && green >= 0 && white >= 0 && light >= 0);
    if (red < 0 || green < 0 || white < 0 || light < 0 || s.num_cameras != 1)
        goto done;
    {
        const scene_camera *c = &s.cameras[0];
        CHECK(fabs(c->yfov * 180 / M_PI - 39.3077) < 1e-3 && c->aspect == 1);
        CHECK(fabs(c->position[0]) < 1e-6 && fabs(c->position[1] - 0.273) < 1e-6 &&
              fabs(c->position[2] - 0.8) < 1e-6);
        CHECK(c->forward[2] == -1 && c->right[0] == 1 && c->up[1] == 1);
        /* as photographed: red wall on the left, green on the right */
        for (uint32_t t = 0; t < s.num_triangles; t++)
            for (int k = 0; k < 3; k++) {
                vec3 p = s.vertices[s.indices[3 * t + k]].position;
                double x = dot(sub(p, v3(c->position)), v3(c->right));
                if (s.tri_material[t] == (uint32_t)red)
                    CHECK(x < -0.27);
                if (s.tri_material[t] == (uint32_t)green)
                    CHECK(x > 0.27);
            }
    }
    for (int i = 0; i < 3; i++) {
        const GnMaterial *m = &s.materials[i == 0 ? red : i == 1 ? green : white];
        CHECK(m->metallic == 0 && m->roughness == 1 && m->specular == 0 && m->emissive.x == 0);
    }
    CHECK(s.materials[white].base_color.x == 0.725f && s.materials[white].base_color.y == 0.71f &&
          s.materials[white].base_color.z == 0.68f);
    CHECK(s.materials[red].base_color.x == 0.63f && s.materials[green].base_color.y == 0.45f);
    CHECK(near3(s.materials[light].emissive, 17, 12, 4, 1e-5));
    CHECK(!(s.materials[light].flags & GN_MAT_DOUBLE_SIDED));
    /* Walls face the box's middle, block faces face out of their block (none faces down),
     * the light faces down; smooth normals agree with the winding. */
    for (uint32_t t = 0; t < s.num_triangles; t++) {
        vec3 c, f = tri_normal(&s, t, &c);
        double len = sqrt(dot(f, f));
        bool wall = s.tri_material[t] == (uint32_t)red || s.tri_material[t] == (uint32_t)green ||
                    c.y < 1e-6 || c.y > 0.5486 || c.z < -0.559;
        for (int k = 0; k < 3; k++)
            CHECK(dot(f, s.vertices[s.indices[3 * t + k]].normal) > 0.999 * len);
        if (s.tri_material[t] == (uint32_t)light) {
            light_tris++;
            light_area += len / 2;
            CHECK(f.x == 0 && f.z == 0 && f.y < 0 && fabs(c.y - 0.5487) < 1e-6);
        } else if (wall) {
            wrong_side += dot(f, sub((vec3){0, 0.2744f, -0.2796f}, c)) <= 0;
        } else {
            float top = 0; /* the blocks are 0.165 and 0.33 high */
            for (int k = 0; k < 3; k++)
                top = fmaxf(top, s.vertices[s.indices[3 * t + k]].position.y);
            const double *bc = top > 0.2f ? tall_c : short_c;
            double out = f.x * (c.x - bc[0]) + f.z * (c.z - bc[1]);
            wrong_side += f.y < -1e-6 * len || (f.y < 0.5 * len && out <= 0); /* top or side */
        }
    }
    CHECKF(wrong_side == 0, "%u triangles face the wrong way", wrong_side);
    CHECK(light_tris == 2 && fabs(light_area - 0.13 * 0.105) < 1e-6);
done:
    scene_destroy(&s);
}

TEST(gen, teapot_scene)
{
    const char *path = tmp_file("teapot.gltf");
    const char *argv[] = {"teapot", "--level", "4", "-o", path};
    scene s = {0};
    CHECK(run_command(cmd_teapot, 0, 5, argv));
    CHECK(scene_load(&s, path));
    unlink(path);
    if (!s.num_triangles)
        return;
    CHECK(s.num_triangles == 64 * 16 - 8 * 4 && s.num_materials == 1 && s.num_lights == 1 &&
          s.num_cameras == 1);
    if (s.num_materials != 1 || s.num_lights != 1 || s.num_cameras != 1)
        goto done;
    {
        const GnMaterial *m = &s.materials[0];
        double r = m->roughness;
        CHECK(near3(m->phong_diffuse, 1, 0, 0, 0) && near3(m->phong_specular, 1, 1, 1, 0) &&
              m->phong_shininess == 128 && near3(m->phong_ambient, 0.2, 0.2, 0.2, 1e-7));
        CHECK(m->base_color.x == 1 && m->base_color.y == 0 && m->metallic == 0);
        CHECKF(fabs(2 / (r * r * r * r) - 2 - 128) < 1e-3, "roughness %g", r);
    }
    {
        const GnLight *l = &s.lights[0];
        double k = -1 / sqrt(3.0);
        CHECK(l->type == GN_LIGHT_DIRECTIONAL && near3(l->direction, k, k, k, 1e-6) &&
              near3(l->color, 1, 1, 1, 0));
    }
    {
        /* front-right, above the teapot, everything in the 4:3 frame, filling most of it */
        const scene_camera *c = &s.cameras[0];
        double th = tan(c->yfov / 2), lo[2] = {1, 1}, hi[2] = {-1, -1};
        uint32_t outside = 0;
        CHECK(fabsf(c->aspect - 4.0f / 3.0f) < 1e-6f);
        CHECK(c->position[0] > 0.5 && c->position[2] > 1 && c->position[1] > 1);
        for (uint32_t i = 0; i < s.num_vertices; i++) {
            vec3 d = sub(s.vertices[i].position, v3(c->position));
            double z = dot(d, v3(c->forward));
            double x = dot(d, v3(c->right)) / (z * th * c->aspect);
            double y = dot(d, v3(c->up)) / (z * th);
            outside += z <= 0 || fabs(x) > 0.95 || fabs(y) > 0.95;
            lo[0] = fmin(lo[0], x);
            hi[0] = fmax(hi[0], x);
            lo[1] = fmin(lo[1], y);
            hi[1] = fmax(hi[1], y);
        }
        CHECK(outside == 0);
        CHECKF(hi[0] - lo[0] > 1.2 && fabs(hi[0] + lo[0]) < 0.2 && fabs(hi[1] + lo[1]) < 0.2,
               "teapot spans x [%.2f, %.2f], y [%.2f, %.2f] of the frame", lo[0], hi[0], lo[1],
               hi[1]);
    }
done:
    scene_destroy(&s);
}

TEST(gen, scene_usage)
{
    const char *p = tmp_file("usage.gltf");
    const char *none[] = {"scene"}, *unknown[] = {"scene", "sphere", "-o", p};
    const char *no_out[] = {"scene", "cornell"}, *level0[] = {"teapot", "--level", "0", "-o", p};
    const char *no_value[] = {"teapot", "-o"};
    const char *bad_opt[] = {"scene", "cornell", "--level", "3", "-o", p};
    const char *unwritable[] = {"scene", "cornell", "-o", "/nonexistent-gonio-dir/c.gltf"};
    struct stat st;
    fprintf(stderr, "    (expected usage errors follow)\n");
    CHECK(run_command(cmd_scene, 2, 1, none));
    CHECK(run_command(cmd_scene, 2, 4, unknown));
    CHECK(run_command(cmd_scene, 2, 2, no_out));
    CHECK(run_command(cmd_teapot, 2, 5, level0));
    CHECK(run_command(cmd_teapot, 2, 2, no_value));
    CHECK(run_command(cmd_scene, 2, 6, bad_opt));
    CHECK(run_command(cmd_scene, 1, 4, unwritable));
    CHECK(stat(p, &st) != 0); /* nothing written by the failed commands */
}
