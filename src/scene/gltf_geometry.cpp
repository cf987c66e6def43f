/* gltf_geometry.cpp: the geometry of a glTF file: accessors read (sparse, normalised), the
 * node hierarchy's transforms, primitives as triangles (strips and fans, flat normals, vertex
 * colours, MikkTSpace tangents for the materials that need them), the placements of the
 * scene's meshes (nodes, and EXT_mesh_gpu_instancing's instances): a mesh placed once baked
 * into world space, one placed several times kept once in its own space with an instance
 * per placement (scene_instanced_mesh, scene_instance); cameras and lights baked into world
 * space; normals with the cofactor matrix (the
 * inverse transpose up to det, Lengyel, "Mathematics for 3D Game Programming and Computer
 * Graphics", 3rd ed., 4.5). */
#include "gltf_internal.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

extern "C" {
#include "tangent.h"
#include "vec.h"
}

namespace gltf {

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

double mat_cofactors3(const Mat &m, double a[3][3], double cof[3][3])
{
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++)
            a[r][k] = m[size_t(k * 4 + r)];
    return vec_cofactors3(a, cof);
}

/* T R S as a matrix: translation t, rotation by the unit quaternion q (x, y, z, w), scale s. */
Mat trs_matrix(const double t[3], const double q[4], const double s[3])
{
    double x = q[0], y = q[1], z = q[2], w = q[3];
    const double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w),
                         2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                         2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y)};
    Mat out{};
    for (int col = 0; col < 3; col++)
        for (int row = 0; row < 3; row++)
            out[size_t(col * 4 + row)] = r[col * 3 + row] * s[col];
    out[12] = t[0];
    out[13] = t[1];
    out[14] = t[2];
    out[15] = 1;
    return out;
}

bool node_local(Ctx &c, int i, Mat &out, const Pose *pose)
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
    const double u[4] = {q[0] / len, q[1] / len, q[2] / len, q[3] / len};
    out = trs_matrix(t, u, s);
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
    f.influences = p.influences;
    f.joints = std::move(p.joints);
    f.weights = std::move(p.weights);
    f.targets = std::move(p.targets);
    f.max_joint = p.max_joint;
    f.max_joint_at = std::move(p.max_joint_at);
    f.flat = true;
    remap_skin_and_targets(f, p.idx.data(), nt * 3);
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
    remap_skin_and_targets(p, remap, n);
    p.tan.assign(tan, tan + n * 4);
    free(remap);
    free(tan);
}

/* Are all of p's triangles of zero area (their corners on one line or at one point)? */
static bool all_degenerate(const Prim &p)
{
    for (size_t t = 0; t < p.idx.size(); t += 3) {
        const float *a = &p.pos[3 * size_t(p.idx[t])], *b = &p.pos[3 * size_t(p.idx[t + 1])], *d = &p.pos[3 * size_t(p.idx[t + 2])];
        double u[3], v[3];
        for (int k = 0; k < 3; k++)
            u[k] = double(b[k]) - a[k], v[k] = double(d[k]) - a[k];
        if (u[1] * v[2] - u[2] * v[1] != 0 || u[2] * v[0] - u[0] * v[2] != 0 || u[0] * v[1] - u[1] * v[0] != 0)
            return false;
    }
    return true;
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
    /* Nothing can ever hit a primitive of zero-area triangles unless a morph target or a
     * skin moves its corners apart: dropped here, before normals, tangents or a tree are made
     * of it (a 4 M-vertex accessor of zeros is a few hundred bytes of JSON). */
    if (p.targets.empty() && !p.attributes.count("JOINTS_0") && !out.idx.empty() && all_degenerate(out)) {
        warn(c, "%s: all %zu triangles have zero area (skipped)", what.c_str(), out.idx.size() / 3);
        return false;
    }
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
    if (!read_skin_and_targets(c, mi, pi, out))
        return false;
    if (out.nrm.empty())
        make_flat(out);
    /* a normal map, a clearcoat normal map or anisotropy needs tangents (the mesh's, else
     * MikkTSpace's) on the set its texture reads */
    int set = p.material >= 0 ? material_tangent_set(c, uint32_t(p.material)) : -1;
    const std::vector<float> &tuv = set == 1 ? out.uv1 : out.uv;
    if (out.tan.empty() && !tuv.empty() && set >= 0)
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
/* EXT_mesh_gpu_instancing (checked with the document: Doc::check_gpu_instancing): node i's mesh
 * placed once by each instance's T R S (absent attributes: none, the identity, one), after
 * the node's own world transform. The node's mesh is drawn only by them. */
bool gpu_instances(Ctx &c, int i, const Mat &world, std::vector<Instance> &inst)
{
    const auto &n = c.m.nodes[size_t(i)];
    const tinygltf::Value &attrs = n.extensions.at("EXT_mesh_gpu_instancing").Get("attributes");
    const char *names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
    std::vector<double> v[3];
    size_t count = 0;
    for (int k = 0; k < 3; k++)
        if (attrs.Has(names[k])) {
            int a = attrs.Get(names[k]).GetNumberAsInt();
            count = c.m.accessors[size_t(a)].count;
            if (inst.size() + count > SCENE_MAX_INSTANCES)
                return fail(c, "%s: EXT_mesh_gpu_instancing places %zu instances, more than the %u a scene may have",
                            label("node", i, n.name).c_str(), inst.size() + count, SCENE_MAX_INSTANCES);
            v[k] = read_accessor(c, a);
        }
    std::string what = label("node", i, n.name) + ": EXT_mesh_gpu_instancing";
    size_t not_unit = 0;
    for (size_t j = 0; j < count; j++) {
        double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s3[3] = {1, 1, 1};
        if (!v[0].empty())
            std::copy(&v[0][3 * j], &v[0][3 * j + 3], t);
        if (!v[1].empty())
            std::copy(&v[1][4 * j], &v[1][4 * j + 4], q);
        if (!v[2].empty())
            std::copy(&v[2][3 * j], &v[2][3 * j + 3], s3);
        double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        for (int k = 0; k < 3; k++)
            if (!std::isfinite(t[k]) || !std::isfinite(s3[k]))
                return fail(c, "%s: instance %zu: its translation or scale is not finite", what.c_str(), j);
        if (!(len > 1e-6) || !std::isfinite(len))
            return fail(c, "%s: instance %zu: rotation is not a unit quaternion (length %g)", what.c_str(), j, len);
        not_unit += std::fabs(len - 1) > 1e-3; /* (a quantized one is unit to its rounding: 1e-3 > 2^-8) */
        for (double &x : q)
            x /= len;
        Mat w = mat_mul(world, trs_matrix(t, q, s3));
        if (!mat_finite(w))
            return fail(c, "%s: instance %zu: world transform is not finite", what.c_str(), j);
        Instance it{i, n.mesh, w};
        it.gpu = true;
        inst.push_back(it);
    }
    if (not_unit)
        warn(c, "%s: %zu instance rotation(s) are not unit quaternions (normalised)", what.c_str(), not_unit);
    return true;
}

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
            it.moving = it.moving || (size_t(it.node) < c.animated.size() && c.animated[size_t(it.node)]);
            if (!mat_finite(it.world))
                return fail(c, "%s: world transform is not finite", label("node", it.node, n.name).c_str());
            if (n.mesh >= 0 && n.extensions.count("EXT_mesh_gpu_instancing")) {
                size_t first = inst.size();
                if (!gpu_instances(c, it.node, it.world, inst))
                    return false;
                for (size_t k = first; k < inst.size(); k++)
                    inst[k].moving = it.moving;
            } else if (n.mesh >= 0) {
                Instance mi{it.node, n.mesh, it.world};
                mi.moving = it.moving;
                inst.push_back(mi);
            }
            if (n.camera >= 0 && c.camera_ok[size_t(n.camera)])
                cams.push_back(it);
            int light = node_light(n);
            if (light >= 0 && c.light_ok[size_t(light)])
                lights.push_back(it);
            for (auto ch = n.children.rbegin(); ch != n.children.rend(); ++ch) {
                Instance next{*ch, -1, it.world};
                next.moving = it.moving;
                stack.push_back(next);
            }
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

/* Instance in's mesh, posed for its node (skins, morph targets: pose_primitive) and
 * transformed by w, into vertices, indices and tri_material, from vertex vbase (the indices'
 * base too) and triangle tbase; false on a bad pose. */
bool bake_mesh(Ctx &c, const Instance &in, const Mat &w, GnVertex *vertices, uint32_t *indices, uint32_t *tri_material,
               uint32_t vbase, uint32_t tbase, scene *out)
{
    /* Normals go through the cofactor matrix, det * inverse transpose: defined even for a
     * singular matrix; multiplied by sign(det) so mirroring keeps them pointing out. */
    double a[3][3], cof[3][3];
    double det = mat_cofactors3(w, a, cof);
    double sgn = det < 0 ? -1 : 1;
    uint32_t default_material = uint32_t(c.m.materials.size());
    for (const Prim &base : c.meshes[size_t(in.mesh)]) {
        Prim posed; /* skinned or morphed: this node's own copy */
        const double t0 = util_now();
        const Prim &p = pose_primitive(c, in, base, posed) ? posed : base;
        out->pose_seconds += util_now() - t0;
        if (c.failed)
            return false;
        if (p.pos.size() != base.pos.size() || p.idx.size() != base.idx.size())
            return fail(c, "%s: posing changed its vertex count", label("mesh", in.mesh, c.m.meshes[size_t(in.mesh)].name).c_str());
        size_t pv = p.pos.size() / 3;
        for (size_t v = 0; v < pv; v++) {
            GnVertex &o = vertices[vbase + v];
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
            uint32_t *dst = &indices[(tbase + t) * 3];
            dst[0] = vbase + p.idx[t * 3];
            dst[1] = vbase + p.idx[t * 3 + (det < 0 ? 2 : 1)]; /* mirrored: keep front faces */
            dst[2] = vbase + p.idx[t * 3 + (det < 0 ? 1 : 2)];
            tri_material[tbase + t] = p.material == GN_INVALID ? default_material : p.material;
        }
        vbase += uint32_t(pv);
        tbase += uint32_t(pt);
    }
    return true;
}

/* w as an instance's transform (scene_instance: 3x4, row-major, float); false when that is
 * not invertible in float (a scale that flattens the mesh: then it is baked, which the
 * cofactor normals allow). */
bool instance_transform(const Mat &w, float out[12])
{
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 4; k++)
            out[4 * r + k] = float(w[size_t(k * 4 + r)]);
    double a[3][3], c[3][3];
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++)
            a[r][k] = out[4 * r + k];
    double det = vec_cofactors3(a, c);
    if (!(det != 0) || !std::isfinite(det))
        return false;
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++)
            if (!std::isfinite(float(c[k][r] / det)))
                return false;
    return true;
}

/* Whether instance in's geometry is its node's own: skinned, or a mesh with morph targets. */
static bool posed_mesh(const Ctx &c, const Instance &in)
{
    if (instance_skinned(c, in))
        return true;
    for (const Prim &p : c.meshes[size_t(in.mesh)])
        if (!p.targets.empty())
            return true;
    return false;
}

/* The instances' geometry: a mesh that several nodes use, or that EXT_mesh_gpu_instancing
 * places, or (scene_instance_animated) that an animation moves, is kept once in its own
 * space (scene_instanced_mesh) and placed by instances; the others, and placements whose
 * transform is not invertible, are baked into world space. */
bool bake_geometry(Ctx &c, const std::vector<Instance> &inst, scene *out)
{
    std::vector<uint32_t> uses(c.meshes.size(), 0), imesh(c.meshes.size(), GN_INVALID);
    std::vector<bool> gpu(c.meshes.size(), false);
    std::vector<float> xf(12 * inst.size());
    std::vector<bool> placed(inst.size(), false);
    for (const auto &in : inst) {
        uses[size_t(in.mesh)]++;
        gpu[size_t(in.mesh)] = gpu[size_t(in.mesh)] || in.gpu;
    }
    uint64_t nv = 0, nt = 0, np = 0, ni = 0;
    uint32_t meshes = 0;
    for (size_t i = 0; i < inst.size(); i++) {
        size_t m = size_t(inst[i].mesh);
        uint64_t mv = 0, mt = 0;
        for (const Prim &p : c.meshes[m]) {
            mv += p.pos.size() / 3;
            mt += p.idx.size() / 3;
        }
        np += c.meshes[m].size();
        /* a skinned or morphed mesh is posed per node, in world space: never placed */
        placed[i] = !posed_mesh(c, inst[i]) && (uses[m] > 1 || gpu[m] || (instance_animated && inst[i].moving)) && mt > 0 &&
                    instance_transform(inst[i].world, &xf[12 * i]);
        if (!placed[i]) {
            nv += mv;
            nt += mt;
            continue;
        }
        ni++;
        if (imesh[m] == GN_INVALID) { /* its first placement: the mesh is stored, once */
            imesh[m] = meshes++;
            nv += mv;
            nt += mt;
        }
    }
    if (nv > MAX_SCENE || nt > MAX_SCENE)
        return fail(c, "scene too large: %llu triangles and %llu vertices after instancing; the limit is %zu each",
                    (unsigned long long)nt, (unsigned long long)nv, MAX_SCENE);
    if (ni > SCENE_MAX_INSTANCES)
        return fail(c, "scene too large: %llu instances; the limit is %u", (unsigned long long)ni, SCENE_MAX_INSTANCES);
    uint64_t wv = 0, wt = 0;
    for (size_t i = 0; i < inst.size(); i++)
        for (const Prim &p : c.meshes[size_t(inst[i].mesh)])
            if (!placed[i]) {
                wv += p.pos.size() / 3;
                wt += p.idx.size() / 3;
            }
    out->num_vertices = uint32_t(wv);
    out->num_triangles = uint32_t(wt);
    out->num_meshes = uint32_t(np);
    out->vertices = static_cast<GnVertex *>(util_calloc(wv, sizeof(GnVertex)));
    out->indices = static_cast<uint32_t *>(util_calloc(wt * 3, sizeof(uint32_t)));
    out->tri_material = static_cast<uint32_t *>(util_calloc(wt, sizeof(uint32_t)));
    out->num_instanced_meshes = meshes;
    out->instanced_meshes = static_cast<scene_instanced_mesh *>(util_calloc(meshes, sizeof(scene_instanced_mesh)));
    out->num_instances = uint32_t(ni);
    out->instances = static_cast<scene_instance *>(util_calloc(ni, sizeof(scene_instance)));
    uint32_t vbase = 0, tbase = 0, k = 0;
    Mat id{};
    id[0] = id[5] = id[10] = id[15] = 1;
    for (size_t i = 0; i < inst.size(); i++) {
        const Instance &in = inst[i];
        if (!placed[i]) {
            /* a skin places its vertices in the world: its node's transform is not applied */
            if (!bake_mesh(c, in, instance_skinned(c, in) ? id : in.world, out->vertices, out->indices,
                           out->tri_material, vbase, tbase, out))
                return false;
            for (const Prim &p : c.meshes[size_t(in.mesh)]) {
                vbase += uint32_t(p.pos.size() / 3);
                tbase += uint32_t(p.idx.size() / 3);
            }
            continue;
        }
        uint32_t m = imesh[size_t(in.mesh)];
        scene_instanced_mesh &im = out->instanced_meshes[m];
        if (!im.vertices) { /* the mesh's data, once, in its own space */
            for (const Prim &p : c.meshes[size_t(in.mesh)]) {
                im.num_vertices += uint32_t(p.pos.size() / 3);
                im.num_triangles += uint32_t(p.idx.size() / 3);
            }
            im.gltf_mesh = uint32_t(in.mesh);
            im.vertices = static_cast<GnVertex *>(util_calloc(im.num_vertices, sizeof(GnVertex)));
            im.indices = static_cast<uint32_t *>(util_calloc(3 * size_t(im.num_triangles), sizeof(uint32_t)));
            im.tri_material = static_cast<uint32_t *>(util_calloc(im.num_triangles, sizeof(uint32_t)));
            if (!bake_mesh(c, in, id, im.vertices, im.indices, im.tri_material, 0, 0, out))
                return false;
        }
        scene_instance &o = out->instances[k++];
        memcpy(o.to_world, &xf[12 * i], sizeof o.to_world);
        o.mesh = m;
        o.node = uint32_t(in.node);
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

} // namespace gltf
