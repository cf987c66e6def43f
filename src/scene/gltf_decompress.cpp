/* gltf_decompress.cpp: KHR_draco_mesh_compression (Draco) and EXT_meshopt_compression
 * (meshoptimizer) decoded into plain buffers, as the two extensions' specifications define
 * them. Runs after tinygltf's parse and before the loader's checks, so the offsets it reads
 * are checked here. tinygltf's own Draco support is not used: distributions build it out. */
#include <tiny_gltf.h>

#include <draco/compression/decode.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include <cstring>
#include <string>
#include <vector>

#include "gltf_decompress.h"

namespace {

struct Out {
    tinygltf::Model &m;
    size_t max_elements;
    std::vector<std::string> *errors;
    /* Bytes all decoded data may still take: a few hundred bytes of JSON naming one small
     * compressed view many times must not ask for gigabytes before the loader's own limits. */
    size_t budget;
    bool take(const std::string &what, size_t bytes)
    {
        if (bytes <= budget) {
            budget -= bytes;
            return true;
        }
        return error(what + ": the decoded data would exceed " + std::to_string(max_elements * 16) +
                     " bytes in all (the loader's limit)");
    }
    bool error(const std::string &s)
    {
        errors->push_back(s);
        return false;
    }
};

const tinygltf::Value *ext(const tinygltf::ExtensionMap &e, const char *name)
{
    auto it = e.find(name);
    return it == e.end() || !it->second.IsObject() ? nullptr : &it->second;
}

/* A non-negative integer member, or -1 when absent or not one. */
long long member(const tinygltf::Value &v, const char *name)
{
    if (!v.Has(name) || !v.Get(name).IsNumber())
        return -1;
    double d = v.Get(name).GetNumberAsDouble();
    return d >= 0 && d <= 9e15 && d == double((long long)d) ? (long long)d : -1;
}

/* A new buffer holding bytes, with one view over all of it; returns the view. */
int add_view(tinygltf::Model &m, std::vector<unsigned char> &&bytes, size_t stride)
{
    tinygltf::Buffer b;
    b.data = std::move(bytes);
    tinygltf::BufferView v;
    v.buffer = int(m.buffers.size());
    v.byteOffset = 0;
    v.byteLength = b.data.size();
    v.byteStride = stride;
    m.buffers.push_back(std::move(b));
    m.bufferViews.push_back(v);
    return int(m.bufferViews.size() - 1);
}

/* The bytes [off, off + len) of buffer `buf`, or null when they are not all there. */
const unsigned char *span(const tinygltf::Model &m, long long buf, long long off, long long len)
{
    if (buf < 0 || size_t(buf) >= m.buffers.size() || off < 0 || len <= 0)
        return nullptr;
    size_t n = m.buffers[size_t(buf)].data.size();
    return size_t(off) <= n && size_t(len) <= n - size_t(off) ? m.buffers[size_t(buf)].data.data() + off : nullptr;
}

/* ---- EXT_meshopt_compression ------------------------------------------------------------ */

bool meshopt_view(Out &o, size_t i)
{
    tinygltf::Model &m = o.m;
    const tinygltf::Value &e = *ext(m.bufferViews[i].extensions, "EXT_meshopt_compression");
    std::string what = "buffer view " + std::to_string(i) + " (EXT_meshopt_compression)";
    long long buf = member(e, "buffer"), off = e.Has("byteOffset") ? member(e, "byteOffset") : 0,
              len = member(e, "byteLength"), stride = member(e, "byteStride"), count = member(e, "count");
    std::string mode = e.Has("mode") && e.Get("mode").IsString() ? e.Get("mode").Get<std::string>() : "";
    std::string filter = e.Has("filter") && e.Get("filter").IsString() ? e.Get("filter").Get<std::string>() : "NONE";
    const unsigned char *src = span(m, buf, off, len);
    if (!src)
        return o.error(what + ": buffer " + std::to_string(buf) + ", byteOffset " + std::to_string(off) +
                       ", byteLength " + std::to_string(len) + " do not name bytes of a buffer");
    if (count < 1 || size_t(count) > o.max_elements)
        return o.error(what + ": count " + std::to_string(count) + " is out of range (1.." +
                       std::to_string(o.max_elements) + ")");
    bool attrs = mode == "ATTRIBUTES", tris = mode == "TRIANGLES", seq = mode == "INDICES";
    if (!attrs && !tris && !seq)
        return o.error(what + ": mode '" + mode + "' is not ATTRIBUTES, TRIANGLES or INDICES");
    if (attrs ? stride < 4 || stride > 256 || stride % 4 : stride != 2 && stride != 4)
        return o.error(what + ": byteStride " + std::to_string(stride) + " is not allowed in mode " + mode);
    if (tris && count % 3)
        return o.error(what + ": count " + std::to_string(count) + " is not a multiple of 3 in mode TRIANGLES");
    bool oct = filter == "OCTAHEDRAL", quat = filter == "QUATERNION", expo = filter == "EXPONENTIAL";
    bool filter_ok = filter == "NONE" || (attrs && ((oct && (stride == 4 || stride == 8)) || (quat && stride == 8) || expo));
    if (!filter_ok)
        return o.error(what + ": filter '" + filter + "' is not allowed with mode " + mode + " and byteStride " +
                       std::to_string(stride));
    if (!o.take(what, size_t(count) * size_t(stride)))
        return false;
    std::vector<unsigned char> dst(size_t(count) * size_t(stride));
    int r = attrs ? meshopt_decodeVertexBuffer(dst.data(), size_t(count), size_t(stride), src, size_t(len))
            : tris ? meshopt_decodeIndexBuffer(dst.data(), size_t(count), size_t(stride), src, size_t(len))
                   : meshopt_decodeIndexSequence(dst.data(), size_t(count), size_t(stride), src, size_t(len));
    if (r != 0)
        return o.error(what + ": meshoptimizer cannot decode its " + std::to_string(len) + " bytes (error " +
                       std::to_string(r) + ": corrupt or not " + mode + " data)");
    if (oct)
        meshopt_decodeFilterOct(dst.data(), size_t(count), size_t(stride));
    else if (quat)
        meshopt_decodeFilterQuat(dst.data(), size_t(count), size_t(stride));
    else if (expo)
        meshopt_decodeFilterExp(dst.data(), size_t(count), size_t(stride));
    size_t view_stride = m.bufferViews[i].byteStride;
    int v = add_view(m, std::move(dst), view_stride);
    /* The view keeps its name and target; only where its bytes live changes. */
    tinygltf::BufferView &bv = m.bufferViews[i];
    bv.buffer = m.bufferViews[size_t(v)].buffer;
    bv.byteOffset = 0;
    bv.byteLength = m.bufferViews[size_t(v)].byteLength;
    m.bufferViews.pop_back();
    return true;
}

/* ---- KHR_draco_mesh_compression ------------------------------------------------------------ */

/* The decoded values of attribute a as the accessor declares them: floats (Draco
 * dequantizes and normalizes what it stored as integers), or the accessor's own integer
 * type when Draco stored integers (JOINTS_n as unsigned byte or short, normalized colours),
 * so the loader's checks of each attribute's formats see what the file declares. */
template <class T>
bool draco_values(const draco::PointAttribute *a, size_t np, int nc, std::vector<unsigned char> &bytes)
{
    T val[4];
    bytes.resize(np * size_t(nc) * sizeof(T));
    for (size_t k = 0; k < np; k++) {
        if (!a->ConvertValue<T>(a->mapped_index(draco::PointIndex(uint32_t(k))), int8_t(nc), val))
            return false;
        memcpy(&bytes[k * size_t(nc) * sizeof(T)], val, size_t(nc) * sizeof(T));
    }
    return true;
}

bool draco_is_integer(draco::DataType t)
{
    return t == draco::DT_INT8 || t == draco::DT_UINT8 || t == draco::DT_INT16 || t == draco::DT_UINT16 ||
           t == draco::DT_INT32 || t == draco::DT_UINT32;
}

bool draco_primitive(Out &o, size_t mi, size_t pi)
{
    tinygltf::Model &m = o.m;
    tinygltf::Primitive &p = m.meshes[mi].primitives[pi];
    const tinygltf::Value &e = *ext(p.extensions, "KHR_draco_mesh_compression");
    std::string what = "meshes[" + std::to_string(mi) + "].primitives[" + std::to_string(pi) +
                       "].extensions.KHR_draco_mesh_compression";
    long long view = member(e, "bufferView");
    if (view < 0 || size_t(view) >= m.bufferViews.size())
        return o.error(what + ": bufferView " + std::to_string(view) + " does not exist");
    const tinygltf::BufferView &bv = m.bufferViews[size_t(view)];
    const unsigned char *src = span(m, bv.buffer, (long long)bv.byteOffset, (long long)bv.byteLength);
    if (!src)
        return o.error(what + ": buffer view " + std::to_string(view) + " does not fit in its buffer");
    if (p.mode != TINYGLTF_MODE_TRIANGLES && p.mode != TINYGLTF_MODE_TRIANGLE_STRIP)
        return o.error(what + ": mode " + std::to_string(p.mode) + " is not triangles or a triangle strip");
    draco::DecoderBuffer in;
    in.Init(reinterpret_cast<const char *>(src), bv.byteLength);
    draco::Decoder dec;
    auto res = dec.DecodeMeshFromBuffer(&in);
    if (!res.ok())
        return o.error(what + ": Draco cannot decode buffer view " + std::to_string(view) + ": " +
                       res.status().error_msg_string());
    const draco::Mesh &mesh = *res.value();
    size_t np = mesh.num_points(), nf = mesh.num_faces();
    if (!e.Has("attributes") || !e.Get("attributes").IsObject())
        return o.error(what + ": has no attributes object");
    const tinygltf::Value &attrs = e.Get("attributes");
    for (const std::string &name : attrs.Keys()) {
        auto it = p.attributes.find(name);
        if (it == p.attributes.end())
            return o.error(what + ": attribute " + name + " is not one of the primitive's attributes");
        if (it->second < 0 || size_t(it->second) >= m.accessors.size())
            return o.error(what + ": " + name + " refers to accessor " + std::to_string(it->second) +
                           ", which does not exist");
        long long id = member(attrs, name.c_str());
        const draco::PointAttribute *a = id < 0 || id > 0xffffffffll ? nullptr
                                                                      : mesh.GetAttributeByUniqueId(uint32_t(id));
        if (!a)
            return o.error(what + ": the Draco data has no attribute " + std::to_string(id) + " (" + name + ")");
        tinygltf::Accessor &acc = m.accessors[size_t(it->second)];
        int nc = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
        if (nc < 1 || nc > 4 || acc.count != np)
            return o.error(what + ": " + name + " accessor " + std::to_string(it->second) + " (" +
                           std::to_string(acc.count) + " elements) does not match the " + std::to_string(np) +
                           " decoded points");
        if (a->num_components() != nc)
            return o.error(what + ".attributes." + name + ": accessors[" + std::to_string(it->second) + "] has " +
                           std::to_string(nc) + " components, but Draco attribute " + std::to_string(id) + " has " +
                           std::to_string(int(a->num_components())));
        if (np > o.max_elements)
            return o.error(what + ": " + std::to_string(np) + " points exceed the limit");
        const int ct = acc.componentType;
        const bool as_float = ct == TINYGLTF_COMPONENT_TYPE_FLOAT;
        if (!as_float && !draco_is_integer(a->data_type()))
            return o.error(what + ".attributes." + name + ": accessors[" + std::to_string(it->second) +
                           "] declares component type " + std::to_string(ct) + ", but Draco attribute " +
                           std::to_string(id) + " decodes to floats");
        const size_t size = as_float ? 4 : size_t(tinygltf::GetComponentSizeInBytes(uint32_t(ct)));
        if (size < 1 || size > 4 || !o.take(what, np * size_t(nc) * size))
            return size >= 1 && size <= 4 ? false : o.error(what + ": " + name + " has an unknown component type");
        std::vector<unsigned char> bytes;
        bool ok = ct == TINYGLTF_COMPONENT_TYPE_BYTE             ? draco_values<int8_t>(a, np, nc, bytes)
                  : ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE  ? draco_values<uint8_t>(a, np, nc, bytes)
                  : ct == TINYGLTF_COMPONENT_TYPE_SHORT          ? draco_values<int16_t>(a, np, nc, bytes)
                  : ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? draco_values<uint16_t>(a, np, nc, bytes)
                  : ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT   ? draco_values<uint32_t>(a, np, nc, bytes)
                                                                 : draco_values<float>(a, np, nc, bytes);
        if (!ok)
            return o.error(what + ": Draco cannot convert " + name + " to the accessor's component type");
        acc.bufferView = add_view(m, std::move(bytes), 0);
        acc.byteOffset = 0;
        if (as_float)
            acc.normalized = false; /* ConvertValue normalizes integer data that was */
        acc.sparse.isSparse = false;
    }
    if (p.indices < 0) { /* the decoded points are not in drawing order: index them */
        tinygltf::Accessor acc;
        acc.type = TINYGLTF_TYPE_SCALAR;
        acc.count = 3 * nf;
        p.indices = int(m.accessors.size());
        m.accessors.push_back(acc);
    }
    {
        if (size_t(p.indices) >= m.accessors.size())
            return o.error(what + ": indices accessor " + std::to_string(p.indices) + " does not exist");
        tinygltf::Accessor &acc = m.accessors[size_t(p.indices)];
        if (acc.count != 3 * nf || nf > o.max_elements)
            return o.error(what + ": indices accessor " + std::to_string(p.indices) + " (" +
                           std::to_string(acc.count) + " elements) does not match the " + std::to_string(nf) +
                           " decoded triangles");
        if (!o.take(what, nf * 12))
            return false;
        std::vector<unsigned char> bytes(nf * 12);
        for (size_t f = 0; f < nf; f++) {
            const draco::Mesh::Face &face = mesh.face(draco::FaceIndex(uint32_t(f)));
            for (int k = 0; k < 3; k++) {
                uint32_t x = face[k].value();
                memcpy(&bytes[(f * 3 + size_t(k)) * 4], &x, 4);
            }
        }
        acc.bufferView = add_view(m, std::move(bytes), 0);
        acc.byteOffset = 0;
        acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        acc.sparse.isSparse = false;
        /* Draco always decodes a triangle list (the extension's spec: strips are encoded as
         * their triangles). */
        p.mode = TINYGLTF_MODE_TRIANGLES;
    }
    return true;
}

} // namespace

bool gltf_decompress(tinygltf::Model &m, size_t max_elements, std::vector<std::string> *errors)
{
    Out o{m, max_elements, errors, max_elements * 16};
    size_t views = m.bufferViews.size();
    for (size_t i = 0; i < views; i++)
        if (ext(m.bufferViews[i].extensions, "EXT_meshopt_compression"))
            meshopt_view(o, i);
    /* Fallback buffers without a uri (EXT_meshopt_compression "fallback": true) hold no
     * bytes (gltf_json_patch gave them a placeholder): nothing may read them once
     * every compressed view over them is decoded. */
    for (size_t b = 0; b < m.buffers.size(); b++) {
        const tinygltf::Value *e = ext(m.buffers[b].extensions, "EXT_meshopt_compression");
        if (!e || !e->Has("gonio_no_data"))
            continue;
        for (size_t i = 0; i < views; i++)
            if (m.bufferViews[i].buffer == int(b))
                o.error("buffer view " + std::to_string(i) + " reads fallback buffer " + std::to_string(b) +
                        ", which holds no data (EXT_meshopt_compression: only compressed views may use it)");
    }
    for (size_t mi = 0; mi < m.meshes.size(); mi++)
        for (size_t pi = 0; pi < m.meshes[mi].primitives.size(); pi++)
            if (ext(m.meshes[mi].primitives[pi].extensions, "KHR_draco_mesh_compression"))
                draco_primitive(o, mi, pi);
    return errors->empty();
}

std::string gltf_json_patch(const char *json, size_t len, bool glb)
{
    if (!memmem(json, len, "KHR_draco_mesh_compression", 26) && !memmem(json, len, "EXT_meshopt_compression", 23))
        return "";
    /* A file nlohmann cannot parse is left to tinygltf, which says what is wrong. */
    nlohmann::json j = nlohmann::json::parse(json, json + len, nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("meshes") || !j["meshes"].is_array() ||
        !j.contains("accessors") || !j["accessors"].is_array())
        return "";
    bool changed = false;
    /* tinygltf 2.7 also reads a buffer without uri as a file named "": meshopt's fallback
     * buffers get one byte and a mark that they hold no data (see gltf_decompress). */
    if (j.contains("buffers") && j["buffers"].is_array())
        for (size_t i = glb ? 1 : 0; i < j["buffers"].size(); i++) {
            nlohmann::json &b = j["buffers"][i];
            if (b.is_object() && !b.contains("uri") && b.contains("extensions") && b["extensions"].is_object() &&
                b["extensions"].contains("EXT_meshopt_compression") &&
                b["extensions"]["EXT_meshopt_compression"].is_object()) {
                b["uri"] = "data:application/octet-stream;base64,AA==";
                b["byteLength"] = 1;
                b["extensions"]["EXT_meshopt_compression"]["gonio_no_data"] = true;
                changed = true;
            }
        }
    nlohmann::json &acc = j["accessors"];
    for (auto &mesh : j["meshes"]) {
        if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array())
            continue;
        for (auto &p : mesh["primitives"]) {
            if (!p.is_object() || !p.contains("indices") || !p["indices"].is_number_unsigned() ||
                !p.contains("extensions") || !p["extensions"].is_object() ||
                !p["extensions"].contains("KHR_draco_mesh_compression"))
                continue;
            const nlohmann::json &d = p["extensions"]["KHR_draco_mesh_compression"];
            size_t i = p["indices"].get<size_t>();
            if (!d.is_object() || !d.contains("bufferView") || !d["bufferView"].is_number_unsigned() ||
                i >= acc.size() || !acc[i].is_object() || acc[i].contains("bufferView"))
                continue;
            acc[i]["bufferView"] = d["bufferView"];
            changed = true;
        }
    }
    return changed ? j.dump() : "";
}
