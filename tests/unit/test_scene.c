/* test_scene.c: tests of the scene module (glTF loading, scene helpers). References come from
 * outside the loader: counts read from the sample files' JSON with a Python script while the
 * tests were written, transforms worked out by hand from the nodes' TRS/matrices, the
 * glTF-Validator's own reports for the invalid corpus, and analytic values for the helpers. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "scene.h"
#include "scene_files.h"
#include "test.h"
#include "util.h"

/* This process's scratch files: runs at once (a job pool, other trees on the machine) must
 * not write each other's. */
static char tmp_gltf[64], tmp_glb[64];
static void tmp_remove(void)
{
    if (*tmp_gltf)
        unlink(tmp_gltf);
    if (*tmp_glb)
        unlink(tmp_glb);
}
static const char *tmp_path(const char *ext)
{
    char *p = strcmp(ext, "glb") ? tmp_gltf : tmp_glb;
    if (!*tmp_gltf && !*tmp_glb)
        atexit(tmp_remove);
    if (!*p)
        snprintf(p, sizeof tmp_gltf, "/tmp/gonio_scene_test-%d.%s", (int)getpid(), ext);
    return p;
}
#define TMP_GLTF tmp_path("gltf")
#define TMP_GLB tmp_path("glb")

/* ---- helpers ------------------------------------------------------------------------------ */

static const char *asset(char *buf, size_t cap, const char *rel)
{
    snprintf(buf, cap, "%s/%s", test_assets_dir(), rel);
    return buf;
}

static bool near(float a, float b, float tol) { return fabsf(a - b) <= tol; }

static bool near3(vec3 v, float x, float y, float z, float tol)
{
    return near(v.x, x, tol) && near(v.y, y, tol) && near(v.z, z, tol);
}

/* Vertices the scene places: its world-space ones and each instance's copy of its mesh's
 * (a mesh several nodes use is kept once, with an instance per node: scene_instanced_mesh). */
static uint64_t placed_vertices(const scene *s)
{
    uint64_t n = s->num_vertices;
    for (uint32_t i = 0; i < s->num_instances; i++)
        n += s->instanced_meshes[s->instances[i].mesh].num_vertices;
    return n;
}

/* Instance i's placement of object-space point p (scene_instance.to_world: 3x4, row-major). */
static vec3 placed(const scene *s, uint32_t i, vec3 p)
{
    const float *w = s->instances[i].to_world;
    return (vec3){w[0] * p.x + w[1] * p.y + w[2] * p.z + w[3], w[4] * p.x + w[5] * p.y + w[6] * p.z + w[7],
                  w[8] * p.x + w[9] * p.y + w[10] * p.z + w[11]};
}

static void write_bytes(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    fwrite(data, 1, n, f);
    fclose(f);
}

/* Writes a .gltf whose JSON `fmt` holds one %s, replaced by a buffer object carrying `bin` as a
 * data URI (so the buffer is index 0). */
static void write_gltf(const char *path, const char *fmt, const void *bin, size_t n)
{
    char *b64 = base64(bin, n);
    size_t cap = strlen(b64) + 128;
    char *buffer = util_malloc(cap);
    snprintf(buffer, cap, "{\"uri\":\"data:application/octet-stream;base64,%s\",\"byteLength\":%zu}", b64, n);
    FILE *f = fopen(path, "wb");
    fprintf(f, fmt, buffer);
    fclose(f);
    free(buffer);
    free(b64);
}

/* Every triangle's winding agrees with its vertex normals (flat-faced meshes). */
static bool winding_matches_normals(const scene *s)
{
    for (uint32_t t = 0; t < s->num_triangles; t++) {
        const GnVertex *v[3];
        for (int k = 0; k < 3; k++)
            v[k] = &s->vertices[s->indices[3 * t + k]];
        float e1[3] = {v[1]->position.x - v[0]->position.x, v[1]->position.y - v[0]->position.y, v[1]->position.z - v[0]->position.z};
        float e2[3] = {v[2]->position.x - v[0]->position.x, v[2]->position.y - v[0]->position.y, v[2]->position.z - v[0]->position.z};
        float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; k++)
            if (!((n[0] * v[k]->normal.x + n[1] * v[k]->normal.y + n[2] * v[k]->normal.z) / len >= 0.99f))
                return false;
    }
    return true;
}

/* Invariants every loaded scene must satisfy, whatever the file. */
static void check_invariants(const scene *s, const char *name)
{
    bool idx_ok = true, mat_ok = true, vert_ok = true, tex_ok = true, col_ok = true;
    for (uint32_t i = 0; i < 3 * s->num_triangles; i++)
        idx_ok &= s->indices[i] < s->num_vertices;
    for (uint32_t t = 0; t < s->num_triangles; t++)
        mat_ok &= s->tri_material[t] < s->num_materials;
    for (uint32_t v = 0; v < s->num_vertices; v++) {
        const GnVertex *g = &s->vertices[v];
        float nl = sqrtf(g->normal.x * g->normal.x + g->normal.y * g->normal.y + g->normal.z * g->normal.z);
        float tl = sqrtf(g->tangent.x * g->tangent.x + g->tangent.y * g->tangent.y + g->tangent.z * g->tangent.z);
        vert_ok &= isfinite(g->position.x) && isfinite(g->position.y) && isfinite(g->position.z) &&
                   isfinite(g->u) && isfinite(g->v) && fabsf(nl - 1) < 1e-4f &&
                   ((tl == 0 && g->tangent.w == 0) || (fabsf(tl - 1) < 1e-4f && fabsf(g->tangent.w) == 1));
        /* COLOR_0 in [0, 1]; without vertex colours in the scene, every one is white */
        const float *c = &g->color.x;
        for (int k = 0; k < 4; k++)
            col_ok &= s->vertex_colors ? c[k] >= 0 && c[k] <= 1 : c[k] == 1;
    }
    for (uint32_t m = 0; m < s->num_materials; m++) {
        const GnMaterial *g = &s->materials[m];
        const uint32_t slots[5] = {g->tex_base, g->tex_mr, g->tex_normal, g->tex_emissive, g->tex_occlusion};
        for (int k = 0; k < 5; k++)
            tex_ok &= slots[k] == GN_INVALID || slots[k] < s->num_textures;
        tex_ok &= g->brdf == 0;
    }
    for (uint32_t t = 0; t < s->num_textures; t++)
        tex_ok &= s->textures[t].image < s->num_images;
    CHECKF(idx_ok, "%s: index out of range", name);
    CHECKF(mat_ok, "%s: material out of range", name);
    CHECKF(vert_ok, "%s: non-finite vertex or non-unit normal/tangent", name);
    CHECKF(tex_ok, "%s: texture or image reference out of range", name);
    CHECKF(col_ok, "%s: a vertex colour outside [0, 1] (or not white without COLOR_0)", name);
    CHECKF(s->bounds_min[0] <= s->bounds_max[0] && s->bounds_min[1] <= s->bounds_max[1] &&
               s->bounds_min[2] <= s->bounds_max[2], "%s: empty bounds", name);
}

static int find_material(const scene *s, const char *name)
{
    for (uint32_t i = 0; i < s->num_materials; i++)
        if (strcmp(s->material_names[i], name) == 0)
            return (int)i;
    return -1;
}

/* Distance from p to the nearest scene vertex. */
static float nearest_vertex(const scene *s, float x, float y, float z)
{
    float best = INFINITY;
    for (uint32_t v = 0; v < s->num_vertices; v++) {
        vec3 p = s->vertices[v].position;
        best = fminf(best, sqrtf((p.x - x) * (p.x - x) + (p.y - y) * (p.y - y) + (p.z - z) * (p.z - z)));
    }
    return best;
}

/* ---- scene helpers ------------------------------------------------------------------------ */

TEST(scene, phong_mapping)
{
    GnMaterial m;
    scene_material_default(&m);
    /* Dielectric, roughness 0.5: alpha = 0.25, n = 2 / 0.25^2 - 2 = 30. */
    m.base_color = (vec4){0.8f, 0.4f, 0.2f, 1};
    m.metallic = 0;
    m.roughness = 0.5f;
    m.emissive = (vec3){1, 2, 3};
    scene_phong_from_pbr(&m);
    CHECK(near3(m.phong_diffuse, 0.8f, 0.4f, 0.2f, 1e-6f));
    CHECK(near3(m.phong_ambient, 0.8f, 0.4f, 0.2f, 1e-6f));
    CHECK(near3(m.phong_specular, 0.04f, 0.04f, 0.04f, 1e-6f));
    CHECK(near3(m.phong_emission, 1, 2, 3, 0));
    CHECK(near(m.phong_shininess, 30, 1e-3f));
    /* Metal: no diffuse, specular is the base colour; roughness 1 -> n = 0, clamped to 1. */
    m.metallic = 1;
    m.roughness = 1;
    scene_phong_from_pbr(&m);
    CHECK(near3(m.phong_diffuse, 0, 0, 0, 0));
    CHECK(near3(m.phong_specular, 0.8f, 0.4f, 0.2f, 1e-6f));
    CHECK(m.phong_shininess == 1);
    /* Half metal, tinted KHR_materials_specular, half transmissive, mirror-smooth. */
    m.metallic = 0.5f;
    m.specular_color = (vec3){0.5f, 1, 1};
    m.specular = 0.5f;
    m.transmission = 0.5f;
    m.roughness = 0;
    scene_phong_from_pbr(&m);
    CHECK(near3(m.phong_diffuse, 0.8f * 0.25f, 0.4f * 0.25f, 0.2f * 0.25f, 1e-6f));
    CHECK(near3(m.phong_specular, 0.5f * 0.01f + 0.4f, 0.5f * 0.02f + 0.2f, 0.5f * 0.02f + 0.1f, 1e-6f));
    CHECK(m.phong_shininess == 10000);    /* Specular-glossiness as the loader reads it (metallic 0, ior 0: F0 = the specular colour):
     * diffuse (1 - max(specular)), specular the specular colour. */
    scene_material_default(&m);
    m.base_color = (vec4){0.8f, 0.4f, 0.2f, 1};
    m.metallic = 0;
    m.ior = 0;
    m.specular_color = (vec3){0.5f, 0.25f, 0.1f};
    m.flags |= GN_MAT_SPEC_GLOSS;
    scene_phong_from_pbr(&m);
    CHECK(near3(m.phong_diffuse, 0.4f, 0.2f, 0.1f, 1e-6f));
    CHECK(near3(m.phong_specular, 0.5f, 0.25f, 0.1f, 1e-6f));
}

TEST(scene, default_material)
{
    GnMaterial m;
    scene_material_default(&m);
    /* glTF 2.0 defaults: white, metallic 1, roughness 1; extension defaults. */
    CHECK(m.base_color.x == 1 && m.base_color.y == 1 && m.base_color.z == 1 && m.base_color.w == 1);
    CHECK(m.metallic == 1 && m.roughness == 1 && m.specular == 1 && m.ior == 1.5f && m.transmission == 0);
    CHECK(m.alpha_cutoff == 0.5f && m.normal_scale == 1 && m.occlusion_strength == 1 && m.flags == 0);
    CHECK(m.tex_base == GN_INVALID && m.tex_mr == GN_INVALID && m.tex_normal == GN_INVALID &&
          m.tex_emissive == GN_INVALID && m.tex_occlusion == GN_INVALID);
    CHECK(near3(m.phong_diffuse, 0, 0, 0, 0) && near3(m.phong_specular, 1, 1, 1, 0) && m.phong_shininess == 1);
    /* KHR_materials_volume: white, +infinity, thin-walled; no dispersion. */
    CHECK(near3(m.attenuation_color, 1, 1, 1, 0) && isinf(m.attenuation_distance) && m.attenuation_distance > 0);
    CHECK(m.volume == 0 && m.thickness == 0 && m.dispersion == 0);
}

/* Projects a point with the pinhole model of GnCamera; true when it is inside the image and
 * between the clip planes. */
static bool projects_inside(const scene_camera *c, const float p[3])
{
    float d[3] = {p[0] - c->position[0], p[1] - c->position[1], p[2] - c->position[2]};
    float z = d[0] * c->forward[0] + d[1] * c->forward[1] + d[2] * c->forward[2];
    float x = d[0] * c->right[0] + d[1] * c->right[1] + d[2] * c->right[2];
    float y = d[0] * c->up[0] + d[1] * c->up[1] + d[2] * c->up[2];
    float t = tanf(0.5f * c->yfov);
    return z > c->znear && z < c->zfar && fabsf(x / (z * t * c->aspect)) <= 1 && fabsf(y / (z * t)) <= 1;
}

static bool orthonormal(const scene_camera *c);

TEST(scene, default_camera)
{
    static const float boxes[][6] = {
        {-1, -1, -1, 1, 1, 1}, {0, 0, 0, 100, 1, 1}, {1000, 2000, -3000, 1001, 2010, -2999}, {-5, 0, 0, 5, 0, 0}};
    static const float aspects[] = {0.25f, 1, 16.0f / 9, 4};
    for (size_t b = 0; b < sizeof boxes / sizeof boxes[0]; b++)
        for (size_t a = 0; a < sizeof aspects / sizeof aspects[0]; a++) {
            scene s;
            memset(&s, 0, sizeof s);
            memcpy(s.bounds_min, boxes[b], sizeof s.bounds_min);
            memcpy(s.bounds_max, boxes[b] + 3, sizeof s.bounds_max);
            scene_camera c;
            scene_default_camera(&s, aspects[a], &c);
            CHECK(near(c.yfov, (float)(M_PI / 4), 1e-6f) && c.aspect == aspects[a]);
            CHECK(orthonormal(&c) && c.right[1] == 0 && c.up[1] > 0.8f);
            /* Raised and turned: looking down, toward -Z and -X (a three-quarter view). */
            CHECK(c.forward[1] < -0.3f && c.forward[2] < -0.5f && c.forward[0] < -0.3f);
            for (int corner = 0; corner < 8; corner++) {
                float p[3];
                for (int k = 0; k < 3; k++)
                    p[k] = (corner >> k & 1) ? boxes[b][3 + k] : boxes[b][k];
                CHECKF(projects_inside(&c, p), "box %zu aspect %g corner %d", b, aspects[a], corner);
            }
        }
    /* Empty bounds (min > max) and a single point still give a usable camera. */
    scene s;
    memset(&s, 0, sizeof s);
    for (int k = 0; k < 3; k++) {
        s.bounds_min[k] = 1e30f;
        s.bounds_max[k] = -1e30f;
    }
    for (int pass = 0; pass < 2; pass++) {
        scene_camera c;
        scene_default_camera(&s, 1.5f, &c);
        CHECK(isfinite(c.position[0]) && isfinite(c.position[1]) && isfinite(c.position[2]));
        CHECK(c.znear > 0 && c.zfar > c.znear && isfinite(c.zfar));
        float p[3] = {pass ? 7.0f : 0.0f, pass ? -3.0f : 0.0f, pass ? 2.0f : 0.0f};
        CHECK(projects_inside(&c, p));
        for (int k = 0; k < 3; k++)
            s.bounds_min[k] = s.bounds_max[k] = p[k] + (k == 0 ? 7.0f : k == 1 ? -3.0f : 2.0f);
    }
}

TEST(scene, drop_invalid_triangles)
{
    scene s;
    memset(&s, 0, sizeof s);
    s.num_vertices = 5;
    s.vertices = util_calloc(5, sizeof(GnVertex));
    s.vertices[1].position = (vec3){1, 0, 0};
    s.vertices[2].position = (vec3){0, 1, 0};
    s.vertices[3].position = (vec3){NAN, 0, 0};
    s.vertices[4].position = (vec3){0, 0, 2e15f};
    s.vertices[4].normal = (vec3){0, 0, 1};
    static const uint32_t idx[] = {0, 3, 1, 0, 1, 2, 4, 1, 2, 2, 1, 0};
    s.num_triangles = 4;
    s.indices = util_malloc(sizeof idx);
    memcpy(s.indices, idx, sizeof idx);
    s.tri_material = util_malloc(4 * sizeof(uint32_t));
    for (uint32_t t = 0; t < 4; t++)
        s.tri_material[t] = 10 + t;
    CHECK(scene_drop_invalid_triangles(&s) == 2);
    CHECK(s.num_triangles == 2);
    CHECK(s.indices[0] == 0 && s.indices[1] == 1 && s.indices[2] == 2 && s.indices[3] == 2 && s.indices[5] == 0);
    CHECK(s.tri_material[0] == 11 && s.tri_material[1] == 13);
    CHECK(s.vertices[3].position.x == 0 && s.vertices[4].position.z == 0 && s.vertices[4].normal.z == 0);
    scene_compute_bounds(&s);
    CHECK(s.bounds_min[0] == 0 && s.bounds_max[0] == 1 && s.bounds_max[1] == 1 && s.bounds_max[2] == 0);
    scene_destroy(&s);
    CHECK(s.vertices == NULL && s.num_triangles == 0);
    scene_destroy(&s); /* a zeroed struct is fine */
}

/* ---- the Khronos sample models ------------------------------------------------------------ */

/* Expected values read from each file's JSON by a Python script (not by the loader): triangles
 * = index (or position) count / 3 summed over the primitive instances of the default scene;
 * vertices = POSITION counts, 3 per triangle where a primitive has no NORMAL (flat normals);
 * materials = the file's plus one default when a drawn primitive has none; DamagedHelmet (a
 * normal map, no TANGENT) has 10 more, the vertices its MikkTSpace tangents split (seams
 * where the uv chart is mirrored). Warnings: the unsupported features visible in the JSON
 * (none left: KHR_xmp, TransmissionTest's metadata, is no warning). */
static const struct {
    const char *path;
    uint32_t tris, verts, prims, meshes, nodes, mats, images, textures, cameras, lights;
    int warnings;
} samples[] = {
    {"gltf/AnimatedMorphCube/glTF/AnimatedMorphCube.gltf", 12, 24, 1, 1, 1, 1, 0, 0, 0, 0, 0},
    {"gltf/Avocado/glTF/Avocado.gltf", 682, 406, 1, 1, 1, 1, 3, 3, 0, 0, 0},
    {"gltf/Box/glTF-Binary/Box.glb", 12, 24, 1, 1, 2, 1, 0, 0, 0, 0, 0},
    {"gltf/Box/glTF-Embedded/Box.gltf", 12, 24, 1, 1, 2, 1, 0, 0, 0, 0, 0},
    {"gltf/Box/glTF/Box.gltf", 12, 24, 1, 1, 2, 1, 0, 0, 0, 0, 0},
    {"gltf/BoxTextured/glTF-Binary/BoxTextured.glb", 12, 24, 1, 1, 2, 1, 1, 1, 0, 0, 0},
    {"gltf/BoxTextured/glTF-Embedded/BoxTextured.gltf", 12, 24, 1, 1, 2, 1, 1, 1, 0, 0, 0},
    {"gltf/BoxTextured/glTF/BoxTextured.gltf", 12, 24, 1, 1, 2, 1, 1, 1, 0, 0, 0},
    {"gltf/Cameras/glTF-Embedded/Cameras.gltf", 2, 6, 1, 1, 3, 1, 0, 0, 2, 0, 0},
    {"gltf/Cameras/glTF/Cameras.gltf", 2, 6, 1, 1, 3, 1, 0, 0, 2, 0, 0},
    {"gltf/CesiumMan/glTF/CesiumMan.gltf", 4672, 3273, 1, 1, 22, 1, 1, 1, 0, 0, 0},
    {"gltf/DamagedHelmet/glTF/DamagedHelmet.gltf", 15452, 14566, 1, 1, 1, 1, 5, 5, 0, 0, 0},
    {"gltf/Duck/glTF-Binary/Duck.glb", 4212, 2399, 1, 1, 3, 1, 1, 1, 1, 0, 0},
    {"gltf/Duck/glTF/Duck.gltf", 4212, 2399, 1, 1, 3, 1, 1, 1, 1, 0, 0},
    {"gltf/EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb", 90, 188, 6, 6, 6, 6, 1, 1, 0, 0, 0},
    {"gltf/EmissiveStrengthTest/glTF/EmissiveStrengthTest.gltf", 90, 188, 6, 6, 6, 6, 1, 1, 0, 0, 0},
    {"gltf/IridescenceSuzanne/glTF/IridescenceSuzanne.gltf", 11808, 9963, 3, 3, 4, 3, 1, 1, 0, 1, 0}, /* all its extensions supported: no warning */
    {"gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf", 6000, 4555, 3, 3, 8, 3, 7, 7, 0, 5, 0},
    {"gltf/MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb", 1040409, 528291, 123, 102, 119, 99, 0, 0, 0, 0, 0},
    {"gltf/MetalRoughSpheresNoTextures/glTF/MetalRoughSpheresNoTextures.gltf", 1040409, 528291, 123, 102, 119, 99, 0, 0, 0, 0, 0},
    {"gltf/MorphPrimitivesTest/glTF/MorphPrimitivesTest.gltf", 32, 30, 2, 1, 2, 2, 1, 1, 0, 0, 0},
    {"gltf/NormalTangentTest/glTF/NormalTangentTest.gltf", 7774, 3983, 1, 1, 2, 1, 3, 3, 0, 0, 0},
    {"gltf/OrientationTest/glTF-Binary/OrientationTest.glb", 524, 1048, 13, 13, 13, 7, 0, 0, 0, 0, 0},
    {"gltf/OrientationTest/glTF/OrientationTest.gltf", 524, 1048, 13, 13, 13, 7, 0, 0, 0, 0, 0},
    {"gltf/RiggedSimple/glTF/RiggedSimple.gltf", 188, 160, 1, 1, 5, 1, 0, 0, 0, 0, 0},
    {"gltf/SimpleMeshes/glTF-Embedded/SimpleMeshes.gltf", 2, 6, 2, 1, 2, 1, 0, 0, 0, 0, 0},
    {"gltf/SimpleMeshes/glTF/SimpleMeshes.gltf", 2, 6, 2, 1, 2, 1, 0, 0, 0, 0, 0},
    {"gltf/SimpleMorph/glTF/SimpleMorph.gltf", 1, 3, 1, 1, 1, 1, 0, 0, 0, 0, 0},
    {"gltf/SimpleSkin/glTF/SimpleSkin.gltf", 8, 24, 1, 1, 3, 1, 0, 0, 0, 0, 0},
    {"gltf/SimpleSparseAccessor/glTF/SimpleSparseAccessor.gltf", 12, 36, 1, 1, 1, 1, 0, 0, 0, 0, 0},
    {"gltf/Suzanne/glTF/Suzanne.gltf", 3936, 11808, 1, 1, 1, 1, 2, 2, 0, 0, 0},
    {"gltf/TextureCoordinateTest/glTF-Binary/TextureCoordinateTest.glb", 10, 20, 5, 5, 5, 5, 1, 1, 0, 0, 0},
    {"gltf/TextureCoordinateTest/glTF/TextureCoordinateTest.gltf", 10, 20, 5, 5, 5, 5, 1, 1, 0, 0, 0},
    {"gltf/TransmissionRoughnessTest/glTF/TransmissionRoughnessTest.gltf", 77792, 47260, 9, 9, 10, 9, 5, 9, 0, 0, 0},
    {"gltf/TransmissionTest/glTF/TransmissionTest.gltf", 128775, 66902, 22, 22, 25, 14, 9, 9, 1, 0, 0},
    {"gltf/Triangle/glTF-Embedded/Triangle.gltf", 1, 3, 1, 1, 1, 1, 0, 0, 0, 0, 0},
    {"gltf/Triangle/glTF/Triangle.gltf", 1, 3, 1, 1, 1, 1, 0, 0, 0, 0, 0},
    {"gltf/TriangleWithoutIndices/glTF-Embedded/TriangleWithoutIndices.gltf", 1, 3, 1, 1, 1, 1, 0, 0, 0, 0, 0},
    {"gltf/TriangleWithoutIndices/glTF/TriangleWithoutIndices.gltf", 1, 3, 1, 1, 1, 1, 0, 0, 0, 0, 0},
    {"gltf/WaterBottle/glTF/WaterBottle.gltf", 4510, 2549, 1, 1, 1, 1, 4, 4, 0, 0, 0},
};

TEST(scene, sample_models)
{
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    for (size_t i = 0; i < sizeof samples / sizeof samples[0]; i++) {
        char path[4096];
        scene s;
        int w0 = util_warning_count();
        bool ok = load(&s, asset(path, sizeof path, samples[i].path));
        int warnings = util_warning_count() - w0;
        CHECKF(ok, "%s did not load:\n%s", samples[i].path, load_log);
        if (!ok)
            continue;
        /* (placed: a mesh several nodes use is kept once, with its instances) */
        CHECKF(scene_placed_triangles(&s) == samples[i].tris && placed_vertices(&s) == samples[i].verts &&
                   s.num_meshes == samples[i].prims && s.num_gltf_meshes == samples[i].meshes &&
                   s.num_nodes == samples[i].nodes && s.num_materials == samples[i].mats,
               "%s: %llu triangles %llu vertices %u prims %u meshes %u nodes %u materials", samples[i].path,
               (unsigned long long)scene_placed_triangles(&s), (unsigned long long)placed_vertices(&s), s.num_meshes,
               s.num_gltf_meshes, s.num_nodes, s.num_materials);
        CHECKF(s.num_images == samples[i].images && s.num_textures == samples[i].textures &&
                   s.num_cameras == samples[i].cameras && s.num_lights == samples[i].lights,
               "%s: %u images %u textures %u cameras %u lights", samples[i].path, s.num_images, s.num_textures,
               s.num_cameras, s.num_lights);
        CHECKF(warnings == samples[i].warnings, "%s: %d warnings:\n%s", samples[i].path, warnings, load_log);
        CHECK(strcmp(s.path, path) == 0);
        check_invariants(&s, samples[i].path);
        scene_destroy(&s);
    }
}

TEST(scene, triangle)
{
    static const char *const files[] = {"gltf/Triangle/glTF/Triangle.gltf", "gltf/Triangle/glTF-Embedded/Triangle.gltf",
                                        "gltf/TriangleWithoutIndices/glTF/TriangleWithoutIndices.gltf",
                                        "gltf/TriangleWithoutIndices/glTF-Embedded/TriangleWithoutIndices.gltf"};
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    for (int f = 0; f < 4; f++) {
        char path[4096];
        scene s;
        CHECKF(load(&s, asset(path, sizeof path, files[f])), "%s", load_log);
        /* The files' positions (0,0,0) (1,0,0) (0,1,0) under an identity node; no NORMAL, so
         * the flat normal is +Z; no material, so the glTF default is appended. */
        CHECK(s.num_triangles == 1);
        if (s.num_triangles != 1)
            continue;
        CHECK(near3(s.vertices[s.indices[0]].position, 0, 0, 0, 0));
        CHECK(near3(s.vertices[s.indices[1]].position, 1, 0, 0, 0));
        CHECK(near3(s.vertices[s.indices[2]].position, 0, 1, 0, 0));
        for (int k = 0; k < 3; k++)
            CHECK(near3(s.vertices[s.indices[k]].normal, 0, 0, 1, 1e-6f));
        CHECK(s.num_materials == 1 && s.tri_material[0] == 0 && strcmp(s.material_names[0], "default") == 0);
        CHECK(s.materials[0].metallic == 1 && s.materials[0].base_color.x == 1);
        CHECK(s.bounds_min[0] == 0 && s.bounds_max[0] == 1 && s.bounds_max[1] == 1 && s.bounds_max[2] == 0);
        scene_destroy(&s);
    }
}

TEST(scene, simple_meshes)
{
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    char path[4096];
    scene s;
    CHECKF(load(&s, asset(path, sizeof path, "gltf/SimpleMeshes/glTF/SimpleMeshes.gltf")), "%s", load_log);
    /* One triangle mesh (0,0,0) (1,0,0) (0,1,0), normals +Z, drawn by node 0 (identity) and
     * node 1 (translation 1,0,0), in that order: used twice, it is kept once in its own space
     * and placed by two instances, nothing in world space. */
    CHECK(s.num_triangles == 0 && s.num_meshes == 2 && s.num_gltf_meshes == 1 && s.num_instanced_meshes == 1 &&
          s.num_instances == 2 && scene_placed_triangles(&s) == 2);
    if (s.num_instanced_meshes == 1 && s.num_instances == 2 && s.instanced_meshes[0].num_triangles == 1 &&
        s.instanced_meshes[0].num_vertices == 3) {
        const scene_instanced_mesh *m = &s.instanced_meshes[0];
        const uint32_t *t = m->indices;
        for (uint32_t inst = 0; inst < 2; inst++) {
            CHECK(s.instances[inst].node == inst && s.instances[inst].mesh == 0);
            CHECK(near3(placed(&s, inst, m->vertices[t[0]].position), (float)inst, 0, 0, 0));
            CHECK(near3(placed(&s, inst, m->vertices[t[1]].position), 1.0f + inst, 0, 0, 0));
            CHECK(near3(placed(&s, inst, m->vertices[t[2]].position), (float)inst, 1, 0, 0));
        }
        CHECK(near3(m->vertices[t[0]].normal, 0, 0, 1, 0));
        CHECK(s.bounds_min[0] == 0 && s.bounds_max[0] == 2);
    } else {
        CHECK(!"SimpleMeshes: one mesh of one triangle, placed twice");
    }
    scene_destroy(&s);
}

TEST(scene, box)
{
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    char path[4096];
    scene s;
    CHECKF(load(&s, asset(path, sizeof path, "gltf/Box/glTF/Box.gltf")), "%s", load_log);
    /* The unit cube around the origin under a -90 degree rotation about X: still [-0.5, 0.5]^3;
     * faces must keep their outward normals and windings. Material 'Red': base (0.8, 0, 0),
     * metallic 0 -> Phong diffuse (0.8, 0, 0). */
    CHECK(s.num_triangles == 12 && s.num_vertices == 24);
    for (int k = 0; k < 3; k++)
        CHECK(near(s.bounds_min[k], -0.5f, 1e-6f) && near(s.bounds_max[k], 0.5f, 1e-6f));
    CHECK(winding_matches_normals(&s));
    CHECK(s.num_materials == 1 && strcmp(s.material_names[0], "Red") == 0);
    CHECK(near3(s.materials[0].phong_diffuse, 0.8f, 0, 0, 1e-6f) && s.materials[0].metallic == 0);
    scene_destroy(&s);
}

/* .glb and data-URI variants must give exactly the geometry, materials and images of the .gltf. */
TEST(scene, variants_identical)
{
    static const char *const sets[][3] = {
        {"gltf/Box/glTF/Box.gltf", "gltf/Box/glTF-Binary/Box.glb", "gltf/Box/glTF-Embedded/Box.gltf"},
        {"gltf/BoxTextured/glTF/BoxTextured.gltf", "gltf/BoxTextured/glTF-Binary/BoxTextured.glb",
         "gltf/BoxTextured/glTF-Embedded/BoxTextured.gltf"},
        {"gltf/Duck/glTF/Duck.gltf", "gltf/Duck/glTF-Binary/Duck.glb", NULL},
        {"gltf/OrientationTest/glTF/OrientationTest.gltf", "gltf/OrientationTest/glTF-Binary/OrientationTest.glb", NULL},
    };
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    for (size_t i = 0; i < sizeof sets / sizeof sets[0]; i++) {
        char path[4096];
        scene a, b;
        CHECKF(load(&a, asset(path, sizeof path, sets[i][0])), "%s", load_log);
        for (int v = 1; v < 3 && sets[i][v]; v++) {
            CHECKF(load(&b, asset(path, sizeof path, sets[i][v])), "%s", load_log);
            bool same = a.num_vertices == b.num_vertices && a.num_triangles == b.num_triangles &&
                        a.num_materials == b.num_materials && a.num_images == b.num_images &&
                        !memcmp(a.vertices, b.vertices, a.num_vertices * sizeof *a.vertices) &&
                        !memcmp(a.indices, b.indices, 3 * a.num_triangles * sizeof *a.indices) &&
                        !memcmp(a.materials, b.materials, a.num_materials * sizeof *a.materials);
            for (uint32_t m = 0; same && m < a.num_images; m++)
                same = a.images[m].width == b.images[m].width && a.images[m].height == b.images[m].height &&
                       !memcmp(a.images[m].rgba8, b.images[m].rgba8, 4 * (size_t)a.images[m].width * a.images[m].height);
            CHECKF(same, "%s differs from %s", sets[i][v], sets[i][0]);
            scene_destroy(&b);
        }
        scene_destroy(&a);
    }
}

TEST(scene, orientation)
{
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    char path[4096];
    scene s;
    CHECKF(load(&s, asset(path, sizeof path, "gltf/OrientationTest/glTF/OrientationTest.gltf")), "%s", load_log);
    /* ArrowX1: rotation (-0.3007, 0, 0, 0.9537) = -35 degrees about X, translation (5, 0, 0).
     * Its mesh has a tip vertex at (-0.33065, 3, 0) -> (5 - 0.33065, 3 cos 35, -3 sin 35). */
    CHECKF(nearest_vertex(&s, 4.66935f, 2.457456f, -1.720729f) < 1e-3f, "ArrowX1 tip");
    /* ArrowZ2: matrix columns (0.9563, -0.2924, 0), (0.2924, 0.9563, 0), (0, 0, 1),
     * translation (0, 0, -5); tip vertex (0, 3, 0.33065) -> 3 * column 1 + (0, 0, 0.33065 - 5). */
    CHECKF(nearest_vertex(&s, 0.877115f, 2.868914f, -4.669349f) < 1e-3f, "ArrowZ2 tip");
    /* Whole-scene bounds, from transforming every POSITION in Python: the targets at +-5
     * reach 5.33065 on every axis. */
    for (int k = 0; k < 3; k++)
        CHECKF(near(s.bounds_min[k], -5.33065f, 1e-4f) && near(s.bounds_max[k], 5.33065f, 1e-4f), "axis %d: %g %g",
               k, s.bounds_min[k], s.bounds_max[k]);
    check_invariants(&s, "OrientationTest");
    scene_destroy(&s);
}

static bool orthonormal(const scene_camera *c)
{
    const float *v[3] = {c->right, c->up, c->forward};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            float d = v[i][0] * v[j][0] + v[i][1] * v[j][1] + v[i][2] * v[j][2];
            if (fabsf(d - (i == j)) > 1e-5f)
                return false;
        }
    /* right-handed: right = forward x up */
    const float *f = c->forward, *u = c->up;
    const float r[3] = {f[1] * u[2] - f[2] * u[1], f[2] * u[0] - f[0] * u[2], f[0] * u[1] - f[1] * u[0]};
    return fabsf(r[0] - c->right[0]) < 1e-5f && fabsf(r[1] - c->right[1]) < 1e-5f && fabsf(r[2] - c->right[2]) < 1e-5f;
}

TEST(scene, cameras)
{
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    char path[4096];
    scene s;
    int w0 = util_warning_count();
    CHECKF(load(&s, asset(path, sizeof path, "gltf/Cameras/glTF/Cameras.gltf")), "%s", load_log);
    /* Camera 0 is perspective (aspect 1, yfov 0.7, znear 0.01, zfar 100) on a node translated
     * to (0.5, 0.5, 3); camera 1 orthographic (xmag = ymag = 1) on a node at the same place. */
    CHECK(s.num_cameras == 2 && util_warning_count() == w0);
    if (s.num_cameras == 2) {
        const scene_camera *c = &s.cameras[0];
        CHECK(c->position[0] == 0.5f && c->position[1] == 0.5f && c->position[2] == 3);
        CHECK(c->forward[2] == -1 && c->up[1] == 1 && c->right[0] == 1 && orthonormal(c));
        CHECK(near(c->yfov, 0.7f, 1e-6f) && c->aspect == 1 && near(c->znear, 0.01f, 1e-9f) && c->zfar == 100);
        CHECK(c->ortho_half_height == 0);
        c = &s.cameras[1];
        CHECK(c->position[0] == 0.5f && c->position[1] == 0.5f && c->position[2] == 3 && orthonormal(c));
        CHECK(c->ortho_half_height == 1 && c->aspect == 1 && near(c->znear, 0.01f, 1e-9f) && c->zfar == 100);
    }
    scene_destroy(&s);
    CHECKF(load(&s, asset(path, sizeof path, "gltf/Duck/glTF/Duck.gltf")), "%s", load_log);
    /* Duck: the camera node's matrix (rotation, translation (400.113, 463.264, -431.078)) under
     * a root scaled by 0.01: position = 0.01 * translation; forward = -column 2 and up =
     * column 1 of the node matrix (unit columns: the root's scale must be removed). */
    CHECK(s.num_cameras == 1);
    if (s.num_cameras == 1) {
        const scene_camera *c = &s.cameras[0];
        CHECK(near(c->position[0], 4.00113f, 1e-4f) && near(c->position[1], 4.63264f, 1e-4f) &&
              near(c->position[2], -4.31078f, 1e-4f));
        CHECK(near(c->forward[0], -0.5364751f, 1e-5f) && near(c->forward[1], -0.6211478f, 1e-5f) &&
              near(c->forward[2], 0.5712880f, 1e-5f));
        CHECK(near(c->up[0], -0.4252049f, 1e-5f) && near(c->up[1], 0.7836934f, 1e-5f) && near(c->up[2], 0.4527973f, 1e-5f));
        CHECK(orthonormal(c) && near(c->aspect, 1.5f, 1e-6f) && c->znear == 1 && c->zfar == 10000);
        CHECK(strcmp(c->name, "camera 0") == 0);
    }
    scene_destroy(&s);
}

TEST(scene, textures)
{
    static const struct {
        const char *file;
        uint32_t w, h; /* the PNGs' IHDR sizes, read with Python */
    } cases[] = {{"gltf/BoxTextured/glTF/BoxTextured.gltf", 256, 256},
                 {"gltf/BoxTextured/glTF-Embedded/BoxTextured.gltf", 256, 256},
                 {"gltf/Duck/glTF-Binary/Duck.glb", 512, 512}};
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    for (int i = 0; i < 3; i++) {
        char path[4096];
        scene s;
        CHECKF(load(&s, asset(path, sizeof path, cases[i].file)), "%s", load_log);
        CHECK(s.num_images == 1 && s.num_textures == 1 && s.num_materials == 1);
        if (s.num_images == 1 && s.num_textures == 1) {
            CHECK(s.images[0].width == cases[i].w && s.images[0].height == cases[i].h && s.images[0].rgba8);
            /* Sampler: REPEAT/REPEAT, LINEAR magnification -> flags 0. */
            CHECK(s.textures[0].image == 0 && s.textures[0].flags == 0);
            CHECK(s.materials[0].tex_base == 0 && s.materials[0].tex_mr == GN_INVALID);
        }
        scene_destroy(&s);
    }
}

TEST(scene, khr_materials)
{
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    char path[4096];
    scene s;
    CHECKF(load(&s, asset(path, sizeof path, "gltf/EmissiveStrengthTest/glTF/EmissiveStrengthTest.gltf")), "%s", load_log);
    /* Every EmitN material has emissiveFactor (0.1, 0.5, 0.9) and emissiveStrength N (Emit1: none). */
    static const struct { const char *name; float k; } emit[] = {{"Emit1", 1}, {"Emit2", 2}, {"Emit4", 4}, {"Emit8", 8}, {"Emit16", 16}};
    for (int i = 0; i < 5; i++) {
        int m = find_material(&s, emit[i].name);
        CHECKF(m >= 0, "%s missing", emit[i].name);
        if (m < 0)
            continue;
        CHECK(near3(s.materials[m].emissive, 0.1f * emit[i].k, 0.5f * emit[i].k, 0.9f * emit[i].k, 1e-5f));
        CHECK(near3(s.materials[m].phong_emission, 0.1f * emit[i].k, 0.5f * emit[i].k, 0.9f * emit[i].k, 1e-5f));
    }
    scene_destroy(&s);
    CHECKF(load(&s, asset(path, sizeof path, "gltf/TransmissionRoughnessTest/glTF/TransmissionRoughnessTest.gltf")), "%s", load_log);
    /* KHR_materials_ior per sphere (Mat_IOR_1.50 gives none: the default 1.5), all fully
     * transmissive, so the Phong diffuse term is 0. */
    static const struct { const char *name; float ior; } iors[] = {
        {"Mat_IOR_1.0", 1.0f}, {"Mat_IOR_1.33", 1.33f}, {"Mat_IOR_1.50", 1.5f}, {"Mat_IOR_1.76", 1.76f}, {"Mat_IOR_2.42", 2.42f}};
    for (int i = 0; i < 5; i++) {
        int m = find_material(&s, iors[i].name);
        CHECKF(m >= 0 && near(s.materials[m].ior, iors[i].ior, 1e-6f) && s.materials[m].transmission == 1 &&
                   near3(s.materials[m].phong_diffuse, 0, 0, 0, 0), "%s", iors[i].name);
    }
    int opaque = find_material(&s, "Mat_Opaque");
    CHECK(opaque >= 0 && s.materials[opaque].ior == 1.5f && s.materials[opaque].transmission == 0);
    scene_destroy(&s);
}

TEST(scene, lights)
{
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    char path[4096];
    scene s;
    CHECKF(load(&s, asset(path, sizeof path, "gltf/LightsPunctualLamp/glTF/LightsPunctualLamp.gltf")), "%s", load_log);
    /* Five point lights on nodes 3..7 (scene order). Node 3: light 0, colour (1, 0.631875,
     * 0.2390998) intensity 15, matrix translation (0.0462236, 0.9077973, 0.0066966); node 4:
     * light 1, no colour (white), intensity 1.5, translation (0.1754562, -0.7642199, -0.0057041).
     * Their matrices rotate -Z onto -Y. */
    CHECK(s.num_lights == 5);
    if (s.num_lights == 5) {
        const GnLight *l = s.lights;
        for (int i = 0; i < 5; i++)
            CHECK(l[i].type == GN_LIGHT_POINT && l[i].range == 0 && near3(l[i].direction, 0, -1, 0, 1e-6f));
        CHECK(near3(l[0].position, 0.0462236f, 0.9077973f, 0.0066966f, 1e-6f));
        CHECK(near3(l[0].color, 15, 9.478125f, 3.586497f, 1e-4f));
        CHECK(near3(l[1].position, 0.1754562f, -0.7642199f, -0.0057041f, 1e-6f));
        CHECK(near3(l[1].color, 1.5f, 1.5f, 1.5f, 1e-6f));
        CHECK(near(l[4].color.x, 180, 1e-3f));
    }
    scene_destroy(&s);
}

/* Two Asset Generator sets (attribute formats, vertex colours, texture combinations): all load
 * and satisfy the invariants. The other two sets decode one 3 MB PNG per model for little more
 * coverage, which would double the suite's time. */
TEST(scene, asset_generator)
{
    static const char *const sets[] = {"Material_MetallicRoughness", "Mesh_PrimitiveAttribute"};
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    int loaded = 0, coloured = 0;
    for (int i = 0; i < 2; i++) {
        char dir[4096];
        snprintf(dir, sizeof dir, "%s/asset-generator/%s", test_assets_dir(), sets[i]);
        DIR *d = opendir(dir);
        struct dirent *e;
        while (d && (e = readdir(d))) {
            size_t n = strlen(e->d_name);
            if (n < 5 || strcmp(e->d_name + n - 5, ".gltf") != 0)
                continue;
            char path[8192];
            scene s;
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            bool ok = load(&s, path);
            CHECKF(ok && s.num_triangles > 0, "%s:\n%s", path, load_log);
            if (ok)
                check_invariants(&s, path);
            loaded += ok;
            coloured += ok && s.vertex_colors;
            scene_destroy(&s);
        }
        if (d)
            closedir(d);
    }
    CHECKF(loaded == 19, "%d asset-generator models loaded", loaded);
    /* Material_MetallicRoughness_01, _07 and _11 have COLOR_0 */
    CHECKF(coloured == 3, "%d asset-generator models with vertex colours, expected 3", coloured);
}

/* ---- the glTF-Validator's invalid corpus ---------------------------------------------------- */

/* Valid files (no validator error) that still cannot load, and why. */
static const char *const valid_but_refused[][2] = {
    {"buffer/non_relative_uri.gltf", "its buffer is an http:// URI, and gonio reads local files only"},
    {"accessor/unknown_type.gltf", "an unknown accessor type cannot be read (the validator only warns)"},
};

static int corpus_files, corpus_rejected, corpus_warned, corpus_no_triangles;

static void check_corpus_file(const char *path, const char *rel)
{
    char report[8192];
    snprintf(report, sizeof report, "%s.report.json", path);
    char *json = util_read_file(report, NULL);
    CHECKF(json != NULL, "%s: no report", rel);
    if (!json)
        return;
    const char *p = strstr(json, "\"numErrors\"");
    long errors = p ? strtol(strchr(p, ':') + 1, NULL, 10) : -1;
    free(json);
    CHECKF(errors >= 0, "%s: no numErrors in the report", rel);
    scene s;
    int w0 = util_warning_count();
    bool ok = load(&s, path);
    int warnings = util_warning_count() - w0;
    corpus_files++;
    /* Every message names the file. */
    bool named = true;
    for (const char *line = load_log; *line; line = strchr(line, '\n') + 1) {
        named &= strncmp(line, "gonio: ", 7) == 0 && strstr(line, path) != NULL;
        if (!strchr(line, '\n'))
            break;
    }
    CHECKF(named, "%s: a message does not name the file:\n%s", rel, load_log);
    if (ok)
        check_invariants(&s, rel);
    scene_destroy(&s);
    if (errors > 0) {
        corpus_rejected += !ok;
        corpus_warned += ok;
        CHECKF((!ok && strstr(load_log, "error: ")) || (ok && warnings > 0),
               "%s (%ld validator errors): loaded=%d warnings=%d\n%s", rel, errors, ok, warnings, load_log);
        return;
    }
    bool refused_ok = strstr(load_log, ": no triangles") != NULL;
    corpus_no_triangles += refused_ok;
    for (size_t i = 0; i < sizeof valid_but_refused / sizeof valid_but_refused[0]; i++)
        refused_ok |= strcmp(rel, valid_but_refused[i][0]) == 0;
    CHECKF(ok || refused_ok, "%s (valid): refused\n%s", rel, load_log);
}

static void walk_corpus(const char *dir, const char *rel)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d))) {
        if (e->d_name[0] == '.')
            continue;
        char path[4096], sub[4096];
        struct stat st;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        snprintf(sub, sizeof sub, "%s%s%s", rel, *rel ? "/" : "", e->d_name);
        size_t n = strlen(e->d_name);
        if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
            walk_corpus(path, sub);
        else if ((n > 5 && strcmp(e->d_name + n - 5, ".gltf") == 0) || (n > 4 && strcmp(e->d_name + n - 4, ".glb") == 0))
            check_corpus_file(path, sub);
    }
    if (d)
        closedir(d);
}

TEST(scene, invalid_corpus)
{
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    char dir[4096];
    corpus_files = corpus_rejected = corpus_warned = corpus_no_triangles = 0;
    walk_corpus(asset(dir, sizeof dir, "invalid-gltf"), "");
    CHECKF(corpus_files == 85, "%d files in the corpus", corpus_files);
    /* Summary kept visible in the test log: with errors, rejected or loaded with a warning;
     * valid controls without drawable triangles end in "no triangles". */
    printf("    invalid-gltf: %d files; with errors: %d rejected, %d loaded with warnings; "
           "valid but no triangles: %d\n", corpus_files, corpus_rejected, corpus_warned, corpus_no_triangles);
}

/* ---- synthetic files ------------------------------------------------------------------------ */

/* Buffer of the synthetic scenes: a unit right triangle with +Z normals and +X tangents, then
 * a spare vertex (index 3) and u8 indices. */
static const struct {
    float pos[4][3];
    float nrm[4][3];
    float tan[4][4];
    uint8_t idx[8];
} tri_buf = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}},
             {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}},
             {{1, 0, 0, 1}, {1, 0, 0, 1}, {1, 0, 0, 1}, {1, 0, 0, 1}},
             {0, 1, 2, 1, 3, 2, 0, 0}};

/* accessor 0 positions, 1 normals, 2 tangents, 3 indices (3 of them), 4 positions of the 4
 * vertices; the positions with the min and max glTF requires. */
#define TRI_ACCESSORS                                                                                 \
    "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":48},"    \
    "{\"buffer\":0,\"byteOffset\":96,\"byteLength\":64},{\"buffer\":0,\"byteOffset\":160,\"byteLength\":6}],"   \
    "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","                  \
    "\"min\":[0,0,0],\"max\":[1,1,0]},"                                                                      \
    "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"                                \
    "{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"},"                                \
    "{\"bufferView\":3,\"componentType\":5121,\"count\":3,\"type\":\"SCALAR\"},"                              \
    "{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]}," \
    "{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}]"
#define TRI_MESH "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TANGENT\":2},\"indices\":3}]}]"

/* Writes a scene around the triangle buffer: `body` holds the nodes/scenes/etc. */
static void write_tri_scene(const char *path, const char *body)
{
    size_t cap = strlen(body) + sizeof TRI_ACCESSORS + 64;
    char *fmt = util_malloc(cap);
    snprintf(fmt, cap, "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[%%s]," TRI_ACCESSORS ",%s}", body);
    write_gltf(path, fmt, &tri_buf, sizeof tri_buf);
    free(fmt);
}

static bool load_tri_scene(scene *s, const char *body)
{
    write_tri_scene(TMP_GLTF, body);
    return load(s, TMP_GLTF);
}

/* KHR_materials_volume and _dispersion: the values read, glTF's defaults, thicknessFactor 0
 * as thin-walled (no medium), and a warning for each bad value (the default kept, or clamped);
 * a thicknessTexture that names no texture is an error with its JSON path, as every texture
 * slot's is. */
TEST(scene, volume)
{
    const char *body =
        "\"extensionsUsed\":[\"KHR_materials_transmission\",\"KHR_materials_volume\",\"KHR_materials_dispersion\"],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":3,\"material\":0}]}],"
        "\"materials\":["
        "{\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
        "\"KHR_materials_volume\":{\"thicknessFactor\":0.5,\"attenuationColor\":[0.5,0.25,1],\"attenuationDistance\":2},"
        "\"KHR_materials_dispersion\":{\"dispersion\":0.4}}},"
        "{\"extensions\":{\"KHR_materials_volume\":{}}},"
        "{\"extensions\":{\"KHR_materials_volume\":{\"thicknessFactor\":1,\"attenuationColor\":[1.5,0,0],"
        "\"attenuationDistance\":0},\"KHR_materials_dispersion\":{\"dispersion\":-1}}}],"
        "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]";
    scene s;
    int w0 = util_warning_count();
    CHECKF(load_tri_scene(&s, body), "%s", load_log);
    CHECKF(util_warning_count() - w0 == 3, "%d warnings:\n%s", util_warning_count() - w0, load_log);
    CHECK(strstr(load_log, "material 2: attenuationColor") && strstr(load_log, "material 2: attenuationDistance 0") &&
          strstr(load_log, "material 2: dispersion -1") && !strstr(load_log, "unsupported"));
    CHECK(s.num_materials == 3);
    if (s.num_materials != 3) {
        scene_destroy(&s);
        return;
    }
    const GnMaterial *m = s.materials;
    CHECK(m[0].volume == 1 && m[0].thickness == 0.5f && near3(m[0].attenuation_color, 0.5f, 0.25f, 1, 0) &&
          m[0].attenuation_distance == 2 && m[0].dispersion == 0.4f && m[0].transmission == 1);
    CHECK(m[1].volume == 0 && m[1].thickness == 0 && near3(m[1].attenuation_color, 1, 1, 1, 0) &&
          isinf(m[1].attenuation_distance) && m[1].dispersion == 0);
    CHECK(m[2].volume == 1 && near3(m[2].attenuation_color, 1, 1, 1, 0) && isinf(m[2].attenuation_distance) &&
          m[2].dispersion == 0);
    scene_destroy(&s);
    CHECK(!load_tri_scene(&s, "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":3,\"material\":0}]}],"
                              "\"materials\":[{\"extensions\":{\"KHR_materials_volume\":{\"thicknessFactor\":1,"
                              "\"thicknessTexture\":{\"index\":3}}}}],\"nodes\":[{\"mesh\":0}]") &&
          strstr(load_log, "materials[0].extensions.KHR_materials_volume.thicknessTexture.index: 3 does not exist"));
}

TEST(scene, transforms)
{
    scene s;
    /* Mirror (scale -1 on X): positions mirrored, the winding swapped so the face still faces
     * its normal, the normal kept (+Z), the tangent mirrored to -X with w flipped. */
    CHECKF(load_tri_scene(&s, TRI_MESH ",\"nodes\":[{\"mesh\":0,\"scale\":[-1,1,1]}]"), "%s", load_log);
    if (s.num_triangles == 1) {
        CHECK(winding_matches_normals(&s));
        CHECK(near3(s.vertices[1].position, -1, 0, 0, 0) && near3(s.vertices[1].normal, 0, 0, 1, 1e-6f));
        CHECK(s.vertices[1].tangent.x == -1 && s.vertices[1].tangent.w == -1);
        CHECK(s.indices[0] == 0 && s.indices[1] == 2 && s.indices[2] == 1);
    }
    scene_destroy(&s);
    /* Non-uniform scale: the child's rotation (columns (0,0,1), (1,-1,0)/sqrt 2, (1,1,0)/sqrt 2)
     * turns the +Z normal into (1, 1, 0)/sqrt 2; the parent's scale (2, 1, 1) then acts on
     * normals by its inverse transpose diag(1/2, 1, 1): (0.5, 1, 0) normalised. */
    CHECKF(load_tri_scene(&s, TRI_MESH ",\"nodes\":[{\"children\":[1],\"scale\":[2,1,1]},"
                              "{\"mesh\":0,\"matrix\":[0,0,1,0, 0.70710678,-0.70710678,0,0, 0.70710678,0.70710678,0,0, 0,0,0,1]}]"),
           "%s", load_log);
    if (s.num_triangles == 1)
        CHECK(near3(s.vertices[0].normal, 0.4472136f, 0.8944272f, 0, 1e-5f));
    scene_destroy(&s);
    /* Hierarchy: parent translation (1, 2, 3), child rotation 90 degrees about Z: vertex
     * (1, 0, 0) -> (0, 1, 0) + (1, 2, 3). */
    CHECKF(load_tri_scene(&s, TRI_MESH ",\"nodes\":[{\"children\":[1],\"translation\":[1,2,3]},"
                              "{\"mesh\":0,\"rotation\":[0,0,0.70710678,0.70710678]}],\"scenes\":[{\"nodes\":[0]}]"),
           "%s", load_log);
    if (s.num_triangles == 1)
        CHECK(near3(s.vertices[1].position, 1, 3, 3, 1e-6f) && near(s.vertices[1].tangent.y, 1, 1e-6f) &&
              s.vertices[1].tangent.w == 1);
    scene_destroy(&s);
}

TEST(scene, primitive_modes)
{
    scene s;
    int w0 = util_warning_count();
    /* A strip and a fan over the 4 vertices, and a POINTS primitive (skipped with a warning).
     * glTF's lists: strip (0,1,2) (1,3,2); fan (1,2,0) (2,3,0). */
    CHECKF(load_tri_scene(&s, "\"meshes\":[{\"primitives\":["
                              "{\"attributes\":{\"POSITION\":4,\"NORMAL\":5},\"mode\":5},"
                              "{\"attributes\":{\"POSITION\":4,\"NORMAL\":5},\"mode\":6},"
                              "{\"attributes\":{\"POSITION\":4,\"NORMAL\":5},\"mode\":0}]}],\"nodes\":[{\"mesh\":0}]"),
           "%s", load_log);
    static const uint32_t want[] = {0, 1, 2, 1, 3, 2, 5, 6, 4, 6, 7, 4};
    CHECK(s.num_triangles == 4 && s.num_meshes == 2 && s.num_vertices == 8);
    if (s.num_triangles == 4)
        CHECK(memcmp(s.indices, want, sizeof want) == 0);
    CHECK(util_warning_count() == w0 + 1 && strstr(load_log, "POINTS"));
    scene_destroy(&s);
}

TEST(scene, bad_geometry)
{
    scene s;
    /* Three non-indexed triangles; the 2nd has a NaN corner, the 3rd a corner at 1e20: both
     * dropped with one warning giving the count. */
    float pos[9][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {NAN, 0, 0}, {0, 1, 0}, {0, 0, 0}, {1, 0, 0}, {0, 1e20f, 0}};
    const char *fmt = "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[%s],\"bufferViews\":[{\"buffer\":0,\"byteLength\":108}],"
                      "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":9,\"type\":\"VEC3\"}],"
                      "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}]}";
    write_gltf(TMP_GLTF, fmt, pos, sizeof pos);
    int w0 = util_warning_count();
    CHECKF(load(&s, TMP_GLTF), "%s", load_log);
    CHECK(s.num_triangles == 1 && strstr(load_log, "dropped 2 triangle"));
    CHECK(util_warning_count() > w0);
    CHECK(s.bounds_max[0] == 1 && s.bounds_max[1] == 1);
    scene_destroy(&s);
    /* Only huge triangles: nothing left. */
    for (int v = 0; v < 9; v++)
        pos[v][2] = 1e16f;
    write_gltf(TMP_GLTF, fmt, pos, sizeof pos);
    CHECK(!load(&s, TMP_GLTF) && strstr(load_log, "no triangles") && s.vertices == NULL);
    /* Transforms that overflow: two nested scales of 1e200. */
    CHECK(!load_tri_scene(&s, TRI_MESH ",\"nodes\":[{\"children\":[1],\"scale\":[1e200,1,1]},{\"mesh\":0,\"scale\":[1e200,1,1]}]") &&
          strstr(load_log, "node 1: world transform is not finite"));
    /* Node loops, a self-loop, and a node with two parents. */
    CHECK(!load_tri_scene(&s, TRI_MESH ",\"nodes\":[{\"mesh\":0,\"children\":[1]},{\"children\":[0]}],\"scenes\":[{\"nodes\":[0]}]") &&
          strstr(load_log, "node loop"));
    CHECK(!load_tri_scene(&s, TRI_MESH ",\"nodes\":[{\"mesh\":0},{\"children\":[1]}]") && strstr(load_log, "node 1 is part of a node loop"));
    CHECK(!load_tri_scene(&s, TRI_MESH ",\"nodes\":[{\"mesh\":0},{\"children\":[0]},{\"children\":[0]}]") &&
          strstr(load_log, "more than one parent"));
    /* An empty scene. */
    CHECK(!load_tri_scene(&s, TRI_MESH ",\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[]}],\"scene\":0") &&
          strstr(load_log, "no triangles"));
    /* Accessors and views that do not fit, misalignment, bad formats, counts and indices. The
     * file has buffer views 0..3 of the triangle, two small ones, and view 6: in case 2 one
     * that overruns the buffer, else one whose stride is below a VEC3 element. */
    static const struct {
        const char *accessor, *attributes, *message;
    } bad[] = {
        {"{\"bufferView\":0,\"componentType\":5126,\"count\":5,\"type\":\"VEC3\"}", "\"POSITION\":6", "does not fit in buffer view 0"},
        {"{\"bufferView\":0,\"byteOffset\":2,\"componentType\":5126,\"count\":1,\"type\":\"VEC3\"}", "\"POSITION\":6", "not a multiple"},
        {"{\"bufferView\":6,\"componentType\":5126,\"count\":1,\"type\":\"VEC3\"}", "\"POSITION\":6",
         "bufferViews[6]: bytes 160 to 260 lie beyond buffers[0].byteLength 168"},
        {"{\"bufferView\":6,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"}", "\"POSITION\":6", "smaller than the element size"},
        {"{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"}", "\"POSITION\":6", "not allowed for attribute POSITION"},
        {"{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}", "\"POSITION\":0,\"NORMAL\":6", "same count"},
        {"{\"bufferView\":3,\"byteOffset\":3,\"componentType\":5121,\"count\":3,\"type\":\"SCALAR\"}",
         "\"POSITION\":0},\"indices\":6,\"x\":{", "only 3 vertices"},
        {"{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}", "\"POSITION\":6},\"mode\":9,\"x\":{",
         "mode: 9 is not one of"},
        {"{\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"normalized\":true}", "\"POSITION\":6", "normalized"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char json[4096];
        snprintf(json, sizeof json, "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[%%s],"
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":48},"
                 "{\"buffer\":0,\"byteOffset\":96,\"byteLength\":64},{\"buffer\":0,\"byteOffset\":160,\"byteLength\":6},"
                 "{\"buffer\":0,\"byteLength\":4},{\"buffer\":0,\"byteLength\":4},"
                 "%s],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},{\"bufferView\":4,"
                 "\"componentType\":5126,\"count\":1,\"type\":\"SCALAR\"},{\"bufferView\":4,\"componentType\":5126,\"count\":1,"
                 "\"type\":\"SCALAR\"},{\"bufferView\":4,\"componentType\":5126,\"count\":1,\"type\":\"SCALAR\"},"
                 "{\"bufferView\":4,\"componentType\":5126,\"count\":1,\"type\":\"SCALAR\"},{\"bufferView\":5,"
                 "\"componentType\":5126,\"count\":1,\"type\":\"SCALAR\"},%s],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{%s}}]}],\"nodes\":[{\"mesh\":0}]}",
                 i == 2 ? "{\"buffer\":0,\"byteOffset\":160,\"byteLength\":100}" : "{\"buffer\":0,\"byteLength\":48,\"byteStride\":8}",
                 bad[i].accessor, bad[i].attributes);
        write_gltf(TMP_GLTF, json, &tri_buf, sizeof tri_buf);
        CHECKF(!load(&s, TMP_GLTF) && strstr(load_log, bad[i].message), "case %zu:\n%s", i, load_log);
        scene_destroy(&s);
    }
    /* Bad rotation, wrong matrix size. */
    CHECK(!load_tri_scene(&s, TRI_MESH ",\"nodes\":[{\"mesh\":0,\"rotation\":[0,0,0,0]}]") && strstr(load_log, "unit quaternion"));
    CHECK(!load_tri_scene(&s, TRI_MESH ",\"nodes\":[{\"mesh\":0,\"matrix\":[1,0,0]}]") && strstr(load_log, "matrix: must have 16"));
    /* Deep JSON nesting (tinygltf would recurse on it). */
    char body[2048] = TRI_MESH ",\"nodes\":[{\"mesh\":0,\"extras\":";
    for (int i = 0; i < 200; i++)
        strcat(body, "[");
    for (int i = 0; i < 200; i++)
        strcat(body, "]");
    strcat(body, "}]");
    CHECK(!load_tri_scene(&s, body) && strstr(load_log, "nested deeper"));
}

TEST(scene, truncated_files)
{
    if (!test_assets_dir()) {
        test_skip("no test assets");
        return;
    }
    static const char *const files[] = {"gltf/Box/glTF-Binary/Box.glb", "gltf/Box/glTF/Box.gltf", "gltf/Duck/glTF-Binary/Duck.glb"};
    for (int f = 0; f < 3; f++) {
        char path[4096];
        size_t size;
        char *data = util_read_file(asset(path, sizeof path, files[f]), &size);
        CHECK(data != NULL);
        if (!data)
            continue;
        const size_t cuts[] = {0, 1, 4, 11, 12, 19, 20, 21, 100, size / 3, size / 2, size - 4, size - 1};
        for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
            scene s;
            write_bytes(f == 1 ? TMP_GLTF : TMP_GLB, data, cuts[i]);
            bool ok = load(&s, f == 1 ? TMP_GLTF : TMP_GLB);
            CHECKF(!ok && strstr(load_log, "error: "), "%s cut at %zu: %s", files[f], cuts[i], load_log);
            scene_destroy(&s);
        }
        free(data);
    }
}

/* A GLB built here: the triangle scene's JSON (buffer 0 = the BIN chunk), BIN, then a chunk of
 * unknown type that must be skipped. */
TEST(scene, glb_container)
{
    char json[4096];
    snprintf(json, sizeof json, "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":%zu}]," TRI_ACCESSORS
             "," TRI_MESH ",\"nodes\":[{\"mesh\":0}]}", sizeof tri_buf);
    size_t jlen = (strlen(json) + 3) & ~(size_t)3, blen = (sizeof tri_buf + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jlen + 8 + blen + 8 + 4;
    unsigned char *glb = util_calloc(total, 1);
    uint32_t head[3] = {0x46546C67, 2, (uint32_t)total}, jh[2] = {(uint32_t)jlen, 0x4E4F534A},
             bh[2] = {(uint32_t)blen, 0x004E4942}, uh[2] = {4, 0x12345678};
    memcpy(glb, head, 12);
    memcpy(glb + 12, jh, 8);
    memset(glb + 20, ' ', jlen);
    memcpy(glb + 20, json, strlen(json));
    memcpy(glb + 20 + jlen, bh, 8);
    memcpy(glb + 28 + jlen, &tri_buf, sizeof tri_buf);
    memcpy(glb + 28 + jlen + blen, uh, 8);
    write_bytes(TMP_GLB, glb, total);
    scene s;
    int w0 = util_warning_count();
    CHECKF(load(&s, TMP_GLB), "%s", load_log);
    CHECK(s.num_triangles == 1 && util_warning_count() == w0 + 1 && strstr(load_log, "unknown GLB chunk"));
    if (s.num_triangles == 1)
        CHECK(near3(s.vertices[s.indices[1]].position, 1, 0, 0, 0));
    scene_destroy(&s);
    /* The same bytes named .gltf are still read as GLB (by the magic), and a broken BIN length
     * (past the end) is refused. */
    write_bytes(TMP_GLTF, glb, total);
    CHECKF(load(&s, TMP_GLTF), "%s", load_log);
    scene_destroy(&s);
    bh[0] = 4096;
    memcpy(glb + 20 + jlen, bh, 8);
    write_bytes(TMP_GLB, glb, total);
    CHECK(!load(&s, TMP_GLB) && strstr(load_log, "runs past the end"));
    free(glb);
}

TEST(scene, sparse_accessor)
{
    scene s;
    /* Accessor 6: the 3 triangle positions with vertex 1 replaced by (5, 0, 0) through a sparse
     * substitution (index in bytes 0..1 of buffer view 4, value in buffer view 5). */
    static const struct {
        float pos[4][3], nrm[4][3], tan[4][4];
        uint8_t idx[8];
        uint16_t sparse_index[2];
        float sparse_value[3];
    } buf = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}}, {{0}}, {0, 1, 2}, {1, 0}, {5, 0, 0}};
    char fmt[4096];
    snprintf(fmt, sizeof fmt, "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[%%s],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":48},"
             "{\"buffer\":0,\"byteOffset\":96,\"byteLength\":64},{\"buffer\":0,\"byteOffset\":160,\"byteLength\":6},"
             "{\"buffer\":0,\"byteOffset\":168,\"byteLength\":2},{\"buffer\":0,\"byteOffset\":172,\"byteLength\":12}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
             "\"sparse\":{\"count\":1,\"indices\":{\"bufferView\":4,\"componentType\":5123},\"values\":{\"bufferView\":5}}},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1}}]}],\"nodes\":[{\"mesh\":0}]}");
    write_gltf(TMP_GLTF, fmt, &buf, sizeof buf);
    CHECKF(load(&s, TMP_GLTF), "%s", load_log);
    if (s.num_vertices == 3)
        CHECK(near3(s.vertices[0].position, 0, 0, 0, 0) && near3(s.vertices[1].position, 5, 0, 0, 0) &&
              near3(s.vertices[2].position, 0, 1, 0, 0));
    scene_destroy(&s);
}

/* 2x1 PNGs made with Python's zlib: 16-bit grey (0x1234, 0xffff) and 8-bit grey+alpha
 * ((0x10, 0x80), (0xf0, 0x20)). */
static const char png_g16[] = "iVBORw0KGgoAAAANSUhEUgAAAAIAAAABEAAAAACB2fwVAAAADUlEQVR4nGMQMvn/HwAD5gJFLkKWdQAAAABJRU5ErkJggg==";
static const char png_ga8[] = "iVBORw0KGgoAAAANSUhEUgAAAAIAAAABCAQAAABeK7cBAAAADUlEQVR4nGMQaPigAAADxQGhlMj5CAAAAABJRU5ErkJggg==";

TEST(scene, materials_lights_cameras)
{
    char body[8192];
    snprintf(body, sizeof body,
             "\"extensionsUsed\":[\"KHR_lights_punctual\",\"KHR_materials_unlit\",\"KHR_materials_specular\","
             "\"KHR_materials_transmission\",\"EXT_unknown\"],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TANGENT\":2},\"indices\":3,\"material\":0}]}],"
             "\"images\":[{\"uri\":\"data:image/png;base64,%s\"},{\"uri\":\"data:image/png;base64,%s\"},"
             "{\"bufferView\":0,\"mimeType\":\"image/png\"}],"
             "\"samplers\":[{\"wrapS\":33071,\"wrapT\":33648,\"magFilter\":9728}],"
             "\"textures\":[{\"source\":0,\"sampler\":0},{\"source\":1},{\"source\":2}],"
             "\"materials\":[{\"name\":\"M\",\"doubleSided\":true,\"alphaMode\":\"MASK\",\"alphaCutoff\":0.25,"
             "\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1],\"metallicFactor\":0,\"roughnessFactor\":0.5,"
             "\"baseColorTexture\":{\"index\":0},\"metallicRoughnessTexture\":{\"index\":1,\"texCoord\":1}},"
             "\"normalTexture\":{\"index\":1,\"scale\":0.5},\"occlusionTexture\":{\"index\":1,\"strength\":0.75},"
             "\"extensions\":{\"KHR_materials_unlit\":{},\"KHR_materials_specular\":{\"specularFactor\":0.5,"
             "\"specularColorFactor\":[1,0,0]},\"KHR_materials_transmission\":{\"transmissionFactor\":0.25}},"
             "\"extras\":{\"gonio\":{\"brdf\":\"ward\",\"alpha_x\":0.1,\"alpha_y\":0.3,"
             "\"phong\":{\"diffuse\":[0.1,0.2,0.3],\"shininess\":50}}}}],"
             "\"cameras\":[{\"type\":\"perspective\",\"name\":\"cam\",\"perspective\":{\"yfov\":0.5,\"znear\":0.1}},"
             "{\"type\":\"perspective\",\"perspective\":{\"yfov\":4,\"znear\":0.1}}],"
             "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"spot\",\"color\":[1,0.5,0.25],\"intensity\":2,"
             "\"range\":7,\"spot\":{\"innerConeAngle\":0.2,\"outerConeAngle\":0.5}},{\"type\":\"point\",\"intensity\":-1}]}},"
             "\"nodes\":[{\"mesh\":0},"
             "{\"translation\":[1,2,3],\"rotation\":[0.70710678,0,0,0.70710678],\"scale\":[3,3,3],\"camera\":0,"
             "\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
             "{\"camera\":1,\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}}]",
             png_g16, png_ga8);
    scene s;
    int w0 = util_warning_count();
    CHECKF(load_tri_scene(&s, body), "%s", load_log);
    /* Expected warnings: EXT_unknown, image 2 not a PNG (its buffer view holds floats; only
     * texture 2 uses it, which no material does), camera 1 yfov, light 1 intensity. */
    CHECKF(util_warning_count() - w0 == 4, "%d warnings:\n%s", util_warning_count() - w0, load_log);
    CHECK(strstr(load_log, "EXT_unknown") && !strstr(load_log, "MASK") && !strstr(load_log, "TEXCOORD_1") &&
          strstr(load_log, "image 2") && strstr(load_log, "camera 1") && strstr(load_log, "light 1"));
    /* Images: 16-bit grey -> (0x1234 / 257 rounded = 18); grey+alpha expands to RGBA. */
    static const uint8_t g16[8] = {18, 18, 18, 255, 255, 255, 255, 255}, ga8[8] = {0x10, 0x10, 0x10, 0x80, 0xf0, 0xf0, 0xf0, 0x20};
    /* texture 1 read through TEXCOORD_1 by metallicRoughnessTexture: a third scene texture */
    CHECK(s.num_images == 2 && s.num_textures == 3);
    if (s.num_images == 2 && s.num_textures == 3) {
        CHECK(s.images[0].width == 2 && s.images[0].height == 1 && memcmp(s.images[0].rgba8, g16, 8) == 0);
        CHECK(s.images[1].width == 2 && memcmp(s.images[1].rgba8, ga8, 8) == 0);
        /* CLAMP_TO_EDGE S (1), MIRRORED_REPEAT T (2 << 2), NEAREST (16). */
        CHECK(s.textures[0].flags == (1u | 2u << 2 | GN_TEX_NEAREST) && s.textures[1].flags == 0);
        CHECK(s.textures[2].image == s.textures[1].image && s.textures[2].flags == GN_TEX_UV1);
    }
    CHECK(s.num_materials == 1);
    const GnMaterial *m = &s.materials[0];
    CHECK(m->tex_base == 0 && m->tex_mr == 2 && m->tex_normal == 1 && m->tex_occlusion == 1);
    CHECK(m->flags == (GN_MAT_DOUBLE_SIDED | GN_MAT_UNLIT | GN_MAT_MASK) && m->alpha_cutoff == 0.25f);
    CHECK(m->normal_scale == 0.5f && m->occlusion_strength == 0.75f && m->transmission == 0.25f);
    CHECK(m->specular == 0.5f && near3(m->specular_color, 1, 0, 0, 0) && m->ior == 1.5f);
    /* Phong: diffuse overridden by extras; specular from the mapping, 0.04 * (1,0,0) * 0.5. */
    CHECK(near3(m->phong_diffuse, 0.1f, 0.2f, 0.3f, 1e-6f) && m->phong_shininess == 50);
    CHECK(near3(m->phong_specular, 0.02f, 0, 0, 1e-6f) && near3(m->phong_ambient, 0.5f * 0.75f, 0.5f * 0.75f, 0.5f * 0.75f, 1e-6f));
    const scene_material_extras *x = &s.material_extras[0];
    CHECK(strcmp(x->brdf, "ward") == 0 && x->has_phong && x->num_params == 2);
    CHECK(strcmp(x->param_names[0], "alpha_x") == 0 && near(x->param_values[0], 0.1f, 1e-7f));
    CHECK(strcmp(x->param_names[1], "alpha_y") == 0 && near(x->param_values[1], 0.3f, 1e-7f));
    CHECK(strcmp(s.material_names[0], "M") == 0);
    /* Node 1: rotation +90 degrees about X maps -Z to +Y and +Y to +Z; scale 3 removed. */
    CHECK(s.num_cameras == 1 && s.num_lights == 1);
    if (s.num_cameras == 1) {
        const scene_camera *c = &s.cameras[0];
        CHECK(strcmp(c->name, "cam") == 0 && c->position[0] == 1 && c->position[1] == 2 && c->position[2] == 3);
        CHECK(near(c->forward[1], 1, 1e-6f) && near(c->up[2], 1, 1e-6f) && near(c->right[0], 1, 1e-6f) && orthonormal(c));
        CHECK(c->yfov == 0.5f && c->aspect == 0 && c->zfar == 0 && near(c->znear, 0.1f, 1e-8f));
    }
    if (s.num_lights == 1) {
        const GnLight *l = &s.lights[0];
        CHECK(l->type == GN_LIGHT_SPOT && near3(l->position, 1, 2, 3, 0) && near3(l->direction, 0, 1, 0, 1e-6f));
        CHECK(near3(l->color, 2, 1, 0.5f, 1e-6f) && l->range == 7);
        CHECK(near(l->inner_cos, cosf(0.2f), 1e-6f) && near(l->outer_cos, cosf(0.5f), 1e-6f));
    }
    scene_destroy(&s);
    /* A missing image file a drawn material uses: an error naming the material's slot, the
     * texture and the image. */
    CHECK(!load_tri_scene(&s, "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
                              "\"nodes\":[{\"mesh\":0}],\"images\":[{\"uri\":\"no_such_image.png\"}],\"textures\":[{\"source\":0}],"
                              "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}]"));
    CHECKF(strstr(load_log, "material 0: baseColorTexture: texture 0: image 0 no_such_image.png: file missing or unreadable"),
           "%s", load_log);
    /* KHR_texture_transform: the rows of T R S (spec: R = [cos sin; -sin cos]); rotation
     * pi/2, scale (2, 3), offset (0.5, 0.25) -> (0, 3, 0.5), (-2, 0, 0.25). */
    snprintf(body, sizeof body, "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":0}]}],"
                              "\"nodes\":[{\"mesh\":0}],\"images\":[{\"uri\":\"data:image/png;base64,%s\"}],"
                              "\"textures\":[{\"source\":0}],\"extensionsUsed\":[\"KHR_texture_transform\"],"
                              "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,"
                              "\"extensions\":{\"KHR_texture_transform\":{\"rotation\":1.5707963267948966,"
                              "\"scale\":[2,3],\"offset\":[0.5,0.25]}}}}}]", png_g16);
    CHECKF(load_tri_scene(&s, body), "%s", load_log);
    CHECK(s.num_textures == 2 && s.materials[0].tex_base == 1);
    if (s.num_textures == 2) {
        const float *t = s.textures[1].transform, want[6] = {0, 3, 0.5f, -2, 0, 0.25f};
        for (int k = 0; k < 6; k++)
            CHECKF(fabsf(t[k] - want[k]) < 1e-6f, "transform[%d] = %g, want %g", k, t[k], want[k]);
        CHECK(s.textures[0].transform[0] == 1 && s.textures[0].transform[4] == 1 && s.textures[0].transform[2] == 0);
    }
    scene_destroy(&s);
    /* An unsupported required extension refuses the file. */
    CHECK(!load_tri_scene(&s, TRI_MESH ",\"nodes\":[{\"mesh\":0}],\"extensionsUsed\":[\"EXT_gonio_unknown\"],"
                              "\"extensionsRequired\":[\"EXT_gonio_unknown\"]") &&
          strstr(load_log, "requires unsupported extension EXT_gonio_unknown"));
}

/* KHR_materials_clearcoat and _sheen: factors, textures (one through KHR_texture_transform,
 * one through TEXCOORD_1), the coat's normal scale; out-of-range factors clamped with a
 * warning; a texture index that names no texture, or a factor that is no number, is an
 * error with its JSON path. */
TEST(scene, layers)
{
    char body[8192];
    const char *tex = "\"images\":[{\"uri\":\"data:image/png;base64,%s\"}],\"textures\":[{\"source\":0},{\"source\":0}],";
    char head[1024];
    snprintf(head, sizeof head, tex, png_ga8);
    snprintf(body, sizeof body,
             "\"extensionsUsed\":[\"KHR_materials_clearcoat\",\"KHR_materials_sheen\",\"KHR_texture_transform\"],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TANGENT\":2},\"indices\":3,\"material\":0}]}],"
             "%s\"materials\":[{\"extensions\":{"
             "\"KHR_materials_clearcoat\":{\"clearcoatFactor\":0.75,\"clearcoatRoughnessFactor\":1.5,"
             "\"clearcoatTexture\":{\"index\":0},\"clearcoatRoughnessTexture\":{\"index\":1,\"texCoord\":1},"
             "\"clearcoatNormalTexture\":{\"index\":1,\"scale\":0.5}},"
             "\"KHR_materials_sheen\":{\"sheenColorFactor\":[1,0.5,0.25],\"sheenRoughnessFactor\":0.3,"
             "\"sheenColorTexture\":{\"index\":0,\"extensions\":{\"KHR_texture_transform\":{\"scale\":[2,2]}}},"
             "\"sheenRoughnessTexture\":{\"index\":1}}}}],\"nodes\":[{\"mesh\":0}]",
             head);
    scene s;
    int w0 = util_warning_count();
    CHECKF(load_tri_scene(&s, body), "%s", load_log);
    CHECKF(util_warning_count() - w0 == 1 && strstr(load_log, "clearcoatRoughnessFactor"), "warnings:\n%s", load_log);
    CHECK(!strstr(load_log, "unsupported extension"));
    CHECK(s.num_materials == 1 && s.num_textures == 4);
    if (s.num_materials == 1 && s.num_textures == 4) {
        const GnMaterial *m = &s.materials[0];
        CHECK(m->clearcoat == 0.75f && m->clearcoat_roughness == 1 && m->clearcoat_normal_scale == 0.5f);
        CHECK(m->tex_clearcoat == 0 && m->tex_clearcoat_normal == 1 && m->tex_sheen_roughness == 1);
        CHECK(m->tex_clearcoat_roughness >= 2 && s.textures[m->tex_clearcoat_roughness].flags == GN_TEX_UV1);
        CHECK(m->tex_sheen_color >= 2 && s.textures[m->tex_sheen_color].transform[0] == 2);
        CHECK(near3(m->sheen_color, 1, 0.5f, 0.25f, 0) && m->sheen_roughness == 0.3f);
    }
    scene_destroy(&s);
    snprintf(body, sizeof body,
             TRI_MESH ",%s\"materials\":[{\"extensions\":{\"KHR_materials_sheen\":{\"sheenColorTexture\":{\"index\":7}}}}],"
             "\"nodes\":[{\"mesh\":0}]", head);
    CHECK(!load_tri_scene(&s, body) &&
          strstr(load_log, "materials[0].extensions.KHR_materials_sheen.sheenColorTexture.index: 7 does not exist"));
    snprintf(body, sizeof body,
             TRI_MESH ",\"materials\":[{\"extensions\":{\"KHR_materials_clearcoat\":{\"clearcoatFactor\":\"high\"}}}],"
             "\"nodes\":[{\"mesh\":0}]");
    CHECK(!load_tri_scene(&s, body) && strstr(load_log, "materials[0].extensions.KHR_materials_clearcoat.clearcoatFactor"));
}

/* KHR_materials_anisotropy: strength, rotation (reduced to [-pi, pi]) and texture (through
 * TEXCOORD_1); a strength out of [0, 1] clamped with a warning; a texture that names no
 * texture, or a strength that is no number, is an error with its JSON path. */
TEST(scene, anisotropy)
{
    char body[8192], head[1024];
    snprintf(head, sizeof head, "\"images\":[{\"uri\":\"data:image/png;base64,%s\"}],\"textures\":[{\"source\":0}],",
             png_ga8);
    snprintf(body, sizeof body,
             "\"extensionsUsed\":[\"KHR_materials_anisotropy\"],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TANGENT\":2},\"indices\":3,\"material\":0},"
             "{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TANGENT\":2},\"indices\":3,\"material\":1}]}],"
             "%s\"materials\":[{\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyStrength\":0.6,"
             "\"anisotropyRotation\":7.5,\"anisotropyTexture\":{\"index\":0,\"texCoord\":1}}}},"
             "{\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyStrength\":1.25}}}],\"nodes\":[{\"mesh\":0}]",
             head);
    scene s;
    int w0 = util_warning_count();
    CHECKF(load_tri_scene(&s, body), "%s", load_log);
    CHECKF(util_warning_count() - w0 == 1 && strstr(load_log, "anisotropyStrength 1.25 is out of range [0, 1] (clamped)"),
           "warnings:\n%s", load_log);
    CHECK(!strstr(load_log, "unsupported extension"));
    CHECK(s.num_materials == 2);
    if (s.num_materials == 2) {
        const GnMaterial *m = &s.materials[0];
        CHECK(m->anisotropy_strength == 0.6f && near(m->anisotropy_rotation, (float)(7.5 - 2 * M_PI), 1e-6f));
        CHECK(m->tex_anisotropy != GN_INVALID && m->tex_anisotropy < s.num_textures &&
              s.textures[m->tex_anisotropy].flags == GN_TEX_UV1);
        CHECK(s.materials[1].anisotropy_strength == 1 && s.materials[1].anisotropy_rotation == 0 &&
              s.materials[1].tex_anisotropy == GN_INVALID);
    }
    scene_destroy(&s);
    snprintf(body, sizeof body,
             TRI_MESH ",%s\"materials\":[{\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyTexture\":{\"index\":3}}}}],"
             "\"nodes\":[{\"mesh\":0}]", head);
    CHECK(!load_tri_scene(&s, body) &&
          strstr(load_log, "materials[0].extensions.KHR_materials_anisotropy.anisotropyTexture.index: 3 does not exist"));
    snprintf(body, sizeof body,
             TRI_MESH ",\"materials\":[{\"extensions\":{\"KHR_materials_anisotropy\":{\"anisotropyStrength\":\"high\"}}}],"
             "\"nodes\":[{\"mesh\":0}]");
    CHECK(!load_tri_scene(&s, body) &&
          strstr(load_log, "materials[0].extensions.KHR_materials_anisotropy.anisotropyStrength"));
}

/* ---- the material table's rows and the extension table (src/scene/gltf_material.cpp) ------ */

/* The rows as the loader reads them: JSON path, components (a texture slot: 0) and word. */
static const struct material_row {
    const char *ext, *json;
    int n;
    int word;
} material_rows[] = {
#define ROW_PARAM(name, type, word, ext, json, def, lo, hi, rule, feat, brdf) {ext, json, GN_MAT_COUNT_##type, word},
#define ROW_TEX(name, word, ext, json, space, gate, uses) {ext, json, 0, word},
    GN_MATERIAL(ROW_PARAM, ROW_TEX, GN_MAT_NO_FIELD)
#undef ROW_PARAM
#undef ROW_TEX
};

/* A material that sets row r's JSON path to `value`: the path's objects nested (each with an
 * index, for those that are textureInfos), in the row's extension object. */
static void material_json(char *out, size_t cap, const struct material_row *r, const char *value)
{
    char path[128], *part[4];
    int n = 0;
    size_t len = 0;
    snprintf(path, sizeof path, "%s", r->json);
    for (char *save = NULL, *t = strtok_r(path, ".", &save); t && n < 4; t = strtok_r(NULL, ".", &save))
        part[n++] = t;
    len += (size_t)snprintf(out + len, cap - len, "{");
    if (*r->ext)
        len += (size_t)snprintf(out + len, cap - len, "\"extensions\":{\"%s\":{", r->ext);
    for (int k = 0; k < n - 1; k++)
        len += (size_t)snprintf(out + len, cap - len, "\"%s\":{\"index\":0,", part[k]);
    len += (size_t)snprintf(out + len, cap - len, "\"%s\":%s", part[n - 1], value);
    for (int k = 0; k < n - 1; k++)
        len += (size_t)snprintf(out + len, cap - len, "}");
    snprintf(out + len, cap - len, "%s}", *r->ext ? "}}" : "");
}

/* Every row of the material table is read and checked alike, in the core and in every
 * extension: a factor of the wrong JSON type is an error naming its JSON path ("... is not a
 * number", "... is not an array"), a texture slot's index of the wrong type is one too; a
 * slot's texture is read, with its texCoord (TEXCOORD_1: the slot's own copy of the texture);
 * and every extension a row names is one the table of extensions supports. */
TEST(scene, material_rows)
{
    char head[1024], material[1024], body[8192], path[256], want[512];
    snprintf(head, sizeof head, "\"images\":[{\"uri\":\"data:image/png;base64,%s\"}],\"textures\":[{\"source\":0}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TANGENT\":2},\"indices\":3,"
             "\"material\":0}]}],\"nodes\":[{\"mesh\":0}],", png_ga8);
    for (size_t i = 0; i < sizeof material_rows / sizeof *material_rows; i++) {
        const struct material_row *r = &material_rows[i];
        scene s;
        snprintf(path, sizeof path, "materials[0]%s%s.%s", *r->ext ? ".extensions." : "", r->ext, r->json);
        if (*r->ext) {
            const char *how = NULL;
            scene_support sup = scene_extension_support(r->ext, &how);
            CHECKF(sup != SCENE_UNSUPPORTED && how && *how, "%s: the extension of row %s is not a supported one", r->ext,
                   r->json);
        }
        /* a wrong type */
        material_json(material, sizeof material, r, r->n ? "\"x\"" : "{\"index\":\"x\"}");
        snprintf(body, sizeof body, "%s\"materials\":[%s]", head, material);
        snprintf(want, sizeof want, r->n ? "%s: \"x\" is not a" : "%s.index: \"x\" is not an integer", path);
        CHECKF(!load_tri_scene(&s, body) && strstr(load_log, want), "row %s: no error \"%s\":\n%s", path, want, load_log);
        if (r->n)
            continue;
        /* a texture slot read, through TEXCOORD_1 */
        material_json(material, sizeof material, r, "{\"index\":0,\"texCoord\":1}");
        snprintf(body, sizeof body, "%s\"materials\":[%s]", head, material);
        bool ok = load_tri_scene(&s, body);
        CHECKF(ok, "row %s: %s", path, load_log);
        if (ok && s.num_materials >= 1) {
            uint32_t t = ((const uint32_t *)&s.materials[0])[r->word];
            CHECKF(t < s.num_textures && s.textures[t].flags == GN_TEX_UV1, "row %s: slot %u (of %u textures) is not the "
                   "texture read through TEXCOORD_1", path, t, s.num_textures);
        }
        if (ok)
            scene_destroy(&s);
    }
}

/* gonio info's lines of the table's extensions (scene_material_line): each has a label and
 * help that fits --help's column, says nothing of the default material, and speaks of a
 * material that uses its extension. */
TEST(scene, material_lines)
{
    GnMaterial plain, aniso;
    char text[512];
    size_t n = 0, anisotropy = 0;
    const scene_material_line *l;
    scene_material_default(&plain);
    aniso = plain;
    aniso.anisotropy_strength = 0.5f;
    for (size_t k = 0; (l = scene_material_line_at(k)); k++, n++) {
        CHECKF(l->label && *l->label && l->help && *l->help && l->text, "line %zu", k);
        for (const char *line = l->help; *line;) {
            size_t len = strcspn(line, "\n");
            CHECKF(len <= 68, "%s: a help line of %zu characters", l->label, len);
            line += len + (line[len] == '\n');
        }
        CHECKF(!l->text(&plain, text, sizeof text), "%s: the default material: %s", l->label, text);
        if (!strcmp(l->label, "anisotropy")) {
            anisotropy++;
            CHECKF(l->text(&aniso, text, sizeof text) && !strcmp(text, "strength 0.5, rotation 0 deg"), "%s", text);
        }
    }
    CHECKF(n >= 4 && anisotropy == 1, "%zu lines", n);
}

/* The extensions a file lists, once each in its order, with how gonio handles each: the
 * table's supported and partly supported ones, metadata (supported: nothing in it changes
 * the image, so no warning), and a name it does not know; a required unsupported one
 * refuses the file, naming it and why. */
TEST(scene, extension_list)
{
    scene s;
    int w0 = util_warning_count();
    CHECKF(load_tri_scene(&s, TRI_MESH ",\"nodes\":[{\"mesh\":0}],\"extensionsUsed\":[\"KHR_materials_sheen\","
                              "\"KHR_materials_volume\",\"KHR_xmp_json_ld\",\"EXT_gonio_unknown\","
                              "\"KHR_materials_sheen\"],\"extensionsRequired\":[\"KHR_materials_volume\","
                              "\"KHR_texture_transform\"]"), "%s", load_log);
    CHECKF(util_warning_count() - w0 == 1 && !strstr(load_log, "KHR_xmp_json_ld") &&
               strstr(load_log, "uses unsupported extension EXT_gonio_unknown (ignored)"), "%s", load_log);
    static const struct { const char *name; bool required; scene_support support; } want[] = {
        {"KHR_materials_sheen", false, SCENE_SUPPORTED}, {"KHR_materials_volume", true, SCENE_PARTLY},
        {"KHR_xmp_json_ld", false, SCENE_SUPPORTED}, {"EXT_gonio_unknown", false, SCENE_UNSUPPORTED},
        {"KHR_texture_transform", true, SCENE_SUPPORTED}};
    CHECK(s.num_extensions == 5);
    for (uint32_t i = 0; i < 5 && i < s.num_extensions; i++)
        CHECKF(!strcmp(s.extensions[i].name, want[i].name) && s.extensions[i].required == want[i].required &&
                   s.extensions[i].support == want[i].support && s.extensions[i].how && *s.extensions[i].how,
               "extension %u: %s", i, s.extensions[i].name);
    CHECK(!strcmp(s.extensions[3].how, "unknown to gonio"));
    scene_destroy(&s);
    /* a refusal is the refusal only: no "(ignored)" warning for the same or another name */
    w0 = util_warning_count();
    CHECK(!load_tri_scene(&s, TRI_MESH ",\"nodes\":[{\"mesh\":0}],\"extensionsUsed\":[\"EXT_gonio_unknown\","
                              "\"EXT_gonio_other\"],\"extensionsRequired\":[\"EXT_gonio_unknown\"]") &&
          strstr(load_log, "requires unsupported extension EXT_gonio_unknown"));
    CHECKF(util_warning_count() == w0 && !strstr(load_log, "ignored"), "%s", load_log);
}
