/* gltf_environment.cpp: the file's image-based light, EXT_lights_image_based: a cube map of
 * radiance (six images per level, the first level the sharpest), a rotation and an intensity,
 * one light per scene. The path tracer needs no prefiltered levels nor the irradiance
 * coefficients a rasterizer uses: the first level, baked into gonio's lat-long environment
 * map (environment_from_cube), lights the scene, unless the command line's --env replaces it.
 * The images are JPEG (LDR, sRGB) or PNG: a PNG with an alpha channel is RGBD (the radiance is
 * RGB / A, RGB stored with a 2.2 gamma, as the extension's encoders write it), without one it
 * is LDR like a JPEG. */
#include "gltf_json.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

extern "C" {
#include "environment.h"
}

namespace gltf {

static const char *const EXT = "EXT_lights_image_based";

void check_ibl(Doc &d)
{
    Ctx &c = d.c;
    const Json *ext = d.object(d.root, "extensions", "");
    const Json *lib = ext ? d.object(*ext, EXT, "extensions") : nullptr;
    const std::string pl = std::string("extensions.") + EXT;
    size_t images = d.count_of("images");
    if (lib)
        d.each(*lib, "lights", pl, [&](const Json &l, const std::string &p, size_t) {
            Ibl ibl;
            d.string(l, "name", p);
            if (l.count("name") && l["name"].is_string())
                ibl.name = l["name"].get<std::string>().substr(0, 40);
            const Json *v = d.member(l, "intensity", p);
            if (v && d.is_number(*v, Doc::at(p, "intensity"))) {
                double x = v->get<double>();
                if (!(x >= 0 && x <= 1e6))
                    d.error(Doc::at(p, "intensity"), "%s is out of range [0, 1e6]", Doc::show(*v).c_str());
                else
                    ibl.intensity = float(x);
            }
            if (d.numbers(l, "rotation", p, 4)) {
                const Json &r = l["rotation"];
                double n = 0;
                for (int k = 0; k < 4; k++) {
                    ibl.rotation[k] = float(r[size_t(k)].get<double>());
                    n += double(ibl.rotation[k]) * ibl.rotation[k];
                }
                if (!(std::fabs(n - 1) < 1e-3)) /* the glTF spec's unit-quaternion tolerance for rotations */
                    d.error(Doc::at(p, "rotation"), "is not a unit quaternion (length %g)", std::sqrt(n));
            }
            if (const Json *ic = d.array(l, "irradianceCoefficients", p, true)) {
                if (ic->size() != 9)
                    d.error(Doc::at(p, "irradianceCoefficients"), "must have 9 entries (has %zu)", ic->size());
                for (size_t i = 0; i < ic->size() && i < 9; i++) {
                    const std::string pi = Doc::item(Doc::at(p, "irradianceCoefficients"), i);
                    if (!(*ic)[i].is_array() || (*ic)[i].size() != 3)
                        d.error(pi, "%s is not an array of 3 numbers", Doc::show((*ic)[i]).c_str());
                    else
                        for (size_t k = 0; k < 3; k++)
                            d.is_number((*ic)[i][k], Doc::item(pi, k));
                }
            }
            ibl.size = int(d.integer(l, "specularImageSize", p, 1, 1 << 14, true));
            if (const Json *si = d.array(l, "specularImages", p, true)) {
                const std::string ps = Doc::at(p, "specularImages");
                if (si->empty())
                    d.error(ps, "is empty (the first level's six faces are required)");
                ibl.mips = int(si->size());
                for (size_t m = 0; m < si->size(); m++) {
                    const std::string pm = Doc::item(ps, m);
                    if (!(*si)[m].is_array() || (*si)[m].size() != 6) {
                        d.error(pm, "%s is not an array of 6 image indices (+X, -X, +Y, -Y, +Z, -Z)",
                                Doc::show((*si)[m]).c_str());
                        continue;
                    }
                    for (size_t f = 0; f < 6; f++) {
                        int64_t i = d.index((*si)[m][f], Doc::item(pm, f), "images", images);
                        if (m == 0)
                            ibl.faces[f] = int(i);
                    }
                }
            }
            c.ibls.push_back(ibl);
        });
    d.each(d.root, "scenes", "", [&](const Json &s, const std::string &p, size_t i) {
        c.scene_ibl.resize(i + 1, -1);
        const Json *se = d.object(s, "extensions", p);
        const Json *r = se ? d.object(*se, EXT, Doc::at(p, "extensions")) : nullptr;
        if (r) {
            const std::string pr = Doc::at(Doc::at(p, "extensions"), EXT);
            const Json *lv = d.member(*r, "light", pr, true);
            c.scene_ibl[i] = lv ? int(d.index(*lv, Doc::at(pr, "light"), "EXT_lights_image_based lights", c.ibls.size())) : -1;
        }
    });
}

/* sRGB's transfer function, and the 2.2 gamma of RGBD's colour. */
static float srgb_to_linear(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

bool bake_environment(Ctx &c, scene *out)
{
    int s = c.scene_index >= 0 ? c.scene_index : (c.m.defaultScene >= 0 ? c.m.defaultScene : 0);
    if (size_t(s) >= c.scene_ibl.size() || c.scene_ibl[size_t(s)] < 0)
        return true;
    int li = c.scene_ibl[size_t(s)];
    const Ibl &l = c.ibls[size_t(li)];
    std::string what = label("light", li, l.name);
    std::vector<std::vector<float>> faces(6);
    int size = 0;
    for (int f = 0; f < 6; f++) {
        int idx = l.faces[f];
        static const char *const names[6] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
        if (idx < 0)
            return fail(c, "%s %s: the first level's %s face is missing", EXT, what.c_str(), names[f]);
        int src = c.image_alias.count(idx) ? c.image_alias[idx] : idx;
        uint32_t k = c.image_map.size() > size_t(idx) ? c.image_map[size_t(idx)] : GN_INVALID;
        if (k == GN_INVALID) {
            std::string why = c.image_errors.count(src) ? c.image_errors[src] : "file missing or unreadable";
            while (!why.empty() && why.back() == '\n')
                why.pop_back();
            return fail(c, "%s %s: the %s face, image %d: %s", EXT, what.c_str(), names[f], idx, why.c_str());
        }
        const scene_image &img = out->images[k];
        if (img.width != img.height || int(img.width) != l.size)
            return fail(c, "%s %s: the %s face, image %d, is %ux%u: the faces must be square, specularImageSize (%d)",
                        EXT, what.c_str(), names[f], idx, img.width, img.height, l.size);
        size = l.size;
        bool rgbd = c.image_channels.count(src) && c.image_channels[src] == 4; /* JPEG has no alpha */
        size_t n = size_t(size) * size_t(size);
        faces[size_t(f)].resize(n * 3);
        float *o = faces[size_t(f)].data();
        for (size_t i = 0; i < n; i++) {
            const uint8_t *p = img.rgba8 + i * 4;
            /* RGBD: alpha 0 would divide by zero; the encoders never write it (D >= 1/255). */
            float dv = rgbd ? std::max(p[3], uint8_t(1)) / 255.0f : 1;
            for (int k = 0; k < 3; k++) {
                float v = p[k] / 255.0f;
                o[i * 3 + size_t(k)] = (rgbd ? std::pow(v, 2.2f) / dv : srgb_to_linear(v)) * l.intensity;
            }
        }
    }
    const float *fp[6];
    for (int f = 0; f < 6; f++)
        fp[f] = faces[size_t(f)].data();
    int width = std::min(4 * size, 4096);
    environment_from_cube(&out->environment, width, fp, size, l.rotation);
    snprintf(out->environment_what, sizeof out->environment_what, "%s %s, 6 faces of %dx%d", EXT, what.c_str(), size,
             size);
    return true;
}

} // namespace gltf
