# gltf_io.py: the bench's own small glTF reader and writer (numpy). The reader bakes the
# node hierarchy into world-space triangles, which is all the Mitsuba converter needs; it
# reads only what the bench scenes and DamagedHelmet use (no sparse accessors, no
# compression), and says so for anything else. Written here rather than taken from a
# library because it must run in the bench's venv next to Mitsuba with numpy alone.
import base64
import json
import os

import numpy as np

_COMPONENT = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16,
              5125: np.uint32, 5126: np.float32}
_COUNT = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


class GltfError(Exception):
    pass


def _buffer(doc, folder, i, cache):
    if i not in cache:
        uri = doc["buffers"][i].get("uri")
        if uri is None:
            raise GltfError(f"buffers[{i}]: no uri (GLB is not read by the bench converter)")
        if uri.startswith("data:"):
            cache[i] = base64.b64decode(uri.split(",", 1)[1])
        else:
            with open(os.path.join(folder, uri), "rb") as f:
                cache[i] = f.read()
    return cache[i]


def accessor(doc, folder, i, cache):
    a = doc["accessors"][i]
    if "sparse" in a or "bufferView" not in a:
        raise GltfError(f"accessors[{i}]: sparse or view-less accessors are not read")
    v = doc["bufferViews"][a["bufferView"]]
    data = _buffer(doc, folder, v["buffer"], cache)
    dt = np.dtype(_COMPONENT[a["componentType"]])
    n = _COUNT[a["type"]]
    off = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    stride = v.get("byteStride", dt.itemsize * n)
    rows = np.ndarray((a["count"], n), dtype=dt, buffer=data, offset=off,
                      strides=(stride, dt.itemsize)).copy()
    if a.get("normalized"):
        rows = rows.astype(np.float64) / np.iinfo(dt).max
    return rows


def _quat_matrix(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def node_matrix(n):
    if "matrix" in n:
        return np.array(n["matrix"], dtype=np.float64).reshape(4, 4).T  # column-major
    m = np.eye(4)
    m[:3, :3] = _quat_matrix(n.get("rotation", [0, 0, 0, 1])) * np.array(n.get("scale", [1, 1, 1]))
    m[:3, 3] = n.get("translation", [0, 0, 0])
    return m


def load(path):
    """The default scene of a .gltf as world-space primitives and cameras:
    {'doc', 'folder', 'prims': [{'P', 'N' (or None), 'UV' (or None), 'I', 'material'}],
     'cameras': [{'eye', 'forward', 'up', 'yfov'}], 'lights': [{'type', 'color', 'intensity',
     'position', 'direction'}]}."""
    with open(path) as f:
        doc = json.load(f)
    folder = os.path.dirname(path)
    cache = {}
    out = {"doc": doc, "folder": folder, "prims": [], "cameras": [], "lights": []}
    lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    roots = doc["scenes"][doc.get("scene", 0)]["nodes"] if "scenes" in doc else range(len(doc["nodes"]))

    def walk(ni, parent):
        n = doc["nodes"][ni]
        m = parent @ node_matrix(n)
        if "mesh" in n:
            lin = m[:3, :3]
            nrm = np.linalg.inv(lin).T
            for pi, p in enumerate(doc["meshes"][n["mesh"]]["primitives"]):
                if p.get("mode", 4) != 4:
                    raise GltfError(f"meshes[{n['mesh']}].primitives[{pi}]: only triangles are read")
                if "extensions" in p:
                    raise GltfError(f"meshes[{n['mesh']}].primitives[{pi}]: compressed meshes are not read")
                at = p["attributes"]
                P = accessor(doc, folder, at["POSITION"], cache).astype(np.float64) @ lin.T + m[:3, 3]
                N = None
                if "NORMAL" in at:
                    N = accessor(doc, folder, at["NORMAL"], cache).astype(np.float64) @ nrm.T
                    N /= np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-30)
                UV = accessor(doc, folder, at["TEXCOORD_0"], cache) if "TEXCOORD_0" in at else None
                if "indices" in p:
                    I = accessor(doc, folder, p["indices"], cache).reshape(-1, 3).astype(np.uint32)
                else:
                    I = np.arange(len(P), dtype=np.uint32).reshape(-1, 3)
                if np.linalg.det(lin) < 0:  # a mirroring transform turns the winding
                    I = I[:, ::-1].copy()
                out["prims"].append({"P": P, "N": N, "UV": UV, "I": I, "material": p.get("material")})
        if "camera" in n:
            c = doc["cameras"][n["camera"]]
            if c.get("type") != "perspective":
                raise GltfError(f"cameras[{n['camera']}]: only perspective cameras are converted")
            out["cameras"].append({"eye": m[:3, 3], "forward": -m[:3, 2] / np.linalg.norm(m[:3, 2]),
                                   "up": m[:3, 1] / np.linalg.norm(m[:3, 1]),
                                   "yfov": c["perspective"]["yfov"]})
        li = n.get("extensions", {}).get("KHR_lights_punctual", {}).get("light")
        if li is not None:
            L = lights[li]
            out["lights"].append({"type": L["type"], "color": L.get("color", [1, 1, 1]),
                                  "intensity": L.get("intensity", 1.0), "position": m[:3, 3],
                                  "direction": -m[:3, 2] / np.linalg.norm(m[:3, 2])})
        for c in n.get("children", []):
            walk(c, m)

    for r in roots:
        walk(r, np.eye(4))
    return out


def look_at_matrix(eye, target, up):
    """A glTF camera node matrix (column-major list) at eye looking at target."""
    eye, target, up = (np.asarray(v, dtype=np.float64) for v in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = r, u, -f, eye
    return [float(x) for x in m.T.reshape(-1)]


def write(path, meshes, materials, camera=None, extensions=()):
    """Writes PATH (.gltf) and PATH's .bin: meshes = [(name, P, N or None, I, material)],
    materials = glTF material objects, camera = (eye, target, up, yfov radians)."""
    blob = bytearray()
    views, accessors, gmeshes, nodes = [], [], [], []

    def add(arr, ctype, gtype, target, minmax=False):
        arr = np.ascontiguousarray(arr)
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": arr.nbytes, "target": target})
        blob.extend(arr.tobytes())
        a = {"bufferView": len(views) - 1, "componentType": ctype, "count": len(arr), "type": gtype}
        if minmax:
            a["min"] = [float(x) for x in arr.min(axis=0)]
            a["max"] = [float(x) for x in arr.max(axis=0)]
        accessors.append(a)
        return len(accessors) - 1

    for name, P, N, I, mat in meshes:
        attrs = {"POSITION": add(np.asarray(P, np.float32), 5126, "VEC3", 34962, True)}
        if N is not None:
            attrs["NORMAL"] = add(np.asarray(N, np.float32), 5126, "VEC3", 34962)
        idx = add(np.asarray(I, np.uint32).reshape(-1), 5125, "SCALAR", 34963)
        gmeshes.append({"name": name, "primitives": [{"attributes": attrs, "indices": idx, "material": mat}]})
        nodes.append({"name": name, "mesh": len(gmeshes) - 1})
    doc = {"asset": {"version": "2.0", "generator": "gonio tests/peer"}, "scene": 0,
           "materials": materials, "meshes": gmeshes, "accessors": accessors, "bufferViews": views,
           "buffers": [{"byteLength": len(blob), "uri": os.path.basename(path)[:-5] + ".bin"}]}
    if extensions:
        doc["extensionsUsed"] = sorted(extensions)
    if camera is not None:
        eye, target, up, yfov = camera
        doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": yfov, "znear": 1e-3}}]
        nodes.append({"name": "camera", "camera": 0, "matrix": look_at_matrix(eye, target, up)})
    doc["nodes"] = nodes
    doc["scenes"] = [{"nodes": list(range(len(nodes)))}]
    with open(path[:-5] + ".bin", "wb") as f:
        f.write(blob)
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
