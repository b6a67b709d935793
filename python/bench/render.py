"""Render times and sizes: baked spectral file vs render-time uplift vs Mitsuba's own bitmap.

    python python/bench/render.py IMAGE [--res 256] [--spp 16] [--variants scalar_spectral,...]

One run, one machine: every time is reported with its ratio to Mitsuba's `bitmap` of the same
source in the same variant (timing is relative, never absolute); each texture's render is the
best of --rounds, the textures interleaved in every round. The scene is the tests' plate
(an orthographic camera filling it, a uniform illuminant-A environment, BSDF sampling).

Textures compared:
  bitmap              Mitsuba's own RGB texture of IMAGE (Jakob–Hanika uplift at render time)
  specconv_spectral   the file `specconv convert IMAGE` bakes (what ships: ≈15× the RGB size)
  specconv_rgb        IMAGE uplifted per texel at load, then looked up as the baked file
  per-lookup (bound)  what uplifting at each lookup costs at least: bilinear XYZ, then the
                      affine leaf map r(λ) = T(λ)·c + o(λ) of ONE leaf (no tree walk, no bounded
                      projection): a lower bound on the time, not a correct uplift
  per-lookup (uplift) scalar only, with the compiled package: `specconv.uplift` of the bilinear
                      XYZ at every lookup (the exact per-lookup path a Python plugin has)

The LLVM variants trace a texture's Python `eval` once into a kernel, so no library call can run
per lookup there: per lookup in LLVM would mean the tree in Dr.Jit code, which the bound prices.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

import numpy as np


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("image", help="an 8-bit sRGB image (PNG, JPEG)")
    ap.add_argument("--res", type=int, default=256, help="render width and height")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--rounds", type=int, default=3, help="renders per texture; the best counts")
    ap.add_argument("--variants", default="scalar_spectral,llvm_ad_spectral")
    ap.add_argument("--work", default=None, help="folder for the converted files (default: temp)")
    args = ap.parse_args()

    import mitsuba as mi
    import OpenImageIO as oiio

    import specconv
    import specconv.mitsuba

    work = args.work or tempfile.mkdtemp(prefix="specconv-bench-")
    os.makedirs(work, exist_ok=True)
    stem = os.path.splitext(os.path.basename(args.image))[0]
    png = os.path.join(work, stem + ".png")
    oiio.ImageBuf(args.image).write(png)  # the source as a PNG: what `bitmap` and specconv_rgb read
    # The RGB counterpart in the spectral file's container: half, 64² tiles, MIP-mapped, ZIP.
    rgb_exr = os.path.join(work, stem + "_rgb_half.exr")
    config = oiio.ImageSpec()
    config.attribute("maketx:filtername", "box")
    config.attribute("tile_width", 64)
    config.attribute("tile_height", 64)
    config.attribute("compression", "zip")
    config.set_format(oiio.HALF)
    assert oiio.ImageBufAlgo.make_texture(oiio.MakeTxTexture, oiio.ImageBuf(png), rgb_exr, config)
    baked = os.path.join(work, stem + "_spectral.exr")
    t = time.perf_counter()
    specconv.convert([png], baked)
    convert_s = time.perf_counter() - t

    spec = oiio.ImageInput.open(png).spec()
    print(f"image {args.image}: {spec.width}x{spec.height}; render {args.res}² at {args.spp} spp")
    print(f"convert (baking): {convert_s:.2f} s")
    sizes = {p: os.path.getsize(p) for p in (png, rgb_exr, baked)}
    for p, size in sizes.items():
        ratio = size / sizes[rgb_exr]
        print(f"  {os.path.basename(p):32s} {size / 1e6:8.2f} MB  ({ratio:.1f}× RGB half EXR)")

    for variant in args.variants.split(","):
        try:
            mi.set_variant(variant)
        except Exception as e:  # an LLVM variant without a usable libLLVM
            print(f"{variant}: unavailable ({e})")
            continue
        specconv.mitsuba.register()
        register_bounds(mi, specconv)
        textures = {
            "bitmap": {"type": "bitmap", "filename": png},
            "specconv_spectral": {"type": "specconv_spectral", "filename": baked},
            "specconv_rgb": {"type": "specconv_rgb", "filename": png},
            "per-lookup (bound)": {"type": "bench_lookup_bound", "filename": png},
        }
        if variant.startswith("scalar") and hasattr(specconv, "_specconv"):
            textures["per-lookup (uplift)"] = {"type": "bench_lookup_uplift", "filename": png}
        print(f"\n{variant}")
        print(f"  {'texture':22s} {'load s':>8s} {'render s':>9s} {'× bitmap':>9s}  texel memory")
        loads, scenes = {}, {}
        for name, tex in textures.items():
            t = time.perf_counter()
            scenes[name] = mi.load_dict(scene(mi, tex, args.res, args.spp))
            loads[name] = time.perf_counter() - t
            mi.render(scenes[name], seed=0)  # LLVM compiles here: time the cached kernel below
        renders = best_of_rounds(mi, scenes, args.rounds)
        for name in textures:
            ratio = renders[name] / renders["bitmap"]
            print(
                f"  {name:22s} {loads[name]:8.2f} {renders[name]:9.2f} {ratio:9.2f}  "
                f"{memory(mi, scenes[name])}"
            )
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


def best_of_rounds(mi, scenes: dict, rounds: int) -> dict:
    """Each scene's fastest render over `rounds` rounds, the scenes interleaved in every round:
    a shared machine's load then weighs on all of them alike."""
    best = {name: float("inf") for name in scenes}
    for r in range(rounds):
        for name, s in scenes.items():
            t = time.perf_counter()
            np.array(mi.render(s, seed=1 + r))
            best[name] = min(best[name], time.perf_counter() - t)
    return best


def memory(mi, s) -> str:
    """The texture's texel storage, from its traversed `data` tensor."""
    params = mi.traverse(s.shapes()[0].bsdf())
    for key in params.keys():
        if key.endswith("data"):
            shape = params[key].shape
            return f"{np.prod(shape)} values ({'x'.join(map(str, shape))})"
    return ""


def register_bounds(mi, specconv) -> None:
    """The two per-lookup textures: measured here, not shipped (per texel was chosen)."""
    import drjit as dr

    class Bound(mi.Texture):
        def __init__(self, props):
            mi.Texture.__init__(self, props)
            xyz = specconv.mitsuba.texel_xyz(props["filename"])
            self.tex = mi.Texture2f(mi.TensorXf(xyz), use_accel=False)
            model = specconv.Model.builtin()
            self.w0 = float(model.wavelengths[0])
            self.step = float(model.wavelengths[1] - model.wavelengths[0])
            n = len(model.wavelengths)
            # One leaf's T (n×3) and o (n), as four channels over wavelength.
            rng = np.random.default_rng(0)
            table = rng.random((n, 4)).astype(np.float32) * 0.1
            self.leaf = mi.Texture1f(
                mi.TensorXf(table[:, None, :].reshape(n, 4)),
                use_accel=False,
                wrap_mode=dr.WrapMode.Clamp,
            )
            self.n = n

        def eval(self, si, active=True):
            c = self.tex.eval(si.uv, active)
            out = []
            for i in range(len(si.wavelengths)):
                lam = si.wavelengths[i]
                x = ((lam - self.w0) / self.step + 0.5) / self.n
                t = self.leaf.eval(mi.Point1f(x), active)
                out.append(t[0] * c[0] + t[1] * c[1] + t[2] * c[2] + t[3])
            return mi.UnpolarizedSpectrum(out)

        def mean(self):
            return 0.5

        def traverse(self, callback):
            callback.put("data", self.tex.tensor(), mi.ParamFlags.NonDifferentiable)

    class Uplift(Bound):
        def __init__(self, props):
            Bound.__init__(self, props)
            self.model = specconv.Model.builtin()
            self.wl = np.asarray(self.model.wavelengths)

        def eval(self, si, active=True):
            c = np.array(self.tex.eval(si.uv, active), dtype=np.float32).reshape(1, 3)
            r = specconv.uplift(c, model=self.model)[0]
            lam = np.array(si.wavelengths, dtype=np.float64).ravel()
            return mi.UnpolarizedSpectrum(*np.interp(lam, self.wl, r, left=0.0, right=0.0))

    mi.register_texture("bench_lookup_bound", lambda p: Bound(p))
    mi.register_texture("bench_lookup_uplift", lambda p: Uplift(p))


if __name__ == "__main__":
    sys.exit(main())
