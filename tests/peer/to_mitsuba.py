# to_mitsuba.py: a glTF scene (gltf_io.load) as a Mitsuba 3 scene dictionary, for the peer
# bench only: triangle meshes (written as PLY beside the other outputs), the project's
# materials mapped to Mitsuba's closest BSDFs, emissive meshes as area lights, point and
# directional lights, a constant environment and the perspective camera.
#
# Materials: glTF's Lambert case (metallic 0, roughness 1, KHR_materials_specular 0, no
# textures) -> `diffuse`, which is the same BRDF; smooth full transmission -> `dielectric`
# (same Fresnel, tint = base colour); anything else -> `principled` (base colour,
# metallic, roughness and transmission from the material and its textures, eta = ior),
# Mitsuba's model nearest glTF's metallic-roughness one: both GGX with alpha = roughness^2
# and Schlick-weighted metal, but Disney's diffuse and a dielectric Fresnel where glTF has
# Lambert and Schlick, so rough plastic and textured scenes agree only approximately.
# gonio shades both sides of an opaque surface, so opaque BSDFs are `twosided`.
import os

import numpy as np

import gltf_io


def _write_ply(path, P, N, UV, I):
    cols = [P.astype(np.float32)]
    props = ["x", "y", "z"]
    if N is not None:
        cols.append(N.astype(np.float32))
        props += ["nx", "ny", "nz"]
    if UV is not None:
        cols.append(UV.astype(np.float32))
        props += ["u", "v"]
    vert = np.ascontiguousarray(np.concatenate(cols, axis=1))
    faces = np.zeros(len(I), dtype=[("n", np.uint8), ("i", np.int32, 3)])
    faces["n"] = 3
    faces["i"] = I.astype(np.int32)
    head = ["ply", "format binary_little_endian 1.0", f"element vertex {len(P)}"]
    head += [f"property float {p}" for p in props]
    head += [f"element face {len(I)}", "property list uchar int vertex_indices", "end_header"]
    with open(path, "wb") as f:
        f.write(("\n".join(head) + "\n").encode())
        f.write(vert.tobytes())
        f.write(faces.tobytes())


class Converter:
    def __init__(self, mi, doc, workdir):
        self.mi, self.doc, self.workdir = mi, doc, workdir
        self.images = {}

    def _image(self, tex_ref, srgb):
        """The linear float pixels (H x W x C) of a textureInfo's image."""
        d = self.doc["doc"]
        if tex_ref.get("texCoord", 0) != 0 or "extensions" in tex_ref:
            raise gltf_io.GltfError("texture: only TEXCOORD_0 without a transform is converted")
        src = d["images"][d["textures"][tex_ref["index"]]["source"]]
        if "uri" not in src or src["uri"].startswith("data:"):
            raise gltf_io.GltfError("images: only image files are converted")
        key = (src["uri"], srgb)
        if key not in self.images:
            mi = self.mi
            b = mi.Bitmap(os.path.join(self.doc["folder"], src["uri"]))
            if not srgb:  # data (metal-roughness, normals): the numbers as stored
                b.set_srgb_gamma(False)
            b = b.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
            self.images[key] = np.array(b)
        return self.images[key]

    def _texture(self, pixels):
        return {"type": "bitmap", "bitmap": self.mi.Bitmap(np.ascontiguousarray(pixels, dtype=np.float32)),
                "raw": True, "filter_type": "bilinear", "wrap_mode": "repeat"}

    def _rgb(self, v):
        return {"type": "rgb", "value": [float(x) for x in v]}

    def material(self, mi_index):
        d = self.doc["doc"]
        m = d["materials"][mi_index] if mi_index is not None else {}
        pbr = m.get("pbrMetallicRoughness", {})
        ext = m.get("extensions", {})
        base = np.array(pbr.get("baseColorFactor", [1, 1, 1, 1])[:3], float)
        metal = float(pbr.get("metallicFactor", 1))
        rough = float(pbr.get("roughnessFactor", 1))
        spec = float(ext.get("KHR_materials_specular", {}).get("specularFactor", 1))
        trans = float(ext.get("KHR_materials_transmission", {}).get("transmissionFactor", 0))
        ior = float(ext.get("KHR_materials_ior", {}).get("ior", 1.5))
        textured = any(k in pbr for k in ("baseColorTexture", "metallicRoughnessTexture")) or \
            "normalTexture" in m
        if not textured and metal == 0 and rough == 1 and spec == 0 and trans == 0:
            return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": self._rgb(base)}}
        if not textured and metal == 0 and rough == 0 and trans == 1:
            return {"type": "dielectric", "int_ior": ior, "ext_ior": 1.0,
                    "specular_transmittance": self._rgb(base)}
        b = {"type": "principled", "eta": ior, "spec_trans": trans}
        if "baseColorTexture" in pbr:
            b["base_color"] = self._texture(self._image(pbr["baseColorTexture"], True) * base)
        else:
            b["base_color"] = self._rgb(base)
        if "metallicRoughnessTexture" in pbr:
            px = self._image(pbr["metallicRoughnessTexture"], False)
            b["roughness"] = self._texture(px[:, :, 1:2] * rough)
            b["metallic"] = self._texture(px[:, :, 2:3] * metal)
        else:
            b["roughness"], b["metallic"] = rough, metal
        if "normalTexture" in m:
            b = {"type": "normalmap", "normalmap": self._texture(self._image(m["normalTexture"], False)),
                 "bsdf": b}
        return b if trans > 0 else {"type": "twosided", "bsdf": b}

    def emission(self, mi_index):
        if mi_index is None:
            return None
        m = self.doc["doc"]["materials"][mi_index]
        e = np.array(m.get("emissiveFactor", [0, 0, 0]), float)
        e *= m.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1)
        if not e.any():
            return None
        if "emissiveTexture" in m:
            return {"type": "area", "radiance": self._texture(self._image(m["emissiveTexture"], True) * e)}
        return {"type": "area", "radiance": self._rgb(e)}


def scene_dict(mi, path, workdir, width, height, spp, env, look_at=None, fov=None):
    """The Mitsuba scene of glTF PATH: camera from LOOK_AT/FOV (degrees) when given, else
    the file's first camera; ENV: constant environment radiance (0: none)."""
    doc = gltf_io.load(path)
    os.makedirs(workdir, exist_ok=True)
    conv = Converter(mi, doc, workdir)
    if look_at is not None:
        eye, target, up = (np.asarray(v, float) for v in look_at)
        yfov = np.radians(fov)
    elif doc["cameras"]:
        c = doc["cameras"][0]
        eye, target, up, yfov = c["eye"], c["eye"] + c["forward"], c["up"], c["yfov"]
    else:
        raise gltf_io.GltfError(f"{path}: no camera (pass look_at)")
    T = mi.ScalarTransform4f()
    to_world = T.look_at(origin=[float(x) for x in eye], target=[float(x) for x in target],
                         up=[float(x) for x in up])
    sc = {"type": "scene",
          "integrator": {"type": "path", "max_depth": -1, "rr_depth": 3, "hide_emitters": False},
          "sensor": {"type": "perspective", "fov": float(np.degrees(yfov)), "fov_axis": "y",
                     "near_clip": 1e-3, "to_world": to_world,
                     "sampler": {"type": "independent", "sample_count": spp},
                     "film": {"type": "hdrfilm", "width": width, "height": height,
                              "rfilter": {"type": "box"}, "pixel_format": "rgb"}}}
    for k, p in enumerate(doc["prims"]):
        ply = os.path.join(workdir, f"mesh{k}.ply")
        _write_ply(ply, p["P"], p["N"], p["UV"], p["I"])
        shape = {"type": "ply", "filename": ply, "bsdf": conv.material(p["material"]),
                 "face_normals": p["N"] is None}
        e = conv.emission(p["material"])
        if e is not None:
            shape["emitter"] = e
        sc[f"mesh{k}"] = shape
    for k, L in enumerate(doc["lights"]):
        c = np.array(L["color"], float) * L["intensity"]
        if L["type"] == "point":
            sc[f"light{k}"] = {"type": "point", "position": [float(x) for x in L["position"]],
                               "intensity": conv._rgb(c)}
        elif L["type"] == "directional":
            sc[f"light{k}"] = {"type": "directional", "direction": [float(x) for x in L["direction"]],
                               "irradiance": conv._rgb(c)}
        else:
            raise gltf_io.GltfError(f"{path}: {L['type']} lights are not converted")
    if env:
        sc["env"] = {"type": "constant", "radiance": conv._rgb([env] * 3)}
    return sc
