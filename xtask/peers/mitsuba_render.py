"""Render a lueur scene file with Mitsuba 3, for `cargo xtask peers`.

Translates what both renderers can express (boxes, spheres and planes with
lueur's transform keys, Lambertian and mirror materials, sphere, rectangle
and directional lights, a constant sky, a pinhole camera) and refuses the
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


def normalized(v):
    length = sum(c * c for c in v) ** 0.5
    return [c / length for c in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def frame_to(T, n, origin, half):
    """The square `half` wide on each side of `origin`, in the plane of unit normal `n`,
    as a transform of Mitsuba's rectangle (whose normal is +z)."""
    a = [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0]
    s = normalized(cross(a, n))
    t = cross(n, s)
    m = [[half * s[r], half * t[r], n[r], origin[r]] for r in range(3)] + [[0, 0, 0, 1]]
    return T(m)


def transformed(T, shape):
    """lueur's transform keys as one transform: `scale`, then `rotate` (degrees about the
    fixed x, then y, then z axes), then `translate`, applied after the shape's own
    centre, as `crates/scene/src/shape.rs` applies them."""
    tr = T()
    if "translate" in shape:
        tr = tr.translate(shape["translate"])
    if "rotate" in shape:
        rx, ry, rz = shape["rotate"]
        tr = tr.rotate([0, 0, 1], rz).rotate([0, 1, 0], ry).rotate([1, 0, 0], rx)
    if "scale" in shape:
        tr = tr.scale(shape["scale"])
    return tr


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
        kind = shape["type"]
        if kind == "box":
            unit = {"type": "cube"}
            local = T().translate(shape.get("center", [0, 0, 0])).scale(shape["half_extents"])
        elif kind == "sphere":
            unit = {"type": "sphere"}
            local = T().translate(shape.get("center", [0, 0, 0])).scale(shape["radius"])
        elif kind == "plane":
            # The half-space below `normal . p = height`, as the square 2e4 wide its top
            # face is: wide enough that no ray the image sees reaches its edge.
            n = normalized(shape["normal"])
            unit = {"type": "rectangle"}
            local = frame_to(T, n, [c * shape.get("height", 0.0) for c in n], 1e4)
        else:
            fail(f"object {i}: shape {kind} has no Mitsuba twin here")
        d[f"object{i}"] = {**unit, "to_world": transformed(T, shape) @ local, "bsdf": bsdf}
    for i, light in enumerate(scene.get("lights", [])):
        emitter = {"type": "area", "radiance": {"type": "rgb", "value": light["radiance"]}} \
            if "radiance" in light else None
        black = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0, 0, 0]}}
        if light["type"] == "sphere":
            d[f"light{i}"] = {
                "type": "sphere",
                "center": light["center"],
                "radius": light["radius"],
                "emitter": emitter,
                "bsdf": black,
            }
        elif light["type"] == "quad":
            # Mitsuba's rectangle is [-1, 1]^2 at z = 0, emitting toward +z: its columns
            # are the half edges, and the normal's column the edges' cross product, which
            # both renderers emit toward.
            u, v = light["edge_u"], light["edge_v"]
            if abs(sum(a * b for a, b in zip(u, v))) > 1e-6 * sum(a * a for a in u + v):
                fail(f"light {i}: a parallelogram that is no rectangle has no Mitsuba twin here")
            n = cross(u, v)
            c = [light["corner"][k] + (u[k] + v[k]) / 2 for k in range(3)]
            m = [[u[r] / 2, v[r] / 2, n[r], c[r]] for r in range(3)] + [[0, 0, 0, 1]]
            d[f"light{i}"] = {
                "type": "rectangle",
                "to_world": T(m),
                "emitter": emitter,
                "bsdf": black,
            }
        elif light["type"] == "directional":
            d[f"light{i}"] = {
                "type": "directional",
                "direction": normalized(light["direction"]),
                "irradiance": {"type": "rgb", "value": light["irradiance"]},
            }
        else:
            fail(f"light {i}: type {light['type']} has no Mitsuba twin here")
    if "sky" in scene:
        d["sky"] = {
            "type": "constant",
            "radiance": {"type": "rgb", "value": scene["sky"]["radiance"]},
        }
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
