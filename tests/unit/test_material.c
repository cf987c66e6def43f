/* test_material.c: the one declaration of a material (glsl/lib/material.h) end to end: the
 * kernels' reader (tests/kernels/material_test.comp runs material_at) gives back every field
 * as the host wrote it, and every texture slot of glTF and its extensions, read by the loader
 * from a file and applied by the kernels' material_eval, scales its factor by the channels
 * the specifications name (a list written here from the specifications, not from the table). */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gpu.h"
#include "image.h"
#include "material_test.h" /* spv_material_test: tests/kernels/material_test.comp */
#include "scene.h"
#include "shared.h"
#include "test.h"
#include "util.h"

/* material_test.comp's records (std430) */
typedef struct material_query {
    vec4 uv;
    uint32_t material, pad0, pad1, pad2;
} material_query;
typedef struct material_result {
    GnMaterial m;
    vec4 film; /* x: the film's thickness */
} material_result;
#define MATERIAL_TEST_EVAL 1u

/* Every field's name by word, from the table (a field of n components names n words). */
static const char *word_names[GN_MATERIAL_WORDS];
#define NAME_FIELD(name, type, word)                       \
    for (int k = 0; k < GN_MAT_COUNT_##type; k++)          \
        word_names[(word) + k] = #name;
#define NAME_PARAM(name, type, word, ext, json, def, lo, hi, rule, feat, brdf) NAME_FIELD(name, type, word)
#define NAME_TEX(name, word, ext, json, space, gate, uses) NAME_FIELD(name, uint, word)

/* Runs material_test.comp over n queries: pass 0 reads materials[i] back, MATERIAL_TEST_EVAL
 * evaluates the queries with the scene's textures (sc; NULL: none). */
static bool run_materials(const GnMaterial *materials, uint32_t num_materials, const scene *sc,
                          const material_query *q, uint32_t n, uint32_t pass, material_result *out)
{
    gpu g = {0};
    gpu_buffer mats, texels, textures, queries, results;
    gpu_pipeline p;
    uint32_t total = 0, *pixels;
    GnTexture *tex;
    if (!test_open_gpu(&g))
        return false;
    /* the textures packed as the renderer packs them: RGBA8 texels of every image, a GnTexture
     * per texture (src/render/render.c: renderer_create) */
    uint32_t num_images = sc ? sc->num_images : 0, num_textures = sc ? sc->num_textures : 0;
    uint32_t *offset = util_calloc(num_images + 1, sizeof *offset);
    for (uint32_t i = 0; i < num_images; i++) {
        offset[i] = total;
        total += sc->images[i].width * sc->images[i].height;
    }
    pixels = util_calloc(total + 1, sizeof *pixels);
    for (uint32_t i = 0; i < num_images; i++)
        memcpy(pixels + offset[i], sc->images[i].rgba8, 4 * (size_t)sc->images[i].width * sc->images[i].height);
    tex = util_calloc(num_textures + 1, sizeof *tex);
    for (uint32_t i = 0; i < num_textures; i++) {
        const scene_texture *t = &sc->textures[i];
        const float *x = t->transform;
        tex[i] = (GnTexture){offset[t->image], sc->images[t->image].width, sc->images[t->image].height, t->flags,
                             {x[0], x[1], x[2]}, 0, {x[3], x[4], x[5]}, 0};
    }
    gpu_buffer_create_texels(&g, &mats, materials, sizeof *materials * num_materials);
    gpu_buffer_create_texels_as(&g, &texels, pixels, sizeof *pixels * (total + 1), VK_FORMAT_R32_UINT);
    gpu_buffer_create_texels(&g, &textures, tex, sizeof *tex * (num_textures + 1));
    gpu_buffer_create_storage(&g, &queries, q, sizeof *q * n);
    gpu_buffer_create(&g, &results, sizeof *out * n, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, GPU_MEMORY_HOST);
    memset(results.mapped, 0, sizeof *out * n);
    {
        const gpu_binding bind[] = {{GN_BIND_MATERIALS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &mats},
                                    {GN_BIND_TEXELS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &texels},
                                    {GN_BIND_TEXTURES, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, &textures},
                                    {GN_BIND_AOV, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &queries},
                                    {GN_BIND_ACCUM, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, &results}};
        gpu_pipeline_desc pd = {.name = "material_test", .code = spv_material_test,
                                .code_size = sizeof spv_material_test, .local_size = {64, 1, 1},
                                .push_size = sizeof(GnPush), .bindings = bind,
                                .num_bindings = sizeof bind / sizeof *bind};
        GnPush push = {n, pass, 0, 0};
        VkCommandBuffer cmd;
        gpu_pipeline_create(&g, &p, &pd);
        cmd = gpu_begin(&g);
        gpu_dispatch(cmd, &p, &push, n, 1, 1);
        gpu_submit_wait(&g, cmd);
    }
    memcpy(out, results.mapped, sizeof *out * n);
    CHECK(gpu_validation_message_count() == 0);
    gpu_pipeline_destroy(&g, &p);
    gpu_buffer_destroy(&g, &results);
    gpu_buffer_destroy(&g, &queries);
    gpu_buffer_destroy(&g, &textures);
    gpu_buffer_destroy(&g, &texels);
    gpu_buffer_destroy(&g, &mats);
    gpu_destroy(&g);
    free(tex);
    free(pixels);
    free(offset);
    return true;
}

/* Materials whose every word holds its own value (a float that is also a distinct bit
 * pattern), read by material_at on the GPU and written back: each word must come back as
 * it went, so two fields of one type swapped in the reader (or in the table's places) fail. */
TEST(material, gpu_reader_round_trip)
{
    enum { N = 3 };
    GnMaterial in[N];
    material_result out[N];
    material_query q[N];
    float *w = (float *)in;
    GN_MATERIAL(NAME_PARAM, NAME_TEX, NAME_FIELD)
    for (uint32_t i = 0; i < GN_MATERIAL_WORDS; i++)
        CHECKF(word_names[i] != NULL, "word %u of GnMaterial is in no row of GN_MATERIAL", i);
    for (uint32_t i = 0; i < N * GN_MATERIAL_WORDS; i++)
        w[i] = 1.0f + (float)i * 0.25f; /* distinct, normal floats */
    memset(q, 0, sizeof q);
    if (!run_materials(in, N, NULL, q, N, 0, out))
        return;
    int bad = 0;
    for (uint32_t k = 0; k < N; k++) {
        const uint32_t *a = (const uint32_t *)&in[k], *b = (const uint32_t *)&out[k].m;
        for (uint32_t i = 0; i < GN_MATERIAL_WORDS; i++)
            if (a[i] != b[i] && bad++ < 8)
                CHECKF(0, "material %u, word %u (%s): wrote 0x%08x, the GPU read 0x%08x", k, i, word_names[i], a[i],
                       b[i]);
    }
    CHECKF(bad == 0, "%d of %u words differ", bad, N * GN_MATERIAL_WORDS);
}

/* ---- texture slots against the specifications -------------------------------------------- */

enum { CH_R = 1, CH_G = 2, CH_B = 4, CH_A = 8, CH_RGB = 7, CH_RGBA = 15 };
/* A slot as its specification defines it: the factor (JSON key and value), the textureInfo's
 * key, the channels that scale the factor and whether they are sRGB (colour; alpha linear),
 * and the GnMaterial field the loader and the kernels keep the factor in. */
static const struct slot_spec {
    const char *ext, *factor;
    float value[4];
    int n;
    const char *texture;
    int channels;
    bool srgb;
    size_t field;
} slots[] = {
    {"", "baseColorFactor", {0.5f, 0.6f, 0.7f, 0.8f}, 4, "baseColorTexture", CH_RGBA, true, offsetof(GnMaterial, base_color)},
    {"", "metallicFactor", {0.7f}, 1, "metallicRoughnessTexture", CH_B, false, offsetof(GnMaterial, metallic)},
    {"", "roughnessFactor", {0.6f}, 1, "metallicRoughnessTexture", CH_G, false, offsetof(GnMaterial, roughness)},
    {"", "emissiveFactor", {0.3f, 0.5f, 0.9f}, 3, "emissiveTexture", CH_RGB, true, offsetof(GnMaterial, emissive)},
    {"KHR_materials_specular", "specularFactor", {0.8f}, 1, "specularTexture", CH_A, false, offsetof(GnMaterial, specular)},
    {"KHR_materials_specular", "specularColorFactor", {0.9f, 0.7f, 0.5f}, 3, "specularColorTexture", CH_RGB, true,
     offsetof(GnMaterial, specular_color)},
    {"KHR_materials_transmission", "transmissionFactor", {0.9f}, 1, "transmissionTexture", CH_R, false,
     offsetof(GnMaterial, transmission)},
    {"KHR_materials_volume", "thicknessFactor", {2.5f}, 1, "thicknessTexture", CH_G, false, offsetof(GnMaterial, thickness)},
    {"KHR_materials_clearcoat", "clearcoatFactor", {0.9f}, 1, "clearcoatTexture", CH_R, false, offsetof(GnMaterial, clearcoat)},
    {"KHR_materials_clearcoat", "clearcoatRoughnessFactor", {0.7f}, 1, "clearcoatRoughnessTexture", CH_G, false,
     offsetof(GnMaterial, clearcoat_roughness)},
    {"KHR_materials_sheen", "sheenColorFactor", {0.6f, 0.5f, 0.4f}, 3, "sheenColorTexture", CH_RGB, true,
     offsetof(GnMaterial, sheen_color)},
    {"KHR_materials_sheen", "sheenRoughnessFactor", {0.8f}, 1, "sheenRoughnessTexture", CH_A, false,
     offsetof(GnMaterial, sheen_roughness)},
    {"KHR_materials_iridescence", "iridescenceFactor", {0.9f}, 1, "iridescenceTexture", CH_R, false,
     offsetof(GnMaterial, iridescence)},
    {"KHR_materials_diffuse_transmission", "diffuseTransmissionFactor", {0.9f}, 1, "diffuseTransmissionTexture", CH_A,
     false, offsetof(GnMaterial, diffuse_transmission)},
    {"KHR_materials_diffuse_transmission", "diffuseTransmissionColorFactor", {0.8f, 0.6f, 0.4f}, 3,
     "diffuseTransmissionColorTexture", CH_RGB, true, offsetof(GnMaterial, diffuse_transmission_color)},
};
#define NUM_SLOTS ((int)(sizeof slots / sizeof *slots))
/* two texels, every channel its own value (a wrong channel reads another number) */
static const uint8_t texels[2][4] = {{51, 102, 153, 204}, {230, 20, 90, 140}};

/* glTF's sRGB transfer function (the sRGB standard's), a channel in [0, 1] */
static double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }

/* Writes dir/scene.gltf: a triangle (dir/tri.bin), the 2x1 texture dir/tex.png (nearest
 * filtering), one material per slot with its factor and that texture, and a last one with
 * KHR_materials_iridescence's thickness range and texture. */
static bool write_slot_scene(const char *dir, char *path, size_t cap)
{
    static const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    char file[4096], *json = util_malloc(1 << 16);
    size_t len = 0, cap_json = 1 << 16;
    FILE *f;
    snprintf(file, sizeof file, "%s/tri.bin", dir);
    if (!(f = fopen(file, "wb")) || fwrite(tri, sizeof tri, 1, f) != 1 || fclose(f))
        return false;
    snprintf(file, sizeof file, "%s/tex.png", dir);
    if (!image_write_png(file, &texels[0][0], 2, 1))
        return false;
#define OUT(...) (len += (size_t)snprintf(json + len, cap_json - len, __VA_ARGS__))
    OUT("{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_materials_specular\",\"KHR_materials_transmission\","
        "\"KHR_materials_volume\",\"KHR_materials_clearcoat\",\"KHR_materials_sheen\",\"KHR_materials_iridescence\","
        "\"KHR_materials_diffuse_transmission\"],"
        "\"buffers\":[{\"uri\":\"tri.bin\",\"byteLength\":36}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],"
        "\"max\":[1,1,0]}],\"images\":[{\"uri\":\"tex.png\"}],\"samplers\":[{\"magFilter\":9728,\"minFilter\":9728}],"
        "\"textures\":[{\"source\":0,\"sampler\":0}],\"meshes\":[{\"primitives\":[");
    for (int i = 0; i <= NUM_SLOTS; i++)
        OUT("%s{\"attributes\":{\"POSITION\":0},\"material\":%d}", i ? "," : "", i);
    OUT("]}],\"nodes\":[{\"mesh\":0}],\"materials\":[");
    for (int i = 0; i < NUM_SLOTS; i++) {
        const struct slot_spec *s = &slots[i];
        char value[128];
        bool pbr = !*s->ext && (!strcmp(s->texture, "baseColorTexture") || !strcmp(s->texture, "metallicRoughnessTexture"));
        if (s->n == 1)
            snprintf(value, sizeof value, "%.9g", s->value[0]);
        else if (s->n == 3)
            snprintf(value, sizeof value, "[%.9g,%.9g,%.9g]", s->value[0], s->value[1], s->value[2]);
        else
            snprintf(value, sizeof value, "[%.9g,%.9g,%.9g,%.9g]", s->value[0], s->value[1], s->value[2], s->value[3]);
        OUT("%s{", i ? "," : "");
        if (*s->ext)
            OUT("\"extensions\":{\"%s\":{", s->ext);
        else if (pbr)
            OUT("\"pbrMetallicRoughness\":{");
        OUT("\"%s\":%s,\"%s\":{\"index\":0}", s->factor, value, s->texture);
        OUT("%s}", *s->ext ? "}}" : pbr ? "}" : "");
    }
    OUT(",{\"extensions\":{\"KHR_materials_iridescence\":{\"iridescenceFactor\":1,\"iridescenceThicknessMinimum\":200,"
        "\"iridescenceThicknessMaximum\":600,\"iridescenceThicknessTexture\":{\"index\":0}}}}]}");
#undef OUT
    snprintf(path, cap, "%s/scene.gltf", dir);
    bool ok = len < cap_json && (f = fopen(path, "w")) && fputs(json, f) >= 0 && !fclose(f);
    free(json);
    return ok;
}

/* Every slot: the loader reads the texture into its slot, and material_eval gives factor x
 * the channels at each texel, sRGB decoded for colours, exactly as the specifications say;
 * KHR_materials_iridescence's thickness is mix(min, max, G). */
TEST(material, texture_slots_as_specified)
{
    char dir[] = "/tmp/gonio_material_test_XXXXXX", path[4096];
    scene sc;
    enum { Q = 2 * (NUM_SLOTS + 1) };
    material_query q[Q];
    material_result r[Q];
    if (!mkdtemp(dir)) {
        CHECKF(0, "no temporary folder");
        return;
    }
    CHECK(write_slot_scene(dir, path, sizeof path));
    bool loaded = scene_load(&sc, path);
    CHECKF(loaded, "%s does not load", path);
    if (loaded && sc.num_materials == (uint32_t)NUM_SLOTS + 1) {
        memset(q, 0, sizeof q);
        for (int i = 0; i < Q; i++) /* texel 0, then texel 1, of each material */
            q[i] = (material_query){{i % 2 ? 0.75f : 0.25f, 0.5f, 0, 0}, (uint32_t)(i / 2), 0, 0, 0};
        if (run_materials(sc.materials, sc.num_materials, &sc, q, Q, MATERIAL_TEST_EVAL, r)) {
            for (int i = 0; i < 2 * NUM_SLOTS; i++) {
                const struct slot_spec *s = &slots[i / 2];
                const uint8_t *t = texels[i % 2];
                const float *got = (const float *)((const char *)&r[i].m + s->field);
                for (int k = 0, c = 0; k < 4; k++) {
                    if (!(s->channels & (1 << k)))
                        continue;
                    double x = t[k] / 255.0, want = s->value[c] * (s->srgb && k < 3 ? srgb_to_linear(x) : x);
                    CHECKF(fabs(got[c] - want) <= 2e-6 * fabs(want) + 1e-7, "%s x %s, texel %d, channel %d: %.7g, not %.7g",
                           s->factor, s->texture, i % 2, k, got[c], want);
                    c++;
                }
            }
            for (int k = 0; k < 2; k++) {
                double want = 200 + 400 * (texels[k][1] / 255.0), got = r[2 * NUM_SLOTS + k].film.x;
                CHECKF(fabs(got - want) < 1e-4, "iridescence thickness at texel %d: %g, not %g", k, got, want);
            }
        }
    } else if (loaded) {
        CHECKF(0, "%u materials, not %d", sc.num_materials, NUM_SLOTS + 1);
    }
    if (loaded)
        scene_destroy(&sc);
    char file[4200];
    for (int k = 0; k < 3; k++) {
        snprintf(file, sizeof file, "%s/%s", dir, (const char *[]){"tri.bin", "tex.png", "scene.gltf"}[k]);
        remove(file);
    }
    rmdir(dir);
}
