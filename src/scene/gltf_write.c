/* gltf_write.c: glTF 2.0 writer (Khronos glTF 2.0 specification; KHR_lights_punctual and
 * KHR_materials_{emissive_strength,specular,ior,transmission}); the buffer is embedded as
 * base64 (RFC 4648) in a data URI; .glb goes through tinygltf (gltf_glb.cpp). */
#include "gltf_write.h"

#include <assert.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "util.h"

#define GLTF_FLOAT 5126u
#define GLTF_UNSIGNED_INT 5125u
#define GLTF_ARRAY_BUFFER 34962u
#define GLTF_ELEMENT_ARRAY_BUFFER 34963u

/* glTF buffers are little-endian whatever the host is. */
static uint8_t *put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
    return p + 4;
}

static uint8_t *put_floats(uint8_t *p, const float *f, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        uint32_t bits;
        memcpy(&bits, &f[i], 4);
        p = put_u32(p, bits);
    }
    return p;
}

static void write_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

/* ,"name":"..." when the name is set (every object written here has an earlier member). */
static void write_name(FILE *f, const char *name)
{
    if (name) {
        fputs(",\"name\":", f);
        write_string(f, name);
    }
}

static void write_floats(FILE *f, const float *v, int n)
{
    fputc('[', f);
    for (int i = 0; i < n; i++) {
        assert(isfinite(v[i]));
        fprintf(f, "%s%.9g", i ? "," : "", v[i]);
    }
    fputc(']', f);
}

static bool all_zero(const float *v, int n)
{
    for (int i = 0; i < n; i++)
        if (v[i] != 0.0f)
            return false;
    return true;
}

static void write_base64(FILE *f, const uint8_t *data, size_t n)
{
    static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char out[4096];
    size_t len = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)data[i] << 16;
        if (i + 1 < n)
            v |= (uint32_t)data[i + 1] << 8;
        if (i + 2 < n)
            v |= data[i + 2];
        out[len++] = digits[v >> 18];
        out[len++] = digits[(v >> 12) & 63];
        out[len++] = i + 1 < n ? digits[(v >> 6) & 63] : '=';
        out[len++] = i + 2 < n ? digits[v & 63] : '=';
        if (len == sizeof out) {
            fwrite(out, 1, len, f);
            len = 0;
        }
    }
    fwrite(out, 1, len, f);
}

/* Separator before the i-th element of a top-level array: one element per line. */
static const char *item(uint32_t i) { return i ? ",\n    " : "\n    "; }

static void write_material(FILE *f, const gltf_write_material *m)
{
    bool ext = m->emissive_strength != 0.0f || m->has_specular || m->ior != 0.0f ||
               m->transmission != 0.0f || m->unlit;
    fputs("{\"pbrMetallicRoughness\":{\"baseColorFactor\":", f);
    write_floats(f, m->base_color, 4);
    fprintf(f, ",\"metallicFactor\":%.9g,\"roughnessFactor\":%.9g}", m->metallic, m->roughness);
    write_name(f, m->name);
    if (!all_zero(m->emissive, 3)) {
        fputs(",\"emissiveFactor\":", f);
        write_floats(f, m->emissive, 3);
    }
    if (m->double_sided)
        fputs(",\"doubleSided\":true", f);
    if (m->alpha_mode)
        fprintf(f, ",\"alphaMode\":\"%s\"", m->alpha_mode);
    if (m->alpha_cutoff != 0)
        fprintf(f, ",\"alphaCutoff\":%.9g", m->alpha_cutoff);
    if (ext) {
        const char *sep = "";
        fputs(",\"extensions\":{", f);
        if (m->emissive_strength != 0.0f) {
            fprintf(f, "\"KHR_materials_emissive_strength\":{\"emissiveStrength\":%.9g}",
                    m->emissive_strength);
            sep = ",";
        }
        if (m->has_specular) {
            fprintf(f, "%s\"KHR_materials_specular\":{\"specularFactor\":%.9g,"
                       "\"specularColorFactor\":", sep, m->specular);
            write_floats(f, m->specular_color, 3);
            fputc('}', f);
            sep = ",";
        }
        if (m->ior != 0.0f) {
            fprintf(f, "%s\"KHR_materials_ior\":{\"ior\":%.9g}", sep, m->ior);
            sep = ",";
        }
        if (m->transmission != 0.0f) {
            fprintf(f, "%s\"KHR_materials_transmission\":{\"transmissionFactor\":%.9g}", sep,
                    m->transmission);
            sep = ",";
        }
        if (m->unlit)
            fprintf(f, "%s\"KHR_materials_unlit\":{}", sep);
        fputc('}', f);
    }
    if (m->extras) {
        assert(m->extras[0] == '{');
        fprintf(f, ",\"extras\":%s", m->extras);
    }
    fputc('}', f);
}

static void write_node(FILE *f, const gltf_write_node *n, const gltf_write_desc *d)
{
    static const float identity[4] = {0, 0, 0, 1}, unit[3] = {1, 1, 1};
    switch (n->kind) {
    case GLTF_WRITE_NODE_MESH:
        assert(n->index < d->num_meshes);
        fprintf(f, "{\"mesh\":%u", n->index);
        break;
    case GLTF_WRITE_NODE_CAMERA:
        assert(n->index < d->num_cameras);
        fprintf(f, "{\"camera\":%u", n->index);
        break;
    case GLTF_WRITE_NODE_LIGHT:
        assert(n->index < d->num_lights);
        fprintf(f, "{\"extensions\":{\"KHR_lights_punctual\":{\"light\":%u}}", n->index);
        break;
    }
    write_name(f, n->name);
    if (n->matrix) {
        fputs(",\"matrix\":", f);
        write_floats(f, n->matrix, 16);
    } else {
        if (!all_zero(n->translation, 3)) {
            fputs(",\"translation\":", f);
            write_floats(f, n->translation, 3);
        }
        if (!all_zero(n->rotation, 4) && memcmp(n->rotation, identity, sizeof identity) != 0) {
            fputs(",\"rotation\":", f);
            write_floats(f, n->rotation, 4);
        }
        if (!all_zero(n->scale, 3) && memcmp(n->scale, unit, sizeof unit) != 0) {
            fputs(",\"scale\":", f);
            write_floats(f, n->scale, 3);
        }
    }
    fputc('}', f);
}

static void write_light(FILE *f, const gltf_write_light *l)
{
    static const char *types[] = {"point", "spot", "directional"};
    static const float white[3] = {1, 1, 1};
    fprintf(f, "{\"type\":\"%s\"", types[l->type]);
    write_name(f, l->name);
    fputs(",\"color\":", f);
    write_floats(f, all_zero(l->color, 3) ? white : l->color, 3);
    fprintf(f, ",\"intensity\":%.9g", l->intensity != 0.0f ? l->intensity : 1.0f);
    if (l->range != 0.0f)
        fprintf(f, ",\"range\":%.9g", l->range);
    if (l->type == GLTF_WRITE_SPOT)
        fprintf(f, ",\"spot\":{\"innerConeAngle\":%.9g,\"outerConeAngle\":%.9g}", l->inner_cone,
                l->outer_cone != 0.0f ? l->outer_cone : (float)(M_PI / 4));
    fputc('}', f);
}

/* Accessors and buffer views correspond one to one, in the order: for each mesh POSITION,
 * NORMAL, TEXCOORD_0 (those present), then its indices. All sizes are multiples of 4, so
 * every view is 4-byte aligned as the specification requires. */
static void write_accessors(FILE *f, const gltf_write_desc *d)
{
    uint32_t a = 0;
    size_t offset = 0;
    fputs(",\n  \"accessors\": [", f);
    for (uint32_t i = 0; i < d->num_meshes; i++) {
        const gltf_write_mesh *m = &d->meshes[i];
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (uint32_t v = 0; v < m->num_vertices; v++)
            for (int k = 0; k < 3; k++) {
                lo[k] = fminf(lo[k], m->positions[3 * v + k]);
                hi[k] = fmaxf(hi[k], m->positions[3 * v + k]);
            }
        fprintf(f, "%s{\"bufferView\":%u,\"componentType\":%u,\"count\":%u,\"type\":\"VEC3\","
                   "\"min\":", item(a), a, GLTF_FLOAT, m->num_vertices);
        write_floats(f, lo, 3);
        fputs(",\"max\":", f);
        write_floats(f, hi, 3);
        fputc('}', f);
        a++;
        if (m->normals) {
            fprintf(f, "%s{\"bufferView\":%u,\"componentType\":%u,\"count\":%u,\"type\":\"VEC3\"}",
                    item(a), a, GLTF_FLOAT, m->num_vertices);
            a++;
        }
        if (m->uvs) {
            fprintf(f, "%s{\"bufferView\":%u,\"componentType\":%u,\"count\":%u,\"type\":\"VEC2\"}",
                    item(a), a, GLTF_FLOAT, m->num_vertices);
            a++;
        }
        fprintf(f, "%s{\"bufferView\":%u,\"componentType\":%u,\"count\":%u,\"type\":\"SCALAR\"}",
                item(a), a, GLTF_UNSIGNED_INT, m->num_indices);
        a++;
    }
    fputs("\n  ],\n  \"bufferViews\": [", f);
    a = 0;
    for (uint32_t i = 0; i < d->num_meshes; i++) {
        const gltf_write_mesh *m = &d->meshes[i];
        size_t nv = m->num_vertices;
        size_t sizes[4] = {12 * nv, m->normals ? 12 * nv : 0, m->uvs ? 8 * nv : 0,
                           4 * (size_t)m->num_indices};
        for (int k = 0; k < 4; k++) {
            if (!sizes[k])
                continue;
            fprintf(f, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,\"target\":%u}",
                    item(a++), offset, sizes[k],
                    k < 3 ? GLTF_ARRAY_BUFFER : GLTF_ELEMENT_ARRAY_BUFFER);
            offset += sizes[k];
        }
    }
    fputs("\n  ]", f);
}

/* The binary buffer in the layout write_accessors describes. */
static uint8_t *make_buffer(const gltf_write_desc *d, size_t *size)
{
    size_t n = 0;
    uint8_t *buf, *p;
    for (uint32_t i = 0; i < d->num_meshes; i++) {
        const gltf_write_mesh *m = &d->meshes[i];
        n += (12 + (m->normals ? 12 : 0) + (m->uvs ? 8 : 0)) * (size_t)m->num_vertices +
             4 * (size_t)m->num_indices;
    }
    p = buf = util_malloc(n);
    for (uint32_t i = 0; i < d->num_meshes; i++) {
        const gltf_write_mesh *m = &d->meshes[i];
        assert(m->num_vertices > 0 && m->num_indices > 0 && m->num_indices % 3 == 0);
        for (uint32_t v = 0; v < 3 * m->num_vertices; v++)
            assert(isfinite(m->positions[v]));
        p = put_floats(p, m->positions, 3 * (size_t)m->num_vertices);
        if (m->normals)
            p = put_floats(p, m->normals, 3 * (size_t)m->num_vertices);
        if (m->uvs)
            p = put_floats(p, m->uvs, 2 * (size_t)m->num_vertices);
        for (uint32_t k = 0; k < m->num_indices; k++) {
            assert(m->indices[k] < m->num_vertices);
            p = put_u32(p, m->indices[k]);
        }
    }
    assert((size_t)(p - buf) == n);
    *size = n;
    return buf;
}

static void write_json(FILE *f, const gltf_write_desc *d, const uint8_t *buf, size_t size)
{
    const char *used[7];
    int num_used = 0;
    bool strength = false, specular = false, ior = false, transmission = false, unlit = false;
    uint32_t a = 0;
    for (uint32_t i = 0; i < d->num_materials; i++) {
        strength |= d->materials[i].emissive_strength != 0.0f;
        specular |= d->materials[i].has_specular;
        ior |= d->materials[i].ior != 0.0f;
        transmission |= d->materials[i].transmission != 0.0f;
        unlit |= d->materials[i].unlit;
    }
    if (d->num_lights)
        used[num_used++] = "KHR_lights_punctual";
    if (strength)
        used[num_used++] = "KHR_materials_emissive_strength";
    if (specular)
        used[num_used++] = "KHR_materials_specular";
    if (ior)
        used[num_used++] = "KHR_materials_ior";
    if (transmission)
        used[num_used++] = "KHR_materials_transmission";
    if (unlit)
        used[num_used++] = "KHR_materials_unlit";

    fputs("{\n  \"asset\": {\"version\":\"2.0\",\"generator\":\"gonio\"}", f);
    if (num_used) {
        fputs(",\n  \"extensionsUsed\": [", f);
        for (int i = 0; i < num_used; i++)
            fprintf(f, "%s\"%s\"", i ? "," : "", used[i]);
        fputc(']', f);
    }
    if (d->num_nodes) {
        fputs(",\n  \"scene\": 0,\n  \"scenes\": [{\"nodes\":[", f);
        for (uint32_t i = 0; i < d->num_nodes; i++)
            fprintf(f, "%s%u", i ? "," : "", i);
        fputs("]}],\n  \"nodes\": [", f);
        for (uint32_t i = 0; i < d->num_nodes; i++) {
            fputs(item(i), f);
            write_node(f, &d->nodes[i], d);
        }
        fputs("\n  ]", f);
    }
    if (d->num_meshes) {
        fputs(",\n  \"meshes\": [", f);
        for (uint32_t i = 0; i < d->num_meshes; i++) {
            const gltf_write_mesh *m = &d->meshes[i];
            fprintf(f, "%s{\"primitives\":[{\"attributes\":{\"POSITION\":%u", item(i), a++);
            if (m->normals)
                fprintf(f, ",\"NORMAL\":%u", a++);
            if (m->uvs)
                fprintf(f, ",\"TEXCOORD_0\":%u", a++);
            fprintf(f, "},\"indices\":%u", a++);
            if (d->num_materials) {
                assert(m->material < d->num_materials);
                fprintf(f, ",\"material\":%u", m->material);
            }
            fputs("}]", f);
            write_name(f, m->name);
            fputc('}', f);
        }
        fputs("\n  ]", f);
    }
    if (d->num_materials) {
        fputs(",\n  \"materials\": [", f);
        for (uint32_t i = 0; i < d->num_materials; i++) {
            fputs(item(i), f);
            write_material(f, &d->materials[i]);
        }
        fputs("\n  ]", f);
    }
    if (d->num_cameras) {
        fputs(",\n  \"cameras\": [", f);
        for (uint32_t i = 0; i < d->num_cameras; i++) {
            const gltf_write_camera *c = &d->cameras[i];
            assert(c->yfov > 0.0f);
            fprintf(f, "%s{\"type\":\"perspective\"", item(i));
            write_name(f, c->name);
            fprintf(f, ",\"perspective\":{\"yfov\":%.9g,\"znear\":%.9g", c->yfov,
                    c->znear != 0.0f ? c->znear : 0.01f);
            if (c->aspect != 0.0f)
                fprintf(f, ",\"aspectRatio\":%.9g", c->aspect);
            if (c->zfar != 0.0f)
                fprintf(f, ",\"zfar\":%.9g", c->zfar);
            fputs("}}", f);
        }
        fputs("\n  ]", f);
    }
    if (d->num_lights) {
        fputs(",\n  \"extensions\": {\"KHR_lights_punctual\":{\"lights\":[", f);
        for (uint32_t i = 0; i < d->num_lights; i++) {
            fputs(item(i), f);
            write_light(f, &d->lights[i]);
        }
        fputs("\n  ]}}", f);
    }
    if (d->num_meshes) {
        write_accessors(f, d);
        fprintf(f, ",\n  \"buffers\": [{\"byteLength\":%zu,"
                   "\"uri\":\"data:application/octet-stream;base64,", size);
        write_base64(f, buf, size);
        fputs("\"}]", f);
    }
    fputs("\n}\n", f);
}

/* .glb: the same document, built in memory and handed to tinygltf (gltf_glb.cpp). */
static bool write_glb(const char *path, const gltf_write_desc *desc, const uint8_t *buf, size_t size)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    bool ok;
    if (!f) {
        util_error("%s: out of memory", path);
        return false;
    }
    write_json(f, desc, buf, size);
    ok = !ferror(f);
    ok = fclose(f) == 0 && ok;
    ok = ok ? gltf_write_glb_from_json(path, text, len) : (util_error("%s: out of memory", path), false);
    free(text);
    return ok;
}

bool gltf_write_file(const char *path, const gltf_write_desc *desc)
{
    util_out out;
    size_t size = 0;
    uint8_t *buf = make_buffer(desc, &size);
    const char *dot = strrchr(path, '.');
    FILE *f;
    bool ok;
    if (dot && !strcasecmp(dot, ".glb")) {
        ok = write_glb(path, desc, buf, size);
        free(buf);
        return ok;
    }
    if (!util_out_open(&out, path) || !(f = util_out_file(&out))) {
        if (out.fd >= 0)
            util_out_commit(&out, false);
        free(buf);
        return false;
    }
    write_json(f, desc, buf, size);
    free(buf);
    return util_out_commit(&out, true);
}
