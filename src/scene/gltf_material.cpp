/* gltf_material.cpp: what a glTF file's materials read: the table of extensions gonio knows
 * (each one's support, and a material extension's own rules), images (PNG and JPEG through
 * stb, WebP and KTX2 through image_decode.h; each distinct one decoded once), samplers, textures with their texCoord and
 * KHR_texture_transform, KHR_materials_variants, and the materials, read and checked from the
 * JSON document row by row of the material table (glsl/lib/material.h), as cgltf reads each
 * extension into its struct: the types are checked while reading, so the check and the read
 * cannot drift, and a wrong type is the same error everywhere. */
#include "gltf_json.h"

#include <stb_image.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace gltf {

/* ---- the extensions gonio knows: one table ---------------------------------------------------
 * A material extension's factors and textures are its rows of the material table
 * (glsl/lib/material.h), read by material_read; `read` is what the table cannot say (a
 * factor that scales another, a flag); `info` what gonio info says of a material that uses
 * it (scene.h: scene_material_line). Adding one: docs/architecture.md, "Adding a glTF
 * material extension". */
struct Extension {
    const char *name;
    scene_support support;
    const char *how;  /* what gonio does with it (partly: what is left out; unsupported: why) */
    bool material;    /* an extension of materials: its object is read by material_read */
    void (*read)(Doc &d, const Json &e, const std::string &p, MaterialDraft &m); /* after its rows */
    const scene_material_line *info = nullptr;
};

/* A factor of an extension object that is no row of the table (it scales one): the row
 * reader's checks and messages. */
bool read_number(Doc &d, const Json &o, const char *key, const std::string &p, const std::string &what, double lo,
                 double hi, float *out);

void read_emissive_strength(Doc &d, const Json &e, const std::string &p, MaterialDraft &m)
{
    float s = 1;
    if (read_number(d, e, "emissiveStrength", p, m.what, 0, MAX_RADIANCE, &s)) {
        m.g.emissive.x *= s;
        m.g.emissive.y *= s;
        m.g.emissive.z *= s;
    }
}

/* thicknessFactor 0 (its default) means thin-walled: no medium. Any other thickness only
 * says there is one: the path tracer follows the real geometry (docs/path-tracing.md). */
void read_volume(Doc &, const Json &, const std::string &, MaterialDraft &m) { m.g.volume = m.g.thickness > 0; }

void read_unlit(Doc &, const Json &, const std::string &, MaterialDraft &m) { m.g.flags |= GN_MAT_UNLIT; }

/* A factor and a textureInfo of an extension object that are no rows of the table (they fill
 * the core's): the rows' reader, its checks and messages. */
bool read_param(Doc &d, const Json &o, std::string p, const std::string &what, const char *json, int n, float *out,
                double lo, double hi, int rule);
void read_texture(Doc &d, const Json &o, std::string p, const std::string &what, const char *json, TextureRef &t);

/* The specular-glossiness model read into the metallic-roughness record, as the extension
 * defines its inputs: c_diff = diffuse (1 - max(specular)), F0 = specular, alpha =
 * (1 - glossiness)^2. The record: base colour the diffuse colour (diffuseFactor x
 * diffuseTexture), metallic 0, the dielectric's F0 = min(((ior-1)/(ior+1))^2 specular_color,
 * 1) specular with ior 0 and specular 1, so F0 = specular_color = specularFactor x the sRGB RGB
 * of specularGlossinessTexture and F90 = 1 (KHR_materials_specular's own conversion of this
 * model), and glossiness = glossinessFactor x its A (the table's rows). The two rules that are
 * no product of texels, roughness = 1 - glossiness and c_diff, are GN_MAT_SPEC_GLOSS's
 * (material_eval at a point; roughness here from the factor). The file's metallic-roughness
 * values and KHR_materials_specular's and _ior's are its fallback for viewers without the
 * extension: replaced. */
void read_spec_gloss(Doc &d, const Json &e, const std::string &p, MaterialDraft &m)
{
    float diffuse[4] = {1, 1, 1, 1}, specular[3] = {1, 1, 1};
    read_param(d, e, p, m.what, "diffuseFactor", 4, diffuse, 0, 1, GN_MAT_RULE_CLAMP);
    read_param(d, e, p, m.what, "specularFactor", 3, specular, 0, 1, GN_MAT_RULE_CLAMP);
    m.g.flags |= GN_MAT_SPEC_GLOSS;
    m.g.base_color = vec4{diffuse[0], diffuse[1], diffuse[2], diffuse[3]};
    m.g.specular_color = vec3{specular[0], specular[1], specular[2]};
    m.g.specular = 1;
    m.g.ior = 0;
    m.g.metallic = 0;
    m.g.roughness = 1 - m.g.glossiness;
    for (size_t slot : {GN_MAT_WORD(tex_base), GN_MAT_WORD(tex_mr), GN_MAT_WORD(tex_specular),
                          GN_MAT_WORD(tex_specular_color)})
        m.tex[slot] = TextureRef();
    read_texture(d, e, p, m.what, "diffuseTexture", m.tex[GN_MAT_WORD(tex_base)]);
}

/* gonio info's lines (scene_material_line): the factors as the path tracer reads them. */

/* The medium a KHR_materials_volume material bounds, or the dispersion of its refraction
 * (glsl/kernels/path.comp: sigma_a = -ln(attenuation colour) / attenuation distance). */
bool info_medium(const GnMaterial *m, char *out, size_t size)
{
    const float *c = &m->attenuation_color.x;
    double sigma[3];
    if (!m->volume && !(m->dispersion > 0))
        return false;
    for (int k = 0; k < 3; k++)
        sigma[k] = c[k] >= 1 ? 0 : -std::log(double(c[k] > 1e-30f ? c[k] : 1e-30f)) / m->attenuation_distance;
    snprintf(out, size, "%s attenuation (%g, %g, %g) distance %g (sigma_a %g, %g, %g), thickness %g, ior %g, "
             "dispersion %g", m->volume ? "volume" : "thin-walled", c[0], c[1], c[2], m->attenuation_distance,
             sigma[0], sigma[1], sigma[2], m->thickness, m->ior, m->dispersion);
    return true;
}
const scene_material_line INFO_MEDIUM = {
    "medium",
    "KHR_materials_volume (a medium the material bounds) or\n"
    "KHR_materials_dispersion: attenuation colour and distance, the\n"
    "absorption coefficient they give, thickness (unused by the path\n"
    "tracer), IOR and dispersion",
    info_medium};

bool info_anisotropy(const GnMaterial *m, char *out, size_t size)
{
    if (!(m->anisotropy_strength > 0) && m->tex_anisotropy == GN_INVALID)
        return false;
    snprintf(out, size, "strength %g, rotation %g deg%s", m->anisotropy_strength, m->anisotropy_rotation * 180 / M_PI,
             m->tex_anisotropy != GN_INVALID ? ", textured" : "");
    return true;
}
const scene_material_line INFO_ANISOTROPY = {
    "anisotropy", "KHR_materials_anisotropy: strength, rotation and whether a texture\nsets them", info_anisotropy};

/* The film's thickness: a range, mix(min, max, texture G), where a texture sets it. */
bool info_iridescence(const GnMaterial *m, char *out, size_t size)
{
    const char *textured = m->tex_iridescence != GN_INVALID ? " x texture" : "";
    if (!(m->iridescence > 0))
        return false;
    if (m->tex_iridescence_thickness != GN_INVALID)
        snprintf(out, size, "factor %g%s, film ior %g, thickness %g - %g nm (texture G)", m->iridescence, textured,
                 m->iridescence_ior, m->iridescence_thickness_min, m->iridescence_thickness_max);
    else
        snprintf(out, size, "factor %g%s, film ior %g, thickness %g nm", m->iridescence, textured, m->iridescence_ior,
                 m->iridescence_thickness_max);
    return true;
}
const scene_material_line INFO_IRIDESCENCE = {
    "iridescence",
    "KHR_materials_iridescence: factor (and whether a texture scales\n"
    "it), film IOR, thickness (the range of a thickness texture's G)",
    info_iridescence};

bool info_diffuse_transmission(const GnMaterial *m, char *out, size_t size)
{
    if (!(m->diffuse_transmission > 0))
        return false;
    snprintf(out, size, "factor %g%s, colour (%g, %g, %g)%s", m->diffuse_transmission,
             m->tex_diffuse_transmission != GN_INVALID ? " x texture" : "", m->diffuse_transmission_color.x,
             m->diffuse_transmission_color.y, m->diffuse_transmission_color.z,
             m->tex_diffuse_transmission_color != GN_INVALID ? " x texture" : "");
    return true;
}
const scene_material_line INFO_DIFFUSE_TRANSMISSION = {
    "diffuse transmission",
    "KHR_materials_diffuse_transmission: factor and colour (and whether\ntextures scale them)",
    info_diffuse_transmission};

const Extension EXTENSIONS[] = {
    {"KHR_materials_emissive_strength", SCENE_SUPPORTED, "emissiveStrength scales emissiveFactor", true,
     read_emissive_strength},
    {"KHR_materials_specular", SCENE_SUPPORTED, "specularFactor, specularColorFactor and their textures", true, nullptr},
    {"KHR_materials_transmission", SCENE_SUPPORTED,
     "transmissionFactor and transmissionTexture: refraction through rough or smooth glass", true, nullptr},
    {"KHR_materials_ior", SCENE_SUPPORTED, "the index of the Fresnel factor and of refraction", true, nullptr},
    {"KHR_materials_volume", SCENE_PARTLY,
     "absorption in the medium a closed mesh bounds; thicknessFactor and thicknessTexture only say there is one "
     "(the path tracer follows the real geometry)",
     true, read_volume, &INFO_MEDIUM},
    {"KHR_materials_dispersion", SCENE_SUPPORTED, "an index per colour channel from the Abbe number", true, nullptr},
    {"KHR_materials_clearcoat", SCENE_SUPPORTED, "a GGX coat with its own roughness and normal map", true, nullptr},
    {"KHR_materials_sheen", SCENE_SUPPORTED, "a Charlie sheen over the base", true, nullptr},
    {"KHR_materials_anisotropy", SCENE_SUPPORTED, "anisotropic GGX along the tangent frame's direction", true, nullptr,
     &INFO_ANISOTROPY},
    {"KHR_materials_iridescence", SCENE_SUPPORTED, "a thin film over the base's Fresnel factor", true, nullptr,
     &INFO_IRIDESCENCE},
    {"KHR_materials_diffuse_transmission", SCENE_SUPPORTED, "a Lambert lobe through the surface", true, nullptr,
     &INFO_DIFFUSE_TRANSMISSION},
    {"KHR_materials_unlit", SCENE_SUPPORTED, "the base colour is the radiance", true, read_unlit},
    {"KHR_materials_pbrSpecularGlossiness", SCENE_SUPPORTED,
     "read as metallic-roughness: the diffuse colour times 1 - max(specular) the base colour, specular the F0, "
     "roughness 1 - glossiness",
     true, read_spec_gloss},
    {"KHR_texture_transform", SCENE_SUPPORTED, "offset, rotation, scale and texCoord of every texture slot", false,
     nullptr},
    {"KHR_materials_variants", SCENE_SUPPORTED, "the variant that --variant names", false, nullptr},
    {"KHR_lights_punctual", SCENE_SUPPORTED,
     "point, spot and directional lights (intensities read as radiometric: W/sr, W/m^2)", false, nullptr},
    {"KHR_mesh_quantization", SCENE_SUPPORTED, "integer vertex attributes", false, nullptr},
    {"KHR_draco_mesh_compression", SCENE_SUPPORTED, "decoded by Draco", false, nullptr},
    {"EXT_meshopt_compression", SCENE_SUPPORTED, "decoded by meshoptimizer", false, nullptr},
    {"KHR_texture_basisu", SCENE_SUPPORTED,
     "KTX2 images (ETC1S, UASTC, Zstandard) transcoded by Basis Universal; the core source is the fallback", false,
     nullptr},
    {"EXT_texture_webp", SCENE_SUPPORTED, "WebP images decoded by libwebp; the core source is the fallback", false,
     nullptr},
    {"EXT_lights_image_based", SCENE_PARTLY,
     "the scene's cube map (its sharpest level) lights it as the environment unless --env; the prefiltered levels "
     "and irradiance coefficients, made for rasterizers, are not needed by the path tracer",
     false, nullptr},
    {"EXT_mesh_gpu_instancing", SCENE_SUPPORTED,
     "TRANSLATION, ROTATION and SCALE: the node's mesh kept once and placed by each instance", false, nullptr},
    /* metadata only: a file renders as meant with them ignored, so they are no warning */
    {"KHR_xmp_json_ld", SCENE_SUPPORTED, "metadata (title, author, licence): nothing in it changes the image", false,
     nullptr},
    {"KHR_xmp", SCENE_SUPPORTED, "metadata (KHR_xmp_json_ld's draft): nothing in it changes the image", false,
     nullptr},
};

const Extension *find_extension(const std::string &name)
{
    for (const Extension &e : EXTENSIONS)
        if (name == e.name)
            return &e;
    return nullptr;
}

/* What this build lacks to read extension e, or nullptr: KHR_texture_basisu needs Basis
 * Universal, which the build fetches where it can (deps/basisu.sh) and goes on without where
 * it cannot. The table says what a full build does; this, what this one cannot. */
const char *missing(const Extension *e)
{
    static const std::string ktx2 =
        std::string("this gonio was built without Basis Universal: ") + image_decode_ktx2_missing();
    if (e && !strcmp(e->name, "KHR_texture_basisu") && !image_decode_has_ktx2())
        return ktx2.c_str();
    return nullptr;
}

bool supported(const Extension *e) { return e && e->support != SCENE_UNSUPPORTED && !missing(e); }

/* What an unsupported extension's messages add: why it is not read. */
const char *why(const Extension *e) { return missing(e) ? missing(e) : e ? e->how : nullptr; }

std::string why_not(const Extension *e) { return why(e) ? std::string(" (") + why(e) + ")" : std::string(); }

bool check_extensions(Ctx &c)
{
    for (const auto &e : c.m.extensionsRequired)
        if (!supported(find_extension(e)))
            fail(c, "requires unsupported extension %s%s", e.c_str(), why_not(find_extension(e)).c_str());
    if (c.failed) /* refused: the refusal only, no "(ignored)" for the same names in extensionsUsed */
        return false;
    std::vector<std::string> warned; /* one warning each, however often the file lists it */
    for (const auto &e : c.m.extensionsUsed)
        if (!supported(find_extension(e)) && std::find(warned.begin(), warned.end(), e) == warned.end()) {
            const char *x = why(find_extension(e));
            warn(c, "uses unsupported extension %s (ignored%s%s)", e.c_str(), x ? ": " : "", x ? x : "");
            warned.push_back(e);
        }
    return !c.failed;
}

void list_extensions(Ctx &c, scene *out)
{
    std::vector<std::string> names;
    for (const auto &e : c.m.extensionsUsed)
        if (std::find(names.begin(), names.end(), e) == names.end())
            names.push_back(e);
    for (const auto &e : c.m.extensionsRequired)
        if (std::find(names.begin(), names.end(), e) == names.end())
            names.push_back(e);
    out->extensions = static_cast<scene_extension *>(util_calloc(names.size() + 1, sizeof(scene_extension)));
    for (const auto &name : names) {
        scene_extension &x = out->extensions[out->num_extensions++];
        snprintf(x.name, sizeof x.name, "%s", name.c_str());
        x.required = std::find(c.m.extensionsRequired.begin(), c.m.extensionsRequired.end(), name) !=
                     c.m.extensionsRequired.end();
        x.support = scene_extension_support(x.name, &x.how);
    }
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

/* An image that alone declares more texels than all a scene's images may have: unusable (its
 * header may lie; a texture's fallback then takes its place), not the scene's limit. */
std::string too_many_texels(uint64_t w, uint64_t h)
{
    return "it declares " + std::to_string(w) + "x" + std::to_string(h) + ", " + std::to_string(w * h) +
           " texels, more than the " + std::to_string(uint64_t(SCENE_MAX_TEXELS)) + " a scene's images may have";
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
        c.image_channels[idx] = c.image_channels[seen->second];
        return "";
    }
    c.image_formats[idx] = format;
    if (format == TEXTURE_FORMAT_WEBP || format == TEXTURE_FORMAT_KTX2) {
        uint8_t *rgba = nullptr;
        uint32_t w = 0, h = 0;
        char why_bad[512];
        image_decode_status st = image_decode(bytes, size, img->mimeType.c_str(), SCENE_MAX_TEXELS - c.texels, &rgba,
                                              &w, &h, why_bad, sizeof why_bad);
        /* one image over the limit alone: unusable; one that overflows what the others left:
         * the scene's limit */
        if (st == IMAGE_TOO_LARGE && uint64_t(w) * h > SCENE_MAX_TEXELS)
            return std::string(format == TEXTURE_FORMAT_KTX2 ? "KTX2: " : "WebP: ") + too_many_texels(w, h);
        if (st == IMAGE_TOO_LARGE)
            return too_large(c, idx, w, h);
        c.texels += uint64_t(w) * h; /* the declared size, decoded or not, as stb's images count */
        if (st == IMAGE_BAD)
            return why_bad;
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
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_memory(bytes, int(size), &w, &h, &comp))
        return "cannot decode";
    if (uint64_t(w) * uint64_t(h) > SCENE_MAX_TEXELS)
        return too_many_texels(uint64_t(w), uint64_t(h));
    if (c.texels + uint64_t(w) * uint64_t(h) > SCENE_MAX_TEXELS)
        return too_large(c, idx, uint64_t(w), uint64_t(h));
    c.texels += uint64_t(w) * uint64_t(h);
    c.decoded[key] = idx;
    c.image_channels[idx] = comp;
    std::string err, warn_text;
    if (!tinygltf::LoadImageData(img, idx, &err, &warn_text, 0, 0, bytes, int(size), nullptr))
        return err.empty() ? "cannot decode" : err;
    return "";
}

/* tinygltf image callback. Images in buffer views arrive before any buffer view is checked, so
 * they are decoded later (decode_view_images); a file that fails to decode is recorded rather
 * than failing the whole load: an error only where a drawn material uses it (texture_slot). */
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

bool check_textures(Ctx &c)
{
    const auto &m = c.m;
    for (size_t i = 0; i < m.textures.size(); i++) {
        const auto &t = m.textures[i];
        if (t.source != -1 && !in_range(t.source, m.images.size()))
            fail(c, "texture %zu refers to image %d, which does not exist", i, t.source);
        if (t.sampler != -1 && !in_range(t.sampler, m.samplers.size()))
            fail(c, "texture %zu refers to sampler %d, which does not exist", i, t.sampler);
    }
    return !c.failed;
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

/* The texture slots of a material (the table's TEX rows). */
#define COUNT_TEX(name, word, ext, json, space, gate, uses) +1
const size_t NUM_TEXTURE_SLOTS = 0 GN_MATERIAL(GN_MAT_NO_PARAM, COUNT_TEX, GN_MAT_NO_FIELD);
#undef COUNT_TEX

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

/* KHR_texture_basisu, EXT_texture_webp: the first extension source (a KTX2 or WebP image;
 * the JSON checks made it an index into images) whose image decoded; else the core source,
 * the optional fallback (a file that requires the extension may omit it); else the first
 * extension source, unusable (load_images_and_textures says why); -1 when there is none. */
int texture_source(Ctx &c, size_t i)
{
    const auto &t = c.m.textures[i];
    int first = -1;
    const char *first_name = "";
    for (const char *name : {"KHR_texture_basisu", "EXT_texture_webp"}) {
        auto e = t.extensions.find(name);
        if (e == t.extensions.end() || !e->second.IsObject() || !e->second.Has("source"))
            continue;
        int s = e->second.Get("source").GetNumberAsInt();
        if (s < 0 || size_t(s) >= c.m.images.size())
            continue;
        if (c.image_map[size_t(s)] != GN_INVALID)
            return s;
        if (first < 0) {
            first = s;
            first_name = name;
        }
    }
    if (first >= 0 && t.source >= 0 && c.image_map[size_t(t.source)] != GN_INVALID) {
        warn(c, "texture %zu: its %s image %d is unusable; its fallback, image %d, is used instead", i, first_name,
             first, t.source);
        return t.source;
    }
    return first >= 0 ? first : t.source;
}

void load_images_and_textures(Ctx &c, scene *out)
{
    const auto &m = c.m;
    decode_view_images(c);
    std::map<int, std::string> unusable; /* image -> what it is and why it cannot be read */
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
            unusable[int(i)] = label("image", int(i), img.name) + (img.uri.empty() ? "" : " ") +
                               img.uri.substr(0, 200) + ": " + why;
            continue;
        }
        out->images[out->num_images].format = uint32_t(c.image_formats[int(i)]);
        c.image_map[i] = out->num_images++;
        std::vector<unsigned char>().swap(c.m.images[i].image); /* keep one copy at a time */
    }
    for (const auto &alias : c.image_alias)
        c.image_map[size_t(alias.first)] = c.image_map[size_t(alias.second)];
    /* room for texture_slot's variants too: one per texture slot of a material at most */
    c.textures_room = m.textures.size() + NUM_TEXTURE_SLOTS * m.materials.size();
    out->textures = static_cast<scene_texture *>(util_calloc(c.textures_room, sizeof(scene_texture)));
    c.textures_out = out;
    c.texture_map.assign(m.textures.size(), GN_INVALID);
    std::vector<bool> used(m.images.size(), false);
    for (size_t i = 0; i < m.textures.size(); i++) {
        const auto &t = m.textures[i];
        int source = texture_source(c, i);
        if (source < 0) {
            warn(c, "texture %zu has no image source (ignored)", i);
            continue;
        }
        if (c.image_map[size_t(source)] == GN_INVALID) { /* an error where a material uses it */
            int original = c.image_alias.count(source) ? c.image_alias[source] : source;
            auto u = unusable.find(original);
            c.texture_errors[int(i)] = u != unusable.end() ? u->second : "an unusable image";
            used[size_t(original)] = true;
            continue;
        }
        uint32_t flags = 0;
        if (t.sampler >= 0) {
            const auto &s = m.samplers[size_t(t.sampler)];
            flags = wrap_mode(c, size_t(t.sampler), s.wrapS) | wrap_mode(c, size_t(t.sampler), s.wrapT) << 2 |
                    filter_mode(c, size_t(t.sampler), s.magFilter, s.minFilter);
        }
        out->textures[out->num_textures] = scene_texture{c.image_map[size_t(source)], flags, {1, 0, 0, 0, 1, 0}};
        c.texture_map[i] = out->num_textures++;
    }
    /* An image no texture draws (or a fallback's other half) is only worth a warning. */
    for (const auto &u : unusable)
        if (!used[size_t(u.first)])
            warn(c, "%s; no texture draws it", u.second.c_str());
}

/* ---- materials: the table's rows read from the JSON document -------------------------------- */

/* How messages name a row: its JSON path, less the pbrMetallicRoughness object the core's
 * factors sit in ("baseColorFactor", "occlusionTexture.strength"). */
const char *shown(const char *json)
{
    static const char pbr[] = "pbrMetallicRoughness.";
    return strncmp(json, pbr, sizeof pbr - 1) == 0 ? json + sizeof pbr - 1 : json;
}

/* A number in [lo, hi]; outside -> warning and clamped. */
float ranged(Ctx &c, double v, double lo, double hi, const std::string &what, const char *name)
{
    if (v >= lo && v <= hi)
        return float(v);
    warn(c, "%s: %s %g is out of range [%g, %g] (clamped)", what.c_str(), name, v, lo, hi);
    return float(v < lo ? lo : hi);
}

/* The object a row's path leads to from o (its last part the value's key), and that path;
 * nullptr when an object on the way is absent or not an object (the latter is the error of
 * the row that reads that object, reported once). */
const Json *row_object(const Json &o, const char *json, std::string &path, std::string &key)
{
    const Json *at = &o;
    std::string rest = json;
    for (size_t dot; (dot = rest.find('.')) != std::string::npos; rest = rest.substr(dot + 1)) {
        std::string part = rest.substr(0, dot);
        auto it = at->find(part);
        if (it == at->end() || !it->is_object())
            return nullptr;
        at = &*it;
        path = Doc::at(path, part.c_str());
    }
    key = rest;
    return at;
}

/* Row (json, n numbers, [lo, hi], rule) of object o at JSON path p into out[n]: a wrong type
 * is an error (Doc), a value out of range gets the rule (GN_MAT_RULE_*). True when the file
 * has a value there of the right type. */
bool read_param(Doc &d, const Json &o, std::string p, const std::string &what, const char *json, int n, float *out,
                double lo, double hi, int rule)
{
    std::string key;
    const Json *obj = row_object(o, json, p, key);
    double v[4];
    if (!obj)
        return false;
    if (n == 1) {
        const Json *x = d.member(*obj, key.c_str(), p);
        if (!x || !d.is_number(*x, Doc::at(p, key.c_str())))
            return false;
        v[0] = x->get<double>();
    } else {
        if (!d.numbers(*obj, key.c_str(), p, size_t(n)))
            return false;
        for (int k = 0; k < n; k++)
            v[k] = (*obj)[key][size_t(k)].get<double>();
    }
    bool in = true;
    for (int k = 0; k < n; k++)
        in = in && v[k] >= lo && v[k] <= hi;
    switch (rule) {
    case GN_MAT_RULE_CLAMP:
        for (int k = 0; k < n; k++)
            out[k] = ranged(d.c, v[k], lo, hi, what, shown(json));
        break;
    case GN_MAT_RULE_CHECK:
        if (in)
            for (int k = 0; k < n; k++)
                out[k] = float(v[k]);
        else if (n == 1)
            warn(d.c, "%s: %s %g must be in [%g, %g] (ignored)", what.c_str(), shown(json), v[0], lo, hi);
        else
            warn(d.c, "%s: %s must be %d numbers in [%g, %g] (ignored)", what.c_str(), shown(json), n, lo, hi);
        break;
    case GN_MAT_RULE_POSITIVE:
        if (v[0] > 0)
            out[0] = float(v[0]); /* beyond float's range: +inf */
        else
            warn(d.c, "%s: %s %g must be positive (ignored)", what.c_str(), shown(json), v[0]);
        break;
    case GN_MAT_RULE_IOR: /* KHR_materials_ior allows 0 besides [1, inf): F0 = ((ior-1)/(ior+1))^2 = 1, a mirror */
        out[0] = v[0] == 0 ? 0.0f : ranged(d.c, v[0], lo, hi, what, shown(json));
        break;
    case GN_MAT_RULE_ANGLE: /* reduced to [-pi, pi], so that float keeps its precision */
        if (std::isfinite(v[0]))
            out[0] = float(std::remainder(v[0], 2 * M_PI));
        break;
    }
    return true;
}

bool read_number(Doc &d, const Json &o, const char *key, const std::string &p, const std::string &what, double lo,
                 double hi, float *out)
{
    return read_param(d, o, p, what, key, 1, out, lo, hi, GN_MAT_RULE_CLAMP);
}

/* A textureInfo of object o at JSON path p (json: its key there, or a path to it): the
 * texture, its set and its KHR_texture_transform. */
void read_texture(Doc &d, const Json &o, std::string p, const std::string &what, const char *json, TextureRef &t)
{
    std::string key;
    const Json *obj = row_object(o, json, p, key);
    const Json *ti = obj ? d.object(*obj, key.c_str(), p) : nullptr;
    if (!ti)
        return;
    p = Doc::at(p, key.c_str());
    t.index = int(d.index(*ti, "index", p, "textures", true));
    int64_t set = d.integer(*ti, "texCoord", p, 0, INT32_MAX);
    t.tex_coord = set < 0 ? 0 : int(set);
    const Json *ex = d.object(*ti, "extensions", p);
    const std::string pe = Doc::at(p, "extensions"), pt = Doc::at(pe, "KHR_texture_transform");
    const Json *tt = ex ? d.object(*ex, "KHR_texture_transform", pe) : nullptr;
    if (!tt)
        return;
    double offset[2] = {0, 0}, scale[2] = {1, 1}, rotation = 0;
    const char *pairs[2] = {"offset", "scale"};
    double *vals[2] = {offset, scale};
    for (int k = 0; k < 2; k++)
        if (d.numbers(*tt, pairs[k], pt, 2)) {
            const Json &v = (*tt)[pairs[k]];
            if (std::isfinite(v[0].get<double>()) && std::isfinite(v[1].get<double>())) {
                vals[k][0] = v[0].get<double>();
                vals[k][1] = v[1].get<double>();
            } else {
                warn(d.c, "%s: %s: KHR_texture_transform %s is not two finite numbers (ignored)", what.c_str(),
                     shown(json), pairs[k]);
            }
        }
    if (const Json *r = d.member(*tt, "rotation", pt)) {
        if (d.is_number(*r, Doc::at(pt, "rotation")) && std::isfinite(r->get<double>()))
            rotation = r->get<double>();
        else if (r->is_number())
            warn(d.c, "%s: %s: KHR_texture_transform rotation is not finite (ignored)", what.c_str(), shown(json));
    }
    set = d.integer(*tt, "texCoord", pt, 0, INT32_MAX);
    if (set >= 0)
        t.tex_coord = int(set);
    /* KHR_texture_transform: uv' = T R S uv, R = [cos sin; -sin cos] */
    double cr = std::cos(rotation), sr = std::sin(rotation);
    double r[6] = {cr * scale[0], sr * scale[1], offset[0], -sr * scale[0], cr * scale[1], offset[1]};
    for (int k = 0; k < 6; k++) {
        t.transform[k] = float(r[k]);
        t.transformed |= t.transform[k] != (k == 0 || k == 4 ? 1.0f : 0.0f);
    }
}

void materials_read(Ctx &c, const Json &root)
{
    auto it = root.find("materials");
    c.materials.assign(it != root.end() && it->is_array() ? it->size() : 0, MaterialDraft());
}

/* The object a row reads from: the material itself (ext "") or its extension object. */
const Json *row_base(const Json &m, const Json *ex, const char *ext, const std::string &p, std::string &base_path)
{
    if (!*ext) {
        base_path = p;
        return &m;
    }
    auto it = ex ? ex->find(ext) : Json::const_iterator();
    if (!ex || it == ex->end() || !it->is_object())
        return nullptr;
    base_path = Doc::at(Doc::at(p, "extensions"), ext);
    return &*it;
}

void material_read(Doc &d, const Json &m, const std::string &p, size_t i)
{
    MaterialDraft &out = d.c.materials[i];
    auto name = m.find("name");
    out.name = name != m.end() && name->is_string() ? name->get<std::string>() : "";
    out.what = label("material", int(i), out.name);
    scene_material_default(&out.g);
    /* the objects the rows read from, each checked once */
    d.object(m, "pbrMetallicRoughness", p);
    const Json *ex = d.object(m, "extensions", p);
    for (const Extension &e : EXTENSIONS)
        if (ex && e.material)
            d.object(*ex, e.name, Doc::at(p, "extensions"));
    std::string bp;
#define READ_PARAM(name, type, word, ext, json, def, lo, hi, rule, feat, brdf)                                              \
    if (const Json *base = row_base(m, ex, ext, p, bp))                                                               \
        read_param(d, *base, bp, out.what, json, GN_MAT_COUNT_##type, (float *)&out.g.name, lo, hi, GN_MAT_RULE_##rule);
#define READ_TEX(name, word, ext, json, space, gate, uses)                                                            \
    if (const Json *base = row_base(m, ex, ext, p, bp))                                                               \
        read_texture(d, *base, bp, out.what, json, out.tex[word]);
    GN_MATERIAL(READ_PARAM, READ_TEX, GN_MAT_NO_FIELD)
#undef READ_PARAM
#undef READ_TEX
    for (const Extension &e : EXTENSIONS)
        if (e.read)
            if (const Json *base = row_base(m, ex, e.name, p, bp))
                e.read(d, *base, bp, out);
    /* The specular-glossiness model has its own specular colour and no index: the PBR
     * extensions made for metallic-roughness do not combine with it, and read_spec_gloss
     * replaced what they set. */
    if (ex && ex->is_object() && ex->count("KHR_materials_pbrSpecularGlossiness"))
        for (const char *other : {"KHR_materials_specular", "KHR_materials_ior"})
            if (ex->count(other))
                warn(d.c, "%s: %s does not combine with KHR_materials_pbrSpecularGlossiness (ignored)",
                     out.what.c_str(), other);
    /* the core's own flags */
    d.boolean(m, "doubleSided", p);
    d.enum_str(m, "alphaMode", p, {"OPAQUE", "MASK", "BLEND"});
    auto ds = m.find("doubleSided");
    if (ds != m.end() && ds->is_boolean() && ds->get<bool>())
        out.g.flags |= GN_MAT_DOUBLE_SIDED;
    auto am = m.find("alphaMode");
    if (am != m.end() && *am == "MASK")
        out.g.flags |= GN_MAT_MASK;
    else if (am != m.end() && *am == "BLEND")
        out.g.flags |= GN_MAT_BLEND;
    auto extras = m.find("extras");
    if (extras != m.end())
        out.extras = *extras;
}

int material_tangent_set(const Ctx &c, uint32_t material)
{
    if (material >= c.materials.size())
        return -1;
    const MaterialDraft &d = c.materials[material];
    const TextureRef &normal = d.tex[GN_MAT_WORD(tex_normal)], &coat = d.tex[GN_MAT_WORD(tex_clearcoat_normal)];
    const TextureRef &aniso = d.tex[GN_MAT_WORD(tex_anisotropy)];
    if (normal.index >= 0)
        return normal.tex_coord;
    if (coat.index >= 0)
        return coat.tex_coord;
    if (d.g.anisotropy_strength > 0)
        return aniso.index >= 0 ? aniso.tex_coord : 0;
    return -1;
}

/* The scene texture a material slot uses: the glTF texture's own one, or, when the
 * reference reads TEXCOORD_1 or has a KHR_texture_transform, a copy with its set and
 * transform (GnTexture), so each slot stays one index. */
uint32_t texture_slot(Ctx &c, const TextureRef &ref, const std::string &what, const char *slot)
{
    auto bad = c.texture_errors.find(ref.index);
    if (bad != c.texture_errors.end()) {
        /* Drawn, an error, not a white or missing slot: the render would silently be another
         * picture than the file's. (Not drawn: load_materials's warning.) */
        if (c.material_drawn) {
            fail(c, "%s: %s: texture %d: %s", what.c_str(), slot, ref.index, bad->second.c_str());
            c.texture_errors_said.insert(ref.index);
        }
        return GN_INVALID;
    }
    if (ref.index < 0 || c.texture_map[size_t(ref.index)] == GN_INVALID)
        return GN_INVALID;
    if (ref.tex_coord > 1) {
        warn(c, "%s: %s uses TEXCOORD_%d, only TEXCOORD_0 and TEXCOORD_1 are supported (texture ignored)", what.c_str(),
             slot, ref.tex_coord);
        return GN_INVALID;
    }
    uint32_t base = c.texture_map[size_t(ref.index)];
    if (ref.tex_coord == 0 && !ref.transformed)
        return base;
    scene *out = c.textures_out;
    if (out->num_textures == c.textures_room) { /* a caller beyond one call per slot */
        c.textures_room *= 2;
        out->textures = static_cast<scene_texture *>(util_realloc(out->textures, c.textures_room * sizeof(scene_texture)));
    }
    scene_texture t = out->textures[base];
    t.flags |= ref.tex_coord == 1 ? GN_TEX_UV1 : 0u;
    memcpy(t.transform, ref.transform, sizeof t.transform);
    out->textures[out->num_textures] = t;
    return out->num_textures++;
}

bool number_triple(const Json &v, float out[3])
{
    if (!v.is_array() || v.size() != 3)
        return false;
    for (size_t k = 0; k < 3; k++) {
        if (!v[k].is_number())
            return false;
        out[k] = float(v[k].get<double>());
    }
    return true;
}

/* extras: {"gonio": {"brdf": NAME, PARAM: number, ..., "phong": {...}}} */
void read_gonio_extras(Ctx &c, const Json &extras, const std::string &what, GnMaterial &g, scene_material_extras &x)
{
    if (!extras.is_object() || !extras.count("gonio"))
        return;
    const Json &go = extras["gonio"];
    if (!go.is_object()) {
        warn(c, "%s: extras.gonio is not an object (ignored)", what.c_str());
        return;
    }
    for (auto it = go.begin(); it != go.end(); ++it) {
        const std::string &key = it.key();
        const Json &v = it.value();
        if (key == "brdf") {
            if (!v.is_string() || v.get_ref<const std::string &>().size() >= sizeof x.brdf)
                warn(c, "%s: extras.gonio.brdf must be a name of at most %zu characters (ignored)", what.c_str(), sizeof x.brdf - 1);
            else
                snprintf(x.brdf, sizeof x.brdf, "%s", v.get_ref<const std::string &>().c_str());
        } else if (key == "phong") {
            if (!v.is_object()) {
                warn(c, "%s: extras.gonio.phong is not an object (ignored)", what.c_str());
                continue;
            }
            x.has_phong = true;
            struct { const char *name; vec3 *dst; } cols[] = {{"ambient", &g.phong_ambient}, {"diffuse", &g.phong_diffuse},
                                                              {"specular", &g.phong_specular}, {"emission", &g.phong_emission}};
            for (auto &col : cols) {
                float t[3];
                if (!v.count(col.name))
                    continue;
                if (number_triple(v[col.name], t) && t[0] >= 0 && t[1] >= 0 && t[2] >= 0)
                    *col.dst = vec3{t[0], t[1], t[2]};
                else
                    warn(c, "%s: extras.gonio.phong.%s must be 3 non-negative numbers (ignored)", what.c_str(), col.name);
            }
            if (v.count("shininess")) {
                const Json &s = v["shininess"];
                if (s.is_number() && s.get<double>() >= 0)
                    g.phong_shininess = float(s.get<double>());
                else
                    warn(c, "%s: extras.gonio.phong.shininess must be a non-negative number (ignored)", what.c_str());
            }
        } else if (!v.is_number() || x.num_params == 8 || key.size() >= sizeof x.param_names[0]) {
            warn(c, "%s: extras.gonio.%s ignored (parameters are up to 8 numbers with names of at most %zu characters)",
                 what.c_str(), key.substr(0, 64).c_str(), sizeof x.param_names[0] - 1);
        } else {
            snprintf(x.param_names[x.num_params], sizeof x.param_names[0], "%s", key.c_str());
            x.param_values[x.num_params++] = float(v.get<double>());
        }
    }
}

bool load_materials(Ctx &c, scene *out)
{
    size_t n = c.materials.size();
    std::vector<bool> drawn(n + 1, false); /* the materials the scene's triangles use */
    for (uint32_t t = 0; t < out->num_triangles; t++)
        drawn[std::min(size_t(out->tri_material[t]), n)] = true;
    for (uint32_t m = 0; m < out->num_instanced_meshes; m++)
        for (uint32_t t = 0; t < out->instanced_meshes[m].num_triangles; t++)
            drawn[std::min(size_t(out->instanced_meshes[m].tri_material[t]), n)] = true;
    bool need_default = drawn[n];
    out->num_materials = uint32_t(n + (need_default ? 1 : 0));
    out->materials = static_cast<GnMaterial *>(util_calloc(out->num_materials, sizeof(GnMaterial)));
    out->material_extras = static_cast<scene_material_extras *>(util_calloc(out->num_materials, sizeof(scene_material_extras)));
    out->material_names = static_cast<char(*)[64]>(util_calloc(out->num_materials, 64));
    for (size_t i = 0; i < n; i++) {
        const MaterialDraft &d = c.materials[i];
        GnMaterial &g = out->materials[i];
        g = d.g;
        c.material_drawn = drawn[i];
#define RESOLVE_TEX(name, word, ext, json, space, gate, uses) g.name = texture_slot(c, d.tex[word], d.what, shown(json));
        GN_MATERIAL(GN_MAT_NO_PARAM, RESOLVE_TEX, GN_MAT_NO_FIELD)
#undef RESOLVE_TEX
        scene_phong_from_pbr(&g);
        read_gonio_extras(c, d.extras, d.what, g, out->material_extras[i]);
        snprintf(out->material_names[i], 64, "%s", d.name.empty() ? ("material " + std::to_string(i)).c_str() : d.name.c_str());
    }
    if (need_default) {
        scene_material_default(&out->materials[n]);
        snprintf(out->material_names[n], 64, "default");
    }
    for (const auto &t : c.texture_errors)
        if (!c.texture_errors_said.count(t.first))
            warn(c, "texture %d: %s; no material the scene draws uses it", t.first, t.second.c_str());
    return !c.failed;
}

} // namespace gltf

const scene_material_line *scene_material_line_at(size_t k)
{
    for (const gltf::Extension &e : gltf::EXTENSIONS)
        if (e.info && k-- == 0)
            return e.info;
    return nullptr;
}

scene_support scene_extension_support(const char *name, const char **how)
{
    const gltf::Extension *e = gltf::find_extension(name);
    if (gltf::missing(e)) {
        *how = gltf::missing(e);
        return SCENE_UNSUPPORTED;
    }
    *how = e ? e->how : "unknown to gonio";
    return e ? e->support : SCENE_UNSUPPORTED;
}
