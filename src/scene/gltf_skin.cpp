/* gltf_skin.cpp: skins and morph targets (glTF 2.0, "Skins" and "Morph Targets"): their
 * checks, their per-vertex data, and a primitive posed for the node that draws it, in the
 * specification's order: the morph targets' displacements weighted and added, then linear
 * blend skinning, each vertex moved by the weighted sum of its joints' matrices (the joint's
 * world transform at the render's time times its inverse bind matrix), which places it in
 * world space (the skinned node's own transform is ignored). Normals take the cofactor of
 * that sum, tangents the sum itself. A posed primitive belongs to its node alone: it is
 * baked like any other, triangles in world space. */
#include "gltf_internal.h"
#include "vec.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace gltf {

namespace {

/* What skins and morph targets add per vertex, summed over the primitives before any is read:
 * 4 joint-weight pairs per JOINTS_n/WEIGHTS_n set and 3 floats per target attribute, counted
 * in vertex-attributes (a file of a few hundred bytes can list one large accessor as
 * thousands of targets). 2^26 of them is 800 MB at most. */
const uint64_t MAX_SKIN_MORPH = uint64_t(1) << 26;

size_t mesh_targets(const tinygltf::Model &m, int mesh)
{
    if (!in_range(mesh, m.meshes.size()) || m.meshes[size_t(mesh)].primitives.empty())
        return 0;
    return m.meshes[size_t(mesh)].primitives[0].targets.size();
}

/* The set number n of an attribute "PREFIXn", or -1. */
int set_number(const std::string &name, const char *prefix)
{
    size_t n = strlen(prefix);
    if (name.compare(0, n, prefix) != 0 || name.size() == n || name.size() > n + 4)
        return -1;
    for (size_t i = n; i < name.size(); i++)
        if (name[i] < '0' || name[i] > '9')
            return -1;
    return atoi(name.c_str() + n);
}

std::string prim_path(int mi, int pi)
{
    return "meshes[" + std::to_string(mi) + "].primitives[" + std::to_string(pi) + "]";
}

Mat identity()
{
    Mat m{};
    m[0] = m[5] = m[10] = m[15] = 1;
    return m;
}

} // namespace

bool check_skins_and_targets(Ctx &c)
{
    const auto &m = c.m;
    const bool quant = uses_extension(m, "KHR_mesh_quantization");
    for (size_t si = 0; si < m.skins.size(); si++) {
        const auto &s = m.skins[si];
        const std::string p = "skins[" + std::to_string(si) + "]";
        if (s.joints.empty())
            return fail(c, "%s.joints: is empty (a skin has at least one joint)", p.c_str());
        std::vector<bool> seen(m.nodes.size(), false);
        for (size_t j = 0; j < s.joints.size(); j++) {
            int n = s.joints[j];
            if (!in_range(n, m.nodes.size()))
                return fail(c, "%s.joints[%zu]: node %d does not exist", p.c_str(), j, n);
            if (seen[size_t(n)])
                return fail(c, "%s.joints[%zu]: node %d is listed twice (a skin's joints are unique)", p.c_str(), j, n);
            seen[size_t(n)] = true;
        }
        if (s.skeleton != -1 && !in_range(s.skeleton, m.nodes.size()))
            return fail(c, "%s.skeleton: node %d does not exist", p.c_str(), s.skeleton);
        if (s.inverseBindMatrices != -1) {
            if (!in_range(s.inverseBindMatrices, m.accessors.size()))
                return fail(c, "%s.inverseBindMatrices: accessor %d does not exist", p.c_str(), s.inverseBindMatrices);
            const auto &a = m.accessors[size_t(s.inverseBindMatrices)];
            if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || a.type != TINYGLTF_TYPE_MAT4)
                return fail(c, "%s.inverseBindMatrices: accessor %d is %s of component type %d, not float MAT4",
                            p.c_str(), s.inverseBindMatrices, type_name(a.type), a.componentType);
            if (a.count < s.joints.size())
                return fail(c, "%s.inverseBindMatrices: accessor %d has %zu matrices for %zu joints", p.c_str(),
                            s.inverseBindMatrices, a.count, s.joints.size());
        }
    }
    uint64_t budget = 0;
    for (size_t mi = 0; mi < m.meshes.size(); mi++) {
        const auto &mesh = m.meshes[mi];
        const size_t nt = mesh_targets(m, int(mi));
        for (size_t pi = 0; pi < mesh.primitives.size(); pi++) {
            const auto &pr = mesh.primitives[pi];
            const std::string pp = prim_path(int(mi), int(pi));
            if (pr.targets.size() != nt)
                return fail(c, "%s.targets: %zu morph targets, but primitives[0] has %zu (every primitive of a mesh "
                            "has the same number)", pp.c_str(), pr.targets.size(), nt);
            auto pos = pr.attributes.find("POSITION");
            if (pos == pr.attributes.end() || !in_range(pos->second, m.accessors.size()))
                continue; /* skipped with a warning when read */
            const size_t nv = m.accessors[size_t(pos->second)].count;
            /* flat normals (no NORMAL) give each triangle corner a vertex, and so may MikkTSpace
             * tangents (no TANGENT): at most 3 a triangle, at most 3 an index (strips, fans) */
            const size_t indices = in_range(pr.indices, m.accessors.size()) ? m.accessors[size_t(pr.indices)].count : nv;
            const uint64_t drawn = pr.attributes.count("NORMAL") && pr.attributes.count("TANGENT")
                                       ? nv : 3 * uint64_t(std::max(nv, indices));
            uint64_t per_vertex = 0;
            for (const auto &attr : pr.attributes) {
                const bool jo = set_number(attr.first, "JOINTS_") >= 0, we = set_number(attr.first, "WEIGHTS_") >= 0;
                if (!jo && !we)
                    continue;
                const int set = set_number(attr.first, jo ? "JOINTS_" : "WEIGHTS_");
                const std::string other = (jo ? "WEIGHTS_" : "JOINTS_") + std::to_string(set);
                if (!pr.attributes.count(other))
                    return fail(c, "%s.attributes.%s: has no %s beside it (joints and weights come in sets)",
                                pp.c_str(), attr.first.c_str(), other.c_str());
                per_vertex += jo ? 4 : 0;
            }
            for (size_t ti = 0; ti < pr.targets.size(); ti++)
                for (const auto &attr : pr.targets[ti]) {
                    const std::string tp = pp + ".targets[" + std::to_string(ti) + "]." + attr.first;
                    const bool position = attr.first == "POSITION";
                    const bool uv = attr.first == "TEXCOORD_0" || attr.first == "TEXCOORD_1", col = attr.first == "COLOR_0";
                    if (!position && attr.first != "NORMAL" && attr.first != "TANGENT" && !uv && !col)
                        continue; /* the other sets are not read, nor are their bases: nothing to morph */
                    if (!in_range(attr.second, m.accessors.size()))
                        return fail(c, "%s: accessor %d does not exist", tp.c_str(), attr.second);
                    const auto &a = m.accessors[size_t(attr.second)];
                    if (uv || col) { /* glTF 2.0, "Morph Targets": float or normalized integers */
                        const unsigned ok = F_F | F_I8N | F_U8N | F_I16N | F_U16N;
                        const bool type = uv ? a.type == TINYGLTF_TYPE_VEC2 : a.type == TINYGLTF_TYPE_VEC3 || a.type == TINYGLTF_TYPE_VEC4;
                        if (!type || !(format_bit(a) & ok))
                            return fail(c, "%s: accessor %d (%s, component type %d%s) is not allowed for a morph "
                                        "target's %s (%s of floats or normalized integers)", tp.c_str(), attr.second,
                                        type_name(a.type), a.componentType, a.normalized ? " normalized" : "",
                                        uv ? "texture coordinates" : "colour", uv ? "VEC2" : "VEC3 or VEC4");
                        if (a.count != nv)
                            return fail(c, "%s: accessor %d has %zu elements, but the primitive has %zu vertices",
                                        tp.c_str(), attr.second, a.count, nv);
                        per_vertex += uv ? 2 : 4;
                        continue;
                    }
                    /* glTF 2.0 and KHR_mesh_quantization: float VEC3, or with the extension
                     * (normalized) byte and short, non-normalized ones only for POSITION */
                    const unsigned allowed = !quant ? F_F : position ? F_F | F_I8 | F_I8N | F_I16 | F_I16N
                                                                     : F_F | F_I8N | F_I16N;
                    if (a.type != TINYGLTF_TYPE_VEC3 || !(format_bit(a) & allowed))
                        return fail(c, "%s: accessor %d (%s, component type %d%s) is not allowed for a morph "
                                    "target's displacement (float VEC3%s)", tp.c_str(), attr.second, type_name(a.type),
                                    a.componentType, a.normalized ? " normalized" : "",
                                    quant ? ", or the integer types KHR_mesh_quantization lists" : "");
                    if (a.count != nv)
                        return fail(c, "%s: accessor %d has %zu elements, but the primitive has %zu vertices",
                                    tp.c_str(), attr.second, a.count, nv);
                    per_vertex += 3;
                }
            budget += per_vertex * drawn;
            if (budget > MAX_SKIN_MORPH)
                return fail(c, "scene too large: its skins' and morph targets' data exceed %llu vertex attributes "
                            "(at %s)", (unsigned long long)MAX_SKIN_MORPH, pp.c_str());
        }
        if (!mesh.weights.empty() && mesh.weights.size() != nt)
            return fail(c, "meshes[%zu].weights: %zu weights for %zu morph targets", mi, mesh.weights.size(), nt);
    }
    for (size_t ni = 0; ni < m.nodes.size(); ni++) {
        const auto &n = m.nodes[ni];
        const std::string p = "nodes[" + std::to_string(ni) + "]";
        if (!n.weights.empty() && !in_range(n.mesh, m.meshes.size()))
            return fail(c, "%s.weights: the node has no mesh to weight the morph targets of", p.c_str());
        if (!n.weights.empty() && n.weights.size() != mesh_targets(m, n.mesh))
            return fail(c, "%s.weights: %zu weights for the %zu morph targets of meshes[%d]", p.c_str(),
                        n.weights.size(), mesh_targets(m, n.mesh), n.mesh);
        if (n.skin < 0 || !in_range(n.mesh, m.meshes.size()))
            continue;
        const auto &prims = m.meshes[size_t(n.mesh)].primitives;
        for (size_t pi = 0; pi < prims.size(); pi++)
            if (!prims[pi].attributes.count("JOINTS_0") || !prims[pi].attributes.count("WEIGHTS_0"))
                return fail(c, "%s.skin: %s has no JOINTS_0 and WEIGHTS_0, which a skinned mesh's primitives need",
                            p.c_str(), prim_path(n.mesh, int(pi)).c_str());
    }
    for (size_t ai = 0; ai < m.animations.size(); ai++) {
        const auto &a = m.animations[ai];
        for (size_t ci = 0; ci < a.channels.size(); ci++) {
            const auto &ch = a.channels[ci];
            if (ch.target_path != "weights" || !in_range(ch.target_node, m.nodes.size()) ||
                !in_range(ch.sampler, a.samplers.size()))
                continue; /* the rest: check_animations */
            const std::string pc = "animations[" + std::to_string(ai) + "].channels[" + std::to_string(ci) + "]";
            const int mesh = m.nodes[size_t(ch.target_node)].mesh;
            const size_t nt = mesh_targets(m, mesh);
            if (nt == 0)
                return fail(c, "%s.target: node %d has no morph targets to weight", pc.c_str(), ch.target_node);
            const auto &s = a.samplers[size_t(ch.sampler)];
            if (!in_range(s.input, m.accessors.size()) || !in_range(s.output, m.accessors.size()) ||
                m.accessors[size_t(s.output)].type != TINYGLTF_TYPE_SCALAR)
                continue; /* check_animations */
            const size_t keys = m.accessors[size_t(s.input)].count, per = s.interpolation == "CUBICSPLINE" ? 3 : 1;
            const size_t have = m.accessors[size_t(s.output)].count;
            if (have != keys * per * nt)
                return fail(c, "animations[%zu].samplers[%d].output: accessor %d has %zu values, but %zu key(s)%s of "
                            "the %zu morph targets of meshes[%d] (%s.target.node %d) need %zu", ai, ch.sampler, s.output,
                            have, keys, per == 3 ? " x 3 (in-tangent, value, out-tangent)" : "", nt, mesh, pc.c_str(),
                            ch.target_node, keys * per * nt);
        }
    }
    return true;
}

bool read_skin_and_targets(Ctx &c, int mi, int pi, Prim &out)
{
    const auto &pr = c.m.meshes[size_t(mi)].primitives[size_t(pi)];
    const std::string pp = prim_path(mi, pi);
    const size_t nv = out.pos.size() / 3;
    std::vector<int> sets;
    for (const auto &attr : pr.attributes)
        if (set_number(attr.first, "JOINTS_") >= 0)
            sets.push_back(set_number(attr.first, "JOINTS_"));
    std::sort(sets.begin(), sets.end());
    out.influences = 4 * sets.size();
    out.joints.assign(nv * out.influences, 0);
    out.weights.assign(nv * out.influences, 0.0f);
    for (size_t s = 0; s < sets.size(); s++) {
        const std::string jn = "JOINTS_" + std::to_string(sets[s]), wn = "WEIGHTS_" + std::to_string(sets[s]);
        std::vector<double> j = read_accessor(c, pr.attributes.at(jn)), w = read_accessor(c, pr.attributes.at(wn));
        for (size_t v = 0; v < nv; v++)
            for (size_t k = 0; k < 4; k++) {
                const double wt = w[v * 4 + k];
                if (!(wt >= 0) || !std::isfinite(wt))
                    return fail(c, "%s.attributes.%s: vertex %zu has weight %g (weights are finite and >= 0)",
                                pp.c_str(), wn.c_str(), v, wt);
                const size_t o = v * out.influences + s * 4 + k;
                out.joints[o] = uint16_t(j[v * 4 + k]);
                out.weights[o] = float(wt);
                if (wt > 0 && int(j[v * 4 + k]) > out.max_joint) {
                    out.max_joint = int(j[v * 4 + k]);
                    out.max_joint_at = pp + ".attributes." + jn + ": vertex " + std::to_string(v);
                }
            }
    }
    /* glTF 2.0, "Skinned Mesh Attributes": the weights of a vertex sum to one. Normalized
     * bytes cannot quite (4 x 0.5 / 255 off at most); farther off they are renormalised. */
    bool off = false, zero = false;
    for (size_t v = 0; v < nv && out.influences; v++) {
        float *w = &out.weights[v * out.influences];
        double sum = 0;
        for (size_t k = 0; k < out.influences; k++)
            sum += w[k];
        if (!(sum > 0)) {
            zero = true;
            continue;
        }
        off = off || std::fabs(sum - 1) > 1e-2;
        for (size_t k = 0; k < out.influences; k++)
            w[k] = float(w[k] / sum);
    }
    if (off)
        warn(c, "%s: joint weights that do not sum to one (renormalised)", pp.c_str());
    if (zero)
        warn(c, "%s: vertices whose joint weights are all zero (drawn with the node's own transform)", pp.c_str());
    out.targets.resize(pr.targets.size());
    bool warned = false;
    for (size_t ti = 0; ti < pr.targets.size(); ti++)
        for (const auto &attr : pr.targets[ti]) {
            const std::string tp = pp + ".targets[" + std::to_string(ti) + "]." + attr.first;
            Prim::Target &t = out.targets[ti];
            const std::string &n = attr.first;
            /* a displacement of an attribute the primitive has (a TEXCOORD or COLOR one without
             * its base changes nothing gonio draws) */
            std::vector<float> *dst = n == "POSITION" ? &t.pos : n == "NORMAL" ? &t.nrm : n == "TANGENT" ? &t.tan
                                      : n == "TEXCOORD_0" ? (out.uv.empty() ? nullptr : &t.uv)
                                      : n == "TEXCOORD_1" ? (out.uv1.empty() ? nullptr : &t.uv1)
                                      : n == "COLOR_0" ? (out.col.empty() ? nullptr : &t.col) : nullptr;
            if (!dst) {
                const bool a_set = set_number(n, "TEXCOORD_") >= 0 || set_number(n, "COLOR_") >= 0;
                if (!a_set && !warned)
                    warn(c, "%s: morph target attribute %s is not read (ignored)", tp.c_str(), n.c_str());
                warned = warned || !a_set;
                continue;
            }
            std::vector<double> d = read_accessor(c, attr.second);
            const size_t k = d.size() / std::max<size_t>(nv, 1); /* components */
            for (size_t e = 0; e < d.size(); e++)
                if (!std::isfinite(d[e]))
                    return fail(c, "%s: element %zu is not finite", tp.c_str(), e / std::max<size_t>(k, 1));
            if (dst == &t.col) { /* RGBA, alpha displaced by nothing where the target is RGB */
                dst->assign(nv * 4, 0.0f);
                for (size_t v = 0; v < nv && k >= 3; v++)
                    for (size_t j = 0; j < k && j < 4; j++)
                        (*dst)[v * 4 + j] = float(d[v * k + j]);
            } else {
                dst->assign(d.begin(), d.end());
            }
        }
    return true;
}

void remap_skin_and_targets(Prim &p, const uint32_t *src, size_t n)
{
    auto remap = [&](auto &a, size_t k) {
        if (a.empty())
            return;
        std::remove_reference_t<decltype(a)> b(n * k);
        for (size_t v = 0; v < n; v++)
            std::copy(&a[src[v] * k], &a[src[v] * k] + k, &b[v * k]);
        a = std::move(b);
    };
    remap(p.joints, p.influences);
    remap(p.weights, p.influences);
    for (auto &t : p.targets) {
        remap(t.pos, 3);
        remap(t.nrm, 3);
        remap(t.tan, 3);
        remap(t.uv, 2);
        remap(t.uv1, 2);
        remap(t.col, 4);
    }
}

std::vector<double> morph_weights(const Ctx &c, int node)
{
    const auto &n = c.m.nodes[size_t(node)];
    if (size_t(node) < c.anim_weights.size() && !c.anim_weights[size_t(node)].empty())
        return c.anim_weights[size_t(node)];
    if (!n.weights.empty())
        return n.weights;
    if (in_range(n.mesh, c.m.meshes.size()) && !c.m.meshes[size_t(n.mesh)].weights.empty())
        return c.m.meshes[size_t(n.mesh)].weights;
    return std::vector<double>(mesh_targets(c.m, n.mesh), 0.0);
}

bool joint_matrices(Ctx &c)
{
    const auto &m = c.m;
    const size_t nn = m.nodes.size();
    std::vector<int> parent(nn, -1);
    for (size_t i = 0; i < nn; i++)
        for (int ch : m.nodes[i].children)
            parent[size_t(ch)] = int(i); /* one parent each, no loops: check_nodes_and_scenes */
    c.world.assign(nn, Mat{});
    std::vector<bool> done(nn, false);
    std::vector<int> chain;
    for (size_t i = 0; i < nn; i++) {
        for (int k = int(i); k >= 0 && !done[size_t(k)]; k = parent[size_t(k)])
            chain.push_back(k);
        for (; !chain.empty(); chain.pop_back()) {
            const int k = chain.back(), up = parent[size_t(k)];
            c.world[size_t(k)] = up < 0 ? c.local[size_t(k)] : mat_mul(c.world[size_t(up)], c.local[size_t(k)]);
            done[size_t(k)] = true;
        }
    }
    c.joint_mats.assign(m.skins.size(), {});
    for (size_t si = 0; si < m.skins.size(); si++) {
        const auto &s = m.skins[si];
        std::vector<double> ibm;
        if (s.inverseBindMatrices >= 0)
            ibm = read_accessor(c, s.inverseBindMatrices);
        bool singular_said = false;
        for (size_t j = 0; j < s.joints.size(); j++) {
            Mat b = identity();
            if (!ibm.empty())
                std::copy(&ibm[j * 16], &ibm[j * 16] + 16, b.begin());
            /* an inverse bind matrix is the inverse of one: a singular one is no such thing, and
             * flattens what the joint weighs (drawn as the file says, said once a skin) */
            double a3[3][3], cof[3][3];
            if (!singular_said && mat_cofactors3(b, a3, cof) == 0) { /* (NaN: the finite check below) */
                warn(c, "skins[%zu].inverseBindMatrices: joint %zu's matrix is singular (what it weighs is "
                     "flattened)", si, j);
                singular_said = true;
            }
            Mat jm = mat_mul(c.world[size_t(s.joints[j])], b);
            if (!mat_finite(jm))
                return fail(c, "skins[%zu].joints[%zu]: the joint's matrix (node %d's world transform x its inverse "
                            "bind matrix) is not finite", si, j, s.joints[j]);
            c.joint_mats[si].push_back(jm);
        }
    }
    return true;
}

bool instance_skinned(const Ctx &c, const Instance &in)
{
    return c.m.nodes[size_t(in.node)].skin >= 0;
}

bool pose_primitive(Ctx &c, const Instance &in, const Prim &p, Prim &out)
{
    const auto &node = c.m.nodes[size_t(in.node)];
    const bool skinned = node.skin >= 0 && p.influences > 0;
    std::vector<double> w;
    bool morphed = false;
    if (!p.targets.empty()) {
        w = morph_weights(c, in.node);
        for (double x : w)
            morphed = morphed || x != 0;
    }
    if (!skinned && !morphed)
        return false;
    const std::vector<Mat> *joints = skinned ? &c.joint_mats[size_t(node.skin)] : nullptr;
    if (joints && p.max_joint >= int(joints->size())) {
        fail(c, "%s names joint %d, but skins[%d] (of nodes[%d]) has %zu joints", p.max_joint_at.c_str(), p.max_joint,
             node.skin, in.node, joints->size());
        return false;
    }
    out.uv = p.uv;
    out.uv1 = p.uv1;
    out.col = p.col;
    out.idx = p.idx;
    out.material = p.material;
    const size_t nv = p.pos.size() / 3;
    std::vector<double> pos(p.pos.begin(), p.pos.end()), nrm(p.nrm.begin(), p.nrm.end()), tan(p.tan.begin(), p.tan.end());
    std::vector<int8_t> mirrored(skinned ? nv : 0); /* the vertex's skin matrix has det < 0 */
    /* glTF 2.0, "Morph Targets": the base plus the weighted sum of the targets' displacements */
    for (size_t t = 0; morphed && t < p.targets.size() && t < w.size(); t++) {
        const Prim::Target &d = p.targets[t];
        if (w[t] == 0)
            continue;
        for (size_t i = 0; i < d.pos.size(); i++)
            pos[i] += w[t] * d.pos[i];
        for (size_t i = 0; !p.flat && i < d.nrm.size(); i++)
            nrm[i] += w[t] * d.nrm[i];
        for (size_t v = 0; !tan.empty() && v < d.tan.size() / 3; v++)
            for (size_t k = 0; k < 3; k++)
                tan[v * 4 + k] += w[t] * d.tan[v * 3 + k];
        for (auto a : {std::make_pair(&out.uv, &d.uv), std::make_pair(&out.uv1, &d.uv1), std::make_pair(&out.col, &d.col)})
            for (size_t i = 0; i < a.second->size() && i < a.first->size(); i++)
                (*a.first)[i] += float(w[t] * (*a.second)[i]);
    }
    for (float &x : out.col) /* a colour stays in [0, 1], as COLOR_0 is read */
        x = std::min(1.0f, std::max(0.0f, x));
    if (skinned) {
        for (size_t v = 0; v < nv; v++) {
            /* the skin matrix: the weighted sum of the joint matrices (weights sum to one) */
            Mat s{};
            double sum = 0;
            for (size_t k = 0; k < p.influences; k++) {
                const float wt = p.weights[v * p.influences + k];
                if (!(wt > 0))
                    continue;
                const Mat &j = (*joints)[p.joints[v * p.influences + k]];
                for (size_t e = 0; e < 16; e++)
                    s[e] += wt * j[e];
                sum += wt;
            }
            if (!(sum > 0))
                s = in.world; /* no joint moves it (warned): the node's own transform */
            double *x = &pos[v * 3], y[3];
            for (int r = 0; r < 3; r++)
                y[r] = s[size_t(r)] * x[0] + s[size_t(4 + r)] * x[1] + s[size_t(8 + r)] * x[2] + s[size_t(12 + r)];
            std::copy(y, y + 3, x);
            /* normals by the cofactor matrix (det x inverse transpose), times sign(det) */
            double a[3][3], cof[3][3];
            const double det = mat_cofactors3(s, a, cof);
            const double sgn = det < 0 ? -1 : 1;
            mirrored[v] = det < 0;
            if (!nrm.empty() && !p.flat) {
                double *n = &nrm[v * 3];
                for (int r = 0; r < 3; r++)
                    y[r] = sgn * (cof[r][0] * n[0] + cof[r][1] * n[1] + cof[r][2] * n[2]);
                std::copy(y, y + 3, n);
            }
            if (!tan.empty()) {
                double *t = &tan[v * 4];
                for (int r = 0; r < 3; r++)
                    y[r] = a[r][0] * t[0] + a[r][1] * t[1] + a[r][2] * t[2];
                std::copy(y, y + 3, t);
                t[3] *= sgn;
            }
        }
    }
    /* A triangle the skin mirrors (most of its corners' matrices have det < 0) is listed the
     * other way round, as bake_mesh lists a mirrored node's: its front stays its front. Flat
     * normals, made from the corners in the vertices' order below, turn with it. */
    std::vector<int8_t> turned(mirrored.empty() ? 0 : out.idx.size() / 3);
    for (size_t t = 0; t < turned.size(); t++) {
        uint32_t *q = &out.idx[t * 3];
        turned[t] = mirrored[q[0]] + mirrored[q[1]] + mirrored[q[2]] >= 2;
        if (turned[t])
            std::swap(q[1], q[2]);
    }
    out.pos.assign(pos.begin(), pos.end());
    out.nrm.resize(nv * 3);
    for (size_t v = 0; v < nv; v++) {
        double n[3] = {0, 0, 1};
        if (p.flat && v % 3 == 0 && v + 2 < nv) { /* flat: a triangle per three vertices, in order */
            const double *a = &pos[v * 3], *b = a + 3, *cc = a + 6;
            const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]};
            const double turn = !turned.empty() && turned[v / 3] ? -1 : 1; /* (flat: triangle v / 3 is vertices v..v+2) */
            n[0] = turn * (e1[1] * e2[2] - e1[2] * e2[1]);
            n[1] = turn * (e1[2] * e2[0] - e1[0] * e2[2]);
            n[2] = turn * (e1[0] * e2[1] - e1[1] * e2[0]);
        } else if (p.flat) {
            std::copy(&out.nrm[(v - v % 3) * 3], &out.nrm[(v - v % 3) * 3] + 3, n);
        } else {
            std::copy(&nrm[v * 3], &nrm[v * 3] + 3, n);
        }
        double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(len > 1e-30) || !std::isfinite(len)) { /* degenerate: never hit, any unit normal */
            n[0] = n[1] = 0;
            n[2] = len = 1;
        }
        for (int k = 0; k < 3; k++)
            out.nrm[v * 3 + size_t(k)] = float(n[k] / len);
    }
    if (!tan.empty()) {
        out.tan.resize(nv * 4);
        for (size_t v = 0; v < nv; v++) {
            double *t = &tan[v * 4], len = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
            if (!(len > 1e-30) || !std::isfinite(len)) /* bake_geometry leaves it zero */
                len = INFINITY;
            for (int k = 0; k < 3; k++)
                out.tan[v * 4 + size_t(k)] = float(t[k] / len);
            out.tan[v * 4 + 3] = float(t[3]);
        }
    }
    return true;
}

} // namespace gltf
