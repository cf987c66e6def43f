/* gltf_animation.cpp: the animation channels sampled at one time (glTF 2.0, 3.11 and
 * Appendix C): their samplers checked as the specification requires, and every channel's
 * translation, rotation or scale at the animation time. */
#include "gltf_internal.h"

#include <algorithm>
#include <cmath>

namespace gltf {

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

} // namespace gltf
