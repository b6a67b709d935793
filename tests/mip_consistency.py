"""How far each MIP level's colour is from the colour of level 0 averaged, under D65, A, F11.

  mip_consistency.py FILTERED UPLIFTED...

FILTERED is a spectral texture whose levels specconv filtered from its level-0 spectra;
UPLIFTED are single-level spectral files, one per level, each uplifted from that level of
the input's own MIP map (maketx's, filtered in RGB). Level 0 must be a power of two in both
directions. The reference for level k is level 0's spectra of FILTERED averaged over
2^k x 2^k blocks (numpy): what a lookup of that footprint should see. Colours are CIE 1931 XYZ
under each illuminant (colour-science's tables at the file's wavelengths, white Y = 1), as
CIELAB against the illuminant's white; differences are CIEDE2000. Prints JSON: per level and
illuminant, the mean and largest difference of each way.
"""
import json
import re
import sys

import colour
import numpy as np
import OpenImageIO as oiio

NAME = re.compile(r"^T\.(\d+),(\d+)nm$")


def read_level(path, level):
    inp = oiio.ImageInput.open(path)
    if inp is None:
        sys.exit(oiio.geterror())
    if not inp.seek_subimage(0, level):
        sys.exit(f"{path} has no level {level}")
    spec = inp.spec()
    px = inp.read_image(0, level, 0, spec.nchannels, "float")
    inp.close()
    px = px.reshape(spec.height, spec.width, spec.nchannels)
    bands = [(float(f"{m[1]}.{m[2]}"), i) for i, n in enumerate(spec.channelnames) if (m := NAME.match(n))]
    bands.sort()
    return np.array([w for w, _ in bands]), px[:, :, [i for _, i in bands]]


def levels_of(path):
    inp = oiio.ImageInput.open(path)
    n = 0
    while inp.seek_subimage(0, n):
        n += 1
    inp.close()
    return n


def lab(spectra, wavelengths, illuminant):
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(
        colour.SpectralShape(360, 830, 1)
    )
    xyz_bar = np.array([cmfs[w] for w in wavelengths])
    sd = colour.SDS_ILLUMINANTS[illuminant].copy().align(colour.SpectralShape(300, 830, 1))
    power = np.array([sd[w] for w in wavelengths])
    k = 1.0 / np.sum(power * xyz_bar[:, 1])
    xyz = np.einsum("...b,b,bc->...c", spectra, power, xyz_bar) * k
    white = np.einsum("b,bc->c", power, xyz_bar) * k
    return colour.XYZ_to_Lab(xyz, colour.XYZ_to_xy(white))


def main(filtered, uplifted):
    wavelengths, base = read_level(filtered, 0)
    h0, w0 = base.shape[:2]
    out = []
    for k in range(min(levels_of(filtered), len(uplifted))):
        w, h = max(w0 >> k, 1), max(h0 >> k, 1)
        truth = base.reshape(h, h0 // h, w, w0 // w, -1).mean(axis=(1, 3))
        _, ours = read_level(filtered, k)
        _, theirs = read_level(uplifted[k], 0)
        row = {"level": k, "size": [w, h]}
        for illuminant in ["D65", "A", "FL11"]:
            ref = lab(truth, wavelengths, illuminant)
            for name, got in [("filtered", ours), ("uplifted", theirs)]:
                de = colour.delta_E(ref, lab(got, wavelengths, illuminant), method="CIE 2000")
                row[f"{name}_{illuminant}"] = [float(np.mean(de)), float(np.max(de))]
        out.append(row)
    print(json.dumps(out))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
