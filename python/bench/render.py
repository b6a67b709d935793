"""Disk, load time, peak memory and render time of specconv's Mitsuba textures against `bitmap`.

    python python/bench/render.py IMAGE [--size 2048] [--res 512] [--spp 64] [--rounds 3]
                                        [--passes 3] [--variant llvm_ad_spectral]
                                        [--textures a,b,...] [--json FILE]

One run, one machine: every figure is reported with its ratio to Mitsuba's own `bitmap` of the
same RGB file in the same run (ratios, never absolute timings, are what the run shows), the
best of each figure over the passes and, with --passes > 1, each pass's ratios to that pass's
`bitmap`, and the ratio of each pass's render CPU time (all threads: on a shared machine the
wall time also counts the waits for a core); issue 47's targets are marked met or missed. Each
texture is measured in a process of its own, so that its peak memory (the process's maximum
resident set, Linux's VmHWM) is its own: load (the scene with the texture, `mi.load_dict`), a
first render (compiling, in the LLVM variants), then the best of --rounds renders. The
processes run one after the other, in --rounds interleaved passes when asked.

--scene plate (default) is the tests' plate: an orthographic camera filling a diffuse
rectangle, a uniform illuminant-A environment, BSDF sampling alone, so that the texture's
lookups are most of the work (a worst case for a costly lookup). --scene room is a path-traced
box (path, max depth 6, an area light of illuminant A): the texture on its floor and on a
sphere, plain grey walls; lookups are then a smaller part of a render, as in production.

Textures compared (IMAGE is cropped and resized to --size², written as an 8-bit sRGB PNG):
  bitmap              Mitsuba's RGB texture of the PNG (Jakob-Hanika coefficients per texel)
  specconv_spectral   the file `specconv convert` bakes from the PNG (36 bands per texel)
  specconv_compact    the file `convert --layout compact` writes (6 values per texel),
                      decoded per lookup, or from a palette of its distinct texels' spectra
                      where they repeat (docs/renderers.md)
  specconv_rgb        the PNG read by Mitsuba's reader, made compact texels in memory by the
                      library at load, then as specconv_compact
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

TEXTURES = ("bitmap", "specconv_spectral", "specconv_compact", "specconv_rgb")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("image", help="any image OpenImageIO reads (a photograph)")
    ap.add_argument("--size", type=int, default=2048, help="texture width and height")
    ap.add_argument("--res", type=int, default=512, help="render width and height")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--rounds", type=int, default=3, help="renders per texture; the best counts")
    ap.add_argument("--passes", type=int, default=1, help="processes per texture, interleaved")
    ap.add_argument("--variant", default="llvm_ad_spectral")
    ap.add_argument("--scene", choices=("plate", "room"), default="plate")
    ap.add_argument("--textures", default=",".join(TEXTURES))
    ap.add_argument("--work", default=None, help="folder for the files (default: temp)")
    ap.add_argument("--json", default=None, help="write every pass's figures to this file")
    ap.add_argument("--child", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        return child(args)

    import OpenImageIO as oiio

    import specconv

    work = args.work or tempfile.mkdtemp(prefix="specconv-bench-")
    os.makedirs(work, exist_ok=True)
    files = make_files(oiio, specconv, args.image, args.size, work)
    print(
        f"{args.image} as {args.size}² 8-bit sRGB PNG; {args.variant}, {args.scene}, "
        f"{args.res}² at {args.spp} spp"
    )
    print("\ndisk (MIP-mapped, 64² tiles, ZIP):")
    rgb = os.path.getsize(files["rgb_half"])
    for name in ("png", "rgb_half", "specconv_spectral", "specconv_compact"):
        size = os.path.getsize(files[name])
        print(f"  {name:20s} {size / 1e6:8.2f} MB  {size / rgb:6.2f}× maketx half RGB")

    names = args.textures.split(",")
    runs: dict[str, list[dict]] = {n: [] for n in names}
    for _ in range(args.passes):
        for name in names:
            out = subprocess.run(
                [sys.executable, __file__, args.image, "--child", name, "--work", work]
                + [f"--{k}={getattr(args, k)}" for k in ("res", "spp", "rounds", "variant")]
                + [f"--scene={args.scene}"],
                capture_output=True,
                text=True,
                env=dict(os.environ, SPECCONV_BENCH_FILES=json.dumps(files)),
            )
            if out.returncode != 0:
                print(f"{name}: failed\n{out.stderr[-2000:]}")
                return 1
            runs[name].append(json.loads(out.stdout.strip().splitlines()[-1]))
    best = {n: {k: min(r[k] for r in runs[n]) for k in runs[n][0]} for n in names}
    base = best["bitmap"] if "bitmap" in best else None
    print(f"\n{'texture':20s} {'load s':>8s} {'peak MB':>8s} {'render s':>9s}", end="")
    print("   × bitmap: load, memory, render   (best of each figure over the passes)")
    for n in names:
        b = best[n]
        line = f"{n:20s} {b['load']:8.2f} {b['peak'] / 1e6:8.0f} {b['render']:9.3f}"
        if base:
            line += "   " + "  ".join(f"{r:5.2f}" for r in ratios(b, base))
            if n in TARGETS:
                met = [r <= t for r, t in zip(ratios(b, base), TARGETS[n])]
                line += "   targets " + ", ".join(
                    f"{t}× {'met' if m else 'missed'}" for t, m in zip(TARGETS[n], met)
                )
        print(line)
    if base and args.passes > 1:
        # Each pass against bitmap's own figures of that pass: how much the ratios move.
        print("\nper pass, × that pass's bitmap: load, memory, render")
        for n in names:
            passes = [ratios(r, b) for r, b in zip(runs[n], runs["bitmap"])]
            print(f"  {n:20s} " + " | ".join("  ".join(f"{v:5.2f}" for v in p) for p in passes))
        # The renders' CPU time (all threads): what a loaded machine's waiting leaves out.
        print("\nper pass, render CPU time × that pass's bitmap's")
        for n in names:
            cpu = [r["cpu"] / b["cpu"] for r, b in zip(runs[n], runs["bitmap"])]
            print(f"  {n:20s} " + "  ".join(f"{v:5.2f}" for v in cpu))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"runs": runs, "best": best}, f, indent=1)
    return 0


# Issue 47's targets, × bitmap's load time, peak memory and render time.
TARGETS = {"specconv_rgb": (1.5, 1.3, 1.5), "specconv_compact": (1.3, 1.3, 1.5)}


def ratios(b: dict, base: dict) -> tuple[float, float, float]:
    """Load, peak memory and render of `b` over `base`'s."""
    return tuple(b[k] / base[k] for k in ("load", "peak", "render"))


def make_files(oiio, specconv, image: str, size: int, work: str) -> dict:
    """The PNG, maketx's half RGB texture of it, and the two files specconv makes of it."""
    png = os.path.join(work, f"texture{size}.png")
    src = oiio.ImageBuf(image)
    spec = src.spec()
    side = min(spec.width, spec.height)
    square = oiio.ImageBufAlgo.cut(
        src, oiio.ROI((spec.width - side) // 2, (spec.width + side) // 2, 0, side)
    )
    resized = oiio.ImageBufAlgo.resize(square, roi=oiio.ROI(0, size, 0, size, 0, 1, 0, 3))
    out = oiio.ImageBuf(oiio.ImageSpec(size, size, 3, "uint8"))
    oiio.ImageBufAlgo.copy(out, resized, "uint8")
    out.write(png)
    rgb_half = os.path.join(work, f"texture{size}_rgb_half.exr")
    config = oiio.ImageSpec()
    config.attribute("maketx:filtername", "box")
    config.attribute("tile_width", 64)
    config.attribute("tile_height", 64)
    config.attribute("compression", "zip")
    config.set_format(oiio.HALF)
    assert oiio.ImageBufAlgo.make_texture(oiio.MakeTxTexture, oiio.ImageBuf(png), rgb_half, config)
    files = {"png": png, "rgb_half": rgb_half}
    for layout in ("spectral", "compact"):
        path = os.path.join(work, f"texture{size}_{layout}.exr")
        if os.path.exists(path):
            os.remove(path)
        specconv.convert([png], path, layout=layout)
        files[f"specconv_{layout}"] = path
    return files


def child(args) -> int:
    """One texture: load, compile, the best of the rounds' renders, the peak memory."""
    import numpy as np

    import mitsuba as mi

    mi.set_variant(args.variant)
    import specconv.mitsuba

    specconv.mitsuba.register()
    files = json.loads(os.environ["SPECCONV_BENCH_FILES"])
    name = args.child
    filename = files["png"] if name in ("bitmap", "specconv_rgb") else files[name]
    texture = {"type": name, "filename": filename}
    t = time.perf_counter()
    s = mi.load_dict((room if args.scene == "room" else scene)(mi, texture, args.res, args.spp))
    load = time.perf_counter() - t
    np.array(mi.render(s, seed=0))  # LLVM compiles here: the rounds below reuse the kernel
    render = cpu = float("inf")
    for r in range(args.rounds):
        t, c = time.perf_counter(), _cpu_seconds()
        np.array(mi.render(s, seed=1 + r))
        render = min(render, time.perf_counter() - t)
        cpu = min(cpu, _cpu_seconds() - c)
    print(json.dumps({"load": load, "render": render, "peak": _peak_bytes(), "cpu": cpu}))


def _peak_bytes() -> int:
    """This process's peak resident memory: Linux's VmHWM, which starts again at exec. Not
    `ru_maxrss`: Linux carries it over an exec from the forked parent, so every child
    reported at least the parent's peak (329 MB, once the parent had baked the files)."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024  # kB
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # Linux: KiB


def _cpu_seconds() -> float:
    """The process's CPU time, all threads: on a machine shared with other work a render's
    wall time waits for the cores, its CPU time much less."""
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
    return 0


def scene(mi, texture: dict, res: int, spp: int) -> dict:
    return {
        "type": "scene",
        "integrator": {"type": "direct", "emitter_samples": 0, "bsdf_samples": 1},
        "sensor": {
            "type": "orthographic",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0]
            ),
            "film": {"type": "hdrfilm", "width": res, "height": res, "pixel_format": "xyz"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "emitter": {"type": "constant", "radiance": {"type": "blackbody", "temperature": 2856}},
        "plate": {"type": "rectangle", "bsdf": {"type": "diffuse", "reflectance": texture}},
    }


def room(mi, texture: dict, res: int, spp: int) -> dict:
    """A closed box lit by an area light: the texture on the floor and on a sphere."""
    T = mi.ScalarTransform4f
    grey = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.6, 0.6, 0.6]}}
    textured = {"type": "diffuse", "reflectance": texture}
    wall = lambda t: {"type": "rectangle", "to_world": t, "bsdf": grey}  # noqa: E731
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 6},
        "sensor": {
            "type": "perspective",
            "fov": 45,
            "to_world": T().look_at(origin=[0, 0, 3.6], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": res, "height": res, "pixel_format": "xyz"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "floor": {
            "type": "rectangle",
            "to_world": T().translate([0, -1, 0]).rotate([1, 0, 0], -90),
            "bsdf": textured,
        },
        "ceiling": wall(T().translate([0, 1, 0]).rotate([1, 0, 0], 90)),
        "back": wall(T().translate([0, 0, -1])),
        "left": wall(T().translate([-1, 0, 0]).rotate([0, 1, 0], 90)),
        "right": wall(T().translate([1, 0, 0]).rotate([0, 1, 0], -90)),
        "sphere": {"type": "sphere", "center": [0.3, -0.55, 0.2], "radius": 0.45, "bsdf": textured},
        "light": {
            "type": "rectangle",
            "to_world": T().translate([0, 0.99, 0]).rotate([1, 0, 0], 90).scale(0.3),
            "emitter": {"type": "area", "radiance": {"type": "blackbody", "temperature": 2856}},
        },
    }


if __name__ == "__main__":
    sys.exit(main())
