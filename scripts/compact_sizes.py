"""The compact layout's sizes (docs/compact.md): what a compact texture weighs against the half
RGB texture maketx makes of the same input, MIP levels included, and what half texels would
cost in precision.

  compact_sizes.py SPECCONV TEXTURE.tx [TEXTURE.tx ...]

Each texture (an 8-bit sRGB .tx, as scripts/bench_textures.sh makes) is cropped to its central
512x512, as scripts/size_table.py crops it, and converted by SPECCONV: the default spectral
file, and compact files with each compression below. The RGB reference: the same crop as maketx
makes a half ZIP MIP-mapped texture of it (linear Rec.709). "half": the compact file's levels
rewritten by OpenImageIO (ZIP) with half samples in all channels, in C only or in U only, and
level 0 decoded from them
(specconv.decode) against the float texels' spectra: the largest error, in half steps at each
band's value, and the share of band values more than one half step off. "mip_delta_e00": the
compact file's levels 1… decoded against the float spectral file's, CIEDE2000 under D65, A and
F11 (mean, 99th percentile, max). Prints JSON lines.
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio

import specconv

COMPACT = [
    ("compact, float, zip (default)", []),
    ("compact, float, zip:9", ["--zip-level", "9"]),
    ("compact, float, piz", ["--compression", "piz"]),
    ("compact, float, zips", ["--compression", "zips"]),
]
CHANNELS = ("C.X", "C.Y", "C.Z", "U.0", "U.1", "U.2")


def as_half(src, dst, which=CHANNELS):
    """Every level of `src` rewritten with half samples in the channels `which` (float in the
    others), ZIP, the same tiles."""
    inp = oiio.ImageInput.open(src)
    spec = inp.spec()
    levels = []
    while inp.seek_subimage(0, len(levels)):
        s = inp.spec()
        levels.append((oiio.ImageSpec(s), inp.read_image(0, len(levels), 0, s.nchannels, "float")))
    inp.close()
    out = oiio.ImageOutput.create(dst)
    for i, (s, px) in enumerate(levels):
        names = list(s.channelnames)
        s.channelformats = tuple(oiio.TypeDesc(oiio.HALF if n in which else oiio.FLOAT) for n in names)
        s.attribute("compression", "zip")
        mask = np.array([n in which for n in names])
        px = np.where(mask, px.astype(np.float16).astype(np.float32), px)
        if i == 0:
            out.open(dst, s, "create")
        else:
            out.open(dst, s, "AppendMIPLevel")
        out.write_image(px)
    out.close()
    return spec


def level0(path):
    inp = oiio.ImageInput.open(path)
    s = inp.spec()
    px = inp.read_image(0, 0, 0, s.nchannels, "float")
    text = s.get_string_attribute("specconvCompact")
    names = list(s.channelnames)
    inp.close()
    return px[..., [names.index(c) for c in CHANNELS]], text


def mip_delta_e(spectral, compact):
    """CIEDE2000 (mean, 99th percentile, max) per light between the compact file's levels 1…
    decoded and the spectral file's (float) levels: what a compact level holds (the filtered
    colour) against the filtered spectra."""
    import colour

    found = {}
    a, b = oiio.ImageInput.open(spectral), oiio.ImageInput.open(compact)
    level = 1
    while a.seek_subimage(0, level) and b.seek_subimage(0, level):
        sa, sb = a.spec(), b.spec()
        pa = a.read_image(0, level, 0, sa.nchannels, "float")
        pb = b.read_image(0, level, 0, sb.nchannels, "float")
        t = sorted((float(n[2:-2].replace(",", ".")), i) for i, n in enumerate(sa.channelnames) if n.startswith("T."))
        wl = np.array([w for w, _ in t])
        want = pa[..., [i for _, i in t]].reshape(-1, len(wl))
        names = list(sb.channelnames)
        got = specconv.decode(sb.get_string_attribute("specconvCompact"),
                              pb[..., [names.index(c) for c in CHANNELS]]).reshape(-1, len(wl))
        for light in ("D65", "A", "FL11"):
            white = specconv.spectra_to_xyz(np.ones((1, len(wl))), wl, illuminant=light)[0]
            lab = [colour.XYZ_to_Lab(specconv.spectra_to_xyz(s, wl, illuminant=light) / white[1],
                                     colour.XYZ_to_xy(white)) for s in (want, got)]
            found.setdefault(light, []).extend(colour.delta_E(*lab, method="CIE 2000"))
        level += 1
    return {k: [round(float(np.mean(v)), 4), round(float(np.percentile(v, 99)), 3), round(float(np.max(v)), 2)]
            for k, v in found.items()}


def main(binary, textures):
    for tx in textures:
        name = os.path.splitext(os.path.basename(tx))[0]
        with tempfile.TemporaryDirectory() as tmp:
            crop = os.path.join(tmp, f"{name}.png")
            subprocess.run(["oiiotool", tx, "--cut", "512x512+768+768", "-o", crop], check=True)
            linear = os.path.join(tmp, "linear.exr")
            subprocess.run(["oiiotool", crop, "--colorconvert", "sRGB", "linear", "-d", "half", "-o", linear], check=True)
            rgb = os.path.join(tmp, "rgb.exr")
            subprocess.run(["maketx", linear, "-d", "half", "--compression", "zip", "-o", rgb], check=True)
            rgb_bytes = os.path.getsize(rgb)
            texels = 512 * 512

            def row(variant, path, **more):
                size = os.path.getsize(path)
                print(json.dumps({"texture": name, "variant": variant, "bytes": size,
                                  "bytes_per_texel": round(size / texels, 2),
                                  "x_rgb": round(size / rgb_bytes, 2), **more}), flush=True)

            row("RGB half zip (maketx)", rgb)
            spectral = os.path.join(tmp, "spectral.exr")
            subprocess.run([binary, crop, spectral, "-q", "--force"], check=True)
            row("spectral 36 half zip (default)", spectral)
            for variant, args in COMPACT:
                out = os.path.join(tmp, "compact.exr")
                subprocess.run([binary, crop, out, "-q", "--force", "--layout", "compact", *args], check=True)
                row(variant, out, header_bytes=len(level0(out)[1]))
            out = os.path.join(tmp, "compact.exr")
            subprocess.run([binary, crop, out, "-q", "--force", "--layout", "compact"], check=True)
            floats = os.path.join(tmp, "float.exr")
            subprocess.run([binary, crop, floats, "-q", "--force", "-d", "float"], check=True)
            print(json.dumps({"texture": name, "mip_delta_e00": mip_delta_e(floats, out)}), flush=True)
            for label, which in [("all", CHANNELS), ("C", CHANNELS[:3]), ("U", CHANNELS[3:])]:
                half = os.path.join(tmp, "half.exr")
                as_half(out, half, which)
                (t32, text), (t16, _) = level0(out), level0(half)
                want = specconv.decode(text, t32).reshape(-1, 36)
                got = specconv.decode(text, t16).reshape(-1, 36)
                spacing = 2.0 ** (np.floor(np.log2(np.maximum(np.abs(want), 2.0**-14))) - 10)
                steps = np.abs(got - want) / spacing
                row(f"compact, half {label} (rewritten), zip", half,
                    half_steps_max=round(float(np.max(steps)), 1),
                    share_beyond_one_step=round(float(np.mean(steps > 1)), 4))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
