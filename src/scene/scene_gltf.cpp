/* scene_gltf.cpp: scene_load, the glTF 2.0 loader (gltf_internal.h names its files). The
 * container (GLB chunks) and the JSON text are checked here, the JSON document as JSON
 * (gltf_json.cpp: types, indices, sizes, enums, which tinygltf's conversions lose); then
 * tinygltf parses the JSON/GLB and fetches buffers and images through the file sandbox
 * (gltf_files.cpp), and everything it returns is checked against the glTF 2.0 specification
 * (gltf_check.cpp) before one byte is read, in cgltf's order: parse, load buffers, validate,
 * read (gltf_animation.cpp, gltf_geometry.cpp, gltf_material.cpp). No C++ exception escapes
 * into C. */
#include "gltf_internal.h"

#include <cstdio>
#include <cstring>
#include <memory>
#include <strings.h>

#include "gltf_decompress.h"

namespace gltf {

bool allow_outside_files = false; /* scene_allow_outside_files */
std::string variant;              /* scene_select_variant */
bool instance_animated = false;   /* scene_instance_animated */
double anim_time = -1;            /* scene_animation_time */

void vreport(const Ctx &c, bool error, const char *fmt, va_list ap)
{
    char msg[1024];
    vsnprintf(msg, sizeof msg, fmt, ap);
    if (error)
        util_error("%s: %s", c.path, msg);
    else
        util_warn("%s: %s", c.path, msg);
}

bool fail(Ctx &c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vreport(c, true, fmt, ap);
    va_end(ap);
    c.failed = true;
    return false;

}

void warn(Ctx &c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vreport(c, false, fmt, ap);
    va_end(ap);
}

std::string label(const char *kind, int i, const std::string &name)
{
    std::string s = std::string(kind) + " " + std::to_string(i);
    if (!name.empty())
        s += " '" + name.substr(0, 64) + "'";
    return s;
}

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

/* Compressed views and primitives become plain ones before anything is checked or read. */
bool decompress(Ctx &c)
{
    std::vector<std::string> errors;
    c.file_buffers = c.m.buffers.size();
    if (gltf_decompress(c.m, MAX_ELEMENTS, &errors))
        return true;
    for (const auto &e : errors)
        fail(c, "%s", e.c_str());
    return false;
}

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
    /* tinygltf 2.7 calls a skin's optional inverseBindMatrices missing; glTF's default is
     * identity matrices (gltf_skin.cpp), so that line says nothing wrong. */
    const std::string ibm = "'inverseBindMatrices' property is missing in Skin.\n";
    for (size_t at; (at = err.find(ibm)) != std::string::npos;)
        err.erase(at, ibm.size());
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
    if (!check_asset(c) || !check_extensions(c) || !decompress(c) || !select_variant(c) || !check_buffers_and_views(c))
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
    if (c.failed || !check_textures(c) || !check_skins_and_targets(c) || !check_nodes_and_scenes(c) ||
        !check_animations(c))
        return false;
    check_cameras(c);
    check_lights(c);
    /* Decoded values (Draco's quantized to the encoder's grid, meshopt's filtered) may stray
     * from the bounds the file kept from before; the data is right as decoded: one line for
     * them all. */
    int stale = -1, num_stale = 0;
    for (size_t i = 0; i < c.m.accessors.size(); i++)
        if (!check_accessor_data(c, int(i)) && num_stale++ == 0)
            stale = int(i);
    if (num_stale)
        warn(c, "%d accessor(s) decoded from compressed data (the first: %s) lie outside the min/max the file "
             "declares for them: its bounds are stale (the data is used as decoded)", num_stale,
             label("accessor", stale, c.m.accessors[size_t(stale)].name).c_str());
    if (!load_meshes(c))
        return false;
    std::vector<Instance> inst, cams, lights;
    if (!collect_instances(c, inst, cams, lights) || !joint_matrices(c) || !bake_geometry(c, inst, out))
        return false;
    load_images_and_textures(c, out);
    if (!c.limit_error.empty()) /* images in buffer views are decoded only now */
        return fail(c, "%s", c.limit_error.c_str());
    if (!load_materials(c, out) || !bake_environment(c, out))
        return false;
    bake_cameras(c, cams, out);
    list_extensions(c, out);
    bake_lights(c, lights, out);
    out->num_gltf_meshes = uint32_t(c.m.meshes.size());
    out->num_nodes = uint32_t(c.m.nodes.size());
    out->num_skins = uint32_t(c.m.skins.size());
    for (const auto &s : c.m.skins)
        out->num_joints += uint32_t(s.joints.size());
    for (const auto &mesh : c.m.meshes)
        if (!mesh.primitives.empty() && !mesh.primitives[0].targets.empty()) {
            out->num_morph_targets += uint32_t(mesh.primitives[0].targets.size());
            out->num_morphed_meshes++;
        }
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
    if (out->num_triangles == 0 && out->num_instances == 0)
        return fail(c, "no triangles");
    scene_compute_bounds(out);
    return true;
}

} // namespace gltf

using namespace gltf;

bool scene_load(scene *out, const char *path) { return scene_load_scene(out, path, -1); }

void scene_animation_time(double seconds)
{
    anim_time = seconds;
}

void scene_allow_outside_files(bool allow) { allow_outside_files = allow; }

void scene_select_variant(const char *name) { variant = name ? name : ""; }

void scene_instance_animated(bool on) { instance_animated = on; }

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
