#!/usr/bin/env python3
# bunny.py OBJ OUT.gltf: the Stanford bunny scene of the peer bench (tests/peer/scenes.py:
# the scan 1 tall on a grey ground, under a small quad light out of view) with the
# standard library alone, for the denoiser's measurements (tests/denoise/quality.sh).
import json
import math
import struct
import sys


def read_obj(path):
    V, F = [], []
    with open(path) as f:
        for line in f:
            s = line.split()
            if s and s[0] == "v":
                V.append([float(x) for x in s[1:4]])
            elif s and s[0] == "f":
                F.append([int(x.split("/")[0]) - 1 for x in s[1:4]])
    return V, F


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def smooth_normals(V, F):
    N = [[0.0, 0.0, 0.0] for _ in V]
    for f in F:  # area-weighted
        n = cross(sub(V[f[1]], V[f[0]]), sub(V[f[2]], V[f[0]]))
        for i in f:
            for k in range(3):
                N[i][k] += n[k]
    out = []
    for n in N:
        ln = math.sqrt(n[0] ** 2 + n[1] ** 2 + n[2] ** 2)
        out.append([n[0] / ln, n[1] / ln, n[2] / ln] if ln > 0 else [0.0, 1.0, 0.0])
    return out


def quad(corner, e1, e2):
    c = corner
    P = [c, [c[k] + e1[k] for k in range(3)], [c[k] + e1[k] + e2[k] for k in range(3)], [c[k] + e2[k] for k in range(3)]]
    n = cross(e1, e2)
    ln = math.sqrt(sum(x * x for x in n))
    return P, [[x / ln for x in n]] * 4, [[0, 1, 3], [1, 2, 3]]


def lambert(rgb):
    return {"pbrMetallicRoughness": {"baseColorFactor": list(rgb) + [1], "metallicFactor": 0, "roughnessFactor": 1},
            "extensions": {"KHR_materials_specular": {"specularFactor": 0}}}


def main(obj, out):
    V, F = read_obj(obj)
    lo = [min(v[k] for v in V) for k in range(3)]
    hi = [max(v[k] for v in V) for k in range(3)]
    h = hi[1] - lo[1]
    V = [[(v[0] - (lo[0] + hi[0]) / 2) / h, (v[1] - lo[1]) / h, (v[2] - (lo[2] + hi[2]) / 2) / h] for v in V]
    meshes = [quad([-3, 0, 3], [6, 0, 0], [0, 0, -6]) + (0,), quad([-0.4, 2.2, -0.4], [0.8, 0, 0], [0, 0, 0.8]) + (1,),
              (V, smooth_normals(V, F), F, 2)]
    light = lambert((0, 0, 0))
    light["emissiveFactor"] = [1, 0.9, 0.8]
    light["extensions"]["KHR_materials_emissive_strength"] = {"emissiveStrength": 40}
    doc = {"asset": {"version": "2.0", "generator": "gonio tests/denoise/bunny.py"},
           "extensionsUsed": ["KHR_materials_specular", "KHR_materials_emissive_strength"],
           "materials": [lambert((0.6, 0.6, 0.6)), light, lambert((0.8, 0.75, 0.7))],
           "meshes": [], "nodes": [], "accessors": [], "bufferViews": [], "buffers": [], "scenes": [{"nodes": []}], "scene": 0}
    blob = bytearray()

    def view(data, count, kind, ctype, target, bounds=None):
        doc["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
        blob.extend(data)
        a = {"bufferView": len(doc["bufferViews"]) - 1, "componentType": ctype, "count": count, "type": kind}
        if bounds:
            a["min"], a["max"] = bounds
        doc["accessors"].append(a)
        return len(doc["accessors"]) - 1

    for i, (P, N, I, mat) in enumerate(meshes):
        pos = view(struct.pack(f"<{3 * len(P)}f", *[x for p in P for x in p]), len(P), "VEC3", 5126, 34962,
                   ([min(p[k] for p in P) for k in range(3)], [max(p[k] for p in P) for k in range(3)]))
        nrm = view(struct.pack(f"<{3 * len(N)}f", *[x for n in N for x in n]), len(N), "VEC3", 5126, 34962)
        idx = view(struct.pack(f"<{3 * len(I)}I", *[x for t in I for x in t]), 3 * len(I), "SCALAR", 5125, 34963)
        doc["meshes"].append({"primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx, "material": mat}]})
        doc["nodes"].append({"mesh": i})
        doc["scenes"][0]["nodes"].append(i)
    # The camera of the peer bench: from (0.4, 0.9, 2.4) towards (0, 0.45, 0), yfov 0.55 rad.
    eye, target = [0.4, 0.9, 2.4], [0, 0.45, 0]
    f = sub(target, eye)
    ln = math.sqrt(sum(x * x for x in f))
    f = [x / ln for x in f]
    r = cross(f, [0, 1, 0])
    ln = math.sqrt(sum(x * x for x in r))
    r = [x / ln for x in r]
    u = cross(r, f)
    # A rotation whose -Z is f, +X r, +Y u, as a quaternion.
    m = [[r[0], u[0], -f[0]], [r[1], u[1], -f[1]], [r[2], u[2], -f[2]]]
    w = math.sqrt(max(0.0, 1 + m[0][0] + m[1][1] + m[2][2])) / 2
    q = [(m[2][1] - m[1][2]) / (4 * w), (m[0][2] - m[2][0]) / (4 * w), (m[1][0] - m[0][1]) / (4 * w), w]
    doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.55, "znear": 0.01, "aspectRatio": 1.0}}]
    doc["nodes"].append({"camera": 0, "translation": eye, "rotation": q})
    doc["scenes"][0]["nodes"].append(len(doc["nodes"]) - 1)
    bin_name = out.rsplit("/", 1)[-1].rsplit(".", 1)[0] + ".bin"
    doc["buffers"].append({"uri": bin_name, "byteLength": len(blob)})
    with open(out.rsplit("/", 1)[0] + "/" + bin_name if "/" in out else bin_name, "wb") as fb:
        fb.write(blob)
    with open(out, "w") as fj:
        json.dump(doc, fj)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
