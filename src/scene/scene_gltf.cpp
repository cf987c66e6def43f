/* scene_gltf.cpp: scene_load, the glTF 2.0 loader. The JSON document is checked first as JSON
 * (check_document: types, indices, sizes, enums, which tinygltf's conversions lose); then
 * tinygltf parses the JSON/GLB and fetches buffers and images, and everything it returns is
 * checked here against the glTF 2.0 specification (references, accessor ranges and formats,
 * values) before one byte is read, in cgltf's order: parse, load buffers, validate, read.
 * Geometry is baked into world space, normals with the cofactor matrix (the inverse transpose
 * up to det, Lengyel, "Mathematics for 3D Game Programming and Computer Graphics", 3rd ed.,
 * 4.5). No C++ exception escapes into C. */
#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <stb_image.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

extern "C" {
#include "scene.h"
#include "tangent.h"
#include "util.h"
}
#include "gltf_decompress.h"
#include "image_decode.h"

namespace {

/* Loader limits: keep a hostile file from asking for more memory than any real scene needs
 * (util_malloc would stop the program) and from recursing deeply inside tinygltf. */
const size_t MAX_ELEMENTS = size_t(1) << 28; /* per accessor backed by a buffer view */
const size_t MAX_ZERO_ELEMENTS = size_t(1) << 22; /* per accessor without one (all zeros) */
/* The decoded scene (scene.h: SCENE_MAX_*), checked before anything is allocated: a few
 * hundred bytes of JSON that instance one large accessor many times asked for gigabytes. */
const size_t MAX_SCENE = SCENE_MAX_TRIANGLES;
const size_t MAX_PIXELS = size_t(1) << 28;   /* per image */
const int MAX_JSON_DEPTH = 64;               /* tinygltf copies extras/extensions recursively */
/* Emission and light intensities above this are clamped: products with areas and squared
 * distances must stay finite in float (1e39 became inf and NaN pixels). */
const double MAX_RADIANCE = 1e9;

const char *const SUPPORTED_EXTENSIONS[] = {
    "KHR_lights_punctual",        "KHR_materials_emissive_strength", "KHR_materials_specular",
    "KHR_materials_transmission", "KHR_materials_ior",               "KHR_materials_unlit",
    "KHR_texture_transform",      "KHR_mesh_quantization",           "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",    "KHR_materials_variants",          "KHR_materials_volume",
    "KHR_materials_dispersion",   "KHR_materials_clearcoat",         "KHR_materials_sheen",
    "KHR_materials_anisotropy",   "KHR_materials_iridescence",       "KHR_materials_diffuse_transmission",
    "EXT_texture_webp"}; /* and KHR_texture_basisu where built with Basis Universal (check_asset) */

using Json = nlohmann::json;

typedef std::array<double, 16> Mat; /* column-major, as glTF stores matrices */

struct Prim {                 /* one triangle primitive of a glTF mesh, in the mesh's space */
    std::vector<float> pos;   /* 3 per vertex */
    std::vector<float> nrm;   /* 3 per vertex */
    std::vector<float> uv;    /* 2 per vertex, empty without TEXCOORD_0 */
    std::vector<float> uv1;   /* 2 per vertex, empty without TEXCOORD_1 */
    std::vector<float> tan;   /* 4 per vertex, empty without TANGENT */
    std::vector<float> col;   /* 4 per vertex (RGBA), empty without COLOR_0 */
    std::vector<uint32_t> idx; /* 3 per triangle */
    uint32_t material;        /* glTF material, or GN_INVALID for the default one */
};

struct Instance {
    int node, mesh;
    Mat world;
};

struct Ctx {
    const char *path;
    tinygltf::Model m;
    bool failed = false;
    std::map<int, std::string> image_errors; /* decode failures reported by the image callback */
    std::vector<Mat> local;                  /* per node */
    std::vector<bool> camera_ok, light_ok;   /* per glTF camera / light: values usable */
    std::vector<std::vector<Prim>> meshes;   /* per glTF mesh */
    std::vector<uint32_t> image_map, texture_map; /* glTF index -> scene index or GN_INVALID */
    scene *textures_out = nullptr;           /* where texture_slot adds transformed textures */
    size_t textures_room = 0;                /* textures_out->textures' allocated entries */
    std::map<std::pair<uint32_t, size_t>, int> decoded; /* (crc32, size) of image bytes -> first image */
    std::map<int, int> image_alias;          /* image -> the earlier image with the same bytes */
    std::map<int, texture_format> image_formats; /* image -> the format of its bytes, once read */
    uint64_t texels = 0;                     /* of the images decoded so far */
    std::string limit_error;                 /* a SCENE_MAX_* limit exceeded while decoding */
    bool warned_skin = false, warned_targets = false;
    int scene_index = -1;                    /* the glTF scene to draw; -1: the default one */
    std::string folder;                      /* realpath of the scene's folder */
    std::string base_dir;                    /* the folder as tinygltf joins URIs to it */
    std::vector<std::string> access_errors;  /* files the confined loader refused */
};

bool allow_outside_files = false; /* scene_allow_outside_files */
std::string variant;              /* scene_select_variant */

void vreport(const Ctx &c, bool error, const char *fmt, va_list ap)
{
    char msg[1024];
    vsnprintf(msg, sizeof msg, fmt, ap);
    if (error)
        util_error("%s: %s", c.path, msg);
    else
        util_warn("%s: %s", c.path, msg);
}

/* Bad input: always returns false so checks read `if (bad) return fail(...)`. */
bool fail(Ctx &c, const char *fmt, ...) UTIL_PRINTF(2, 3);
bool fail(Ctx &c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vreport(c, true, fmt, ap);
    va_end(ap);
    c.failed = true;
    return false;
}

void warn(Ctx &c, const char *fmt, ...) UTIL_PRINTF(2, 3);
void warn(Ctx &c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vreport(c, false, fmt, ap);
    va_end(ap);
}

/* "mesh 3 'Body'": how messages name a glTF object. */
std::string label(const char *kind, int i, const std::string &name)
{
    std::string s = std::string(kind) + " " + std::to_string(i);
    if (!name.empty())
        s += " '" + name.substr(0, 64) + "'";
    return s;
}

bool in_range(int i, size_t n) { return i >= 0 && size_t(i) < n; }

void report_lines(Ctx &c, const std::string &text, bool error)
{
    size_t start = 0;
    while (start < text.size()) {
        size_t end = text.find('\n', start);
        if (end == std::string::npos)
            end = text.size();
        if (end > start) {
            std::string line = text.substr(start, end - start);
            if (error)
                fail(c, "%s", line.c_str());
            else
                warn(c, "%s", line.c_str());
        }
        start = end + 1;
    }
}

/* ---- container and JSON checks, before tinygltf sees the bytes --------------------------- */

uint32_t rd32(const uint8_t *p) { return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24; }

/* GLB layout (glTF 2.0, "Binary glTF Layout"): a 12-byte header, a JSON chunk, an optional
 * BIN chunk that must come second, then chunks of unknown types to ignore. On success the
 * header's length is rewritten to end after JSON/BIN, which is the form tinygltf accepts,
 * and the JSON chunk is returned for the checks below. Returns the new length, 0 on error. */
uint32_t check_glb(Ctx &c, uint8_t *d, size_t size, const uint8_t **json, size_t *json_len)
{
    const uint32_t JSON = 0x4E4F534A, BIN = 0x004E4942;
    if (size < 12)
        return fail(c, "truncated GLB header (%zu bytes)", size);
    if (memcmp(d, "glTF", 4) != 0)
        return fail(c, "not a GLB file (bad magic)");
    if (rd32(d + 4) != 2)
        return fail(c, "unsupported GLB version %u", rd32(d + 4));
    uint32_t length = rd32(d + 8);
    if (length < 20)
        return fail(c, "declared GLB length %u is too small", length);
    if (length > size)
        return fail(c, "declared GLB length %u exceeds the file size %zu (truncated file?)", length, size);
    if (length < size)
        warn(c, "%zu bytes of extra data after the end of the GLB (ignored)", size - length);
    uint32_t pos = 12, end = 0;
    bool have_bin = false;
    for (int n = 0; pos < length; n++) {
        if (length - pos < 8)
            return fail(c, "truncated GLB chunk header at byte %u", pos);
        uint32_t len = rd32(d + pos), type = rd32(d + pos + 4);
        if (len > length - pos - 8)
            return fail(c, "GLB chunk at byte %u (length %u) runs past the end of the GLB", pos, len);
        if (len % 4)
            return fail(c, "GLB chunk at byte %u: length %u is not a multiple of 4", pos, len);
        if (len == 0)
            return fail(c, "GLB chunk at byte %u is empty", pos);
        if (n == 0 && type != JSON)
            return fail(c, "the first GLB chunk must be JSON (found type 0x%08x)", type);
        if (n == 0) {
            *json = d + 20;
            *json_len = len;
            end = 20 + len;
        } else if (type == JSON) {
            return fail(c, "GLB has a second JSON chunk at byte %u", pos);
        } else if (type == BIN) {
            if (have_bin || n != 1)
                return fail(c, "misplaced BIN chunk at byte %u (it must be the second and only one)", pos);
            have_bin = true;
            end = pos + 8 + len;
        } else {
            warn(c, "unknown GLB chunk type 0x%08x at byte %u (ignored)", type, pos);
        }
        pos += 8 + len;
    }
    d[8] = uint8_t(end);
    d[9] = uint8_t(end >> 8);
    d[10] = uint8_t(end >> 16);
    d[11] = uint8_t(end >> 24);
    return end;
}

bool check_json_text(Ctx &c, const uint8_t *s, size_t n)
{
    if (n >= 3 && s[0] == 0xEF && s[1] == 0xBB && s[2] == 0xBF)
        warn(c, "JSON starts with a UTF-8 byte order mark, which glTF forbids (ignored)");
    int depth = 0;
    bool in_string = false;
    for (size_t i = 0; i < n; i++) {
        uint8_t ch = s[i];
        if (in_string) {
            if (ch == '\\')
                i++;
            else if (ch == '"')
                in_string = false;
        } else if (ch == '"') {
            in_string = true;
        } else if (ch == '{' || ch == '[') {
            if (++depth > MAX_JSON_DEPTH)
                return fail(c, "JSON nested deeper than %d levels", MAX_JSON_DEPTH);
        } else if (ch == '}' || ch == ']') {
            depth--;
        }
    }
    return true;
}

/* The texel budget exceeded by image idx of w x h: the load fails with this message. */
std::string too_large(Ctx &c, int idx, uint64_t w, uint64_t h)
{
    char msg[256];
    snprintf(msg, sizeof msg, "images too large: %llu texels with image %d (%llux%llu), the limit is %llu",
             (unsigned long long)(c.texels + w * h), idx, (unsigned long long)w, (unsigned long long)h,
             (unsigned long long)SCENE_MAX_TEXELS);
    if (c.limit_error.empty())
        c.limit_error = msg;
    return msg;
}

/* Decodes PNG or JPEG, the formats glTF 2.0 allows, through tinygltf's stb, and WebP and KTX2
 * (EXT_texture_webp, KHR_texture_basisu) through image_decode.h. Anything else is refused
 * before stb_image sees it: its other decoders are not needed, and the 16-bit PNM path of the
 * stb bundled with tinygltf 2.7 overflows its buffer. On failure returns the reason. */
std::string decode_image(Ctx &c, tinygltf::Image *img, int idx, const unsigned char *bytes, size_t size)
{
    texture_format format = texture_format_of(bytes, size);
    if (format == TEXTURE_FORMAT_UNKNOWN)
        return "not a PNG, JPEG, WebP or KTX2 image" +
               (img->mimeType.empty() ? std::string() : " (its mimeType says " + img->mimeType.substr(0, 40) + ")");
    if (size > size_t(INT32_MAX))
        return "image data too large";
    /* The same bytes are decoded once (a file listing one PNG 500 times decoded it 500 times). */
    std::pair<uint32_t, size_t> key(uint32_t(crc32_z(crc32_z(0, nullptr, 0), bytes, size)), size);
    auto seen = c.decoded.find(key);
    if (seen != c.decoded.end()) {
        c.image_alias[idx] = seen->second;
        return "";
    }
    c.image_formats[idx] = format;
    /* ---- WebP and KTX2 (image_decode.h) ---- */
    if (format == TEXTURE_FORMAT_WEBP || format == TEXTURE_FORMAT_KTX2) {
        uint8_t *rgba = nullptr;
        uint32_t w = 0, h = 0;
        char why[512];
        image_decode_status st = image_decode(bytes, size, img->mimeType.c_str(), SCENE_MAX_TEXELS - c.texels, &rgba,
                                              &w, &h, why, sizeof why);
        if (st == IMAGE_TOO_LARGE)
            return too_large(c, idx, w, h);
        c.texels += uint64_t(w) * h; /* the declared size, decoded or not, as stb's images count */
        if (st == IMAGE_BAD)
            return why;
        c.decoded[key] = idx;
        img->width = int(w);
        img->height = int(h);
        img->component = 4;
        img->bits = 8;
        img->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
        img->image.assign(rgba, rgba + size_t(w) * h * 4);
        free(rgba);
        return "";
    }
    /* ---- end of WebP and KTX2 ---- */
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_memory(bytes, int(size), &w, &h, &comp))
        return "cannot decode";
    if (c.texels + uint64_t(w) * uint64_t(h) > SCENE_MAX_TEXELS)
        return too_large(c, idx, uint64_t(w), uint64_t(h));
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

/* ---- structural validation ---------------------------------------------------------------- */

size_t comp_size(int ct)
{
    switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
    }
}

size_t num_comps(const tinygltf::Accessor &a) { return size_t(tinygltf::GetNumComponentsInType(uint32_t(a.type))); }

const char *type_name(int type)
{
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "?";
    }
}

size_t elem_size(const tinygltf::Accessor &a)
{
    size_t cs = comp_size(a.componentType);
    /* Matrix columns start on 4-byte boundaries (glTF 2.0, "Data Alignment"). */
    if (a.type == TINYGLTF_TYPE_MAT2 && cs == 1)
        return 8;
    if (a.type == TINYGLTF_TYPE_MAT3 && cs == 1)
        return 12;
    if (a.type == TINYGLTF_TYPE_MAT3 && cs == 2)
        return 24;
    return cs * num_comps(a);
}

/* Whether `count` elements of `size` bytes, `stride` apart, starting at `off` fit in `len`
 * bytes; written so no product can overflow. */
bool fits(size_t off, size_t stride, size_t count, size_t size, size_t len)
{
    return off <= len && size <= len - off && count - 1 <= (len - off - size) / stride;
}

bool check_buffers_and_views(Ctx &c)
{
    const auto &m = c.m;
    for (size_t i = 0; i < m.buffers.size(); i++)
        if (m.buffers[i].data.empty())
            fail(c, "buffer %zu is empty (byteLength must be at least 1)", i);
    for (size_t i = 0; i < m.bufferViews.size(); i++) {
        const auto &v = m.bufferViews[i];
        if (!in_range(v.buffer, m.buffers.size())) {
            fail(c, "buffer view %zu refers to buffer %d, which does not exist", i, v.buffer);
            continue;
        }
        size_t blen = m.buffers[size_t(v.buffer)].data.size();
        if (v.byteLength < 1)
            fail(c, "buffer view %zu has byteLength 0", i);
        else if (v.byteOffset > blen || v.byteLength > blen - v.byteOffset)
            fail(c, "buffer view %zu (offset %zu, length %zu) does not fit in buffer %d (%zu bytes)", i,
                 v.byteOffset, v.byteLength, v.buffer, blen);
        if (v.byteStride && (v.byteStride < 4 || v.byteStride > v.byteLength))
            fail(c, "buffer view %zu: byteStride %zu is out of range (4..min(252, byteLength %zu))", i,
                 v.byteStride, v.byteLength);
    }
    return !c.failed;
}

const uint8_t *view_data(const Ctx &c, int view, size_t offset)
{
    const auto &v = c.m.bufferViews[size_t(view)];
    return c.m.buffers[size_t(v.buffer)].data.data() + v.byteOffset + offset;
}

double read_comp(const uint8_t *p, int ct, bool norm)
{
    switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        int8_t v;
        memcpy(&v, p, 1);
        return norm ? std::fmax(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return norm ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        memcpy(&v, p, 2);
        return norm ? std::fmax(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        memcpy(&v, p, 2);
        return norm ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        memcpy(&v, p, 4);
        return v;
    }
    default: {
        float v;
        memcpy(&v, p, 4);
        return v;
    }
    }
}

bool check_sparse(Ctx &c, int i, const tinygltf::Accessor &a)
{
    const auto &s = a.sparse;
    const auto &views = c.m.bufferViews;
    std::string what = label("accessor", i, a.name);
    if (s.count < 1 || size_t(s.count) > a.count)
        return fail(c, "%s: sparse count %d is out of range (1..%zu)", what.c_str(), s.count, a.count);
    size_t is = comp_size(s.indices.componentType), es = elem_size(a);
    if (s.indices.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
        s.indices.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
        s.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT || !is)
        return fail(c, "%s: invalid sparse indices componentType %d", what.c_str(), s.indices.componentType);
    const int vi[2] = {s.indices.bufferView, s.values.bufferView};
    const int off[2] = {s.indices.byteOffset, s.values.byteOffset};
    const size_t sz[2] = {is, es};
    for (int k = 0; k < 2; k++) {
        const char *part = k ? "values" : "indices";
        if (!in_range(vi[k], views.size()))
            return fail(c, "%s: sparse %s refer to buffer view %d, which does not exist", what.c_str(), part, vi[k]);
        const auto &v = views[size_t(vi[k])];
        if (v.byteStride)
            return fail(c, "%s: buffer view %d of the sparse %s must not have a byteStride", what.c_str(), vi[k], part);
        if (off[k] < 0 || (v.byteOffset + size_t(off[k])) % comp_size(k ? a.componentType : s.indices.componentType))
            return fail(c, "%s: sparse %s byteOffset %d is negative or misaligned", what.c_str(), part, off[k]);
        if (!fits(size_t(off[k]), sz[k], size_t(s.count), sz[k], v.byteLength))
            return fail(c, "%s: sparse %s do not fit in buffer view %d", what.c_str(), part, vi[k]);
    }
    const uint8_t *p = view_data(c, vi[0], size_t(off[0]));
    double prev = -1;
    for (int j = 0; j < s.count; j++) {
        double idx = read_comp(p + size_t(j) * is, s.indices.componentType, false);
        if (idx <= prev || idx >= double(a.count))
            return fail(c, "%s: sparse index %.0f at %d is out of range or not increasing", what.c_str(), idx, j);
        prev = idx;
    }
    return true;
}

bool check_accessor(Ctx &c, int i)
{
    const auto &a = c.m.accessors[size_t(i)];
    std::string what = label("accessor", i, a.name);
    size_t cs = comp_size(a.componentType);
    if (!cs)
        return fail(c, "%s: invalid componentType %d", what.c_str(), a.componentType);
    size_t max = a.bufferView == -1 ? MAX_ZERO_ELEMENTS : MAX_ELEMENTS;
    if (a.count < 1 || a.count > max)
        return fail(c, "%s: count %zu is out of range (1..%zu)", what.c_str(), a.count, max);
    if (a.normalized && (a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                         a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
        return fail(c, "%s: only (unsigned) byte and short accessors can be normalized", what.c_str());
    size_t nc = num_comps(a);
    if ((!a.minValues.empty() && a.minValues.size() != nc) || (!a.maxValues.empty() && a.maxValues.size() != nc))
        return fail(c, "%s: min and max must have %zu values", what.c_str(), nc);
    if (a.bufferView == -1) {
        if (a.byteOffset)
            return fail(c, "%s: byteOffset without a bufferView", what.c_str());
    } else {
        if (!in_range(a.bufferView, c.m.bufferViews.size()))
            return fail(c, "%s refers to buffer view %d, which does not exist", what.c_str(), a.bufferView);
        const auto &v = c.m.bufferViews[size_t(a.bufferView)];
        size_t es = elem_size(a), stride = v.byteStride ? v.byteStride : es;
        if (a.byteOffset % cs || (v.byteOffset + a.byteOffset) % cs)
            return fail(c, "%s: byteOffset %zu (in buffer view %d at %zu) is not a multiple of the component size %zu",
                        what.c_str(), a.byteOffset, a.bufferView, v.byteOffset, cs);
        if (v.byteStride && v.byteStride < es)
            return fail(c, "%s: buffer view %d's byteStride %zu is smaller than the element size %zu", what.c_str(),
                        a.bufferView, v.byteStride, es);
        if (!fits(a.byteOffset, stride, a.count, es, v.byteLength))
            return fail(c, "%s (offset %zu, %zu elements of %zu bytes, stride %zu) does not fit in buffer view %d (%zu bytes)",
                        what.c_str(), a.byteOffset, a.count, es, stride, a.bufferView, v.byteLength);
    }
    return !a.sparse.isSparse || check_sparse(c, i, a);
}

/* Accessor data as doubles, count * components, sparse substitution applied, integer types
 * normalised when the accessor says so. Only for validated, non-matrix accessors. */
std::vector<double> read_accessor(const Ctx &c, int i)
{
    const auto &a = c.m.accessors[size_t(i)];
    size_t nc = num_comps(a), cs = comp_size(a.componentType), es = elem_size(a);
    std::vector<double> out(a.count * nc, 0.0);
    if (a.bufferView >= 0) {
        size_t stride = c.m.bufferViews[size_t(a.bufferView)].byteStride;
        stride = stride ? stride : es;
        const uint8_t *p = view_data(c, a.bufferView, a.byteOffset);
        for (size_t j = 0; j < a.count; j++)
            for (size_t k = 0; k < nc; k++)
                out[j * nc + k] = read_comp(p + j * stride + k * cs, a.componentType, a.normalized);
    }
    if (a.sparse.isSparse) {
        const auto &s = a.sparse;
        const uint8_t *ip = view_data(c, s.indices.bufferView, size_t(s.indices.byteOffset));
        const uint8_t *vp = view_data(c, s.values.bufferView, size_t(s.values.byteOffset));
        size_t is = comp_size(s.indices.componentType);
        for (size_t j = 0; j < size_t(s.count); j++) {
            size_t row = size_t(read_comp(ip + j * is, s.indices.componentType, false));
            for (size_t k = 0; k < nc; k++)
                out[row * nc + k] = read_comp(vp + j * es + k * cs, a.componentType, a.normalized);
        }
    }
    return out;
}

/* Data-level problems the validator reports as errors but that cannot make reading unsafe:
 * warn, and let the geometry code deal with what it uses. */
void check_accessor_data(Ctx &c, int i)
{
    const auto &a = c.m.accessors[size_t(i)];
    size_t nc = num_comps(a);
    if (nc > 4 || (a.bufferView < 0 && !a.sparse.isSparse))
        return;
    std::vector<double> d = read_accessor(c, i);
    std::string what = label("accessor", i, a.name);
    for (size_t j = 0; j < d.size(); j++) {
        double v = d[j];
        if (!std::isfinite(v)) {
            warn(c, "%s: element %zu is not finite", what.c_str(), j / nc);
            return;
        }
        /* Declared bounds are decimal JSON numbers, the data float: allow the rounding. */
        double lo = a.minValues.empty() ? v : a.minValues[j % nc];
        double hi = a.maxValues.empty() ? v : a.maxValues[j % nc];
        double tol = 1e-6 * std::fmax(1.0, std::fmax(std::fabs(lo), std::fabs(hi)));
        if (v < lo - tol || v > hi + tol) {
            warn(c, "%s: element %zu (%g) lies outside its declared min/max [%g, %g]", what.c_str(), j / nc, v, lo, hi);
            return;
        }
    }
}

/* Component formats of an attribute accessor, as bits. */
enum : unsigned { F_F = 1, F_I8 = 2, F_I8N = 4, F_U8 = 8, F_U8N = 16, F_I16 = 32, F_I16N = 64, F_U16 = 128, F_U16N = 256 };
const unsigned F_QUANT_ANY = F_F | F_I8 | F_I8N | F_U8 | F_U8N | F_I16 | F_I16N | F_U16 | F_U16N;

struct Format {
    const char *semantic; /* name, or prefix when it ends in '_' */
    int type, alt_type;   /* allowed accessor types */
    unsigned core, quant; /* allowed component formats: glTF 2.0; with KHR_mesh_quantization */
};
/* Accessor formats allowed per attribute semantic: glTF 2.0, "Meshes", and those that
 * KHR_mesh_quantization adds (its README's table; the integer values of a non-normalized
 * POSITION or TEXCOORD are used as they are, the node's transform scaling them). */
const Format FORMATS[] = {
    {"POSITION", TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC3, F_F, F_QUANT_ANY},
    {"NORMAL", TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC3, F_F, F_F | F_I8N | F_I16N},
    {"TANGENT", TINYGLTF_TYPE_VEC4, TINYGLTF_TYPE_VEC4, F_F, F_F | F_I8N | F_I16N},
    {"TEXCOORD_", TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC2, F_F | F_U8N | F_U16N, F_QUANT_ANY},
    {"COLOR_", TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4, F_F | F_U8N | F_U16N, F_F | F_U8N | F_U16N},
    {"JOINTS_", TINYGLTF_TYPE_VEC4, TINYGLTF_TYPE_VEC4, F_U8 | F_U16, F_U8 | F_U16},
    {"WEIGHTS_", TINYGLTF_TYPE_VEC4, TINYGLTF_TYPE_VEC4, F_F | F_U8N | F_U16N, F_F | F_U8N | F_U16N},
};

unsigned format_bit(const tinygltf::Accessor &a)
{
    switch (a.componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return F_F;
    case TINYGLTF_COMPONENT_TYPE_BYTE: return a.normalized ? F_I8N : F_I8;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return a.normalized ? F_U8N : F_U8;
    case TINYGLTF_COMPONENT_TYPE_SHORT: return a.normalized ? F_I16N : F_I16;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return a.normalized ? F_U16N : F_U16;
    default: return 0;
    }
}

bool uses_extension(const tinygltf::Model &m, const char *name)
{
    for (const auto &e : m.extensionsUsed)
        if (e == name)
            return true;
    for (const auto &e : m.extensionsRequired)
        if (e == name)
            return true;
    return false;
}

bool check_primitive(Ctx &c, int mi, int pi)
{
    const auto &m = c.m;
    const auto &p = m.meshes[size_t(mi)].primitives[size_t(pi)];
    std::string what = label("mesh", mi, m.meshes[size_t(mi)].name) + " primitive " + std::to_string(pi);
    if (p.mode < 0 || p.mode > TINYGLTF_MODE_TRIANGLE_FAN)
        return fail(c, "%s: invalid mode %d", what.c_str(), p.mode);
    if (p.material != -1 && !in_range(p.material, m.materials.size()))
        return fail(c, "%s refers to material %d, which does not exist", what.c_str(), p.material);
    if (p.indices != -1) {
        if (!in_range(p.indices, m.accessors.size()))
            return fail(c, "%s: indices refer to accessor %d, which does not exist", what.c_str(), p.indices);
        const auto &a = m.accessors[size_t(p.indices)];
        if (a.type != TINYGLTF_TYPE_SCALAR || a.normalized || a.bufferView < 0 ||
            (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
             a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
             a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT))
            return fail(c, "%s: indices accessor %d must be unsigned byte/short/int scalars in a buffer view",
                        what.c_str(), p.indices);
    }
    size_t count = 0;
    for (const auto &attr : p.attributes) {
        const char *name = attr.first.c_str();
        if (!in_range(attr.second, m.accessors.size()))
            return fail(c, "%s: attribute %s refers to accessor %d, which does not exist", what.c_str(), name, attr.second);
        const auto &a = m.accessors[size_t(attr.second)];
        if (count && a.count != count)
            return fail(c, "%s: attribute %s has %zu elements, others %zu (all must have the same count)",
                        what.c_str(), name, a.count, count);
        count = a.count;
        bool quant = uses_extension(m, "KHR_mesh_quantization");
        for (const Format &f : FORMATS) {
            size_t n = strlen(f.semantic);
            bool prefix = f.semantic[n - 1] == '_';
            if ((prefix ? strncmp(name, f.semantic, n) : strcmp(name, f.semantic)) != 0)
                continue;
            unsigned bit = format_bit(a);
            if ((a.type != f.type && a.type != f.alt_type) || !(bit & (quant ? f.quant : f.core)))
                return fail(c, "%s: accessor %d has a format not allowed for attribute %s%s", what.c_str(), attr.second,
                            name, !quant && (bit & f.quant) ? " (it needs KHR_mesh_quantization in extensionsUsed)" : "");
        }
    }
    return true;
}

bool check_number_array(Ctx &c, const std::vector<double> &v, size_t n, const std::string &what, const char *name)
{
    if (v.empty())
        return true;
    if (v.size() != n)
        return fail(c, "%s: %s must have %zu numbers (has %zu)", what.c_str(), name, n, v.size());
    for (double x : v)
        if (!std::isfinite(x))
            return fail(c, "%s: %s is not finite", what.c_str(), name);
    return true;
}

Mat mat_mul(const Mat &a, const Mat &b)
{
    Mat r;
    for (int col = 0; col < 4; col++)
        for (int row = 0; row < 4; row++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += a[size_t(k * 4 + row)] * b[size_t(col * 4 + k)];
            r[size_t(col * 4 + row)] = s;
        }
    return r;
}

bool mat_finite(const Mat &m)
{
    for (double x : m)
        if (!std::isfinite(x))
            return false;
    return true;
}

/* ---- animation: the channels sampled at one time (glTF 2.0, 3.11 and Appendix C) ------ */

double anim_time = -1; /* scene_animation_time; < 0: the nodes' own transforms */

/* A node's animated properties at anim_time: which of T, R, S a channel set. */
struct Pose {
    bool has[3] = {false, false, false};
    double v[3][4] = {{0, 0, 0, 0}, {0, 0, 0, 1}, {1, 1, 1, 0}}; /* translation, rotation, scale */
};

/* Sampler `sm` of animation `a` at time t into out (n components): before the first key
 * its value, after the last the last's; STEP the value of the key at or before t; LINEAR
 * lerp, or for rotations (quat) slerp along the shorter arc; CUBICSPLINE the Hermite
 * spline of the keys' values and in/out tangents scaled by the key interval. False (a
 * warning) when the sampler's accessors do not fit. */
bool sample_channel(Ctx &c, const tinygltf::Animation &a, int sm, double t, size_t n, bool quat, double *out)
{
    const auto &smp = a.samplers[size_t(sm)];
    if (!in_range(smp.input, c.m.accessors.size()) || !in_range(smp.output, c.m.accessors.size()))
        return fail(c, "animation '%s': sampler %d's accessors do not exist", a.name.c_str(), sm);
    std::vector<double> times = read_accessor(c, smp.input), vals = read_accessor(c, smp.output);
    bool cubic = smp.interpolation == "CUBICSPLINE", step = smp.interpolation == "STEP";
    size_t keys = times.size(), per = cubic ? 3 : 1;
    if (keys == 0 || num_comps(c.m.accessors[size_t(smp.input)]) != 1 || vals.size() != keys * per * n)
        return fail(c, "animation '%s': sampler %d has %zu key times and %zu output values (%zu needed)",
                    a.name.c_str(), sm, keys, vals.size(), keys * per * n);
    auto value = [&](size_t k, size_t part, size_t j) { return vals[(k * per + part) * n + j]; };
    size_t k = 0; /* the last key at or before t */
    while (k + 1 < keys && times[k + 1] <= t)
        k++;
    if (t <= times[0] || k + 1 == keys || step) {
        size_t key = t <= times[0] ? 0 : k;
        for (size_t j = 0; j < n; j++)
            out[j] = value(key, cubic ? 1 : 0, j);
    } else {
        double td = times[k + 1] - times[k], u = (t - times[k]) / td;
        if (cubic) {
            double u2 = u * u, u3 = u2 * u;
            for (size_t j = 0; j < n; j++)
                out[j] = (2 * u3 - 3 * u2 + 1) * value(k, 1, j) + td * (u3 - 2 * u2 + u) * value(k, 2, j) +
                         (-2 * u3 + 3 * u2) * value(k + 1, 1, j) + td * (u3 - u2) * value(k + 1, 0, j);
        } else if (quat) {
            double q0[4], q1[4], d = 0;
            for (size_t j = 0; j < 4; j++) {
                q0[j] = value(k, 0, j);
                q1[j] = value(k + 1, 0, j);
                d += q0[j] * q1[j];
            }
            double sign = d < 0 ? -1 : 1, w0 = 1 - u, w1 = u;
            d = std::fabs(d);
            if (d < 1 - 1e-9) { /* slerp; nearly equal quaternions lerp */
                double th = std::acos(std::min(d, 1.0)), st = std::sin(th);
                w0 = std::sin((1 - u) * th) / st;
                w1 = std::sin(u * th) / st;
            }
            for (size_t j = 0; j < 4; j++)
                out[j] = w0 * q0[j] + w1 * sign * q1[j];
        } else {
            for (size_t j = 0; j < n; j++)
                out[j] = (1 - u) * value(k, 0, j) + u * value(k + 1, 0, j);
        }
    }
    if (quat) {
        double len = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
        if (!(len > 1e-12))
            return fail(c, "animation '%s': sampler %d gives a zero rotation", a.name.c_str(), sm);
        for (size_t j = 0; j < 4; j++)
            out[j] /= len;
    }
    return true;
}

/* The animation samplers as the glTF spec requires them, whether or not a render samples
 * them: key times float scalars, finite and strictly increasing; output values of the
 * formats the channel's path allows (rotations and weights float or normalized integers;
 * translations and scales float, or any integer type with KHR_mesh_quantization), with
 * the number of values the keys need. Errors name the JSON path and the value. */
bool check_animations(Ctx &c)
{
    const bool quant = uses_extension(c.m, "KHR_mesh_quantization");
    for (size_t ai = 0; ai < c.m.animations.size(); ai++) {
        const auto &a = c.m.animations[ai];
        const std::string pa = "animations[" + std::to_string(ai) + "]";
        for (size_t si = 0; si < a.samplers.size(); si++) {
            const auto &s = a.samplers[si];
            const std::string ps = pa + ".samplers[" + std::to_string(si) + "]";
            if (!in_range(s.input, c.m.accessors.size()) || !in_range(s.output, c.m.accessors.size()))
                return fail(c, "%s: its accessors do not exist", ps.c_str());
            const auto &in = c.m.accessors[size_t(s.input)];
            if (in.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || in.type != TINYGLTF_TYPE_SCALAR)
                return fail(c, "%s.input: accessor %d is not float scalars (key times in seconds)", ps.c_str(), s.input);
            std::vector<double> t = read_accessor(c, s.input);
            for (size_t k = 0; k < t.size(); k++)
                if (!std::isfinite(t[k]) || t[k] < 0 || (k && !(t[k] > t[k - 1])))
                    return fail(c, "%s.input: key %zu at %.9g s %s", ps.c_str(), k, t[k],
                                !std::isfinite(t[k]) || t[k] < 0 ? "is not a time >= 0"
                                : "is not after the key before it: key times must increase strictly");
        }
        for (size_t ci = 0; ci < a.channels.size(); ci++) {
            const auto &ch = a.channels[ci];
            const std::string pc = pa + ".channels[" + std::to_string(ci) + "]";
            if (!in_range(ch.sampler, a.samplers.size()))
                return fail(c, "%s.sampler: %d does not exist", pc.c_str(), ch.sampler);
            const auto &s = a.samplers[size_t(ch.sampler)];
            const auto &out = c.m.accessors[size_t(s.output)];
            const bool rot = ch.target_path == "rotation", w = ch.target_path == "weights";
            const unsigned bit = format_bit(out);
            const unsigned normalized = F_I8N | F_U8N | F_I16N | F_U16N;
            const unsigned allowed = rot || w ? F_F | normalized : quant ? F_QUANT_ANY : F_F;
            const int type = rot ? TINYGLTF_TYPE_VEC4 : w ? TINYGLTF_TYPE_SCALAR : TINYGLTF_TYPE_VEC3;
            if (!(bit & allowed) || out.type != type)
                return fail(c, "animations[%zu].samplers[%d].output: accessor %d (component type %d%s, %s) is not "
                            "allowed for '%s' (%s)", ai, ch.sampler, s.output, out.componentType,
                            out.normalized ? " normalized" : "", type_name(out.type), ch.target_path.c_str(),
                            rot || w ? "float, or normalized byte or short"
                            : quant ? "float or integer VEC3" : "float VEC3 (integers need KHR_mesh_quantization)");
        }
    }
    return true;
}

/* Every animation's channels sampled at anim_time (all animations play together), per node. */
bool animate(Ctx &c, std::vector<Pose> &pose)
{
    bool warned_weights = false;
    for (const auto &a : c.m.animations)
        for (const auto &ch : a.channels) {
            const int path = ch.target_path == "translation" ? 0 : ch.target_path == "rotation" ? 1
                           : ch.target_path == "scale" ? 2 : -1;
            if (!in_range(ch.target_node, pose.size()) || !in_range(ch.sampler, a.samplers.size()))
                return fail(c, "animation '%s': a channel targets node %d, sampler %d, which do not exist",
                            a.name.c_str(), ch.target_node, ch.sampler);
            if (path < 0) {
                if (!warned_weights)
                    warn(c, "animation '%s': '%s' channels are not animated (morph targets are not supported)",
                         a.name.c_str(), ch.target_path.c_str());
                warned_weights = true;
                continue;
            }
            Pose &p = pose[size_t(ch.target_node)];
            if (!sample_channel(c, a, ch.sampler, anim_time, path == 1 ? 4 : 3, path == 1, p.v[path]))
                return false;
            p.has[path] = true;
        }
    return true;
}

bool node_local(Ctx &c, int i, Mat &out, const Pose *pose = nullptr)
{
    const auto &n = c.m.nodes[size_t(i)];
    std::string what = label("node", i, n.name);
    if (!check_number_array(c, n.matrix, 16, what, "matrix") || !check_number_array(c, n.translation, 3, what, "translation") ||
        !check_number_array(c, n.rotation, 4, what, "rotation") || !check_number_array(c, n.scale, 3, what, "scale"))
        return false;
    if (!n.matrix.empty()) {
        std::copy(n.matrix.begin(), n.matrix.end(), out.begin());
        return true;
    }
    double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    std::copy(n.translation.begin(), n.translation.end(), t);
    std::copy(n.rotation.begin(), n.rotation.end(), q);
    std::copy(n.scale.begin(), n.scale.end(), s);
    if (pose) { /* animated properties replace the node's */
        if (pose->has[0])
            std::copy(pose->v[0], pose->v[0] + 3, t);
        if (pose->has[1])
            std::copy(pose->v[1], pose->v[1] + 4, q);
        if (pose->has[2])
            std::copy(pose->v[2], pose->v[2] + 3, s);
    }
    double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(len > 1e-6) || !std::isfinite(len))
        return fail(c, "%s: rotation is not a unit quaternion (length %g)", what.c_str(), len);
    if (std::fabs(len - 1) > 1e-3)
        warn(c, "%s: rotation is not a unit quaternion (length %g, normalised)", what.c_str(), len);
    double x = q[0] / len, y = q[1] / len, z = q[2] / len, w = q[3] / len;
    const double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),
                         2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                         2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y)};
    out = Mat{};
    for (int col = 0; col < 3; col++)
        for (int row = 0; row < 3; row++)
            out[size_t(col * 4 + row)] = r[col * 3 + row] * s[col];
    out[12] = t[0];
    out[13] = t[1];
    out[14] = t[2];
    out[15] = 1;
    return true;
}

int node_light(const tinygltf::Node &n)
{
    auto it = n.extensions.find("KHR_lights_punctual");
    if (it == n.extensions.end() || !it->second.IsObject() || !it->second.Has("light"))
        return -1;
    const tinygltf::Value &v = it->second.Get("light");
    return v.IsInt() ? v.Get<int>() : -2;
}

bool check_nodes_and_scenes(Ctx &c)
{
    const auto &m = c.m;
    size_t nn = m.nodes.size();
    std::vector<int> parent(nn, -1);
    std::vector<Pose> pose(nn);
    c.local.assign(nn, Mat{});
    if (anim_time >= 0 && !animate(c, pose))
        return false;
    for (size_t i = 0; i < nn; i++) {
        const auto &n = m.nodes[i];
        std::string what = label("node", int(i), n.name);
        bool animated = pose[i].has[0] || pose[i].has[1] || pose[i].has[2];
        if (animated && !n.matrix.empty())
            warn(c, "%s has a matrix and is animated: the matrix wins (glTF forbids the two)", what.c_str());
        node_local(c, int(i), c.local[i], animated ? &pose[i] : nullptr);
        if (n.mesh != -1 && !in_range(n.mesh, m.meshes.size()))
            fail(c, "%s refers to mesh %d, which does not exist", what.c_str(), n.mesh);
        if (n.camera != -1 && !in_range(n.camera, m.cameras.size()))
            fail(c, "%s refers to camera %d, which does not exist", what.c_str(), n.camera);
        if (n.skin != -1 && !in_range(n.skin, m.skins.size()))
            fail(c, "%s refers to skin %d, which does not exist", what.c_str(), n.skin);
        int light = node_light(n);
        if (light != -1 && !in_range(light, m.lights.size()))
            fail(c, "%s refers to KHR_lights_punctual light %d, which does not exist", what.c_str(), light);
        for (int ch : n.children) {
            if (!in_range(ch, nn))
                fail(c, "%s has child %d, which does not exist", what.c_str(), ch);
            else if (parent[size_t(ch)] != -1)
                fail(c, "node %d has more than one parent (nodes %d and %zu)", ch, parent[size_t(ch)], i);
            else
                parent[size_t(ch)] = int(i);
        }
    }
    if (c.failed)
        return false;
    /* With one parent each, the nodes not reachable from a parentless node are exactly those
     * in loops or below one; walking up from such a node for nn steps lands inside the loop. */
    std::vector<bool> reached(nn, false);
    std::vector<int> stack;
    for (size_t i = 0; i < nn; i++)
        if (parent[i] == -1)
            stack.push_back(int(i));
    while (!stack.empty()) {
        int i = stack.back();
        stack.pop_back();
        reached[size_t(i)] = true;
        for (int ch : m.nodes[size_t(i)].children)
            stack.push_back(ch);
    }
    for (size_t i = 0; i < nn; i++)
        if (!reached[i]) {
            int k = int(i);
            for (size_t step = 0; step < nn; step++)
                k = parent[size_t(k)];
            return fail(c, "node %d is part of a node loop", k);
        }
    if (m.defaultScene != -1 && !in_range(m.defaultScene, m.scenes.size()))
        return fail(c, "default scene %d does not exist", m.defaultScene);
    if (c.scene_index >= 0 && !in_range(c.scene_index, m.scenes.size()))
        return fail(c, "--scene %d: the file has %zu scene(s)", c.scene_index, m.scenes.size());
    for (size_t s = 0; s < m.scenes.size(); s++)
        for (int r : m.scenes[s].nodes)
            if (!in_range(r, nn))
                fail(c, "scene %zu refers to node %d, which does not exist", s, r);
    return !c.failed;
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

/* Cameras and lights with bad values are skipped with a warning: the rest of the scene is fine. */
void check_cameras(Ctx &c)
{
    c.camera_ok.assign(c.m.cameras.size(), false);
    for (size_t i = 0; i < c.m.cameras.size(); i++) {
        const auto &cam = c.m.cameras[i];
        std::string what = label("camera", int(i), cam.name);
        if (cam.type == "orthographic") {
            const auto &o = cam.orthographic;
            if (!(std::isfinite(o.xmag) && std::isfinite(o.ymag) && o.xmag != 0 && o.ymag != 0))
                warn(c, "%s: xmag %g and ymag %g must be finite and non-zero; skipped", what.c_str(), o.xmag, o.ymag);
            else if (!(o.znear >= 0))
                warn(c, "%s: znear %g must not be negative; skipped", what.c_str(), o.znear);
            else if (!(o.zfar > o.znear) || !std::isfinite(o.zfar))
                warn(c, "%s: zfar %g must be finite and greater than znear %g; skipped", what.c_str(), o.zfar, o.znear);
            else
                c.camera_ok[i] = true;
            continue;
        }
        if (cam.type != "perspective") {
            warn(c, "%s: unknown type '%s'; skipped", what.c_str(), cam.type.substr(0, 32).c_str());
            continue;
        }
        const auto &p = cam.perspective;
        if (!(p.yfov > 0 && p.yfov < M_PI))
            warn(c, "%s: yfov %g is out of range (0, pi); skipped", what.c_str(), p.yfov);
        else if (!(p.znear > 0))
            warn(c, "%s: znear %g must be positive; skipped", what.c_str(), p.znear);
        else if (p.zfar != 0 && !(p.zfar > p.znear))
            warn(c, "%s: zfar %g must be greater than znear %g; skipped", what.c_str(), p.zfar, p.znear);
        else if (p.aspectRatio < 0)
            warn(c, "%s: aspectRatio %g must be positive; skipped", what.c_str(), p.aspectRatio);
        else
            c.camera_ok[i] = true;
    }
}

void check_lights(Ctx &c)
{
    c.light_ok.assign(c.m.lights.size(), false);
    for (size_t i = 0; i < c.m.lights.size(); i++) {
        const auto &l = c.m.lights[i];
        std::string what = label("KHR_lights_punctual light", int(i), l.name);
        bool neg_color = l.color.size() == 3 && (l.color[0] < 0 || l.color[1] < 0 || l.color[2] < 0);
        if (l.type != "point" && l.type != "spot" && l.type != "directional")
            warn(c, "%s: unknown type '%s'; skipped", what.c_str(), l.type.c_str());
        else if (!l.color.empty() && (l.color.size() != 3 || neg_color))
            warn(c, "%s: color must be 3 non-negative numbers; skipped", what.c_str());
        else if (!(l.intensity >= 0))
            warn(c, "%s: intensity %g must not be negative; skipped", what.c_str(), l.intensity);
        else if (l.type == "spot" && !(l.spot.innerConeAngle >= 0 && l.spot.innerConeAngle < l.spot.outerConeAngle &&
                                       l.spot.outerConeAngle <= M_PI / 2))
            warn(c, "%s: cone angles inner %g, outer %g must satisfy 0 <= inner < outer <= pi/2; skipped",
                 what.c_str(), l.spot.innerConeAngle, l.spot.outerConeAngle);
        else
            c.light_ok[i] = true;
        if (l.range < 0)
            warn(c, "%s: negative range %g ignored (infinite)", what.c_str(), l.range);
    }
}

bool check_asset(Ctx &c)
{
    const auto &m = c.m;
    const std::string &v = m.asset.version;
    if (v.compare(0, 2, "2.") != 0)
        return fail(c, "unsupported glTF version '%s' (gonio reads 2.x)", v.c_str());
    if (v != "2.0")
        warn(c, "glTF version %s is newer than 2.0; read as 2.0", v.c_str());
    if (!m.asset.minVersion.empty() && m.asset.minVersion != "2.0")
        return fail(c, "requires glTF %s (gonio reads 2.0)", m.asset.minVersion.c_str());
    auto supported = [](const std::string &e) {
        for (const char *s : SUPPORTED_EXTENSIONS)
            if (e == s)
                return true;
        return e == "KHR_texture_basisu" && image_decode_has_ktx2();
    };
    for (const auto &e : m.extensionsRequired)
        if (e == "KHR_texture_basisu" && !supported(e))
            fail(c, "requires unsupported extension %s (this gonio was built without Basis Universal: %s)", e.c_str(),
                 image_decode_ktx2_missing());
        else if (!supported(e))
            fail(c, "requires unsupported extension %s", e.c_str());
    std::vector<std::string> warned; /* one warning each, however often the file lists it */
    for (const auto &e : m.extensionsUsed)
        if (!supported(e) && std::find(warned.begin(), warned.end(), e) == warned.end()) {
            warn(c, "uses unsupported extension %s (ignored)", e.c_str());
            warned.push_back(e);
        }
    return !c.failed;
}

/* Compressed views and primitives become plain ones before anything is checked or read. */
bool decompress(Ctx &c)
{
    std::vector<std::string> errors;
    if (gltf_decompress(c.m, MAX_ELEMENTS, &errors))
        return true;
    for (const auto &e : errors)
        fail(c, "%s", e.c_str());
    return false;
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

/* ---- geometry ------------------------------------------------------------------------------- */

std::vector<float> to_float(const std::vector<double> &d)
{
    return std::vector<float>(d.begin(), d.end());
}

bool all_finite(const std::vector<double> &d)
{
    for (double x : d)
        if (!std::isfinite(x))
            return false;
    return true;
}

void read_normals(Ctx &c, const std::string &what, int acc, Prim &out)
{
    std::vector<double> d = read_accessor(c, acc);
    bool off_unit = false;
    for (size_t j = 0; j < d.size(); j += 3) {
        double len = std::sqrt(d[j] * d[j] + d[j + 1] * d[j + 1] + d[j + 2] * d[j + 2]);
        if (!(len > 1e-20) || !std::isfinite(len)) {
            warn(c, "%s: normal %zu is zero or not finite; using flat normals", what.c_str(), j / 3);
            return;
        }
        off_unit |= std::fabs(len - 1) > 1e-2;
        for (int k = 0; k < 3; k++)
            d[j + size_t(k)] /= len;
    }
    if (off_unit)
        warn(c, "%s: normals are not unit length (renormalised)", what.c_str());
    out.nrm = to_float(d);
}

const tinygltf::Value *extension(const tinygltf::Material &mat, const char *name)
{
    auto it = mat.extensions.find(name);
    return it == mat.extensions.end() ? nullptr : &it->second;
}

/* A textureInfo of a material extension (e may be null) as tinygltf's own TextureInfo, so
 * texture_slot reads both alike; index -1 when absent. Doc::check_material has checked its
 * form (an index of an existing texture, texCoord an integer). */
tinygltf::TextureInfo ext_texture(const tinygltf::Value *e, const char *key, double *scale = nullptr)
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

void read_tangents(Ctx &c, const std::string &what, int acc, Prim &out)
{
    std::vector<double> d = read_accessor(c, acc);
    bool bad_w = false;
    for (size_t j = 0; j < d.size(); j += 4) {
        double len = std::sqrt(d[j] * d[j] + d[j + 1] * d[j + 1] + d[j + 2] * d[j + 2]);
        if (!(len > 1e-20) || !std::isfinite(len) || !std::isfinite(d[j + 3])) {
            warn(c, "%s: tangent %zu is zero or not finite; tangents ignored", what.c_str(), j / 4);
            return;
        }
        for (int k = 0; k < 3; k++)
            d[j + size_t(k)] /= len;
        bad_w |= std::fabs(d[j + 3]) != 1;
        d[j + 3] = d[j + 3] < 0 ? -1 : 1;
    }
    if (bad_w)
        warn(c, "%s: tangent w must be 1 or -1 (replaced by its sign)", what.c_str());
    out.tan = to_float(d);
}

/* COLOR_0 (glTF 2.0, "Meshes"): linear RGB or RGBA, float or normalised integers, which
 * multiplies the base colour. RGB gets alpha 1; values outside [0, 1] are clamped, with a
 * warning, and non-finite ones make the attribute ignored. */
void read_colors(Ctx &c, const std::string &what, int acc, Prim &out)
{
    const auto &a = c.m.accessors[size_t(acc)];
    size_t nc = num_comps(a), nv = out.pos.size() / 3;
    if (a.count != nv) {
        warn(c, "%s: COLOR_0 has %zu elements for %zu vertices (ignored)", what.c_str(), size_t(a.count), nv);
        return;
    }
    std::vector<double> d = read_accessor(c, acc);
    if (!all_finite(d)) {
        warn(c, "%s: COLOR_0 has non-finite values (ignored)", what.c_str());
        return;
    }
    bool clamped = false;
    out.col.resize(nv * 4);
    for (size_t v = 0; v < nv; v++)
        for (size_t k = 0; k < 4; k++) {
            double x = k < nc ? d[v * nc + k] : 1.0;
            clamped = clamped || x < 0 || x > 1;
            out.col[v * 4 + k] = float(std::fmin(std::fmax(x, 0.0), 1.0));
        }
    if (clamped)
        warn(c, "%s: COLOR_0 values outside [0, 1] were clamped", what.c_str());
}

/* glTF 2.0, "Meshes": without NORMAL, flat normals are used, so every triangle gets its own
 * three vertices. */
void make_flat(Prim &p)
{
    Prim f;
    f.material = p.material;
    size_t nt = p.idx.size() / 3;
    f.pos.resize(nt * 9);
    f.nrm.resize(nt * 9);
    if (!p.uv.empty())
        f.uv.resize(nt * 6);
    if (!p.uv1.empty())
        f.uv1.resize(nt * 6);
    if (!p.col.empty())
        f.col.resize(nt * 12);
    f.idx.resize(nt * 3);
    for (size_t t = 0; t < nt; t++) {
        for (size_t k = 0; k < 3; k++) {
            size_t v = p.idx[t * 3 + k], o = t * 3 + k;
            std::copy(&p.pos[v * 3], &p.pos[v * 3] + 3, &f.pos[o * 3]);
            if (!p.uv.empty())
                std::copy(&p.uv[v * 2], &p.uv[v * 2] + 2, &f.uv[o * 2]);
            if (!p.uv1.empty())
                std::copy(&p.uv1[v * 2], &p.uv1[v * 2] + 2, &f.uv1[o * 2]);
            if (!p.col.empty())
                std::copy(&p.col[v * 4], &p.col[v * 4] + 4, &f.col[o * 4]);
            f.idx[o] = uint32_t(o);
        }
        const float *a = &f.pos[t * 9], *b = a + 3, *cc = a + 6;
        double e1[3], e2[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = double(b[k]) - a[k];
            e2[k] = double(cc[k]) - a[k];
        }
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(len > 0) || !std::isfinite(len)) { /* degenerate: never hit, any unit normal */
            n[0] = n[1] = 0;
            n[2] = len = 1;
        }
        for (size_t k = 0; k < 3; k++)
            for (size_t j = 0; j < 3; j++)
                f.nrm[t * 9 + k * 3 + j] = float(n[j] / len);
    }
    p = std::move(f);
}

/* glTF 2.0, "Meshes": a normal texture without TANGENT takes MikkTSpace tangents
 * (src/scene/tangent.c), which split vertices where handedness or smoothing groups differ. */
void generate_tangents(Prim &p, const std::vector<float> &uv)
{
    uint32_t *remap;
    float *tan;
    size_t n = tangent_generate(p.pos.size() / 3, p.pos.data(), p.nrm.data(), uv.data(), p.idx.size() / 3,
                                p.idx.data(), &remap, &tan);
    auto expand = [&](std::vector<float> &a, size_t k) {
        if (a.empty())
            return;
        std::vector<float> b(n * k);
        for (size_t v = 0; v < n; v++)
            std::copy(&a[remap[v] * k], &a[remap[v] * k] + k, &b[v * k]);
        a = std::move(b);
    };
    expand(p.pos, 3);
    expand(p.nrm, 3);
    expand(p.uv, 2);
    expand(p.uv1, 2);
    expand(p.col, 4);
    p.tan.assign(tan, tan + n * 4);
    free(remap);
    free(tan);
}

const char *mode_name(int mode)
{
    static const char *const names[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
    return names[mode];
}

/* Reads one primitive into `out`; false when it is skipped (with a warning) or bad (error). */
bool load_primitive(Ctx &c, int mi, int pi, Prim &out)
{
    const auto &p = c.m.meshes[size_t(mi)].primitives[size_t(pi)];
    std::string what = label("mesh", mi, c.m.meshes[size_t(mi)].name) + " primitive " + std::to_string(pi);
    if (p.mode < TINYGLTF_MODE_TRIANGLES) {
        warn(c, "%s: mode %s is not supported (skipped)", what.c_str(), mode_name(p.mode));
        return false;
    }
    auto attr = [&](const char *name) {
        auto it = p.attributes.find(name);
        return it == p.attributes.end() ? -1 : it->second;
    };
    int pos = attr("POSITION"), nrm = attr("NORMAL"), tan = attr("TANGENT"), uv = attr("TEXCOORD_0");
    int col = attr("COLOR_0"), uv1 = attr("TEXCOORD_1");
    if (pos < 0) {
        warn(c, "%s has no POSITION (skipped)", what.c_str());
        return false;
    }
    if (!p.targets.empty() && !c.warned_targets) {
        warn(c, "morph targets are not supported (meshes drawn with their base shapes)");
        c.warned_targets = true;
    }
    size_t nv = c.m.accessors[size_t(pos)].count;
    std::vector<uint32_t> seq;
    if (p.indices >= 0) {
        const auto &a = c.m.accessors[size_t(p.indices)];
        double restart = a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? 255.0
                         : a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 65535.0
                                                                                      : 4294967295.0;
        std::vector<double> d = read_accessor(c, p.indices);
        seq.resize(d.size());
        for (size_t j = 0; j < d.size(); j++) {
            if (d[j] == restart)
                return fail(c, "%s: index %zu is the primitive restart value %.0f, which glTF forbids", what.c_str(), j, restart);
            if (d[j] >= double(nv))
                return fail(c, "%s: index %zu is %.0f but there are only %zu vertices", what.c_str(), j, d[j], nv);
            seq[j] = uint32_t(d[j]);
        }
    } else {
        seq.resize(nv);
        for (size_t j = 0; j < nv; j++)
            seq[j] = uint32_t(j);
    }
    size_t n = seq.size();
    if (p.mode == TINYGLTF_MODE_TRIANGLES) {
        if (n % 3)
            warn(c, "%s: %zu indices is not a multiple of 3 (last %zu ignored)", what.c_str(), n, n % 3);
        out.idx.assign(seq.begin(), seq.begin() + long(n - n % 3));
    } else {
        /* Strips and fans as the glTF 2.0 spec lists their triangles ("Meshes"). */
        for (size_t i = 0; i + 2 < n; i++) {
            uint32_t t[3];
            if (p.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                t[0] = seq[i];
                t[1] = seq[i + 1 + i % 2];
                t[2] = seq[i + 2 - i % 2];
            } else {
                t[0] = seq[i + 1];
                t[1] = seq[i + 2];
                t[2] = seq[0];
            }
            out.idx.insert(out.idx.end(), t, t + 3);
        }
    }
    out.pos = to_float(read_accessor(c, pos));
    out.material = p.material >= 0 ? uint32_t(p.material) : GN_INVALID;
    if (nrm >= 0)
        read_normals(c, what, nrm, out);
    if (tan >= 0 && nrm < 0)
        warn(c, "%s: TANGENT without NORMAL is ignored", what.c_str());
    else if (tan >= 0 && !out.nrm.empty())
        read_tangents(c, what, tan, out);
    for (int set = 0; set < 2; set++) {
        int acc = set ? uv1 : uv;
        if (acc < 0)
            continue;
        std::vector<double> d = read_accessor(c, acc);
        if (all_finite(d))
            (set ? out.uv1 : out.uv) = to_float(d);
        else
            warn(c, "%s: TEXCOORD_%d has non-finite values (ignored)", what.c_str(), set);
    }
    if (col >= 0)
        read_colors(c, what, col, out);
    if (out.nrm.empty())
        make_flat(out);
    const tinygltf::Material *mat = p.material >= 0 && size_t(p.material) < c.m.materials.size()
                                        ? &c.m.materials[size_t(p.material)] : nullptr;
    /* the tangents follow the set the normal texture reads (KHR_texture_transform's texCoord
     * overrides the reference's) */
    int nset = mat ? mat->normalTexture.texCoord : 0;
    if (mat) {
        auto xf = mat->normalTexture.extensions.find("KHR_texture_transform");
        if (xf != mat->normalTexture.extensions.end() && xf->second.IsObject() && xf->second.Has("texCoord") &&
            xf->second.Get("texCoord").IsInt())
            nset = xf->second.Get("texCoord").GetNumberAsInt();
    }
    /* a clearcoat normal map needs them too (the set of the base's normal map, if any) */
    bool coat_normal = false;
    if (mat && mat->normalTexture.index < 0) {
        tinygltf::TextureInfo ct = ext_texture(extension(*mat, "KHR_materials_clearcoat"), "clearcoatNormalTexture");
        coat_normal = ct.index >= 0;
        nset = ct.texCoord;
    }
    /* so does anisotropy: its direction is in the tangent frame (the set of its texture when
     * no normal map chose one) */
    bool aniso = false;
    if (mat) {
        const tinygltf::Value *ae = extension(*mat, "KHR_materials_anisotropy");
        aniso = ae && ae->IsObject() && ae->Has("anisotropyStrength") && ae->Get("anisotropyStrength").IsNumber() &&
                ae->Get("anisotropyStrength").GetNumberAsDouble() > 0;
        if (aniso && mat->normalTexture.index < 0 && !coat_normal) {
            tinygltf::TextureInfo at = ext_texture(ae, "anisotropyTexture");
            nset = at.index >= 0 ? at.texCoord : 0;
        }
    }
    const std::vector<float> &tuv = nset == 1 ? out.uv1 : out.uv;
    if (out.tan.empty() && !tuv.empty() && mat && (mat->normalTexture.index >= 0 || coat_normal || aniso))
        generate_tangents(out, tuv);
    return true;
}

bool load_meshes(Ctx &c)
{
    uint64_t nv = 0, nt = 0; /* what the primitives will hold, counted before reading them */
    c.meshes.resize(c.m.meshes.size());
    for (size_t mi = 0; mi < c.m.meshes.size(); mi++)
        for (size_t pi = 0; pi < c.m.meshes[mi].primitives.size(); pi++) {
            const auto &prim = c.m.meshes[mi].primitives[pi];
            auto pos = prim.attributes.find("POSITION");
            uint64_t verts = pos != prim.attributes.end() && in_range(pos->second, c.m.accessors.size())
                                 ? c.m.accessors[size_t(pos->second)].count : 0;
            nv += verts;
            nt += (in_range(prim.indices, c.m.accessors.size()) ? c.m.accessors[size_t(prim.indices)].count : verts) / 3;
            if (nv > MAX_SCENE || nt > MAX_SCENE)
                return fail(c, "scene too large: its meshes hold over %llu triangles and %llu vertices; the limit "
                            "is %zu each", (unsigned long long)nt, (unsigned long long)nv, MAX_SCENE);
            Prim p;
            if (load_primitive(c, int(mi), int(pi), p))
                c.meshes[mi].push_back(std::move(p));
        }
    return !c.failed;
}

/* Walks the default scene (scene 0 without one; every parentless node without scenes). */
bool collect_instances(Ctx &c, std::vector<Instance> &inst, std::vector<Instance> &cams, std::vector<Instance> &lights)
{
    const auto &m = c.m;
    std::vector<int> roots;
    if (c.scene_index >= 0) {
        roots = m.scenes[size_t(c.scene_index)].nodes;
    } else if (!m.scenes.empty()) {
        roots = m.scenes[size_t(m.defaultScene >= 0 ? m.defaultScene : 0)].nodes;
    } else {
        std::vector<bool> child(m.nodes.size(), false);
        for (const auto &n : m.nodes)
            for (int ch : n.children)
                child[size_t(ch)] = true;
        for (size_t i = 0; i < m.nodes.size(); i++)
            if (!child[i])
                roots.push_back(int(i));
    }
    std::vector<bool> visited(m.nodes.size(), false);
    for (int r : roots) {
        std::vector<Instance> stack;
        Mat id{};
        id[0] = id[5] = id[10] = id[15] = 1;
        stack.push_back({r, -1, id});
        while (!stack.empty()) {
            Instance it = stack.back();
            stack.pop_back();
            const auto &n = m.nodes[size_t(it.node)];
            if (visited[size_t(it.node)]) {
                warn(c, "%s is reached more than once from the scene's roots (drawn once)", label("node", it.node, n.name).c_str());
                continue;
            }
            visited[size_t(it.node)] = true;
            it.world = mat_mul(it.world, c.local[size_t(it.node)]);
            if (!mat_finite(it.world))
                return fail(c, "%s: world transform is not finite", label("node", it.node, n.name).c_str());
            if (n.skin >= 0 && !c.warned_skin) {
                warn(c, "skins are not supported (skinned meshes drawn in their bind pose)");
                c.warned_skin = true;
            }
            if (n.mesh >= 0)
                inst.push_back({it.node, n.mesh, it.world});
            if (n.camera >= 0 && c.camera_ok[size_t(n.camera)])
                cams.push_back(it);
            int light = node_light(n);
            if (light >= 0 && c.light_ok[size_t(light)])
                lights.push_back(it);
            for (auto ch = n.children.rbegin(); ch != n.children.rend(); ++ch)
                stack.push_back({*ch, -1, it.world});
        }
    }
    return true; /* pre-order, children in file order (pushed reversed) */
}

void xform_dir(const Mat &m, const double v[3], double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = m[size_t(r)] * v[0] + m[size_t(4 + r)] * v[1] + m[size_t(8 + r)] * v[2];
}

bool normalize3(double v[3])
{
    double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(len > 1e-30) || !std::isfinite(len))
        return false;
    v[0] /= len;
    v[1] /= len;
    v[2] /= len;
    return true;
}

bool bake_geometry(Ctx &c, const std::vector<Instance> &inst, scene *out)
{
    uint64_t nv = 0, nt = 0, np = 0;
    for (const auto &in : inst)
        for (const Prim &p : c.meshes[size_t(in.mesh)]) {
            nv += p.pos.size() / 3;
            nt += p.idx.size() / 3;
            np++;
        }
    if (nv > MAX_SCENE || nt > MAX_SCENE)
        return fail(c, "scene too large: %llu triangles and %llu vertices after instancing; the limit is %zu each",
                    (unsigned long long)nt, (unsigned long long)nv, MAX_SCENE);
    out->num_vertices = uint32_t(nv);
    out->num_triangles = uint32_t(nt);
    out->num_meshes = uint32_t(np);
    out->vertices = static_cast<GnVertex *>(util_calloc(nv, sizeof(GnVertex)));
    out->indices = static_cast<uint32_t *>(util_calloc(nt * 3, sizeof(uint32_t)));
    out->tri_material = static_cast<uint32_t *>(util_calloc(nt, sizeof(uint32_t)));
    uint32_t vbase = 0, tbase = 0, default_material = uint32_t(c.m.materials.size());
    for (const auto &in : inst) {
        const Mat &w = in.world;
        /* Normals go through the cofactor matrix, det * inverse transpose: defined even for a
         * singular matrix; multiplied by sign(det) so mirroring keeps them pointing out. */
        double a[3][3];
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 3; k++)
                a[r][k] = w[size_t(k * 4 + r)];
        double cof[3][3];
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 3; k++) {
                int r1 = (r + 1) % 3, r2 = (r + 2) % 3, k1 = (k + 1) % 3, k2 = (k + 2) % 3;
                cof[r][k] = a[r1][k1] * a[r2][k2] - a[r1][k2] * a[r2][k1];
            }
        double det = a[0][0] * cof[0][0] + a[0][1] * cof[0][1] + a[0][2] * cof[0][2];
        double sgn = det < 0 ? -1 : 1;
        for (const Prim &p : c.meshes[size_t(in.mesh)]) {
            size_t pv = p.pos.size() / 3;
            for (size_t v = 0; v < pv; v++) {
                GnVertex &o = out->vertices[vbase + v];
                const float *q = &p.pos[v * 3];
                double x[3];
                for (int r = 0; r < 3; r++)
                    x[r] = a[r][0] * q[0] + a[r][1] * q[1] + a[r][2] * q[2] + w[size_t(12 + r)];
                o.position = vec3{float(x[0]), float(x[1]), float(x[2])};
                const float *nn = &p.nrm[v * 3];
                double n[3];
                for (int r = 0; r < 3; r++)
                    n[r] = sgn * (cof[r][0] * nn[0] + cof[r][1] * nn[1] + cof[r][2] * nn[2]);
                if (!normalize3(n)) { /* a scale that flattens the mesh to a line: never hit */
                    n[0] = n[1] = 0;
                    n[2] = 1;
                }
                o.normal = vec3{float(n[0]), float(n[1]), float(n[2])};
                if (!p.uv.empty()) {
                    o.u = p.uv[v * 2];
                    o.v = p.uv[v * 2 + 1];
                }
                if (!p.uv1.empty()) {
                    o.u1 = p.uv1[v * 2];
                    o.v1 = p.uv1[v * 2 + 1];
                }
                if (!p.col.empty()) {
                    o.color = vec4{p.col[v * 4], p.col[v * 4 + 1], p.col[v * 4 + 2], p.col[v * 4 + 3]};
                    out->vertex_colors = true;
                } else {
                    o.color = vec4{1, 1, 1, 1};
                }
                if (!p.tan.empty()) {
                    const double t0[3] = {p.tan[v * 4], p.tan[v * 4 + 1], p.tan[v * 4 + 2]};
                    double t[3];
                    xform_dir(w, t0, t);
                    if (normalize3(t))
                        o.tangent = vec4{float(t[0]), float(t[1]), float(t[2]), float(p.tan[v * 4 + 3] * sgn)};
                }
            }
            size_t pt = p.idx.size() / 3;
            for (size_t t = 0; t < pt; t++) {
                uint32_t *dst = &out->indices[(tbase + t) * 3];
                dst[0] = vbase + p.idx[t * 3];
                dst[1] = vbase + p.idx[t * 3 + (det < 0 ? 2 : 1)]; /* mirrored: keep front faces */
                dst[2] = vbase + p.idx[t * 3 + (det < 0 ? 1 : 2)];
                out->tri_material[tbase + t] = p.material == GN_INVALID ? default_material : p.material;
            }
            vbase += uint32_t(pv);
            tbase += uint32_t(pt);
        }
    }
    return true;
}

void bake_cameras(Ctx &c, const std::vector<Instance> &cams, scene *out)
{
    out->cameras = static_cast<scene_camera *>(util_calloc(cams.size(), sizeof(scene_camera)));
    for (const auto &in : cams) {
        const auto &n = c.m.nodes[size_t(in.node)];
        const auto &cam = c.m.cameras[size_t(n.camera)];
        const double fz[3] = {0, 0, -1}, uy[3] = {0, 1, 0};
        double f[3], u[3];
        xform_dir(in.world, fz, f);
        xform_dir(in.world, uy, u);
        bool ok = normalize3(f);
        double d = f[0] * u[0] + f[1] * u[1] + f[2] * u[2];
        for (int k = 0; k < 3; k++)
            u[k] -= d * f[k];
        if (!ok || !normalize3(u)) {
            warn(c, "camera on %s has a degenerate transform; skipped", label("node", in.node, n.name).c_str());
            continue;
        }
        scene_camera &o = out->cameras[out->num_cameras++];
        snprintf(o.name, sizeof o.name, "%s", cam.name.empty() ? ("camera " + std::to_string(n.camera)).c_str() : cam.name.c_str());
        const double r[3] = {f[1] * u[2] - f[2] * u[1], f[2] * u[0] - f[0] * u[2], f[0] * u[1] - f[1] * u[0]};
        for (int k = 0; k < 3; k++) {
            o.position[k] = float(in.world[size_t(12 + k)]);
            o.forward[k] = float(f[k]);
            o.up[k] = float(u[k]);
            o.right[k] = float(r[k]);
        }
        if (cam.type == "orthographic") {
            /* A negative magnification would mirror the image; glTF says it should not be. */
            const auto &om = cam.orthographic;
            o.ortho_half_height = float(std::fabs(om.ymag));
            o.aspect = float(std::fabs(om.xmag / om.ymag));
            o.znear = float(om.znear);
            o.zfar = float(om.zfar);
            continue;
        }
        o.yfov = float(cam.perspective.yfov);
        o.aspect = float(cam.perspective.aspectRatio);
        o.znear = float(cam.perspective.znear);
        o.zfar = float(cam.perspective.zfar);
    }
}

void bake_lights(Ctx &c, const std::vector<Instance> &lights, scene *out)
{
    out->lights = static_cast<GnLight *>(util_calloc(lights.size(), sizeof(GnLight)));
    for (const auto &in : lights) {
        const auto &n = c.m.nodes[size_t(in.node)];
        const auto &l = c.m.lights[size_t(node_light(n))];
        const double fz[3] = {0, 0, -1};
        double d[3];
        xform_dir(in.world, fz, d);
        if (!normalize3(d) && l.type != "point") {
            warn(c, "light on %s has a degenerate transform; skipped", label("node", in.node, n.name).c_str());
            continue;
        }
        if (!std::isfinite(d[0])) { /* a point light's direction is unused */
            d[0] = d[1] = 0;
            d[2] = -1;
        }
        GnLight &o = out->lights[out->num_lights++];
        o.type = l.type == "point" ? GN_LIGHT_POINT : l.type == "spot" ? GN_LIGHT_SPOT : GN_LIGHT_DIRECTIONAL;
        o.position = vec3{float(in.world[12]), float(in.world[13]), float(in.world[14])};
        o.direction = vec3{float(d[0]), float(d[1]), float(d[2])};
        double col[3] = {1, 1, 1};
        if (l.color.size() == 3)
            std::copy(l.color.begin(), l.color.end(), col);
        double intensity = l.intensity;
        if (intensity > MAX_RADIANCE) {
            warn(c, "%s: intensity %g is above %g (clamped)", label("KHR_lights_punctual light", node_light(c.m.nodes[size_t(in.node)]), l.name).c_str(),
                 intensity, MAX_RADIANCE);
            intensity = MAX_RADIANCE;
        }
        o.color = vec3{float(col[0] * intensity), float(col[1] * intensity), float(col[2] * intensity)};
        o.range = o.type == GN_LIGHT_DIRECTIONAL || l.range < 0 ? 0.0f : float(l.range);
        o.inner_cos = o.outer_cos = -1; /* no cone */
        if (o.type == GN_LIGHT_SPOT) {
            o.inner_cos = float(std::cos(l.spot.innerConeAngle));
            o.outer_cos = float(std::cos(l.spot.outerConeAngle));
        }
    }
}

/* ---- images, textures, materials ----------------------------------------------------------- */

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

/* ---- KHR_texture_basisu, EXT_texture_webp: the image a texture reads ---- */
/* The extension's source (a KTX2 or WebP image; the JSON checks made it an index into
 * images) where its image decoded; else the core source, the optional fallback (a file that
 * requires the extension may omit it); -1 when there is neither. */
int texture_source(Ctx &c, size_t i)
{
    const auto &t = c.m.textures[i];
    for (const char *name : {"KHR_texture_basisu", "EXT_texture_webp"}) {
        auto e = t.extensions.find(name);
        if (e == t.extensions.end() || !e->second.IsObject() || !e->second.Has("source"))
            continue;
        int s = e->second.Get("source").GetNumberAsInt();
        if (s < 0 || size_t(s) >= c.m.images.size())
            continue;
        if (c.image_map[size_t(s)] != GN_INVALID)
            return s;
        if (t.source >= 0 && c.image_map[size_t(t.source)] != GN_INVALID) {
            warn(c, "texture %zu: its %s image %d is unusable; its fallback, image %d, is used instead", i, name, s,
                 t.source);
            return t.source;
        }
        return s; /* unusable and no fallback: ignored, as the image's warning says */
    }
    return t.source;
}
/* ---- end of KHR_texture_basisu, EXT_texture_webp ---- */

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
        out->images[out->num_images].format = uint32_t(c.image_formats[int(i)]);
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
        int source = texture_source(c, i);
        if (source < 0) {
            warn(c, "texture %zu has no image source (ignored)", i);
            continue;
        }
        if (c.image_map[size_t(source)] == GN_INVALID)
            continue;
        uint32_t flags = 0;
        if (t.sampler >= 0) {
            const auto &s = m.samplers[size_t(t.sampler)];
            flags = wrap_mode(c, size_t(t.sampler), s.wrapS) | wrap_mode(c, size_t(t.sampler), s.wrapT) << 2 |
                    filter_mode(c, size_t(t.sampler), s.magFilter, s.minFilter);
        }
        out->textures[out->num_textures] = scene_texture{c.image_map[size_t(source)], flags, {1, 0, 0, 0, 1, 0}};
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

/* ---- file access ------------------------------------------------------------------------------
 * tinygltf's own callbacks expand `~` and `$VAR` (wordexp), read any path and fall back to the
 * working directory; these read only regular files under the scene's folder (after `..`,
 * percent-decoding and symlinks: tinygltf decodes URIs before it joins them), unless
 * scene_allow_outside_files. A refused file is an error naming it that says nothing of
 * whether it exists or how large it is. */

/* The absolute, lexically normalised form of p ("." and ".." resolved, no symlinks). */
std::string normal_path(const std::string &p)
{
    std::string full = p;
    if (p.empty() || p[0] != '/') {
        char cwd[4096];
        if (!getcwd(cwd, sizeof cwd))
            return std::string();
        full = std::string(cwd) + "/" + p;
    }
    std::vector<std::string> parts;
    size_t i = 0;
    while (i <= full.size()) {
        size_t j = full.find('/', i);
        if (j == std::string::npos)
            j = full.size();
        std::string part = full.substr(i, j - i);
        if (part == "..") {
            if (!parts.empty())
                parts.pop_back();
        } else if (!part.empty() && part != ".") {
            parts.push_back(part);
        }
        i = j + 1;
    }
    std::string out;
    for (const auto &part : parts)
        out += "/" + part;
    return out.empty() ? "/" : out;
}

bool under(const std::string &path, const std::string &folder)
{
    return folder == "/" || (path.size() > folder.size() && path.compare(0, folder.size(), folder) == 0 &&
                             path[folder.size()] == '/');
}

bool fs_file_exists(const std::string &path, void *user)
{
    Ctx &c = *static_cast<Ctx *>(user);
    struct stat st;
    /* tinygltf tries the scene's folder, then the working directory: never the latter (with
     * a scene in the working directory both are its folder). */
    bool first = c.base_dir.empty() || path.compare(0, c.base_dir.size(), c.base_dir) == 0;
    if (!first && !allow_outside_files)
        return false;
    /* Lexically against the folder as named (a symlinked folder is the scene's folder), then
     * resolved against the folder resolved. */
    const std::string lexical = normal_path(path), folder = normal_path(c.base_dir.empty() ? "." : c.base_dir);
    if (lexical == folder) {
        c.access_errors.push_back("'" + path + "' is not a regular file");
        return false;
    }
    if (!allow_outside_files && !under(lexical, folder)) {
        c.access_errors.push_back("'" + path + "' is outside the scene's folder (--allow-outside-files reads it)");
        return false;
    }
    char *real = realpath(path.c_str(), nullptr);
    if (!real)
        return false;
    std::string resolved(real);
    free(real);
    if (!allow_outside_files && !under(resolved, c.folder)) {
        c.access_errors.push_back("'" + path + "' links outside the scene's folder (--allow-outside-files reads it)");
        return false;
    }
    if (stat(resolved.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
        c.access_errors.push_back("'" + path + "' is not a regular file");
        return false;
    }
    return true;
}

std::string fs_expand(const std::string &path, void *) { return path; }

bool fs_read(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *)
{
    size_t size = 0;
    void *data = util_read_file(path.c_str(), &size);
    if (!data) {
        if (err)
            *err += "cannot read " + path;
        return false;
    }
    out->assign(static_cast<unsigned char *>(data), static_cast<unsigned char *>(data) + size);
    free(data);
    return true;
}

bool fs_write(std::string *err, const std::string &, const std::vector<unsigned char> &, void *)
{
    if (err)
        *err += "the loader writes no files";
    return false;
}

/* ---- the JSON document, checked before tinygltf converts it -------------------------------
 * tinygltf 2.7 converts JSON numbers with C casts and skips what it cannot convert, so
 * malformed files read as something else: "buffer": 4294967296 became buffer 0, a byteOffset
 * of -12 became 0, "material": 1e20 no material, "children": [1.5] no child. Every property
 * gonio reads is therefore checked here, in the document as parsed by nlohmann::json (the
 * library tinygltf itself parses with), against the glTF 2.0 schema as the Khronos
 * glTF-Validator reads it: the JSON type, indices that are JSON integers (no fraction, no
 * exponent) naming an existing object, sizes and offsets that are non-negative integers in
 * range, enums, and an affine node matrix. Messages name the JSON path. */

const int MAX_DOC_ERRORS = 20; /* then only a count: a fuzzed file can have millions */

struct Doc {
    Ctx &c;
    const Json &root;
    bool glb;
    int errors = 0;
    std::vector<bool> unbounded; /* per accessor: a POSITION without min or max */
    size_t num_variants = 0;     /* KHR_materials_variants' variants */
    size_t num_unbounded = 0, first_unbounded = 0;

    Doc(Ctx &ctx, const Json &r, bool is_glb) : c(ctx), root(r), glb(is_glb) {}

    void error(const std::string &path, const char *fmt, ...) UTIL_PRINTF(3, 4)
    {
        c.failed = true;
        if (++errors > MAX_DOC_ERRORS)
            return;
        char msg[512];
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, sizeof msg, fmt, ap);
        va_end(ap);
        util_error("%s: %s: %s", c.path, path.c_str(), msg);
    }

    static std::string show(const Json &v)
    {
        std::string s = v.dump(-1, ' ', false, Json::error_handler_t::replace);
        return s.size() > 40 ? s.substr(0, 37) + "..." : s;
    }
    static std::string at(const std::string &path, const char *key) { return path.empty() ? key : path + "." + key; }
    static std::string item(const std::string &path, size_t i) { return path + "[" + std::to_string(i) + "]"; }
    /* A key the file chose (attribute names), fit for a message: short, printable. */
    static std::string key_of(const std::string &k)
    {
        std::string s = k.substr(0, 64);
        for (char &ch : s)
            if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f)
                ch = '?';
        return s;
    }

    /* Member `key` of object o, nullptr when absent (an error when required). */
    const Json *member(const Json &o, const char *key, const std::string &path, bool required = false)
    {
        auto it = o.find(key);
        if (it != o.end())
            return &*it;
        if (required)
            error(at(path, key), "missing (required)");
        return nullptr;
    }
    const Json *typed(const Json &o, const char *key, const std::string &path, Json::value_t type, const char *what,
                      bool required = false)
    {
        const Json *v = member(o, key, path, required);
        if (v && v->type() != type) {
            error(at(path, key), "%s is not %s", show(*v).c_str(), what);
            return nullptr;
        }
        return v;
    }
    const Json *object(const Json &o, const char *key, const std::string &path, bool required = false)
    {
        return typed(o, key, path, Json::value_t::object, "an object", required);
    }
    const Json *array(const Json &o, const char *key, const std::string &path, bool required = false)
    {
        return typed(o, key, path, Json::value_t::array, "an array", required);
    }
    void boolean(const Json &o, const char *key, const std::string &path)
    {
        typed(o, key, path, Json::value_t::boolean, "true or false");
    }
    void string(const Json &o, const char *key, const std::string &path, bool required = false)
    {
        typed(o, key, path, Json::value_t::string, "a string", required);
    }
    bool is_number(const Json &v, const std::string &path)
    {
        if (v.is_number())
            return true;
        error(path, "%s is not a number", show(v).c_str());
        return false;
    }
    void number(const Json &o, const char *key, const std::string &path, bool required = false)
    {
        if (const Json *v = member(o, key, path, required))
            is_number(*v, at(path, key));
    }
    /* An array of numbers, n of them unless n is 0; true when it is one. */
    bool numbers(const Json &o, const char *key, const std::string &path, size_t n)
    {
        const Json *v = array(o, key, path);
        if (!v)
            return false;
        if (n && v->size() != n) {
            error(at(path, key), "must have %zu numbers (has %zu)", n, v->size());
            return false;
        }
        bool ok = true;
        for (size_t i = 0; i < v->size(); i++)
            ok &= is_number((*v)[i], item(at(path, key), i));
        return ok;
    }

    /* A non-negative integer in [lo, hi] (the validator's TYPE_MISMATCH, VALUE_NOT_IN_RANGE).
     * Returns it, or -1 when absent or bad. */
    int64_t integer(const Json &v, const std::string &path, uint64_t lo, uint64_t hi)
    {
        if (!v.is_number_integer()) {
            error(path, "%s is not an integer", show(v).c_str());
            return -1;
        }
        bool negative = !v.is_number_unsigned() && v.get<int64_t>() < 0;
        uint64_t u = negative ? 0 : v.get<uint64_t>();
        if (negative || u < lo || u > hi) {
            error(path, "%s is out of range (%llu..%llu)", show(v).c_str(), (unsigned long long)lo,
                  (unsigned long long)hi);
            return -1;
        }
        return int64_t(u);
    }
    int64_t integer(const Json &o, const char *key, const std::string &path, uint64_t lo, uint64_t hi,
                    bool required = false)
    {
        const Json *v = member(o, key, path, required);
        return v ? integer(*v, at(path, key), lo, hi) : -1;
    }

    /* An index into `n` objects of root array `kind` (the validator's TYPE_MISMATCH for 1.5 or
     * 1e20, UNRESOLVED_REFERENCE / INVALID_INDEX out of range). Returns it, or -1. */
    int64_t index(const Json &v, const std::string &path, const char *kind, size_t n)
    {
        if (!v.is_number_integer()) {
            error(path, "%s is not an integer index", show(v).c_str());
            return -1;
        }
        if (!v.is_number_unsigned() && v.get<int64_t>() < 0) {
            error(path, "%s is not a valid index (negative)", show(v).c_str());
            return -1;
        }
        if (v.get<uint64_t>() >= n) {
            if (n)
                error(path, "%s does not exist (%s has %zu entr%s)", show(v).c_str(), kind, n, n == 1 ? "y" : "ies");
            else
                error(path, "%s does not exist (the file has no %s)", show(v).c_str(), kind);
            return -1;
        }
        return int64_t(v.get<uint64_t>());
    }
    size_t count_of(const char *kind) const
    {
        auto it = root.find(kind);
        return it != root.end() && it->is_array() ? it->size() : 0;
    }
    int64_t index(const Json &o, const char *key, const std::string &path, const char *kind, bool required = false)
    {
        const Json *v = member(o, key, path, required);
        return v ? index(*v, at(path, key), kind, count_of(kind)) : -1;
    }
    void indices(const Json &o, const char *key, const std::string &path, const char *kind)
    {
        if (const Json *v = array(o, key, path))
            for (size_t i = 0; i < v->size(); i++)
                index((*v)[i], item(at(path, key), i), kind, count_of(kind));
    }

    void enum_int(const Json &o, const char *key, const std::string &path, std::initializer_list<int> values,
                  bool required = false)
    {
        const Json *v = member(o, key, path, required);
        if (!v)
            return;
        if (v->is_number_integer() && !(v->is_number_unsigned() && v->get<uint64_t>() > INT32_MAX))
            for (int x : values)
                if (v->get<int64_t>() == x)
                    return;
        std::string list;
        for (int x : values)
            list += (list.empty() ? "" : ", ") + std::to_string(x);
        error(at(path, key), "%s is not one of %s", show(*v).c_str(), list.c_str());
    }
    void enum_str(const Json &o, const char *key, const std::string &path, std::initializer_list<const char *> values,
                  bool required = false)
    {
        const Json *v = member(o, key, path, required);
        if (!v)
            return;
        if (v->is_string())
            for (const char *x : values)
                if (v->get_ref<const std::string &>() == x)
                    return;
        std::string list;
        for (const char *x : values)
            list += std::string(list.empty() ? "" : ", ") + x;
        error(at(path, key), "%s is not one of %s", show(*v).c_str(), list.c_str());
    }

    /* The objects of array o.key, each passed to f with its path and position. */
    template <class F> void each(const Json &o, const char *key, const std::string &path, F f)
    {
        const Json *a = array(o, key, path);
        if (!a)
            return;
        for (size_t i = 0; i < a->size(); i++) {
            std::string p = item(at(path, key), i);
            if (!(*a)[i].is_object())
                error(p, "%s is not an object", show((*a)[i]).c_str());
            else
                f((*a)[i], p, i);
        }
    }

    void check();
    void check_accessor(const Json &a, const std::string &p);
    void check_primitive(const Json &pr, const std::string &p);
    void check_node(const Json &n, const std::string &p);
    void check_material(const Json &m, const std::string &p);
    void texture_info(const Json &o, const char *key, const std::string &path);
};

void Doc::check_accessor(const Json &a, const std::string &p)
{
    index(a, "bufferView", p, "bufferViews");
    /* gonio's loader limits (MAX_ELEMENTS) come later, with their own message. */
    if (integer(a, "byteOffset", p, 0, UINT32_MAX) >= 0 && !a.count("bufferView"))
        error(at(p, "byteOffset"), "requires a bufferView");
    enum_int(a, "componentType", p, {5120, 5121, 5122, 5123, 5125, 5126}, true);
    boolean(a, "normalized", p);
    integer(a, "count", p, 1, UINT32_MAX, true);
    enum_str(a, "type", p, {"SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"}, true);
    numbers(a, "min", p, 0);
    numbers(a, "max", p, 0);
    if (const Json *s = object(a, "sparse", p)) {
        std::string sp = at(p, "sparse");
        integer(*s, "count", sp, 1, INT32_MAX, true); /* tinygltf holds it in an int */
        if (const Json *i = object(*s, "indices", sp, true)) {
            std::string ip = at(sp, "indices");
            index(*i, "bufferView", ip, "bufferViews", true);
            integer(*i, "byteOffset", ip, 0, INT32_MAX);
            enum_int(*i, "componentType", ip, {5121, 5123, 5125}, true);
        }
        if (const Json *v = object(*s, "values", sp, true)) {
            std::string vp = at(sp, "values");
            index(*v, "bufferView", vp, "bufferViews", true);
            integer(*v, "byteOffset", vp, 0, INT32_MAX);
        }
    }
}

void Doc::check_primitive(const Json &pr, const std::string &p)
{
    if (const Json *attrs = object(pr, "attributes", p, true)) {
        std::string ap = at(p, "attributes");
        for (auto it = attrs->begin(); it != attrs->end(); ++it) {
            int64_t a = index(it.value(), at(ap, key_of(it.key()).c_str()), "accessors", count_of("accessors"));
            /* The validator's POSITION_ACCESSOR_WITHOUT_BOUNDS is an error, but gonio computes
             * the bounds it needs from the data and never trusts these: refusing would only
             * lose the scene, so it is a warning (one for the file, in check). */
            if (it.key() == "POSITION" && a >= 0 && !unbounded[size_t(a)]) {
                const Json &acc = root.at("accessors").at(size_t(a));
                if (acc.is_object() && (!acc.count("min") || !acc.count("max"))) {
                    unbounded[size_t(a)] = true;
                    if (!num_unbounded++)
                        first_unbounded = size_t(a);
                }
            }
        }
    }
    index(pr, "indices", p, "accessors");
    index(pr, "material", p, "materials");
    enum_int(pr, "mode", p, {0, 1, 2, 3, 4, 5, 6});
    /* KHR_materials_variants: each mapping names existing variants (each at most once in the
     * primitive's mappings) and an existing material. */
    const Json *ext = object(pr, "extensions", p);
    const Json *kv = ext ? object(*ext, "KHR_materials_variants", at(p, "extensions")) : nullptr;
    if (kv) {
        const std::string pk = at(at(p, "extensions"), "KHR_materials_variants");
        std::vector<std::string> seen(num_variants);
        if (!array(*kv, "mappings", pk, true))
            return;
        each(*kv, "mappings", pk, [&](const Json &mp, const std::string &pm, size_t) {
            index(mp, "material", pm, "materials", true);
            const Json *vs = array(mp, "variants", pm, true);
            if (vs && vs->empty())
                error(at(pm, "variants"), "is empty (a mapping names at least one variant)");
            for (size_t i = 0; vs && i < vs->size(); i++) {
                std::string pv = item(at(pm, "variants"), i);
                int64_t v = index((*vs)[i], pv, "KHR_materials_variants variants", num_variants);
                if (v >= 0 && !seen[size_t(v)].empty())
                    error(pv, "variant %lld is mapped already, at %s (a variant has one material per primitive)",
                          (long long)v, seen[size_t(v)].c_str());
                else if (v >= 0)
                    seen[size_t(v)] = pv;
            }
        });
    }
}

void Doc::check_node(const Json &n, const std::string &p)
{
    index(n, "camera", p, "cameras");
    index(n, "mesh", p, "meshes");
    index(n, "skin", p, "skins");
    indices(n, "children", p, "nodes");
    if (numbers(n, "matrix", p, 16)) {
        /* glTF node matrices are affine: the last row (elements 3, 7, 11, 15 in column-major
         * order) is 0 0 0 1. A projective one cannot be a rigid placement; up to rounding. */
        const Json &m = n.at("matrix");
        const double row[4] = {m[3].get<double>(), m[7].get<double>(), m[11].get<double>(), m[15].get<double>()};
        if (!(std::fabs(row[0]) <= 1e-6 && std::fabs(row[1]) <= 1e-6 && std::fabs(row[2]) <= 1e-6 &&
              std::fabs(row[3] - 1) <= 1e-6))
            error(at(p, "matrix"), "is not affine: its last row is %g %g %g %g, not 0 0 0 1", row[0], row[1], row[2], row[3]);
    }
    numbers(n, "translation", p, 3);
    numbers(n, "rotation", p, 4);
    numbers(n, "scale", p, 3);
    const Json *ext = object(n, "extensions", p);
    const Json *lp = ext ? object(*ext, "KHR_lights_punctual", at(p, "extensions")) : nullptr;
    if (lp) {
        size_t nl = 0;
        auto re = root.find("extensions");
        if (re != root.end() && re->is_object()) {
            auto rl = re->find("KHR_lights_punctual");
            if (rl != re->end() && rl->is_object()) {
                auto ls = rl->find("lights");
                nl = ls != rl->end() && ls->is_array() ? ls->size() : 0;
            }
        }
        if (const Json *l = member(*lp, "light", at(at(p, "extensions"), "KHR_lights_punctual"), true))
            index(*l, at(at(at(p, "extensions"), "KHR_lights_punctual"), "light"), "KHR_lights_punctual lights", nl);
    }
}

void Doc::texture_info(const Json &o, const char *key, const std::string &path)
{
    const Json *t = object(o, key, path);
    if (!t)
        return;
    std::string p = at(path, key);
    index(*t, "index", p, "textures", true);
    integer(*t, "texCoord", p, 0, INT32_MAX);
    number(*t, "scale", p);
    number(*t, "strength", p);
}

void Doc::check_material(const Json &m, const std::string &p)
{
    if (const Json *pbr = object(m, "pbrMetallicRoughness", p)) {
        std::string pp = at(p, "pbrMetallicRoughness");
        numbers(*pbr, "baseColorFactor", pp, 4);
        number(*pbr, "metallicFactor", pp);
        number(*pbr, "roughnessFactor", pp);
        texture_info(*pbr, "baseColorTexture", pp);
        texture_info(*pbr, "metallicRoughnessTexture", pp);
    }
    texture_info(m, "normalTexture", p);
    texture_info(m, "occlusionTexture", p);
    if (const Json *ex = object(m, "extensions", p)) {
        std::string pe = at(p, "extensions");
        if (const Json *cc = object(*ex, "KHR_materials_clearcoat", pe)) {
            std::string pc = at(pe, "KHR_materials_clearcoat");
            number(*cc, "clearcoatFactor", pc);
            number(*cc, "clearcoatRoughnessFactor", pc);
            texture_info(*cc, "clearcoatTexture", pc);
            texture_info(*cc, "clearcoatRoughnessTexture", pc);
            texture_info(*cc, "clearcoatNormalTexture", pc);
        }
        if (const Json *sh = object(*ex, "KHR_materials_sheen", pe)) {
            std::string ps = at(pe, "KHR_materials_sheen");
            numbers(*sh, "sheenColorFactor", ps, 3);
            number(*sh, "sheenRoughnessFactor", ps);
            texture_info(*sh, "sheenColorTexture", ps);
            texture_info(*sh, "sheenRoughnessTexture", ps);
        }
        if (const Json *an = object(*ex, "KHR_materials_anisotropy", pe)) {
            std::string pa = at(pe, "KHR_materials_anisotropy");
            number(*an, "anisotropyStrength", pa);
            number(*an, "anisotropyRotation", pa);
            texture_info(*an, "anisotropyTexture", pa);
        }
        if (const Json *ir = object(*ex, "KHR_materials_iridescence", pe)) {
            std::string pi = at(pe, "KHR_materials_iridescence");
            number(*ir, "iridescenceFactor", pi);
            number(*ir, "iridescenceIor", pi);
            number(*ir, "iridescenceThicknessMinimum", pi);
            number(*ir, "iridescenceThicknessMaximum", pi);
            texture_info(*ir, "iridescenceTexture", pi);
            texture_info(*ir, "iridescenceThicknessTexture", pi);
        }
        if (const Json *dt = object(*ex, "KHR_materials_diffuse_transmission", pe)) {
            std::string pd = at(pe, "KHR_materials_diffuse_transmission");
            number(*dt, "diffuseTransmissionFactor", pd);
            numbers(*dt, "diffuseTransmissionColorFactor", pd, 3);
            texture_info(*dt, "diffuseTransmissionTexture", pd);
            texture_info(*dt, "diffuseTransmissionColorTexture", pd);
        }
    }
    texture_info(m, "emissiveTexture", p);
    numbers(m, "emissiveFactor", p, 3);
    enum_str(m, "alphaMode", p, {"OPAQUE", "MASK", "BLEND"});
    number(m, "alphaCutoff", p);
    boolean(m, "doubleSided", p);
}

void Doc::check()
{
    const size_t MAX = size_t(1) << 53; /* exact in a double, as tinygltf's sizes pass through */
    if (const Json *a = object(root, "asset", "", true)) {
        string(*a, "version", "asset", true);
        string(*a, "minVersion", "asset");
    }
    if (const Json *e = array(root, "extensionsUsed", ""))
        for (size_t i = 0; i < e->size(); i++)
            if (!(*e)[i].is_string())
                error(item("extensionsUsed", i), "%s is not a string", show((*e)[i]).c_str());
    if (const Json *e = array(root, "extensionsRequired", ""))
        for (size_t i = 0; i < e->size(); i++)
            if (!(*e)[i].is_string())
                error(item("extensionsRequired", i), "%s is not a string", show((*e)[i]).c_str());
    index(root, "scene", "", "scenes");
    each(root, "scenes", "", [&](const Json &s, const std::string &p, size_t) { indices(s, "nodes", p, "nodes"); });
    if (const Json *ext = object(root, "extensions", ""))
        if (const Json *kv = object(*ext, "KHR_materials_variants", "extensions")) {
            const std::string pk = "extensions.KHR_materials_variants";
            if (const Json *vs = array(*kv, "variants", pk, true))
                num_variants = vs->size();
            each(*kv, "variants", pk, [&](const Json &v, const std::string &p, size_t) { string(v, "name", p, true); });
        }
    each(root, "buffers", "", [&](const Json &b, const std::string &p, size_t i) {
        string(b, "uri", p);
        /* tinygltf would read the folder as the buffer's file. */
        /* EXT_meshopt_compression's fallback buffers have no data: decoding fills them. */
        const Json *ext = b.count("extensions") ? &b["extensions"] : nullptr;
        bool fallback = ext && ext->is_object() && ext->count("EXT_meshopt_compression") &&
                        (*ext)["EXT_meshopt_compression"].is_object() &&
                        (*ext)["EXT_meshopt_compression"].count("fallback") &&
                        (*ext)["EXT_meshopt_compression"]["fallback"] == true;
        if (!b.count("uri") && !(glb && i == 0) && !fallback)
            error(p, "has no uri (only the first buffer of a GLB, its BIN chunk, or a meshopt fallback buffer may omit it)");
        integer(b, "byteLength", p, 1, MAX, true);
    });
    /* A range of a buffer: inside the buffer's declared byteLength (checked against the
     * data later, but a meshopt fallback buffer has no data to check against). */
    auto inside_buffer = [&](const std::string &p, int64_t buf, int64_t off, int64_t len) {
        if (buf < 0 || len < 0)
            return;
        const Json &b = root.at("buffers").at(size_t(buf));
        auto bl = b.is_object() ? b.find("byteLength") : b.end();
        if (bl != b.end() && bl->is_number_unsigned() && uint64_t(off < 0 ? 0 : off) + uint64_t(len) > bl->get<uint64_t>())
            error(p, "bytes %lld to %lld lie beyond buffers[%lld].byteLength %llu", (long long)(off < 0 ? 0 : off),
                  (long long)((off < 0 ? 0 : off) + len), (long long)buf, (unsigned long long)bl->get<uint64_t>());
    };
    each(root, "bufferViews", "", [&](const Json &v, const std::string &p, size_t) {
        int64_t buf = index(v, "buffer", p, "buffers", true);
        int64_t off = integer(v, "byteOffset", p, 0, MAX);
        int64_t len = integer(v, "byteLength", p, 1, MAX, true);
        int64_t stride = integer(v, "byteStride", p, 4, 252);
        if (stride > 0 && stride % 4)
            error(at(p, "byteStride"), "%lld is not a multiple of 4", (long long)stride);
        enum_int(v, "target", p, {34962, 34963});
        inside_buffer(p, buf, off, len);
        /* EXT_meshopt_compression: the compressed range, and the layout the parent view must
         * hold once decoded (the extension's "for the extension object to be valid" rules). */
        const Json *ext = object(v, "extensions", p);
        const Json *mo = ext ? object(*ext, "EXT_meshopt_compression", at(p, "extensions")) : nullptr;
        if (!mo)
            return;
        const std::string pm = at(at(p, "extensions"), "EXT_meshopt_compression");
        int64_t mbuf = index(*mo, "buffer", pm, "buffers", true);
        int64_t moff = integer(*mo, "byteOffset", pm, 0, MAX);
        int64_t mlen = integer(*mo, "byteLength", pm, 1, MAX, true);
        int64_t mstride = integer(*mo, "byteStride", pm, 1, 256, true);
        int64_t count = integer(*mo, "count", pm, 1, UINT32_MAX, true);
        enum_str(*mo, "mode", pm, {"ATTRIBUTES", "TRIANGLES", "INDICES"}, true);
        enum_str(*mo, "filter", pm, {"NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL"});
        inside_buffer(pm, mbuf, moff, mlen);
        if (stride > 0 && mstride > 0 && stride != mstride)
            error(at(pm, "byteStride"), "%lld is not the buffer view's byteStride %lld", (long long)mstride,
                  (long long)stride);
        if (len > 0 && mstride > 0 && count > 0 && uint64_t(mstride) * uint64_t(count) != uint64_t(len))
            error(pm, "count %lld x byteStride %lld = %llu bytes, but the buffer view's byteLength is %lld",
                  (long long)count, (long long)mstride, (unsigned long long)(uint64_t(mstride) * uint64_t(count)),
                  (long long)len);
    });
    unbounded.assign(count_of("accessors"), false);
    each(root, "accessors", "", [&](const Json &a, const std::string &p, size_t) { check_accessor(a, p); });
    each(root, "meshes", "", [&](const Json &m, const std::string &p, size_t) {
        if (!array(m, "primitives", p, true))
            return;
        each(m, "primitives", p, [&](const Json &pr, const std::string &pp, size_t) { check_primitive(pr, pp); });
    });
    each(root, "nodes", "", [&](const Json &n, const std::string &p, size_t) { check_node(n, p); });
    each(root, "cameras", "", [&](const Json &cam, const std::string &p, size_t) {
        enum_str(cam, "type", p, {"perspective", "orthographic"}, true);
        auto t = cam.find("type");
        bool persp = t != cam.end() && *t == "perspective", ortho = t != cam.end() && *t == "orthographic";
        if (const Json *pe = object(cam, "perspective", p, persp)) {
            std::string pp = at(p, "perspective");
            number(*pe, "yfov", pp, true);
            number(*pe, "znear", pp, true);
            number(*pe, "zfar", pp);
            number(*pe, "aspectRatio", pp);
        }
        if (const Json *o = object(cam, "orthographic", p, ortho)) {
            std::string op = at(p, "orthographic");
            for (const char *k : {"xmag", "ymag", "znear", "zfar"})
                number(*o, k, op, true);
        }
    });
    each(root, "images", "", [&](const Json &img, const std::string &p, size_t) {
        string(img, "uri", p);
        string(img, "mimeType", p);
        index(img, "bufferView", p, "bufferViews");
    });
    each(root, "samplers", "", [&](const Json &s, const std::string &p, size_t) {
        enum_int(s, "magFilter", p, {9728, 9729});
        enum_int(s, "minFilter", p, {9728, 9729, 9984, 9985, 9986, 9987});
        enum_int(s, "wrapS", p, {33071, 33648, 10497});
        enum_int(s, "wrapT", p, {33071, 33648, 10497});
    });
    each(root, "textures", "", [&](const Json &t, const std::string &p, size_t) {
        index(t, "sampler", p, "samplers");
        index(t, "source", p, "images");
        /* KHR_texture_basisu, EXT_texture_webp: the image to read (the core source is then the
         * fallback, which a file requiring the extension may omit) */
        if (const Json *ext = object(t, "extensions", p))
            for (const char *name : {"KHR_texture_basisu", "EXT_texture_webp"})
                if (const Json *e = object(*ext, name, at(p, "extensions")))
                    index(*e, "source", at(at(p, "extensions"), name), "images", true);
    });
    each(root, "materials", "", [&](const Json &m, const std::string &p, size_t) { check_material(m, p); });
    each(root, "skins", "", [&](const Json &, const std::string &, size_t) {}); /* only node.skin is read */
    each(root, "animations", "", [&](const Json &a, const std::string &p, size_t) {
        const Json *samplers = array(a, "samplers", p, true);
        size_t ns = samplers ? samplers->size() : 0;
        if (samplers)
            each(a, "samplers", p, [&](const Json &s, const std::string &sp, size_t) {
                index(s, "input", sp, "accessors", true);
                index(s, "output", sp, "accessors", true);
                enum_str(s, "interpolation", sp, {"LINEAR", "STEP", "CUBICSPLINE"});
            });
        if (!array(a, "channels", p, true))
            return;
        each(a, "channels", p, [&](const Json &ch, const std::string &cp, size_t) {
            if (const Json *v = member(ch, "sampler", cp, true))
                index(*v, at(cp, "sampler"), (p + ".samplers").c_str(), ns);
            if (const Json *t = object(ch, "target", cp, true)) {
                index(*t, "node", at(cp, "target"), "nodes");
                enum_str(*t, "path", at(cp, "target"), {"translation", "rotation", "scale", "weights"}, true);
            }
        });
    });
    if (errors > MAX_DOC_ERRORS)
        util_error("%s: %d more errors in the JSON", c.path, errors - MAX_DOC_ERRORS);
    if (num_unbounded && !c.failed)
        warn(c, "accessors[%zu]: a POSITION accessor without min and max%s (glTF requires them; gonio computes "
                "the bounds itself)", first_unbounded,
             num_unbounded > 1 ? (", and " + std::to_string(num_unbounded - 1) + " more").c_str() : "");
}

/* The document checks over the JSON text. Text that is not JSON is left to tinygltf, which
 * parses with the same library and says where the syntax breaks. */
bool check_document(Ctx &c, const uint8_t *json, size_t n, bool glb)
{
    Json root = Json::parse(json, json + n, nullptr, false);
    if (root.is_discarded() || !root.is_object())
        return true;
    Doc doc(c, root, glb);
    doc.check();
    return !c.failed;
}

/* ---- scene_load ------------------------------------------------------------------------------- */

bool parse(Ctx &c, uint8_t *data, size_t size)
{
    const char *ext = strrchr(c.path, '.');
    bool glb = (size >= 4 && memcmp(data, "glTF", 4) == 0) || (ext && strcasecmp(ext, ".glb") == 0);
    const uint8_t *json = data;
    size_t json_len = size, len = size;
    if (size > UINT32_MAX)
        return fail(c, "file too large (%zu bytes)", size);
    if (glb && !(len = check_glb(c, data, size, &json, &json_len)))
        return false;
    if (!glb && size == 0)
        return fail(c, "empty file");
    if (!check_json_text(c, json, json_len) || !check_document(c, json, json_len, glb))
        return false;
    std::string patched = gltf_json_patch(reinterpret_cast<const char *>(json), json_len, glb);
    std::vector<uint8_t> glb_patched;
    if (!patched.empty() && !glb) {
        data = reinterpret_cast<uint8_t *>(&patched[0]);
        size = len = patched.size();
    } else if (!patched.empty()) { /* the GLB again, with the new JSON chunk */
        patched.resize((patched.size() + 3) & ~size_t(3), ' ');
        size_t rest = len - size_t(json + json_len - data); /* the BIN chunk, if any */
        glb_patched.resize(12 + 8 + patched.size() + rest);
        uint8_t *g = glb_patched.data();
        memcpy(g, data, 12);
        uint32_t total = uint32_t(glb_patched.size()), jl = uint32_t(patched.size());
        memcpy(g + 8, &total, 4);
        memcpy(g + 12, &jl, 4);
        memcpy(g + 16, "JSON", 4);
        memcpy(g + 20, patched.data(), patched.size());
        memcpy(g + 20 + patched.size(), json + json_len, rest);
        data = g;
        size = len = glb_patched.size();
    }
    /* tinygltf calls any JSON under 4 bytes "too short"; padded, it says what is wrong. */
    std::string small = size < 4 ? std::string(reinterpret_cast<const char *>(data), size) + "   " : "";
    const char *text = small.empty() ? reinterpret_cast<const char *>(data) : small.c_str();
    unsigned text_len = small.empty() ? unsigned(len) : unsigned(small.size());
    std::string base_dir(c.path, strrchr(c.path, '/') ? size_t(strrchr(c.path, '/') - c.path) : 0);
    if (strrchr(c.path, '/') == c.path)
        base_dir = "/";
    {
        char *real = realpath(base_dir.empty() ? "." : base_dir.c_str(), nullptr);
        if (!real)
            return fail(c, "cannot resolve the scene's folder");
        c.folder = real;
        free(real);
    }
    c.base_dir = base_dir;
    tinygltf::TinyGLTF loader;
    tinygltf::FsCallbacks fs = {fs_file_exists, fs_expand, fs_read, fs_write, &c};
    loader.SetFsCallbacks(fs);
    loader.SetImageLoader(image_callback, &c);
    std::string err, warnings;
    bool ok = glb ? loader.LoadBinaryFromMemory(&c.m, &err, &warnings, data, unsigned(len), base_dir)
                  : loader.LoadASCIIFromString(&c.m, &err, &warnings, text, text_len, base_dir);
    /* tinygltf 2.7 only warns about external images it cannot read, which get their own
     * warning in load_images_and_textures: `warnings` is not repeated. */
    for (const auto &e : c.access_errors)
        fail(c, "%s", e.c_str());
    if (!c.access_errors.empty())
        return false;
    if (!ok && err.empty())
        return fail(c, "cannot parse glTF");
    report_lines(c, err, !ok);
    return ok;
}

bool load(scene *out, const char *path, int scene_index)
{
    Ctx c;
    c.path = path;
    c.scene_index = scene_index;
    snprintf(out->path, sizeof out->path, "%s", path);
    size_t size = 0;
    std::unique_ptr<uint8_t, decltype(&free)> data(static_cast<uint8_t *>(util_read_file(path, &size)), &free);
    if (!data || !parse(c, data.get(), size))
        return false;
    data.reset();
    if (!c.limit_error.empty())
        return fail(c, "%s", c.limit_error.c_str());
    if (!check_asset(c) || !decompress(c) || !select_variant(c) || !check_buffers_and_views(c))
        return false;
    for (size_t i = 0; i < c.m.accessors.size(); i++)
        check_accessor(c, int(i));
    if (c.failed)
        return false;
    for (size_t mi = 0; mi < c.m.meshes.size(); mi++) {
        if (c.m.meshes[mi].primitives.empty())
            fail(c, "%s has no primitives", label("mesh", int(mi), c.m.meshes[mi].name).c_str());
        for (size_t pi = 0; pi < c.m.meshes[mi].primitives.size(); pi++)
            check_primitive(c, int(mi), int(pi));
    }
    if (c.failed || !check_textures_and_materials(c) || !check_nodes_and_scenes(c) || !check_animations(c))
        return false;
    check_cameras(c);
    check_lights(c);
    for (size_t i = 0; i < c.m.accessors.size(); i++)
        check_accessor_data(c, int(i));
    if (!load_meshes(c))
        return false;
    std::vector<Instance> inst, cams, lights;
    if (!collect_instances(c, inst, cams, lights) || !bake_geometry(c, inst, out))
        return false;
    load_images_and_textures(c, out);
    if (!c.limit_error.empty()) /* images in buffer views are decoded only now */
        return fail(c, "%s", c.limit_error.c_str());
    load_materials(c, out);
    bake_cameras(c, cams, out);
    bake_lights(c, lights, out);
    out->num_gltf_meshes = uint32_t(c.m.meshes.size());
    out->num_nodes = uint32_t(c.m.nodes.size());
    std::vector<std::string> variants = variant_names(c.m);
    if (!variants.empty()) {
        out->num_variants = uint32_t(variants.size());
        out->variant_names = static_cast<char (*)[64]>(util_calloc(variants.size(), 64));
        for (size_t i = 0; i < variants.size(); i++)
            snprintf(out->variant_names[i], 64, "%s", variants[i].c_str());
    }
    uint32_t dropped = scene_drop_invalid_triangles(out);
    if (dropped)
        warn(c, "dropped %u triangle(s) with non-finite or huge (|x| > 1e15) vertex positions", dropped);
    if (out->num_triangles == 0)
        return fail(c, "no triangles");
    scene_compute_bounds(out);
    return true;
}

} // namespace

bool scene_load(scene *out, const char *path) { return scene_load_scene(out, path, -1); }

void scene_animation_time(double seconds)
{
    anim_time = seconds;
}

void scene_allow_outside_files(bool allow) { allow_outside_files = allow; }

void scene_select_variant(const char *name) { variant = name ? name : ""; }

bool scene_load_scene(scene *out, const char *path, int scene_index)
{
    bool ok = false;
    memset(out, 0, sizeof *out);
    try {
        ok = load(out, path, scene_index);
    } catch (const std::bad_alloc &) {
        util_error("%s: out of memory", path);
    } catch (const std::exception &e) {
        util_error("%s: %s", path, e.what());
    } catch (...) {
        util_error("%s: unexpected error in the glTF loader", path);
    }
    if (!ok)
        scene_destroy(out);
    return ok;
}
