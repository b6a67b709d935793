"""The spectral EXR layout's reference conversion to XYZ, written independently of specconv.

What afichet/spectral-exr does (lib/SpectrumConverter.cpp, lib/Util.h), in numpy on
colour-science's CIE tables: channel names by the layout's regular expression, wavelengths in
any unit (an SI prefix, m or Hz); the spectrum interpolated linearly at the CIE 1931 2° table's
1 nm wavelengths where they overlap the bands (each band interval from round(start) up to,
not including, round(end), the last one included); emission XYZ = sum of cmf * S, no
normalisation; reflectance XYZ = sum of cmf * D65 * R / sum of ybar * D65. The file is read
with OpenImageIO, not with specconv's reader.

Usage: fichet_reference.py FILE  ->  JSON {"kind", "wavelengths", "xyz": one [X, Y, Z] per
pixel, row by row}. Reflective channels (T) are used when present, else S0.
fichet_reference.py --rec709 FILE  ->  the same "xyz" of a linear Rec.709 (D65) image's
first three channels, by colour-science's ITU-R BT.709 matrix.
"""
import json
import math
import re
import sys
import warnings

warnings.simplefilter("ignore")
import colour  # noqa: E402
import numpy as np  # noqa: E402
import OpenImageIO as oiio  # noqa: E402

NAME = re.compile(
    r"^((S([0-3]))|T)\.(\d*,?\d*([Ee][+-]?\d+)?)(Y|Z|E|P|T|G|M|k|h|da|d|c|m|u|n|p)?(m|Hz)$"
)
PREFIX = {
    "Y": 1e24, "Z": 1e21, "E": 1e18, "P": 1e15, "T": 1e12, "G": 1e9, "M": 1e6, "k": 1e3,
    "h": 1e2, "da": 1e1, "d": 1e-1, "c": 1e-2, "m": 1e-3, "u": 1e-6, "n": 1e-9, "p": 1e-12,
}


def nanometres(value, prefix, unit):
    v = value * PREFIX[prefix] if prefix else value
    return 299792458.0 / v * 1e9 if unit == "Hz" else v * 1e9


def c_round(x):
    """std::round: halves away from zero."""
    return math.floor(x + 0.5)


def weights(wl, cmfs, first, illuminant=None, ill_range=None):
    """Per-band weights (n x 3) of the reference's loop, which is linear in the spectrum."""
    n = len(wl)
    w = np.zeros((n, 3))
    last = first + len(cmfs) - 1
    start, end = max(first, wl[0]), min(last, wl[-1])
    if ill_range:
        start, end = max(start, ill_range[0]), min(end, ill_range[1])
    norm = 0.0
    for i in range(n - 1):
        a, b = wl[i], wl[i + 1]
        if start > b:
            continue
        if end < a:
            break
        a, b = max(a, start), min(b, end)
        i0, i1 = c_round(a - first), c_round(b - first)
        if i == n - 2:
            i1 += 1
        for idx in range(i0, min(i1, len(cmfs))):
            lam = first + idx
            t = (lam - wl[i]) / (wl[i + 1] - wl[i])
            c = cmfs[idx].copy()
            if illuminant is not None:
                e = illuminant(lam)
                norm += e * cmfs[idx][1]
                c *= e
            w[i] += (1 - t) * c
            w[i + 1] += t * c
    return w / norm if illuminant is not None else w


def main(path):
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise SystemExit(f"cannot open {path}: {oiio.geterror()}")
    spec = inp.spec()
    pixels = np.asarray(inp.read_image(0, 0, 0, spec.nchannels, oiio.FLOAT))
    inp.close()
    pixels = pixels.reshape(spec.height * spec.width, spec.nchannels)
    bands = {"T": [], "S0": []}
    for c, name in enumerate(spec.channelnames):
        m = NAME.match(name)
        if m and m.group(1) in bands:
            value = float(m.group(4).replace(",", "."))
            bands[m.group(1)].append((nanometres(value, m.group(6), m.group(7)), c))
    kind = "T" if bands["T"] else "S0"
    chosen = sorted(bands[kind])
    wl = [w for w, _ in chosen]
    values = pixels[:, [c for _, c in chosen]].astype(np.float64)

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    first = float(cmfs.wavelengths[0])
    table = np.asarray(cmfs.values, dtype=np.float64)
    if kind == "S0":
        w = weights(wl, table, first)
    else:
        d65 = colour.SDS_ILLUMINANTS["D65"]
        dw, dv = np.asarray(d65.wavelengths), np.asarray(d65.values)
        w = weights(wl, table, first, lambda lam: float(np.interp(lam, dw, dv)),
                    (float(dw[0]), float(dw[-1])))
    xyz = values @ w
    print(json.dumps({"kind": kind, "wavelengths": wl, "xyz": xyz.tolist()}))


def rec709(path):
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise SystemExit(f"cannot open {path}: {oiio.geterror()}")
    spec = inp.spec()
    rgb = np.asarray(inp.read_image(0, 0, 0, 3, oiio.FLOAT), dtype=np.float64)
    inp.close()
    m = colour.RGB_COLOURSPACES["ITU-R BT.709"].matrix_RGB_to_XYZ
    xyz = rgb.reshape(-1, 3) @ np.asarray(m).T
    print(json.dumps({"xyz": xyz.tolist()}))


if __name__ == "__main__":
    if sys.argv[1] == "--rec709":
        rec709(sys.argv[2])
    else:
        main(sys.argv[1])
