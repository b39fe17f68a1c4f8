"""Render a lueur scene file with Mitsuba 3, for `cargo xtask peers`.

Translates what both renderers can express (boxes, spheres, Lambertian and
mirror materials, sphere and quad lights, a pinhole camera) and refuses the
rest, renders with Mitsuba's `path` integrator (BSDF and emitter sampling
combined by the power heuristic: lueur's `mis`), and prints its timings as
`key value` lines. Never a build or test dependency of lueur: only the xtask
report runs it, and only where `pip install mitsuba` was done.

Conventions matched (checked by the report: the two converged images agree
within noise):
- lueur's `max_depth` counts scattering events (0: emitters seen directly);
  Mitsuba's counts path segments (1: emitters seen directly): +1.
- lueur's pixel filter is the box of the pixel (uniform jitter): `box`.
- The camera: `look_at` with the same up vector and a vertical `fov`
  frames the same image, with the same orientation.
- Russian roulette: `--rr-depth` is lueur's `roulette_depth`, the
  scattering events before roulette may end a path. Both then keep a path
  with the probability of its throughput's largest component; Mitsuba also
  ends at least 1 path in 20 at each bounce past that depth (its survival
  is capped at 0.95), where lueur keeps every path whose throughput has a
  component of 1 or more.

Usage: mitsuba_render.py SCENE.toml VARIANT SPP OUT.exr --rr-depth N
       [--seed S] [--sampler independent|multijitter|ldsampler|orthogonal]
       [--repeats N] [--passes N] [--width W --height H] [--max-depth D]

--repeats N renders N more times after the first (timing: the first render
of a JIT variant includes compiling its kernel), and writes the last.
--passes N writes the mean of N renders of SPP with seeds S..S+N-1 (a
reference too large for one wavefront) and, beside OUT, OUT.var.exr: the
variance of that mean, per pixel, from the spread of the passes.
"""

import argparse
import sys
import time
import tomllib


def fail(msg):
    print(f"mitsuba_render.py: {msg}", file=sys.stderr)
    sys.exit(2)


def translate(scene, args, mi):
    T = mi.ScalarTransform4f
    materials = {}
    for name, m in scene.get("materials", {}).items():
        if m["type"] == "lambertian":
            materials[name] = {
                "type": "diffuse",
                "reflectance": {"type": "rgb", "value": m["albedo"]},
            }
        elif m["type"] == "mirror":
            materials[name] = {
                "type": "conductor",
                "material": "none",
                "specular_reflectance": {"type": "rgb", "value": m["reflectance"]},
            }
        else:
            fail(f"material `{name}` of type {m['type']} has no Mitsuba twin here")
    image = scene.get("image", {})
    render = scene.get("render", {})
    width = args.width or image.get("width", 256)
    height = args.height or image.get("height", 256)
    depth = args.max_depth if args.max_depth is not None else render.get("max_depth", 8)
    cam = scene["camera"]
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": depth + 1, "rr_depth": args.rr_depth},
        "sensor": {
            "type": "perspective",
            "fov": cam.get("vfov", 40.0),
            "fov_axis": "y",
            "to_world": T().look_at(
                origin=cam["position"], target=cam["look_at"], up=cam.get("up", [0, 1, 0])
            ),
            "film": {
                "type": "hdrfilm",
                "width": width,
                "height": height,
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
            "sampler": {"type": args.sampler, "sample_count": args.spp},
        },
    }
    for i, o in enumerate(scene.get("objects", [])):
        shape = o["shape"]
        bsdf = materials[o["material"]]
        if shape["type"] == "box":
            d[f"object{i}"] = {
                "type": "cube",
                "to_world": T().translate(shape["center"]).scale(shape["half_extents"]),
                "bsdf": bsdf,
            }
        elif shape["type"] == "sphere":
            d[f"object{i}"] = {
                "type": "sphere",
                "center": shape["center"],
                "radius": shape["radius"],
                "bsdf": bsdf,
            }
        else:
            fail(f"object {i}: shape {shape['type']} has no Mitsuba twin here")
    for i, light in enumerate(scene.get("lights", [])):
        emitter = {"type": "area", "radiance": {"type": "rgb", "value": light["radiance"]}}
        black = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0, 0, 0]}}
        if light["type"] == "sphere":
            d[f"light{i}"] = {
                "type": "sphere",
                "center": light["center"],
                "radius": light["radius"],
                "emitter": emitter,
                "bsdf": black,
            }
        else:
            fail(f"light {i}: type {light['type']} has no Mitsuba twin here")
    if "sky" in scene:
        fail("a sky has no Mitsuba twin here")
    return d


def main():
    p = argparse.ArgumentParser()
    p.add_argument("scene")
    p.add_argument("variant")
    p.add_argument("spp", type=int)
    p.add_argument("out")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--sampler", default="independent")
    p.add_argument("--repeats", type=int, default=1)
    p.add_argument("--passes", type=int, default=0)
    p.add_argument("--width", type=int)
    p.add_argument("--height", type=int)
    p.add_argument("--max-depth", type=int)
    # lueur's roulette_depth for the scene, which the xtask passes: both
    # renderers count scattering events before roulette may end a path
    # (Mitsuba's `depth >= rr_depth` after a vertex's increment, lueur's
    # `depth >= roulette_depth` after a scatter's), so the same number runs
    # the same estimator. A large value turns roulette off.
    p.add_argument("--rr-depth", type=int, required=True)
    args = p.parse_args()

    import drjit as dr
    import mitsuba as mi

    mi.set_variant(args.variant)
    with open(args.scene, "rb") as f:
        scene_toml = tomllib.load(f)
    t0 = time.perf_counter()
    scene = mi.load_dict(translate(scene_toml, args, mi))
    load_s = time.perf_counter() - t0
    if args.passes > 0:
        import numpy as np

        t0 = time.perf_counter()
        passes = []
        for k in range(args.passes):
            img = mi.render(scene, spp=args.spp, seed=args.seed + k)
            passes.append(np.array(img, dtype=np.float64))
        stack = np.stack(passes)
        mean = stack.mean(axis=0)
        var_of_mean = stack.var(axis=0, ddof=1) / args.passes if args.passes > 1 else 0 * mean
        mi.Bitmap(mean.astype(np.float32)).write(args.out)
        mi.Bitmap(var_of_mean.astype(np.float32)).write(args.out[: -len(".exr")] + ".var.exr")
        report(spp=args.spp * args.passes, total_s=time.perf_counter() - t0)
        return
    times = []
    img = None
    for k in range(args.repeats + 1):
        t0 = time.perf_counter()
        img = mi.render(scene, spp=args.spp, seed=args.seed + k)
        # The JIT variants evaluate lazily: force the image before stopping
        # the clock.
        dr.eval(img)
        dr.sync_thread()
        times.append(time.perf_counter() - t0)
    # The first render of a JIT variant includes tracing and compiling the
    # kernel (cached on disk after a first run); it is reported apart.
    bitmap = mi.Bitmap(img)
    bitmap.write(args.out)
    warm = sorted(times[1:])[len(times[1:]) // 2] if len(times) > 1 else times[0]
    report(spp=args.spp, load_s=load_s, first_s=times[0], warm_s=warm)


def report(**numbers):
    """One `key value` line per number on stdout: what the xtask reads."""
    for key, value in numbers.items():
        print(f"{key} {value}")


if __name__ == "__main__":
    main()
