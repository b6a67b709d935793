"""The size table of docs/guide.md: what each band grid and compression costs in bytes and in
colour, against the RGB texture the spectra came from.

  size_table.py SPECCONV TEXTURE.tx [TEXTURE.tx ...]

Each texture (an 8-bit sRGB .tx, as scripts/bench_textures.sh makes) is cropped to its central
512x512 and converted by SPECCONV with the default settings (a 36-band half ZIP MIP map) and with
each other band grid and compression below. Bytes per texel: the whole file (every MIP level)
over level 0's texels. The RGB reference: the same crop as maketx makes a half ZIP MIP-mapped
texture of it (linear Rec.709, by oiiotool's sRGB decoding).

Colour: level 0 read with OpenImageIO and integrated as the layout's reference implementation
(afichet/spectral-exr) integrates reflectance, here under D65, A and F11: each spectrum
interpolated linearly onto the CIE 1931 2-degree table's 1 nm wavelengths within the bands,
XYZ = sum(cmf * I * R) / sum(ybar * I); CIELAB against the illuminant's white; CIEDE2000, mean
and 99th percentile over texels. Under D65 against the RGB texture's own colour (what the
conversion must keep); under A and F11 against the default grid in float without compression
(what a grid or a compression changes of the spectra). Needs colour-science and OpenImageIO's
Python bindings (.ci/run's venv).
"""
import json
import os
import re
import subprocess
import sys
import tempfile
import warnings

warnings.simplefilter("ignore")
import colour  # noqa: E402
import numpy as np  # noqa: E402
import OpenImageIO as oiio  # noqa: E402

NAME = re.compile(r"^T\.(\d+),(\d+)nm$")
CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
ILLUMINANTS = {"D65": "D65", "A": "A", "F11": "FL11"}
VARIANTS = [
    ("380:730:10 (36), half, zip (default)", []),
    ("380:730:10 (36), float, zip", ["-d", "float"]),
    ("380:730:10 (36), half, pxr24", ["--compression", "pxr24"]),
    ("380:730:10 (36), half, b44", ["--compression", "b44"]),
    ("380:730:10 (36), half, dwaa", ["--compression", "dwaa"]),
    ("380:720:20 (18), half, zip", ["--bands", "380:720:20"]),
    ("400:700:10 (31), half, zip", ["--bands", "400:700:10"]),
    ("380:780:5 (81), half, zip", ["--bands", "380:780:5"]),
]
REFERENCE = ["-d", "float", "--compression", "none"]


def level0(path):
    inp = oiio.ImageInput.open(path)
    spec = inp.spec()
    px = inp.read_image(0, 0, 0, spec.nchannels, "float").reshape(-1, spec.nchannels)
    inp.close()
    return spec, px


def spectra(path):
    spec, px = level0(path)
    bands = sorted(
        (float(f"{m[1]}.{m[2]}"), i) for i, n in enumerate(spec.channelnames) if (m := NAME.match(n))
    )
    return np.array([w for w, _ in bands]), px[:, [i for _, i in bands]]


def lab_of_spectra(wavelengths, r, illuminant):
    # The reference's integration: 1 nm table wavelengths inside the bands, linear interpolation.
    lo, hi = wavelengths[0], wavelengths[-1]
    grid = np.arange(np.ceil(lo), np.floor(hi) + 1)
    cmf = CMFS.copy().align(colour.SpectralShape(360, 830, 1))
    bar = np.array([cmf[w] for w in grid])
    sd = colour.SDS_ILLUMINANTS[illuminant].copy().align(colour.SpectralShape(300, 830, 1))
    power = np.array([sd[w] for w in grid])
    # Interpolate every texel at once: the weights of each 1 nm sample on its two bands.
    idx = np.clip(np.searchsorted(wavelengths, grid, side="right") - 1, 0, len(wavelengths) - 2)
    t = (grid - wavelengths[idx]) / (wavelengths[idx + 1] - wavelengths[idx])
    fine = r[:, idx] * (1 - t) + r[:, idx + 1] * t
    k = 1.0 / np.sum(power * bar[:, 1])
    xyz = fine @ (power[:, None] * bar) * k
    white = (power[:, None] * bar).sum(axis=0) * k
    return colour.XYZ_to_Lab(xyz, colour.XYZ_to_xy(white))


def lab_of_rgb(path):
    _, px = level0(path)
    xyz = colour.RGB_to_XYZ(
        px[:, :3], colour.RGB_COLOURSPACES["ITU-R BT.709"], apply_cctf_decoding=False
    )
    return colour.XYZ_to_Lab(xyz, colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"])


def stats(a, b):
    de = colour.delta_E(a, b, method="CIE 2000")
    return float(np.mean(de)), float(np.percentile(de, 99))


def main(specconv, textures):
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for tx in textures:
            name = os.path.basename(tx).split(".")[0]
            crop = os.path.join(tmp, f"{name}.png")
            subprocess.run(
                ["oiiotool", tx, "--cut", "512x512+768+768", "-o", crop], check=True
            )
            linear = os.path.join(tmp, f"{name}_linear.exr")
            subprocess.run(
                ["oiiotool", crop, "--colorconvert", "sRGB", "linear", "-d", "half", "-o", linear],
                check=True,
            )
            rgb = os.path.join(tmp, f"{name}_rgb.exr")
            subprocess.run(
                ["maketx", linear, "-d", "half", "--compression", "zip", "-o", rgb], check=True
            )
            rgb_bytes = os.path.getsize(rgb) / 512**2
            rgb_lab = lab_of_rgb(rgb)

            def convert(args, out):
                subprocess.run([specconv, crop, out, "-q", "--force", *args], check=True)
                return out

            ref = spectra(convert(REFERENCE, os.path.join(tmp, "ref.exr")))
            ref_lab = {k: lab_of_spectra(*ref, v) for k, v in ILLUMINANTS.items()}
            rows.append(
                {"texture": name, "variant": "RGB half zip (maketx)", "bytes": rgb_bytes}
            )
            for label, args in VARIANTS:
                out = convert(args, os.path.join(tmp, "v.exr"))
                w, r = spectra(out)
                row = {
                    "texture": name,
                    "variant": label,
                    "bytes": os.path.getsize(out) / 512**2,
                    "D65": stats(rgb_lab, lab_of_spectra(w, r, "D65")),
                }
                for k in ["A", "F11"]:
                    row[k] = stats(ref_lab[k], lab_of_spectra(w, r, ILLUMINANTS[k]))
                rows.append(row)
                print(json.dumps(row), file=sys.stderr)
    print("| texture | grid, sample, compression | bytes/texel | × RGB | ΔE00 D65 vs RGB | ΔE00 A | ΔE00 F11 |")
    print("|---|---|---|---|---|---|---|")
    base = {}
    for row in rows:
        if "D65" not in row:
            base[row["texture"]] = row["bytes"]
            print(f"| {row['texture']} | {row['variant']} | {row['bytes']:.2f} | 1 | | | |")
            continue
        cell = lambda s: f"{s[0]:.3f} / {s[1]:.3f}"  # noqa: E731
        print(
            f"| {row['texture']} | {row['variant']} | {row['bytes']:.1f} | "
            f"{row['bytes'] / base[row['texture']]:.1f} | {cell(row['D65'])} | "
            f"{cell(row['A'])} | {cell(row['F11'])} |"
        )


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
