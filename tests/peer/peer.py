#!/usr/bin/env python3
# peer.py: make bench-peer. gonio beside Mitsuba 3 (its LLVM variant, on the same CPU cores)
# on scenes the project did not shape (scenes.py): per scene, gonio's steady-state paths/s
# (a high-spp render minus a low-spp one over the time between, so start-up cancels),
# Mitsuba's paths/s (a render after a first one, which compiles its kernels), the ratio of
# their times for the same paths, and how far the two images agree. Both renderers use
# unbounded depth with Russian roulette from the third bounce on, q = min(max(beta), 0.95)
# (Mitsuba's rr_depth 3; its beta also carries eta^2 inside glass), NEE with MIS (power
# heuristic), a box pixel filter and independent random samples.
#
#   peer.py --gonio build/release/gonio [--out DIR] [--size N] [--spp N] [--low N]
#           [--reps N] [--only a,b] [--check-furnace]
#
# --check-furnace: the converter's test (tests/regress/peer.sh): the white furnace in both
# renderers at 64x64, exit 1 unless each is 0.8 inside the sphere and the two agree.
import argparse
import os
import resource
import subprocess
import sys
import time

import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
import scenes  # noqa: E402
import to_mitsuba  # noqa: E402


def gonio_render(args, sc, spp, seed, exr):
    cmd = [args.gonio, "render", sc["gltf"], "-o", exr, "--size", f"{args.size}x{args.size}",
           "--spp", str(spp), "--seed", str(seed), "--env", str(sc["env"]), "--quiet"]
    if "look_at" in sc:
        cmd += ["--look-at", ",".join(",".join(str(x) for x in v) for v in sc["look_at"]),
                "--fov", str(sc["fov"])]
    t, c = time.perf_counter(), _child_cpu()
    r = subprocess.run(cmd, capture_output=True, text=True)
    t, c = time.perf_counter() - t, _child_cpu() - c
    if r.returncode != 0:
        sys.exit(f"peer: {' '.join(cmd)} failed (exit {r.returncode}):\n{r.stderr}")
    return t, c, r.stderr.strip()


def _child_cpu():
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def read_exr(mi, path):
    b = mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
    return np.array(b, dtype=np.float64)


def steady(paths, lo, hi):
    """paths / (hi - lo): the steady-state rate; none where start-up noise exceeds the
    difference of the two renders' times."""
    return paths / (hi - lo) if hi > lo else float("nan")


def gonio_leaves(args, gltf):
    """gonio bench's line on the BVH's leaf primitives (triangle pairs and singles)."""
    r = subprocess.run([args.gonio, "bench", gltf, "--size", "16x16", "--seconds", "0.05"],
                       capture_output=True, text=True)
    return next((l.split(None, 3)[3] for l in r.stdout.splitlines() if l.startswith("bvh leaf prims")),
                "(gonio bench failed)")


def shuffled(args, a, b):
    """gonio's paths/s on B (A with its index buffer shuffled) against A's, the two timed
    in turn (ABBAAB...), so that the machine's load drifts alike through both."""
    px = args.size * args.size
    ratios = []
    for rep in range(max(args.reps, 3)):
        rate = {}
        for sc in ((a, b) if rep % 2 == 0 else (b, a)):
            exr = os.path.join(args.out, "shuffle.exr")
            t_lo, c_lo, _ = gonio_render(args, sc, args.low, 0, exr)
            t_hi, c_hi, _ = gonio_render(args, sc, args.spp, 0, exr)
            rate[sc["name"]] = (steady(px * (args.spp - args.low), t_lo, t_hi),
                                steady(px * (args.spp - args.low), c_lo, c_hi))
        ra, rb = rate[a["name"]], rate[b["name"]]
        ratios.append((rb[0] / ra[0], rb[1] / ra[1]))
        print(f"{b['name']}, run {rep + 1}: gonio {rb[0] * 1e-6:.3f} M paths/s against {ra[0] * 1e-6:.3f}"
              f" for {a['name']}: ratio {ratios[-1][0]:.3f}; per CPU second {rb[1] * 1e-6:.3f} against "
              f"{ra[1] * 1e-6:.3f}: ratio {ratios[-1][1]:.3f}", flush=True)
    med = np.nanmedian(np.array(ratios), axis=0)
    print(f"{b['name']} / {a['name']}: median ratio {med[0]:.3f}, per CPU second {med[1]:.3f}")
    for sc in (a, b):
        print(f"  {sc['name']}: bvh leaf prims {gonio_leaves(args, sc['gltf'])}")


def machine():
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    return f"{cpu}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}"


def mitsuba_render(mi, dr, scene, spp):
    """(wall seconds, CPU seconds of all the process's threads, the image)."""
    t, c = time.perf_counter(), time.process_time()
    img = mi.render(scene, spp=spp)
    dr.eval(img)
    dr.sync_thread()
    return time.perf_counter() - t, time.process_time() - c, np.array(img, dtype=np.float64)


def agreement(a, b):
    """(mean bias of a against b, relative; relMSE of a against b over pixels and RGB)."""
    bias = (a.mean() - b.mean()) / b.mean()
    relmse = np.mean((a - b) ** 2 / (b ** 2 + 1e-2))
    return bias, relmse


def save_png(mi, path, *imgs):
    img = np.concatenate(imgs, axis=1).astype(np.float32)
    mi.Bitmap(img).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, srgb_gamma=True).write(path)


def setup_mitsuba():
    import drjit as dr
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    return mi, dr


def check_furnace(args):
    """The white furnace at 64x64: gonio and Mitsuba each 0.8 inside the sphere (the
    analytic answer) and the two images equal in mean, each within 4 standard errors
    estimated from the images' own pixel spread (a false failure about 1 in 16000)."""
    mi, dr = setup_mitsuba()
    args.size = 64
    spp = 16
    out = os.path.join(args.out, "check")
    sc = [s for s in scenes.generate(out, args.assets, args.cornell) if s["name"] == "furnace"][0]
    exr = os.path.join(out, "furnace.exr")
    gonio_render(args, sc, spp, 0, exr)
    g = read_exr(mi, exr)
    scene = mi.load_dict(to_mitsuba.scene_dict(mi, sc["gltf"], os.path.join(out, "mitsuba"),
                                               args.size, args.size, spp, sc["env"]))
    m = mitsuba_render(mi, dr, scene, spp)[2]
    # Pixels well inside the silhouette: the sphere (radius 1, 3.2 away) spans
    # tan(asin(1 / 3.2)) / tan(0.35) = 0.90 of the half height; take 0.8 of that.
    n = args.size
    y, x = np.mgrid[0:n, 0:n] + 0.5
    inside = np.hypot(x - n / 2, y - n / 2) < 0.8 * 0.90 * n / 2
    ok = True
    for name, img in (("gonio", g), ("mitsuba", m)):
        v = img[inside].mean(axis=1)
        se = v.std() / np.sqrt(v.size)
        good = abs(v.mean() - 0.8) < 4 * se + 1e-4
        ok &= good
        print(f"{name:8s} inside the sphere {v.mean():.5f} (analytic 0.8, standard error {se:.5f})"
              f" {'ok' if good else 'FAIL'}")
    d = (g - m).mean(axis=2).reshape(-1)
    se = d.std() / np.sqrt(d.size)
    good = abs(d.mean()) < 4 * se + 1e-4
    ok &= good
    print(f"gonio - mitsuba, mean over the image {d.mean():+.5f} (standard error {se:.5f})"
          f" {'ok' if good else 'FAIL'}")
    return 0 if ok else 1


def main():
    ap = argparse.ArgumentParser(description="gonio beside Mitsuba 3 on the bench scenes")
    ap.add_argument("--gonio", required=True)
    ap.add_argument("--out", default="build/peer")
    ap.add_argument("--assets", default=os.environ.get("GONIO_ASSETS", "../shared/assets"))
    ap.add_argument("--cornell", default="scenes/cornell.gltf")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--low", type=int, default=64)
    ap.add_argument("--reps", type=int, default=2)
    ap.add_argument("--only", default="")
    ap.add_argument("--check-furnace", action="store_true")
    args = ap.parse_args()
    if args.check_furnace:
        return check_furnace(args)

    mi, dr = setup_mitsuba()
    out = os.path.abspath(args.out)
    os.makedirs(os.path.join(out, "img"), exist_ok=True)
    todo = scenes.generate(os.path.join(out, "scenes"), args.assets, args.cornell)
    if not any(s["name"] == "bunny" for s in todo):
        print(f"peer: {args.assets}/mesh/stanford-bunny.obj is absent: skipping the bunny scenes")
    if not any(s["name"] == "helmet" for s in todo):
        print(f"peer: {args.assets}/gltf/DamagedHelmet is absent: skipping the helmet")
    if args.only:
        todo = [s for s in todo if s["name"] in args.only.split(",")]
    px = args.size * args.size
    print(f"machine: {machine()}; Mitsuba {mi.__version__} ({mi.variant()}), Dr.Jit {dr.__version__}")
    print(f"{args.size}x{args.size}, {args.spp} spp (gonio: {args.spp} minus {args.low} spp), "
          f"{args.reps} runs each, alternating; M paths/s")
    print(f"{'scene':16s} {'run':>3s} {'gonio':>7s} {'mitsuba':>7s} {'ratio':>6s} {'cpu':>6s}  "
          f"{'bias':>7s} {'relMSE':>7s} {'floor':>7s}")
    for sc in todo:
        if "shuffle_of" in sc:
            continue
        work = os.path.join(out, "mitsuba", sc["name"])
        scene = mi.load_dict(to_mitsuba.scene_dict(mi, sc["gltf"], work, args.size, args.size, args.spp,
                                                   sc["env"], sc.get("look_at"), sc.get("fov")))
        mitsuba_render(mi, dr, scene, args.spp)  # compiles its kernels
        imgs = []
        for rep in range(args.reps):
            exr = os.path.join(out, f"{sc['name']}-gonio{rep}.exr")
            t_lo, c_lo, _ = gonio_render(args, sc, args.low, rep, os.path.join(out, "low.exr"))
            t_hi, c_hi, warn = gonio_render(args, sc, args.spp, rep, exr)
            g_rate = steady(px * (args.spp - args.low), t_lo, t_hi)
            g_cpu = steady(px * (args.spp - args.low), c_lo, c_hi)
            t_m, c_m, m = mitsuba_render(mi, dr, scene, args.spp)
            m_rate, m_cpu = px * args.spp / t_m, px * args.spp / c_m
            g = read_exr(mi, exr)
            imgs.append(g)
            bias, relmse = agreement(g, m)
            # gonio against gonio of another seed: the relMSE that noise alone gives.
            floor = agreement(imgs[0], g)[1] if rep else float("nan")
            print(f"{sc['name']:16s} {rep + 1:3d} {g_rate * 1e-6:7.3f} {m_rate * 1e-6:7.3f} "
                  f"{g_rate / m_rate:6.2f} {g_cpu / m_cpu:6.2f}  {100 * bias:+6.2f}% {relmse:7.4f} {floor:7.4f}",
                  flush=True)
            if warn:
                print(f"  gonio: {warn}")
        save_png(mi, os.path.join(out, "img", sc["name"] + ".png"), imgs[0], m)
    for b in (s for s in todo if "shuffle_of" in s):
        a = [s for s in todo if s["name"] == b["shuffle_of"]][0]
        shuffled(args, a, b)
    print(f"load average at the end: {os.getloadavg()[0]:.1f}")
    print(f"images (gonio | mitsuba): {os.path.join(out, 'img')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
