/* compress.cpp: testtool compress draco|meshopt IN.gltf OUT.gltf, the tests' encoder of
 * compressed glTF. Every triangle primitive of IN (a file with one embedded buffer, as gonio's
 * writer makes) is encoded by the libraries' own encoders, losslessly so the decoded file must
 * render exactly like IN: Draco with sequential connectivity and no quantization (floats kept
 * bit for bit), meshopt's vertex and index codecs (lossless by design) without filters.
 * Everything else of IN's JSON is kept as it is. */
#include <tiny_gltf.h>

#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using nlohmann::json;

namespace {

std::string base64(const std::vector<unsigned char> &d)
{
    static const char *t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string s;
    for (size_t i = 0; i < d.size(); i += 3) {
        uint32_t v = uint32_t(d[i]) << 16 | (i + 1 < d.size() ? uint32_t(d[i + 1]) << 8 : 0) |
                     (i + 2 < d.size() ? d[i + 2] : 0);
        s += t[v >> 18 & 63];
        s += t[v >> 12 & 63];
        s += i + 1 < d.size() ? t[v >> 6 & 63] : '=';
        s += i + 2 < d.size() ? t[v & 63] : '=';
    }
    return s;
}

/* An accessor's elements as tightly packed bytes (element size = components x component size). */
std::vector<unsigned char> packed(const tinygltf::Model &m, int ai, size_t *elem)
{
    const auto &a = m.accessors[size_t(ai)];
    const auto &v = m.bufferViews[size_t(a.bufferView)];
    size_t es = size_t(tinygltf::GetNumComponentsInType(uint32_t(a.type)) *
                       tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType)));
    size_t stride = v.byteStride ? v.byteStride : es;
    std::vector<unsigned char> out(a.count * es);
    const unsigned char *src = m.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset;
    for (size_t i = 0; i < a.count; i++)
        memcpy(&out[i * es], src + i * stride, es);
    *elem = es;
    return out;
}

/* Appends bytes (4-aligned) to the output buffer; returns their offset. */
size_t append(std::vector<unsigned char> &buf, const std::vector<unsigned char> &d)
{
    size_t off = buf.size();
    buf.insert(buf.end(), d.begin(), d.end());
    buf.resize((buf.size() + 3) & ~size_t(3), 0);
    return off;
}

int encode_draco(const tinygltf::Model &m, json &j, std::vector<unsigned char> &out)
{
    for (size_t mi = 0; mi < m.meshes.size(); mi++)
        for (size_t pi = 0; pi < m.meshes[mi].primitives.size(); pi++) {
            const auto &p = m.meshes[mi].primitives[pi];
            size_t np = m.accessors[size_t(p.attributes.at("POSITION"))].count;
            draco::Mesh mesh;
            mesh.set_num_points(uint32_t(np));
            json ids = json::object();
            for (const auto &at : p.attributes) {
                const auto &a = m.accessors[size_t(at.second)];
                /* Integer attributes (JOINTS_n, normalized colours and weights) keep their
                 * type: Draco stores them as integers, lossless too. */
                const int ct = a.componentType;
                const draco::DataType dt = ct == TINYGLTF_COMPONENT_TYPE_FLOAT            ? draco::DT_FLOAT32
                                           : ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE  ? draco::DT_UINT8
                                           : ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? draco::DT_UINT16
                                           : ct == TINYGLTF_COMPONENT_TYPE_BYTE           ? draco::DT_INT8
                                           : ct == TINYGLTF_COMPONENT_TYPE_SHORT          ? draco::DT_INT16
                                                                                          : draco::DT_UINT32;
                int nc = tinygltf::GetNumComponentsInType(uint32_t(a.type));
                int cs = tinygltf::GetComponentSizeInBytes(uint32_t(ct));
                draco::GeometryAttribute::Type t = at.first == "POSITION" ? draco::GeometryAttribute::POSITION
                                                   : at.first == "NORMAL" ? draco::GeometryAttribute::NORMAL
                                                   : at.first.compare(0, 8, "TEXCOORD") == 0
                                                       ? draco::GeometryAttribute::TEX_COORD
                                                   : at.first.compare(0, 6, "COLOR_") == 0 ? draco::GeometryAttribute::COLOR
                                                                                           : draco::GeometryAttribute::GENERIC;
                draco::GeometryAttribute ga;
                ga.Init(t, nullptr, int8_t(nc), dt, a.normalized, int64_t(cs * nc), 0);
                int id = mesh.AddAttribute(ga, true, uint32_t(np));
                size_t es;
                std::vector<unsigned char> d = packed(m, at.second, &es);
                for (size_t i = 0; i < np; i++)
                    mesh.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(uint32_t(i)), &d[i * es]);
                ids[at.first] = mesh.attribute(id)->unique_id();
            }
            const auto &ia = m.accessors[size_t(p.indices)];
            size_t es;
            std::vector<unsigned char> d = packed(m, p.indices, &es);
            for (size_t f = 0; f < ia.count / 3; f++) {
                draco::Mesh::Face face;
                for (int k = 0; k < 3; k++) {
                    uint32_t x = 0;
                    memcpy(&x, &d[(3 * f + size_t(k)) * es], es);
                    face[k] = draco::PointIndex(x);
                }
                mesh.AddFace(face);
            }
            draco::Encoder enc;
            enc.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING); /* no quantization set: lossless */
            draco::EncoderBuffer eb;
            draco::Status st = enc.EncodeMeshToBuffer(mesh, &eb);
            if (!st.ok())
                return fprintf(stderr, "compress: draco: %s\n", st.error_msg()), 1;
            std::vector<unsigned char> bytes(eb.data(), eb.data() + eb.size());
            size_t off = append(out, bytes);
            j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", off}, {"byteLength", bytes.size()}});
            json &jp = j["meshes"][mi]["primitives"][pi];
            jp["extensions"]["KHR_draco_mesh_compression"] = {{"bufferView", j["bufferViews"].size() - 1},
                                                             {"attributes", ids}};
            /* The accessors now have no data of their own, as the extension's spec says. */
            for (const auto &at : p.attributes)
                j["accessors"][size_t(at.second)].erase("bufferView"), j["accessors"][size_t(at.second)].erase("byteOffset");
            j["accessors"][size_t(p.indices)].erase("bufferView");
            j["accessors"][size_t(p.indices)].erase("byteOffset");
        }
    return 0;
}

/* Each accessor gets a view of its own over meshopt data; buffer 0 becomes the fallback. */
int encode_meshopt(const tinygltf::Model &m, json &j, std::vector<unsigned char> &out)
{
    for (size_t mi = 0; mi < m.meshes.size(); mi++)
        for (const auto &p : m.meshes[mi].primitives) {
            std::vector<std::pair<int, bool>> accs;
            for (const auto &at : p.attributes)
                accs.push_back({at.second, false});
            accs.push_back({p.indices, true});
            for (const auto &ai : accs) {
                const auto &a = m.accessors[size_t(ai.first)];
                size_t es;
                std::vector<unsigned char> d = packed(m, ai.first, &es), enc;
                if (ai.second) { /* 32-bit triangle indices */
                    std::vector<uint32_t> idx(a.count);
                    for (size_t i = 0; i < a.count; i++) {
                        uint32_t x = 0;
                        memcpy(&x, &d[i * es], es);
                        idx[i] = x;
                    }
                    enc.resize(meshopt_encodeIndexBufferBound(a.count, a.count));
                    enc.resize(meshopt_encodeIndexBuffer(enc.data(), enc.size(), idx.data(), a.count));
                    d.assign(reinterpret_cast<unsigned char *>(idx.data()),
                             reinterpret_cast<unsigned char *>(idx.data() + a.count));
                    es = 4;
                } else {
                    enc.resize(meshopt_encodeVertexBufferBound(a.count, es));
                    enc.resize(meshopt_encodeVertexBuffer(enc.data(), enc.size(), d.data(), a.count, es));
                }
                size_t off = append(out, enc);
                json view = {{"buffer", 0}, {"byteOffset", 0}, {"byteLength", d.size()},
                             {"extensions", {{"EXT_meshopt_compression",
                                              {{"buffer", 1}, {"byteOffset", off}, {"byteLength", enc.size()},
                                               {"byteStride", es}, {"count", a.count},
                                               {"mode", ai.second ? "TRIANGLES" : "ATTRIBUTES"}}}}}};
                if (!ai.second)
                    view["byteStride"] = es;
                j["bufferViews"].push_back(view);
                json &ja = j["accessors"][size_t(ai.first)];
                ja["bufferView"] = j["bufferViews"].size() - 1;
                ja.erase("byteOffset");
                if (ai.second)
                    ja["componentType"] = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
            }
        }
    return 0;
}

} // namespace

extern "C" int tool_compress(const char *how, const char *in, const char *outp)
{
    tinygltf::TinyGLTF loader;
    tinygltf::Model m;
    std::string err, warn;
    if (!loader.LoadASCIIFromFile(&m, &err, &warn, in))
        return fprintf(stderr, "compress: %s: %s\n", in, err.c_str()), 1;
    std::ifstream f(in);
    std::stringstream ss;
    ss << f.rdbuf();
    json j = json::parse(ss.str());
    std::vector<unsigned char> out;
    bool dr = !strcmp(how, "draco");
    int rc = dr ? encode_draco(m, j, out) : encode_meshopt(m, j, out);
    if (rc)
        return rc;
    const char *name = dr ? "KHR_draco_mesh_compression" : "EXT_meshopt_compression";
    json data = {{"byteLength", out.size()}, {"uri", "data:application/octet-stream;base64," + base64(out)}};
    if (dr) {
        j["buffers"].push_back(data); /* buffer 0 keeps the images, if any */
        for (auto &v : j["bufferViews"])
            if (v["buffer"] == 0 && !v.contains("byteOffset"))
                v["byteOffset"] = 0;
        for (size_t i = m.bufferViews.size(); i < j["bufferViews"].size(); i++)
            j["bufferViews"][i]["buffer"] = j["buffers"].size() - 1;
    } else {
        /* The original bytes go: only the compressed ones remain (a loader that ignored the
         * extension would read nothing). */
        j["buffers"][0] = {{"byteLength", j["buffers"][0]["byteLength"]},
                           {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}};
        j["buffers"][1] = data;
        for (size_t i = 0; i < m.bufferViews.size(); i++) /* the old views: nothing reads them */
            j["bufferViews"][i] = {{"buffer", 1}, {"byteLength", 4}};
    }
    for (const char *k : {"extensionsUsed", "extensionsRequired"})
        j[k].push_back(name);
    std::ofstream o(outp);
    o << j.dump(1) << "\n";
    return o.good() ? 0 : 1;
}
