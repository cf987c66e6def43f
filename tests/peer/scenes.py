# scenes.py: the peer bench's scenes, written as glTF under an output folder. None is
# shaped for gonio's layout: triangles in random order, quads split along the diagonal the
# project's generator does not use, meshes as scanned (the bunny) or as other tools write
# them (DamagedHelmet, read in place). Each scene is a dict: name, gltf, env (constant
# radiance or 0), look_at (eye, target, up) and fov (degrees) when the file has no camera,
# shuffle_of (the scene it is with its index buffer shuffled).
import os

import numpy as np

import gltf_io


def lambert(rgb):
    # KHR_materials_specular 0 and roughness 1: glTF's BRDF reduces to Lambert, which
    # Mitsuba's `diffuse` is exactly.
    return {"pbrMetallicRoughness": {"baseColorFactor": list(rgb) + [1], "metallicFactor": 0,
                                     "roughnessFactor": 1},
            "extensions": {"KHR_materials_specular": {"specularFactor": 0}}}


def emitter(rgb, strength):
    m = lambert((0, 0, 0))
    m["emissiveFactor"] = list(rgb)
    m["extensions"]["KHR_materials_emissive_strength"] = {"emissiveStrength": strength}
    return m


GLASS = {"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0,
                                  "roughnessFactor": 0},
         "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                        "KHR_materials_ior": {"ior": 1.5}}}
GOLD = {"pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.766, 0.336, 1], "metallicFactor": 1,
                                 "roughnessFactor": 0.35}}
PLASTIC = {"pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.25, 0.7, 1], "metallicFactor": 0,
                                    "roughnessFactor": 0.35}}
EXT = {"KHR_materials_specular", "KHR_materials_emissive_strength", "KHR_materials_transmission",
       "KHR_materials_ior"}


def icosphere(level, center=(0, 0, 0), radius=1.0):
    t = (1 + 5 ** 0.5) / 2
    P = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
         (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    F = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9),
         (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    P = [np.array(p, float) / np.linalg.norm(p) for p in P]
    for _ in range(level):
        mid, G = {}, []

        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                v = P[a] + P[b]
                P.append(v / np.linalg.norm(v))
                mid[k] = len(P) - 1
            return mid[k]
        for a, b, c in F:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            G += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        F = G
    N = np.array(P)
    return N * radius + np.asarray(center, float), N, np.array(F, np.uint32)


def quad(corner, e1, e2):
    """Two triangles of the quad corner, corner + e1, corner + e1 + e2, corner + e2, split
    along the (corner + e1, corner + e2) diagonal; the front is e1 x e2."""
    c, e1, e2 = (np.asarray(v, float) for v in (corner, e1, e2))
    P = np.array([c, c + e1, c + e1 + e2, c + e2])
    n = np.cross(e1, e2)
    N = np.tile(n / np.linalg.norm(n), (4, 1))
    return P, N, np.array([[0, 1, 3], [1, 2, 3]], np.uint32)


def smooth_normals(P, I):
    n = np.cross(P[I[:, 1]] - P[I[:, 0]], P[I[:, 2]] - P[I[:, 0]])  # area-weighted
    N = np.zeros_like(P)
    for k in range(3):
        np.add.at(N, I[:, k], n)
    # A vertex no triangle with an area uses (the scan has a few) gets +Y rather than 0,
    # which gonio would answer by dropping the whole mesh's normals for flat ones.
    N[np.linalg.norm(N, axis=1) == 0] = (0, 1, 0)
    return N / np.linalg.norm(N, axis=1, keepdims=True)


def flip_diagonals_and_shuffle(I, rng):
    """Each consecutive pair of triangles that shares an edge (a quad) split along its other
    diagonal, winding kept; then all triangles in random order."""
    out = []
    k = 0
    while k < len(I):
        t0 = list(I[k])
        t1 = list(I[k + 1]) if k + 1 < len(I) else None
        shared = [v for v in t0 if t1 is not None and v in t1]
        if len(shared) == 2:
            o0 = [v for v in t0 if v not in shared][0]
            o1 = [v for v in t1 if v not in shared][0]
            r = t0.index(o0)
            _, sx, sy = t0[r:] + t0[:r]  # t0 = (o0, sx, sy) in its winding
            out += [(o0, sx, o1), (o0, o1, sy)]
            k += 2
        else:
            out.append(tuple(t0))
            k += 1
    out = np.array(out, np.uint32)
    return out[rng.permutation(len(out))]


def read_obj(path):
    V, F = [], []
    with open(path) as f:
        for line in f:
            s = line.split()
            if not s:
                continue
            if s[0] == "v":
                V.append([float(x) for x in s[1:4]])
            elif s[0] == "f":
                idx = [int(x.split("/")[0]) for x in s[1:]]
                idx = [i - 1 if i > 0 else len(V) + i for i in idx]
                for j in range(1, len(idx) - 1):  # a fan for polygons
                    F.append((idx[0], idx[j], idx[j + 1]))
    return np.array(V, float), np.array(F, np.uint32)


def _cornell(out, gonio_scene_gltf, rng):
    doc = gltf_io.load(gonio_scene_gltf)
    meshes = []
    for k, p in enumerate(doc["prims"]):
        meshes.append((f"part{k}", p["P"], p["N"], flip_diagonals_and_shuffle(p["I"], rng), p["material"]))
    # The parts themselves in random order too: the file's triangle order is then random.
    meshes = [meshes[i] for i in rng.permutation(len(meshes))]
    c = doc["cameras"][0]
    path = os.path.join(out, "cornell-flipped.gltf")
    gltf_io.write(path, meshes, doc["doc"]["materials"], (c["eye"], c["eye"] + c["forward"], c["up"], c["yfov"]),
                  EXT)
    return path


def _ground_and_light(size, y, light_y, light_size, strength):
    g = quad((-size / 2, y, size / 2), (size, 0, 0), (0, 0, -size))  # front +Y
    h = light_size / 2
    li = quad((-h, light_y, -h), (light_size, 0, 0), (0, 0, light_size))  # front -Y
    return g, li


def generate(out, assets, gonio_scene_gltf, seed=1):
    """Writes the scenes under OUT; returns the scene list (the bunny's scenes only when
    ASSETS has it, DamagedHelmet only when ASSETS has it)."""
    os.makedirs(out, exist_ok=True)
    rng = np.random.default_rng(seed)
    scenes = [{"name": "cornell-flipped", "gltf": _cornell(out, gonio_scene_gltf, rng), "env": 0}]

    # White furnace: a flat-shaded icosphere (convex, so every bounce escapes): Lambert 0.8
    # under radiance 1 is exactly 0.8 wherever the sphere covers a pixel.
    P, _, I = icosphere(3)
    path = os.path.join(out, "furnace.gltf")
    gltf_io.write(path, [("sphere", P, None, I[rng.permutation(len(I))], 0)], [lambert((0.8, 0.8, 0.8))],
                  ((0, 0, 3.2), (0, 0, 0), (0, 1, 0), 0.7), EXT)
    scenes.append({"name": "furnace", "gltf": path, "env": 1.0})

    # Glass, rough gold and rough plastic spheres on a plane under a quad light.
    (gP, gN, gI), (lP, lN, lI) = _ground_and_light(8, 0, 3, 1.2, 30)
    meshes = [("ground", gP, gN, gI, 0), ("light", lP, lN, lI, 1)]
    for k, (x, mat) in enumerate([(-1.1, 2), (0, 3), (1.1, 4)]):
        P, N, I = icosphere(4, (x, 0.5, 0), 0.5)
        meshes.append((f"sphere{k}", P, N, I[rng.permutation(len(I))], mat))
    path = os.path.join(out, "spheres.gltf")
    gltf_io.write(path, meshes, [lambert((0.6, 0.6, 0.6)), emitter((1, 1, 1), 30), GLASS, GOLD, PLASTIC],
                  ((0, 1.5, 3.8), (0, 0.4, 0), (0, 1, 0), 0.8), EXT)
    scenes.append({"name": "spheres", "gltf": path, "env": 0})

    # Mostly background: one small rough-gold sphere, 20% of the pixels, under a dim
    # constant environment and a quad light out of view.
    P, N, I = icosphere(4, (0, 0, 0), 0.5)
    lP, lN, lI = quad((-0.5, 2, -0.5), (1, 0, 0), (0, 0, 1))
    path = os.path.join(out, "background.gltf")
    # The sphere's image radius is tan(asin(0.5 / 4)) / tan(fov / 2) of the half height:
    # fov 0.49 gives 0.505, pi * 0.505^2 / 4 = 20% of a square image.
    gltf_io.write(path, [("sphere", P, N, I[rng.permutation(len(I))], 0), ("light", lP, lN, lI, 1)],
                  [GOLD, emitter((1, 1, 1), 20)], ((0, 0, 4), (0, 0, 0), (0, 1, 0), 0.49), EXT)
    scenes.append({"name": "background", "gltf": path, "env": 0.3})

    bunny = os.path.join(assets, "mesh", "stanford-bunny.obj")
    if os.path.isfile(bunny):
        V, F = read_obj(bunny)
        lo, hi = V.min(axis=0), V.max(axis=0)
        V = (V - [(lo[0] + hi[0]) / 2, lo[1], (lo[2] + hi[2]) / 2]) / (hi[1] - lo[1])  # 1 tall, on y = 0
        N = smooth_normals(V, F)
        (gP, gN, gI), (lP, lN, lI) = _ground_and_light(6, 0, 2.2, 0.8, 40)
        mats = [lambert((0.6, 0.6, 0.6)), emitter((1, 0.9, 0.8), 40), lambert((0.8, 0.75, 0.7))]
        cam = ((0.4, 0.9, 2.4), (0, 0.45, 0), (0, 1, 0), 0.55)
        for name, FF in (("bunny", F), ("bunny-shuffled", F[rng.permutation(len(F))])):
            path = os.path.join(out, name + ".gltf")
            gltf_io.write(path, [("ground", gP, gN, gI, 0), ("light", lP, lN, lI, 1),
                                 ("bunny", V, N, FF, 2)], mats, cam, EXT)
            scenes.append({"name": name, "gltf": path, "env": 0})
        scenes[-1]["shuffle_of"] = "bunny"  # gonio only, timed in turn with the bunny

    helmet = os.path.join(assets, "gltf", "DamagedHelmet", "glTF", "DamagedHelmet.gltf")
    if os.path.isfile(helmet):
        scenes.append({"name": "helmet", "gltf": helmet, "env": 1.0,
                       "look_at": ((1.2, 0.6, 2.6), (0, 0, 0), (0, 1, 0)), "fov": 40.0})
    return scenes
