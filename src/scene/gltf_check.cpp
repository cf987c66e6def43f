/* gltf_check.cpp: the model tinygltf returns, checked against the glTF 2.0 specification
 * before one byte is read: the asset and its extensions, buffers and views, accessors (and
 * their sparse parts) against their views, attribute formats (with KHR_mesh_quantization's),
 * the node hierarchy and scenes, cameras and lights. */
#include "gltf_internal.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace gltf {

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

/* Data-level problems the validator reports as errors but that cannot make reading unsafe:
 * warn, and let the geometry code deal with what it uses. False (and no warning) for an
 * accessor decompress decoded (its view's bytes in a buffer added after the file's: Draco's
 * new views, meshopt's views decoded in place) whose data lies outside its declared bounds:
 * those are the file's stale ones, said once by the caller. */
bool check_accessor_data(Ctx &c, int i)
{
    const auto &a = c.m.accessors[size_t(i)];
    size_t nc = num_comps(a);
    if (nc > 4 || (a.bufferView < 0 && !a.sparse.isSparse))
        return true;
    const bool decoded = a.bufferView >= 0 && size_t(a.bufferView) < c.m.bufferViews.size() &&
                         size_t(c.m.bufferViews[size_t(a.bufferView)].buffer) >= c.file_buffers;
    std::vector<double> d = read_accessor(c, i);
    std::string what = label("accessor", i, a.name);
    for (size_t j = 0; j < d.size(); j++) {
        double v = d[j];
        if (!std::isfinite(v)) {
            warn(c, "%s: element %zu is not finite", what.c_str(), j / nc);
            return true;
        }
        /* Declared bounds are decimal JSON numbers, the data float: allow the rounding. */
        double lo = a.minValues.empty() ? v : a.minValues[j % nc];
        double hi = a.maxValues.empty() ? v : a.maxValues[j % nc];
        double tol = 1e-6 * std::fmax(1.0, std::fmax(std::fabs(lo), std::fabs(hi)));
        if (v < lo - tol || v > hi + tol) {
            if (decoded)
                return false;
            warn(c, "%s: element %zu (%g) lies outside its declared min/max [%g, %g]", what.c_str(), j / nc, v, lo, hi);
            return true;
        }
    }
    return true;
}

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
        c.animated.push_back(animated);
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
    return !c.failed;
}

} // namespace gltf
