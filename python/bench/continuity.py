"""How smoothly the model's spectra follow a smooth change of colour, seen under other light
(docs/hard-inputs.md, "Continuity near the surface of the solid"):

  python python/bench/continuity.py [--steps 20000] [--model NAME]

Ramps of the most saturated colours (HSV hue sweeps at S = 1, V = 0.5 and V = 1) in ACEScg
and in linear Rec.709, each colour made XYZ by the library (`specconv.rgb_to_xyz`, OpenColorIO)
and uplifted as `convert` uplifts float32 pixels (`specconv.uplift`), bounded (the default) and
unbounded (the model's own spectra). Neighbouring colours of a ramp are close: their CIEDE2000
under D65 is small, and under another light (A, F11) their spectra's colours should be as
close. For each ramp and light, colour-science's CIEDE2000 (CIE 1931 2°, the light's white)
between neighbours: median, 99.9th percentile, largest, and how many steps exceed 0.5.

Then "one ulp": each colour against the same colour with each of X, Y, Z moved by one float32
ulp (a seeded choice of direction), the difference two routes to "the same" colour can make
(OpenColorIO's matrix against a file's own, docs/compact.md): how many spectra move by more
than 0.01 in some band, and their largest CIEDE2000 under F11.

Prints JSON lines. Asserts nothing.
"""
import argparse
import json
import warnings

import numpy as np

warnings.filterwarnings("ignore")
import colour  # noqa: E402
import specconv  # noqa: E402

LIGHTS = {"D65": "D65", "A": "A", "F11": "FL11"}


def lab_under(spectra, wavelengths, light):
    """CIELAB of reflectances under `light` (CIE 1931 2°, Y of the light's white = 1)."""
    step = float(wavelengths[1] - wavelengths[0])
    shape = colour.SpectralShape(float(wavelengths[0]), float(wavelengths[-1]), step)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    sd = colour.SDS_ILLUMINANTS[LIGHTS[light]].copy().align(shape)
    weights = cmfs.values * sd.values[:, None]
    weights /= weights[:, 1].sum()
    white = weights.sum(axis=0)
    return colour.XYZ_to_Lab(spectra @ weights, colour.XYZ_to_xy(white))


def steps(lab):
    d = colour.delta_E(lab[1:], lab[:-1], method="CIE 2000")
    return {
        "median": round(float(np.median(d)), 4),
        "p99.9": round(float(np.percentile(d, 99.9)), 3),
        "max": round(float(d.max()), 3),
        "over 0.5": int((d > 0.5).sum()),
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--model", default=None, help="a built-in model (default: the model in force)")
    a = ap.parse_args()
    model = specconv.Model.builtin(a.model)
    wl = model.wavelengths
    hue = np.linspace(0.0, 1.0, a.steps, endpoint=False)
    rng = np.random.default_rng(47)
    for space in ("ACEScg", "Linear Rec.709 (sRGB)"):
        for value in (0.5, 1.0):
            hsv = np.stack([hue, np.ones_like(hue), np.full_like(hue, value)], axis=1)
            rgb = colour.HSV_to_RGB(hsv).astype(np.float32)
            xyz = specconv.rgb_to_xyz(rgb, space).astype(np.float32)
            ramp = f"{space}, S 1, V {value}"
            for bounded in (True, False):
                r = specconv.uplift(xyz, model, bounded=bounded).astype(np.float64)
                row = {"ramp": ramp, "bounded": bounded, "colours": len(xyz)}
                for light in LIGHTS:
                    row[light] = steps(lab_under(r, wl, light))
                print(json.dumps(row), flush=True)
            # One float32 ulp of each component, towards +∞ or −∞ by a seeded coin.
            towards = np.where(rng.random(xyz.shape) < 0.5, np.inf, -np.inf).astype(np.float32)
            moved = np.nextafter(xyz, towards)
            r0 = specconv.uplift(xyz, model).astype(np.float64)
            r1 = specconv.uplift(moved, model).astype(np.float64)
            far = np.abs(r0 - r1).max(axis=1) > 0.01
            d = colour.delta_E(lab_under(r0, wl, "F11"), lab_under(r1, wl, "F11"), method="CIE 2000")
            print(
                json.dumps(
                    {
                        "ramp": ramp,
                        "one ulp": {
                            "spectra moved > 0.01": int(far.sum()),
                            "F11 max": round(float(d.max()), 3),
                            "F11 over 0.5": int((d > 0.5).sum()),
                        },
                    }
                ),
                flush=True,
            )


if __name__ == "__main__":
    main()
