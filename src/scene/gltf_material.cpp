/* gltf_material.cpp: what a glTF file's materials read: images (PNG and JPEG, each distinct
 * one decoded once), samplers, textures with their texCoord and KHR_texture_transform, the
 * materials and their extensions, and KHR_materials_variants. */
#include "gltf_internal.h"

#include <stb_image.h>
#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstring>

namespace gltf {

const char *const SUPPORTED_EXTENSIONS[] = {
    "KHR_lights_punctual",        "KHR_materials_emissive_strength", "KHR_materials_specular",
    "KHR_materials_transmission", "KHR_materials_ior",               "KHR_materials_unlit",
    "KHR_texture_transform",      "KHR_mesh_quantization",           "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",    "KHR_materials_variants",          "KHR_materials_volume",
    "KHR_materials_dispersion",   "KHR_materials_clearcoat",         "KHR_materials_sheen",
    "KHR_materials_anisotropy",   "KHR_materials_iridescence",       "KHR_materials_diffuse_transmission"};
const size_t NUM_SUPPORTED_EXTENSIONS = sizeof SUPPORTED_EXTENSIONS / sizeof *SUPPORTED_EXTENSIONS;

/* Decodes PNG or JPEG, the formats glTF 2.0 allows. Anything else is refused before stb_image
 * sees it: its other decoders are not needed, and the 16-bit PNM path of the stb bundled with
 * tinygltf 2.7 overflows its buffer. On failure returns the reason. */
std::string decode_image(Ctx &c, tinygltf::Image *img, int idx, const unsigned char *bytes, size_t size)
{
    static const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    bool is_png = size >= 8 && memcmp(bytes, png, 8) == 0;
    bool is_jpeg = size >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
    if (!is_png && !is_jpeg)
        return "not a PNG or JPEG image";
    if (size > size_t(INT32_MAX))
        return "image data too large";
    /* The same bytes are decoded once (a file listing one PNG 500 times decoded it 500 times). */
    std::pair<uint32_t, size_t> key(uint32_t(crc32_z(crc32_z(0, nullptr, 0), bytes, size)), size);
    auto seen = c.decoded.find(key);
    if (seen != c.decoded.end()) {
        c.image_alias[idx] = seen->second;
        return "";
    }
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_memory(bytes, int(size), &w, &h, &comp))
        return "cannot decode";
    if (c.texels + uint64_t(w) * uint64_t(h) > SCENE_MAX_TEXELS) {
        char msg[256];
        snprintf(msg, sizeof msg, "images too large: %llu texels with image %d (%dx%d), the limit is %llu",
                 (unsigned long long)(c.texels + uint64_t(w) * uint64_t(h)), idx, w, h,
                 (unsigned long long)SCENE_MAX_TEXELS);
        if (c.limit_error.empty())
            c.limit_error = msg;
        return msg;
    }
    c.texels += uint64_t(w) * uint64_t(h);
    c.decoded[key] = idx;
    std::string err, warn_text;
    if (!tinygltf::LoadImageData(img, idx, &err, &warn_text, 0, 0, bytes, int(size), nullptr))
        return err.empty() ? "cannot decode" : err;
    return "";
}

/* tinygltf image callback. Images in buffer views arrive before any buffer view is checked, so
 * they are decoded later (decode_view_images); a file that fails to decode is recorded rather
 * than failing the whole load, and its textures are dropped with a warning. */
bool image_callback(tinygltf::Image *img, const int idx, std::string *, std::string *, int, int,
                    const unsigned char *bytes, int size, void *user)
{
    Ctx &c = *static_cast<Ctx *>(user);
    if (img->bufferView >= 0)
        return true;
    std::string why = decode_image(c, img, idx, bytes, size_t(size));
    if (!why.empty())
        c.image_errors[idx] = why;
    return true;
}

bool check_texture_ref(Ctx &c, const tinygltf::Material &mat, int mi, int index, const char *slot)
{
    if (index == -1 || in_range(index, c.m.textures.size()))
        return true;
    return fail(c, "%s: %s refers to texture %d, which does not exist", label("material", mi, mat.name).c_str(), slot, index);
}

bool check_textures_and_materials(Ctx &c)
{
    const auto &m = c.m;
    for (size_t i = 0; i < m.textures.size(); i++) {
        const auto &t = m.textures[i];
        if (t.source != -1 && !in_range(t.source, m.images.size()))
            fail(c, "texture %zu refers to image %d, which does not exist", i, t.source);
        if (t.sampler != -1 && !in_range(t.sampler, m.samplers.size()))
            fail(c, "texture %zu refers to sampler %d, which does not exist", i, t.sampler);
    }
    for (size_t i = 0; i < m.materials.size(); i++) {
        const auto &mat = m.materials[i];
        const auto &pbr = mat.pbrMetallicRoughness;
        check_texture_ref(c, mat, int(i), pbr.baseColorTexture.index, "baseColorTexture");
        check_texture_ref(c, mat, int(i), pbr.metallicRoughnessTexture.index, "metallicRoughnessTexture");
        check_texture_ref(c, mat, int(i), mat.normalTexture.index, "normalTexture");
        check_texture_ref(c, mat, int(i), mat.occlusionTexture.index, "occlusionTexture");
        check_texture_ref(c, mat, int(i), mat.emissiveTexture.index, "emissiveTexture");
    }
    return !c.failed;
}

/* The names of the file's KHR_materials_variants, in order (empty without the extension). */
std::vector<std::string> variant_names(const tinygltf::Model &m)
{
    std::vector<std::string> names;
    auto it = m.extensions.find("KHR_materials_variants");
    if (it == m.extensions.end() || !it->second.Has("variants") || !it->second.Get("variants").IsArray())
        return names;
    const tinygltf::Value &v = it->second.Get("variants");
    for (size_t i = 0; i < v.ArrayLen(); i++) {
        const tinygltf::Value &e = v.Get(int(i));
        names.push_back(e.Has("name") && e.Get("name").IsString() ? e.Get("name").Get<std::string>() : "");
    }
    return names;
}

/* KHR_materials_variants: with a variant selected (scene_select_variant), each primitive's
 * mapping that lists it replaces the primitive's material, before the materials are checked;
 * a primitive without one keeps its own. No variant selected: the file's default materials. */
bool select_variant(Ctx &c)
{
    if (variant.empty())
        return true;
    std::vector<std::string> names = variant_names(c.m);
    auto at = std::find(names.begin(), names.end(), variant);
    if (at == names.end()) {
        std::string list;
        for (const auto &n : names)
            list += (list.empty() ? "" : ", ") + ("'" + n + "'");
        return fail(c, "has no material variant '%s' (%s%s)", variant.c_str(), list.empty() ? "no variants" : "variants: ",
                    list.c_str());
    }
    double want = double(at - names.begin());
    for (size_t mi = 0; mi < c.m.meshes.size(); mi++)
        for (auto &p : c.m.meshes[mi].primitives) {
            auto e = p.extensions.find("KHR_materials_variants");
            if (e == p.extensions.end() || !e->second.Has("mappings") || !e->second.Get("mappings").IsArray())
                continue;
            const tinygltf::Value &maps = e->second.Get("mappings");
            for (size_t k = 0; k < maps.ArrayLen(); k++) {
                const tinygltf::Value &mp = maps.Get(int(k));
                if (!mp.Has("variants") || !mp.Get("variants").IsArray() || !mp.Has("material") ||
                    !mp.Get("material").IsNumber())
                    continue;
                const tinygltf::Value &vs = mp.Get("variants");
                for (size_t j = 0; j < vs.ArrayLen(); j++)
                    if (vs.Get(int(j)).IsNumber() && vs.Get(int(j)).GetNumberAsDouble() == want)
                        p.material = mp.Get("material").GetNumberAsInt();
            }
        }
    return true;
}

const tinygltf::Value *extension(const tinygltf::Material &mat, const char *name)
{
    auto it = mat.extensions.find(name);
    return it == mat.extensions.end() ? nullptr : &it->second;
}

/* A textureInfo of a material extension (e may be null) as tinygltf's own TextureInfo, so
 * texture_slot reads both alike; index -1 when absent. Doc::check_material has checked its
 * form (an index of an existing texture, texCoord an integer). */
tinygltf::TextureInfo ext_texture(const tinygltf::Value *e, const char *key, double *scale)
{
    tinygltf::TextureInfo t;
    if (!e || !e->IsObject() || !e->Has(key) || !e->Get(key).IsObject())
        return t;
    const tinygltf::Value &v = e->Get(key);
    if (v.Has("index") && v.Get("index").IsInt())
        t.index = v.Get("index").GetNumberAsInt();
    if (v.Has("texCoord") && v.Get("texCoord").IsInt())
        t.texCoord = v.Get("texCoord").GetNumberAsInt();
    if (scale && v.Has("scale") && v.Get("scale").IsNumber())
        *scale = v.Get("scale").GetNumberAsDouble();
    if (v.Has("extensions") && v.Get("extensions").IsObject())
        for (const std::string &k : v.Get("extensions").Keys())
            t.extensions[k] = v.Get("extensions").Get(k);
    return t;
}

void decode_view_images(Ctx &c)
{
    for (size_t i = 0; i < c.m.images.size(); i++) {
        tinygltf::Image &img = c.m.images[i];
        if (img.bufferView < 0) /* tinygltf checked that the view exists, check_buffers_and_views that it fits */
            continue;
        const auto &v = c.m.bufferViews[size_t(img.bufferView)];
        std::string why = decode_image(c, &img, int(i), view_data(c, img.bufferView, 0), v.byteLength);
        if (!why.empty())
            c.image_errors[int(i)] = why;
    }
}

/* Decoded image -> RGBA8: grey, grey+alpha and RGB expand as glTF samples them; 16-bit
 * channels round to 8 bits (v * 255 / 65535 = v / 257). */
bool convert_image(const tinygltf::Image &img, scene_image &out)
{
    int comps = img.component, bytes = img.bits / 8;
    if (img.width < 1 || img.height < 1 || comps < 1 || comps > 4 || (img.bits != 8 && img.bits != 16) ||
        size_t(img.width) * size_t(img.height) > MAX_PIXELS ||
        img.image.size() != size_t(img.width) * size_t(img.height) * size_t(comps * bytes))
        return false;
    size_t n = size_t(img.width) * size_t(img.height);
    out.width = uint32_t(img.width);
    out.height = uint32_t(img.height);
    out.rgba8 = static_cast<uint8_t *>(util_malloc(n * 4));
    const uint8_t *src = img.image.data();
    if (comps == 4 && bytes == 1) { /* what tinygltf's decoder delivers */
        memcpy(out.rgba8, src, n * 4);
        return true;
    }
    for (size_t p = 0; p < n; p++) {
        uint8_t ch[4] = {0, 0, 0, 255};
        for (int k = 0; k < comps; k++) {
            const uint8_t *s = src + (p * size_t(comps) + size_t(k)) * size_t(bytes);
            if (bytes == 1) {
                ch[k] = s[0];
            } else {
                uint16_t v;
                memcpy(&v, s, 2);
                ch[k] = uint8_t((v + 128) / 257);
            }
        }
        if (comps <= 2) { /* luminance (+ alpha) */
            ch[3] = comps == 2 ? ch[1] : 255;
            ch[1] = ch[2] = ch[0];
        }
        memcpy(out.rgba8 + p * 4, ch, 4);
    }
    return true;
}

uint32_t wrap_mode(Ctx &c, size_t sampler, int mode)
{
    switch (mode) {
    case TINYGLTF_TEXTURE_WRAP_REPEAT: return GN_WRAP_REPEAT;
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return GN_WRAP_CLAMP;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return GN_WRAP_MIRROR;
    default: warn(c, "sampler %zu: invalid wrap mode %d (using REPEAT)", sampler, mode); return GN_WRAP_REPEAT;
    }
}

/* GN_TEX_NEAREST or 0 for a sampler's filters. The kernels look a texture up at one point
 * of its full-resolution image per sample, and the samples of a pixel average what it
 * covers, which is the minification (no mipmaps are needed for that); so magFilter decides
 * between nearest and bilinear, and without one, minFilter's filter within a level does. */
uint32_t filter_mode(Ctx &c, size_t sampler, int mag, int min)
{
    if (mag != -1 && mag != TINYGLTF_TEXTURE_FILTER_NEAREST && mag != TINYGLTF_TEXTURE_FILTER_LINEAR) {
        warn(c, "sampler %zu: invalid magFilter %d (using LINEAR)", sampler, mag);
        mag = TINYGLTF_TEXTURE_FILTER_LINEAR;
    }
    bool min_nearest = min == TINYGLTF_TEXTURE_FILTER_NEAREST || min == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST ||
                       min == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR;
    if (min != -1 && !min_nearest && min != TINYGLTF_TEXTURE_FILTER_LINEAR &&
        min != TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST && min != TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR)
        warn(c, "sampler %zu: invalid minFilter %d (ignored)", sampler, min);
    if (mag == -1)
        return min_nearest ? GN_TEX_NEAREST : 0u;
    return mag == TINYGLTF_TEXTURE_FILTER_NEAREST ? GN_TEX_NEAREST : 0u;
}

void load_images_and_textures(Ctx &c, scene *out)
{
    const auto &m = c.m;
    decode_view_images(c);
    out->images = static_cast<scene_image *>(util_calloc(m.images.size(), sizeof(scene_image)));
    c.image_map.assign(m.images.size(), GN_INVALID);
    for (size_t i = 0; i < m.images.size(); i++) {
        const auto &img = m.images[i];
        if (c.image_alias.count(int(i)))
            continue; /* below, once its original is in */
        if (c.image_errors.count(int(i)) || !convert_image(img, out->images[out->num_images])) {
            std::string why = c.image_errors.count(int(i)) ? c.image_errors[int(i)] : "file missing or unreadable";
            while (!why.empty() && why.back() == '\n')
                why.pop_back();
            warn(c, "%s%s%s: %s; textures using it are ignored", label("image", int(i), img.name).c_str(),
                 img.uri.empty() ? "" : " ", img.uri.substr(0, 200).c_str(), why.c_str());
            continue;
        }
        c.image_map[i] = out->num_images++;
        std::vector<unsigned char>().swap(c.m.images[i].image); /* keep one copy at a time */
    }
    for (const auto &alias : c.image_alias)
        c.image_map[size_t(alias.first)] = c.image_map[size_t(alias.second)];
    /* room for texture_slot's variants too: one per texture slot of a material at most */
    c.textures_room = m.textures.size() + 10 * m.materials.size();
    out->textures = static_cast<scene_texture *>(util_calloc(c.textures_room, sizeof(scene_texture)));
    c.textures_out = out;
    c.texture_map.assign(m.textures.size(), GN_INVALID);
    for (size_t i = 0; i < m.textures.size(); i++) {
        const auto &t = m.textures[i];
        if (t.source < 0) {
            warn(c, "texture %zu has no image source (ignored)", i);
            continue;
        }
        if (c.image_map[size_t(t.source)] == GN_INVALID)
            continue;
        uint32_t flags = 0;
        if (t.sampler >= 0) {
            const auto &s = m.samplers[size_t(t.sampler)];
            flags = wrap_mode(c, size_t(t.sampler), s.wrapS) | wrap_mode(c, size_t(t.sampler), s.wrapT) << 2 |
                    filter_mode(c, size_t(t.sampler), s.magFilter, s.minFilter);
        }
        out->textures[out->num_textures] = scene_texture{c.image_map[size_t(t.source)], flags, {1, 0, 0, 0, 1, 0}};
        c.texture_map[i] = out->num_textures++;
    }
}

/* A number in [lo, hi]; outside -> warning and clamped. */
float ranged(Ctx &c, double v, double lo, double hi, const std::string &what, const char *name)
{
    if (v >= lo && v <= hi)
        return float(v);
    warn(c, "%s: %s %g is out of range [%g, %g] (clamped)", what.c_str(), name, v, lo, hi);
    return float(v < lo ? lo : hi);
}

/* Member `key` of an extension object, `def` when absent. */
double ext_number(Ctx &c, const tinygltf::Value &ext, const char *key, double def, const std::string &what)
{
    if (!ext.IsObject() || !ext.Has(key))
        return def;
    const tinygltf::Value &v = ext.Get(key);
    if (v.IsNumber())
        return v.GetNumberAsDouble();
    warn(c, "%s: %s is not a number (ignored)", what.c_str(), key);
    return def;
}

/* A number pair of an extension object (KHR_texture_transform's offset and scale); false
 * (with a warning) when it is there but not two finite numbers. */
bool ext_pair(Ctx &c, const tinygltf::Value &ext, const char *key, double out[2], const std::string &what)
{
    if (!ext.Has(key))
        return true;
    const tinygltf::Value &v = ext.Get(key);
    if (v.IsArray() && v.ArrayLen() == 2 && v.Get(0).IsNumber() && v.Get(1).IsNumber() &&
        std::isfinite(v.Get(0).GetNumberAsDouble()) && std::isfinite(v.Get(1).GetNumberAsDouble())) {
        out[0] = v.Get(0).GetNumberAsDouble();
        out[1] = v.Get(1).GetNumberAsDouble();
        return true;
    }
    warn(c, "%s: KHR_texture_transform %s is not two finite numbers (ignored)", what.c_str(), key);
    return false;
}

/* The scene texture a material slot uses: the glTF texture's own one, or, when the
 * reference reads TEXCOORD_1 or has a KHR_texture_transform, a copy with its set and
 * transform (GnTexture), so each slot stays one index. */
template <typename Info> uint32_t texture_slot(Ctx &c, const Info &info, const std::string &what, const char *slot)
{
    if (info.index < 0 || c.texture_map[size_t(info.index)] == GN_INVALID)
        return GN_INVALID;
    int tex_coord = info.texCoord;
    float xf[6] = {1, 0, 0, 0, 1, 0};
    bool transformed = false;
    auto it = info.extensions.find("KHR_texture_transform");
    if (it != info.extensions.end() && it->second.IsObject()) {
        const tinygltf::Value &e = it->second;
        std::string where = what + " " + slot;
        double offset[2] = {0, 0}, scale[2] = {1, 1};
        double rotation = ext_number(c, e, "rotation", 0, where);
        if (!std::isfinite(rotation)) {
            warn(c, "%s: KHR_texture_transform rotation is not finite (ignored)", where.c_str());
            rotation = 0;
        }
        ext_pair(c, e, "offset", offset, where);
        ext_pair(c, e, "scale", scale, where);
        if (e.Has("texCoord")) {
            const tinygltf::Value &t = e.Get("texCoord");
            if (t.IsInt() && t.GetNumberAsInt() >= 0)
                tex_coord = t.GetNumberAsInt();
            else
                warn(c, "%s: KHR_texture_transform texCoord is not a non-negative integer (ignored)", where.c_str());
        }
        /* KHR_texture_transform: uv' = T R S uv, R = [cos sin; -sin cos] */
        double cr = std::cos(rotation), sr = std::sin(rotation);
        double r[6] = {cr * scale[0], sr * scale[1], offset[0], -sr * scale[0], cr * scale[1], offset[1]};
        for (int k = 0; k < 6; k++) {
            xf[k] = float(r[k]);
            transformed |= xf[k] != (k == 0 || k == 4 ? 1.0f : 0.0f);
        }
    }
    if (tex_coord > 1) {
        warn(c, "%s: %s uses TEXCOORD_%d, only TEXCOORD_0 and TEXCOORD_1 are supported (texture ignored)", what.c_str(),
             slot, tex_coord);
        return GN_INVALID;
    }
    uint32_t base = c.texture_map[size_t(info.index)];
    if (tex_coord == 0 && !transformed)
        return base;
    scene *out = c.textures_out;
    if (out->num_textures == c.textures_room) { /* a caller beyond one call per slot */
        c.textures_room *= 2;
        out->textures = static_cast<scene_texture *>(util_realloc(out->textures, c.textures_room * sizeof(scene_texture)));
    }
    scene_texture t = out->textures[base];
    t.flags |= tex_coord == 1 ? GN_TEX_UV1 : 0u;
    memcpy(t.transform, xf, sizeof xf);
    out->textures[out->num_textures] = t;
    return out->num_textures++;
}

bool number_triple(const tinygltf::Value &v, float out[3])
{
    if (!v.IsArray() || v.ArrayLen() != 3)
        return false;
    for (int k = 0; k < 3; k++) {
        if (!v.Get(k).IsNumber())
            return false;
        out[k] = float(v.Get(k).GetNumberAsDouble());
    }
    return true;
}

/* extras: {"gonio": {"brdf": NAME, PARAM: number, ..., "phong": {...}}} */
void read_gonio_extras(Ctx &c, const tinygltf::Value &extras, const std::string &what, GnMaterial &g, scene_material_extras &x)
{
    if (!extras.IsObject() || !extras.Has("gonio"))
        return;
    const tinygltf::Value &go = extras.Get("gonio");
    if (!go.IsObject()) {
        warn(c, "%s: extras.gonio is not an object (ignored)", what.c_str());
        return;
    }
    for (const std::string &key : go.Keys()) {
        const tinygltf::Value &v = go.Get(key);
        if (key == "brdf") {
            if (!v.IsString() || v.Get<std::string>().size() >= sizeof x.brdf)
                warn(c, "%s: extras.gonio.brdf must be a name of at most %zu characters (ignored)", what.c_str(), sizeof x.brdf - 1);
            else
                snprintf(x.brdf, sizeof x.brdf, "%s", v.Get<std::string>().c_str());
        } else if (key == "phong") {
            if (!v.IsObject()) {
                warn(c, "%s: extras.gonio.phong is not an object (ignored)", what.c_str());
                continue;
            }
            x.has_phong = true;
            struct { const char *name; vec3 *dst; } cols[] = {{"ambient", &g.phong_ambient}, {"diffuse", &g.phong_diffuse},
                                                              {"specular", &g.phong_specular}, {"emission", &g.phong_emission}};
            for (auto &col : cols) {
                float t[3];
                if (!v.Has(col.name))
                    continue;
                if (number_triple(v.Get(col.name), t) && t[0] >= 0 && t[1] >= 0 && t[2] >= 0)
                    *col.dst = vec3{t[0], t[1], t[2]};
                else
                    warn(c, "%s: extras.gonio.phong.%s must be 3 non-negative numbers (ignored)", what.c_str(), col.name);
            }
            if (v.Has("shininess")) {
                const tinygltf::Value &s = v.Get("shininess");
                if (s.IsNumber() && s.GetNumberAsDouble() >= 0)
                    g.phong_shininess = float(s.GetNumberAsDouble());
                else
                    warn(c, "%s: extras.gonio.phong.shininess must be a non-negative number (ignored)", what.c_str());
            }
        } else if (!v.IsNumber() || x.num_params == 8 || key.size() >= sizeof x.param_names[0]) {
            warn(c, "%s: extras.gonio.%s ignored (parameters are up to 8 numbers with names of at most %zu characters)",
                 what.c_str(), key.substr(0, 64).c_str(), sizeof x.param_names[0] - 1);
        } else {
            snprintf(x.param_names[x.num_params], sizeof x.param_names[0], "%s", key.c_str());
            x.param_values[x.num_params++] = float(v.GetNumberAsDouble());
        }
    }
}

void convert_material(Ctx &c, int mi, GnMaterial &g, scene_material_extras &x, char name[64])
{
    const auto &mat = c.m.materials[size_t(mi)];
    const auto &pbr = mat.pbrMetallicRoughness;
    std::string what = label("material", mi, mat.name);
    snprintf(name, 64, "%s", mat.name.empty() ? ("material " + std::to_string(mi)).c_str() : mat.name.c_str());
    scene_material_default(&g);
    if (pbr.baseColorFactor.size() == 4)
        g.base_color = vec4{ranged(c, pbr.baseColorFactor[0], 0, 1, what, "baseColorFactor"),
                            ranged(c, pbr.baseColorFactor[1], 0, 1, what, "baseColorFactor"),
                            ranged(c, pbr.baseColorFactor[2], 0, 1, what, "baseColorFactor"),
                            ranged(c, pbr.baseColorFactor[3], 0, 1, what, "baseColorFactor")};
    g.metallic = ranged(c, pbr.metallicFactor, 0, 1, what, "metallicFactor");
    g.roughness = ranged(c, pbr.roughnessFactor, 0, 1, what, "roughnessFactor");
    float strength = 1;
    if (const tinygltf::Value *e = extension(mat, "KHR_materials_emissive_strength"))
        strength = ranged(c, ext_number(c, *e, "emissiveStrength", 1, what), 0, MAX_RADIANCE, what, "emissiveStrength");
    if (mat.emissiveFactor.size() == 3)
        g.emissive = vec3{ranged(c, mat.emissiveFactor[0], 0, 1, what, "emissiveFactor") * strength,
                          ranged(c, mat.emissiveFactor[1], 0, 1, what, "emissiveFactor") * strength,
                          ranged(c, mat.emissiveFactor[2], 0, 1, what, "emissiveFactor") * strength};
    if (const tinygltf::Value *e = extension(mat, "KHR_materials_specular")) {
        g.specular = ranged(c, ext_number(c, *e, "specularFactor", 1, what), 0, 1, what, "specularFactor");
        float t[3];
        if (e->IsObject() && e->Has("specularColorFactor")) {
            if (number_triple(e->Get("specularColorFactor"), t) && t[0] >= 0 && t[1] >= 0 && t[2] >= 0)
                g.specular_color = vec3{t[0], t[1], t[2]};
            else
                warn(c, "%s: specularColorFactor must be 3 non-negative numbers (ignored)", what.c_str());
        }
    }
    if (const tinygltf::Value *e = extension(mat, "KHR_materials_transmission"))
        g.transmission = ranged(c, ext_number(c, *e, "transmissionFactor", 0, what), 0, 1, what, "transmissionFactor");
    if (const tinygltf::Value *e = extension(mat, "KHR_materials_ior")) {
        /* KHR_materials_ior allows 0 besides [1, inf): F0 = ((ior-1)/(ior+1))^2 = 1, a mirror. */
        double ior = ext_number(c, *e, "ior", 1.5, what);
        g.ior = ior == 0 ? 0.0f : ranged(c, ior, 1, INFINITY, what, "ior");
    }
    if (const tinygltf::Value *e = extension(mat, "KHR_materials_volume")) {
        /* The spec's thicknessFactor 0 (its default) means thin-walled: no medium. Any other
         * thickness only says there is one: the path tracer follows the real geometry
         * (docs/path-tracing.md), so the value and thicknessTexture are not used in shading. */
        g.thickness = ranged(c, ext_number(c, *e, "thicknessFactor", 0, what), 0, INFINITY, what, "thicknessFactor");
        g.volume = g.thickness > 0;
        double dist = ext_number(c, *e, "attenuationDistance", INFINITY, what);
        if (dist > 0)
            g.attenuation_distance = float(dist); /* beyond float's range: +inf, no absorption */
        else
            warn(c, "%s: attenuationDistance %g must be positive (ignored)", what.c_str(), dist);
        float t[3];
        if (e->IsObject() && e->Has("attenuationColor")) {
            if (number_triple(e->Get("attenuationColor"), t) && t[0] >= 0 && t[0] <= 1 && t[1] >= 0 &&
                t[1] <= 1 && t[2] >= 0 && t[2] <= 1)
                g.attenuation_color = vec3{t[0], t[1], t[2]};
            else
                warn(c, "%s: attenuationColor must be 3 numbers in [0, 1] (ignored)", what.c_str());
        }
        if (e->IsObject() && e->Has("thicknessTexture")) {
            const tinygltf::Value &tt = e->Get("thicknessTexture");
            const tinygltf::Value *ix = tt.IsObject() && tt.Has("index") ? &tt.Get("index") : nullptr;
            if (!ix || !ix->IsInt() || ix->GetNumberAsInt() < 0 || size_t(ix->GetNumberAsInt()) >= c.m.textures.size())
                warn(c, "%s: thicknessTexture does not name a texture (ignored)", what.c_str());
        }
    }
    if (const tinygltf::Value *e = extension(mat, "KHR_materials_dispersion"))
        g.dispersion = ranged(c, ext_number(c, *e, "dispersion", 0, what), 0, INFINITY, what, "dispersion");
    if (const tinygltf::Value *e = extension(mat, "KHR_materials_clearcoat")) {
        double scale = 1;
        g.clearcoat = ranged(c, ext_number(c, *e, "clearcoatFactor", 0, what), 0, 1, what, "clearcoatFactor");
        g.clearcoat_roughness = ranged(c, ext_number(c, *e, "clearcoatRoughnessFactor", 0, what), 0, 1, what,
                                       "clearcoatRoughnessFactor");
        g.tex_clearcoat = texture_slot(c, ext_texture(e, "clearcoatTexture"), what, "clearcoatTexture");
        g.tex_clearcoat_roughness =
            texture_slot(c, ext_texture(e, "clearcoatRoughnessTexture"), what, "clearcoatRoughnessTexture");
        g.tex_clearcoat_normal =
            texture_slot(c, ext_texture(e, "clearcoatNormalTexture", &scale), what, "clearcoatNormalTexture");
        g.clearcoat_normal_scale = float(scale);
    }
    if (const tinygltf::Value *e = extension(mat, "KHR_materials_sheen")) {
        float t[3];
        if (e->IsObject() && e->Has("sheenColorFactor")) {
            if (number_triple(e->Get("sheenColorFactor"), t))
                g.sheen_color = vec3{ranged(c, t[0], 0, 1, what, "sheenColorFactor"),
                                     ranged(c, t[1], 0, 1, what, "sheenColorFactor"),
                                     ranged(c, t[2], 0, 1, what, "sheenColorFactor")};
            else
                warn(c, "%s: sheenColorFactor must be 3 numbers (ignored)", what.c_str());
        }
        g.sheen_roughness = ranged(c, ext_number(c, *e, "sheenRoughnessFactor", 0, what), 0, 1, what,
                                   "sheenRoughnessFactor");
        g.tex_sheen_color = texture_slot(c, ext_texture(e, "sheenColorTexture"), what, "sheenColorTexture");
        g.tex_sheen_roughness = texture_slot(c, ext_texture(e, "sheenRoughnessTexture"), what, "sheenRoughnessTexture");
    }
    if (const tinygltf::Value *e = extension(mat, "KHR_materials_anisotropy")) {
        double rot = ext_number(c, *e, "anisotropyRotation", 0, what);
        g.anisotropy_strength = ranged(c, ext_number(c, *e, "anisotropyStrength", 0, what), 0, 1, what,
                                       "anisotropyStrength");
        /* any angle: reduced to [-pi, pi] so that float keeps its precision */
        g.anisotropy_rotation = std::isfinite(rot) ? float(std::remainder(rot, 2 * M_PI)) : 0.0f;
        g.tex_anisotropy = texture_slot(c, ext_texture(e, "anisotropyTexture"), what, "anisotropyTexture");
    }
    if (const tinygltf::Value *e = extension(mat, "KHR_materials_iridescence")) {
        /* (thicknesses up to 1 mm and indices up to 100 keep the film's phase finite in float) */
        g.iridescence = ranged(c, ext_number(c, *e, "iridescenceFactor", 0, what), 0, 1, what, "iridescenceFactor");
        g.iridescence_ior = ranged(c, ext_number(c, *e, "iridescenceIor", 1.3, what), 1, 100, what, "iridescenceIor");
        g.iridescence_thickness_min = ranged(c, ext_number(c, *e, "iridescenceThicknessMinimum", 100, what), 0,
                                             1e6, what, "iridescenceThicknessMinimum");
        g.iridescence_thickness_max = ranged(c, ext_number(c, *e, "iridescenceThicknessMaximum", 400, what), 0,
                                             1e6, what, "iridescenceThicknessMaximum");
        g.tex_iridescence = texture_slot(c, ext_texture(e, "iridescenceTexture"), what, "iridescenceTexture");
        g.tex_iridescence_thickness =
            texture_slot(c, ext_texture(e, "iridescenceThicknessTexture"), what, "iridescenceThicknessTexture");
    }
    if (const tinygltf::Value *e = extension(mat, "KHR_materials_diffuse_transmission")) {
        float t[3];
        g.diffuse_transmission = ranged(c, ext_number(c, *e, "diffuseTransmissionFactor", 0, what), 0, 1, what,
                                        "diffuseTransmissionFactor");
        if (e->IsObject() && e->Has("diffuseTransmissionColorFactor")) {
            if (number_triple(e->Get("diffuseTransmissionColorFactor"), t))
                g.diffuse_transmission_color = vec3{ranged(c, t[0], 0, 1, what, "diffuseTransmissionColorFactor"),
                                                    ranged(c, t[1], 0, 1, what, "diffuseTransmissionColorFactor"),
                                                    ranged(c, t[2], 0, 1, what, "diffuseTransmissionColorFactor")};
            else
                warn(c, "%s: diffuseTransmissionColorFactor must be 3 numbers (ignored)", what.c_str());
        }
        g.tex_diffuse_transmission =
            texture_slot(c, ext_texture(e, "diffuseTransmissionTexture"), what, "diffuseTransmissionTexture");
        g.tex_diffuse_transmission_color = texture_slot(c, ext_texture(e, "diffuseTransmissionColorTexture"), what,
                                                        "diffuseTransmissionColorTexture");
    }
    if (extension(mat, "KHR_materials_unlit"))
        g.flags |= GN_MAT_UNLIT;
    if (mat.doubleSided)
        g.flags |= GN_MAT_DOUBLE_SIDED;
    g.normal_scale = float(mat.normalTexture.scale);
    g.occlusion_strength = ranged(c, mat.occlusionTexture.strength, 0, 1, what, "occlusionTexture.strength");
    g.alpha_cutoff = ranged(c, mat.alphaCutoff, 0, INFINITY, what, "alphaCutoff");
    if (mat.alphaMode == "MASK")
        g.flags |= GN_MAT_MASK;
    else if (mat.alphaMode == "BLEND")
        g.flags |= GN_MAT_BLEND;
    else if (mat.alphaMode != "OPAQUE")
        warn(c, "%s: unknown alphaMode '%s' (rendered opaque)", what.c_str(), mat.alphaMode.substr(0, 64).c_str());
    g.tex_base = texture_slot(c, pbr.baseColorTexture, what, "baseColorTexture");
    g.tex_mr = texture_slot(c, pbr.metallicRoughnessTexture, what, "metallicRoughnessTexture");
    g.tex_normal = texture_slot(c, mat.normalTexture, what, "normalTexture");
    g.tex_emissive = texture_slot(c, mat.emissiveTexture, what, "emissiveTexture");
    g.tex_occlusion = texture_slot(c, mat.occlusionTexture, what, "occlusionTexture");
    scene_phong_from_pbr(&g);
    read_gonio_extras(c, mat.extras, what, g, x);
}

void load_materials(Ctx &c, scene *out)
{
    size_t n = c.m.materials.size();
    bool need_default = false;
    for (uint32_t t = 0; t < out->num_triangles; t++)
        need_default |= out->tri_material[t] == n;
    out->num_materials = uint32_t(n + (need_default ? 1 : 0));
    out->materials = static_cast<GnMaterial *>(util_calloc(out->num_materials, sizeof(GnMaterial)));
    out->material_extras = static_cast<scene_material_extras *>(util_calloc(out->num_materials, sizeof(scene_material_extras)));
    out->material_names = static_cast<char(*)[64]>(util_calloc(out->num_materials, 64));
    for (size_t i = 0; i < n; i++)
        convert_material(c, int(i), out->materials[i], out->material_extras[i], out->material_names[i]);
    if (need_default) {
        scene_material_default(&out->materials[n]);
        snprintf(out->material_names[n], 64, "default");
    }
}

} // namespace gltf
