/* gltf_json.cpp: the JSON document, checked before tinygltf converts it.
 * tinygltf 2.7 converts JSON numbers with C casts and skips what it cannot convert, so
 * malformed files read as something else: "buffer": 4294967296 became buffer 0, a byteOffset
 * of -12 became 0, "material": 1e20 no material, "children": [1.5] no child. Every property
 * gonio reads is therefore checked here, in the document as parsed by nlohmann::json (the
 * library tinygltf itself parses with), against the glTF 2.0 schema as the Khronos
 * glTF-Validator reads it: the JSON type, indices that are JSON integers (no fraction, no
 * exponent) naming an existing object, sizes and offsets that are non-negative integers in
 * range, enums, and an affine node matrix. Messages name the JSON path. */
#include "gltf_json.h"

#include <cmath>
#include <cstdio>

namespace gltf {


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
    });
    materials_read(c, root);
    each(root, "materials", "", [&](const Json &m, const std::string &p, size_t i) { material_read(*this, m, p, i); });
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

} // namespace gltf
