"""The compact layout against maketx's half RGB texture (docs/compact.md, "Sizes" and "How
close"): sizes, colour, and the spectra, measured in one run.

  python python/bench/compact.py SPECCONV TEXTURE.tx [TEXTURE.tx ...] [--full TEXTURE.tx]

Each texture (an 8-bit sRGB .tx of scripts/bench_textures.sh) is cropped to its central
512x512 (as docs/compression.md's size table crops it); `--full` ones are taken whole (the
2048x2048 photograph). For each, in the same run:

- sizes: the RGB reference, the same pixels in linear Rec.709 as a tiled half ZIP texture with
  MIP levels (maketx -d half --compression zip; `oiiotool --otex` where maketx is missing),
  against SPECCONV's compact file (default: half colour, u half or float32), the compact file
  with -d float, and the default spectral file;
- where the bytes go: the compact file's channel sets (R G B half, U half, UF float32) each
  written alone as the same tiled ZIP MIP-mapped file, and the share of level 0's texels with
  u in U and in UF;
- D65: per texel of level 0, CIEDE2000 between the input's colour and the compact texel's
  decoded spectrum's colour under D65, and between the input's colour and maketx's half
  texel's: the largest excess of the first over the second, and both means. The input's colour
  is its 8-bit values through the sRGB curve in double ("exact"); also against OpenImageIO's
  float linear pixels, which maketx's texel is the nearest half of ("oiio": they are off the
  exact curve by up to ~50 float32 ulps, enough to move 1 % of maketx's halves to a neighbour);
- expand: `specconv expand` of the compact file against `specconv convert` of the colour the
  compact file stores (its R G B written as a float OpenEXR), every sample of every level: the
  largest difference in half steps at the value, and the share stored identically;
- A and F11: CIEDE2000 between the compact file's decoded level 0 and the baked spectral file
  of the input (float), under A and F11 (and D65), mean / 99th percentile / max;
- MIP levels: the same between the compact file's decoded levels 1 and below (every texel of
  them together) and the baked file's (docs/compact.md, "What a MIP level holds").

Prints JSON lines. Times nothing.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import colour
import numpy as np
import OpenImageIO as oiio

import specconv

STORED = ("R", "G", "B", "U.0", "U.1", "U.2", "UF.0", "UF.1", "UF.2")
LIGHTS = ("D65", "A", "FL11")
CHUNK = 1 << 18


def levels(path):
    inp = oiio.ImageInput.open(str(path))
    out, level = [], 0
    while inp.seek_subimage(0, level):
        s = inp.spec()
        kind = "half" if s.format == oiio.HALF else "float"
        out.append((list(s.channelnames), inp.read_image(0, level, 0, s.nchannels, kind), s))
        level += 1
    inp.close()
    return out


def bands(names, pixels):
    t = sorted((float(n[2:-2].replace(",", ".")), i) for i, n in enumerate(names) if n.startswith("T."))
    return pixels[..., [i for _, i in t]], np.array([w for w, _ in t])


def lab(xyz, light, wl):
    white = specconv.spectra_to_xyz(np.ones((1, len(wl))), wl, illuminant=light)[0]
    return colour.XYZ_to_Lab(xyz / white[1], colour.XYZ_to_xy(white))


def decoded_xyz(text, six, wl, light):
    """The colour under `light` of each texel's decoded spectrum, in chunks."""
    out = []
    for start in range(0, len(six), CHUNK):
        r = specconv.decode(text, six[start : start + CHUNK])
        out.append(specconv.spectra_to_xyz(r, wl, illuminant=light))
    return np.concatenate(out)


def rgb_texture(linear, out):
    if shutil.which("maketx"):
        cmd = ["maketx", linear, "-d", "half", "--compression", "zip", "-o", out]
    else:
        cmd = ["oiiotool", linear, "-d", "half", "--compression", "zip", "--otex", out]
    subprocess.run(cmd, check=True, capture_output=True)


def steps(a, b):
    """Every level of two spectral files: (largest difference in half steps at the value, the
    same at the texel's scale (the larger of the value and its pixel's largest band, the
    scale `compact::u_tolerance` stores u to), share of samples identical)."""
    worst, scaled, same, count = 0, 0, 0, 0
    for (na, pa, _), (nb, pb, _) in zip(levels(a), levels(b)):
        assert na == nb and pa.shape == pb.shape
        fa, fb = pa.astype(np.float64), pb.astype(np.float64)
        nan = np.isnan(fa) & np.isnan(fb)
        spacing = 2.0 ** (np.floor(np.log2(np.maximum(np.abs(fa), 2.0**-14))) - 10)
        d = np.where(nan, 0, np.abs(fa - fb) / spacing)
        worst = max(worst, float(np.nanmax(d)))
        bands = [i for i, n in enumerate(na) if n != "A"]
        peak = np.nanmax(np.abs(fa[..., bands]), axis=-1, keepdims=True, initial=0.0)
        at = np.maximum(np.abs(fa), peak)
        spacing = 2.0 ** (np.floor(np.log2(np.maximum(at, 2.0**-14))) - 10)
        scaled = max(scaled, float(np.nanmax(np.where(nan, 0, np.abs(fa - fb) / spacing))))
        same += int(((pa == pb) | nan).sum())
        count += pa.size
    return round(worst, 3), round(scaled, 3), round(same / count, 6)


def channel_sets(path, tmp):
    """Bytes of each channel set of a compact file written alone (tiled ZIP, its MIP levels)."""
    lv = levels(path)
    out = {}
    for name, names, kind in (("rgb", ["R", "G", "B"], "half"), ("u_half", ["U.0", "U.1", "U.2"], "half"),
                              ("uf_float", ["UF.0", "UF.1", "UF.2"], "float")):
        part = os.path.join(tmp, f"set-{name}.exr")
        o = oiio.ImageOutput.create(part)
        for k, (cn, px, s) in enumerate(lv):
            spec = oiio.ImageSpec(px.shape[1], px.shape[0], 3, kind)
            spec.channelnames = names
            spec.tile_width, spec.tile_height = s.tile_width, s.tile_height
            spec.attribute("compression", "zip")
            spec.attribute("textureformat", "Plain Texture")
            assert o.open(part, spec, "Create" if k == 0 else "AppendMIPLevel"), o.geterror()
            assert o.write_image(np.ascontiguousarray(px[..., [cn.index(c) for c in names]], dtype=np.float32))
        o.close()
        out[name] = os.path.getsize(part)
    cn, px, _ = lv[0]
    share = lambda names: round(float((px[..., [cn.index(c) for c in names]] != 0).any(-1).mean()), 4)  # noqa: E731
    out["texels_u_half"], out["texels_u_float"] = share(["U.0", "U.1", "U.2"]), share(["UF.0", "UF.1", "UF.2"])
    return out


def srgb_exact(png):
    """The 8-bit file's colour: its values through the sRGB curve, in double."""
    inp = oiio.ImageInput.open(png)
    v = inp.read_image(0, 0, 0, 3, "uint8").reshape(-1, 3).astype(np.float64) / 255.0
    inp.close()
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def write_float(path, names, pixels):
    spec = oiio.ImageSpec(pixels.shape[1], pixels.shape[0], len(names), "float")
    spec.channelnames = names
    if "A" in names:
        spec.alpha_channel = names.index("A")
    o = oiio.ImageOutput.create(str(path))
    assert o.open(str(path), spec) and o.write_image(np.ascontiguousarray(pixels, dtype=np.float32))
    o.close()


def measure(binary, tx, full, tmp):
    name = os.path.splitext(os.path.basename(tx))[0] + ("" if not full else "-2048")
    src = os.path.join(tmp, f"{name}.png")
    cut = [] if full else ["--cut", "512x512+768+768"]
    subprocess.run(["oiiotool", tx, *cut, "-o", src], check=True)
    linear = os.path.join(tmp, "linear.exr")
    subprocess.run(["oiiotool", src, "--colorconvert", "sRGB", "linear", "-d", "float", "-o", linear], check=True)
    rgb = os.path.join(tmp, "rgb.exr")
    rgb_texture(linear, rgb)
    run = lambda *a: subprocess.run([binary, *a, "-q", "--force"], check=True)  # noqa: E731
    files = {k: os.path.join(tmp, f"{k}.exr") for k in ("compact", "compact_float", "spectral", "baked")}
    run(src, files["compact"], "--layout", "compact")
    run(src, files["compact_float"], "--layout", "compact", "-d", "float")
    run(src, files["spectral"])
    run(src, files["baked"], "-d", "float")
    size = {k: os.path.getsize(v) for k, v in files.items()}
    base = os.path.getsize(rgb)
    print(json.dumps({"texture": name, "rgb_half_zip_bytes": base,
                      **{f"x_rgb_{k}": round(size[k] / base, 3) for k in ("compact", "compact_float", "spectral")}}),
          flush=True)
    print(json.dumps({"texture": name, "compact_channel_set_bytes": channel_sets(files["compact"], tmp)}), flush=True)

    # D65: the input's colour against the compact texel's and maketx's half texel's.
    m = np.array(specconv.compact.parse(levels(files["compact"])[0][2].get_string_attribute("specconvCompact")).rgb)
    (cn, cp, cs) = levels(files["compact"])[0]
    text = cs.get_string_attribute("specconvCompact")
    six = specconv.compact.unstore(text, cp[..., [cn.index(c) for c in STORED]]).reshape(-1, 6)
    wl = specconv.compact.parse(text).wavelengths
    half = levels(rgb)[0][1][..., :3].reshape(-1, 3).astype(np.float64)
    ours = lab(decoded_xyz(text, six, wl, "D65"), "D65", wl)
    for reference, inp in (("exact", srgb_exact(src)),
                           ("oiio", levels(linear)[0][1][..., :3].reshape(-1, 3).astype(np.float64))):
        ref = lab(inp @ m.T, "D65", wl)
        d_compact = colour.delta_E(ref, ours, method="CIE 2000")
        d_maketx = colour.delta_E(ref, lab(half @ m.T, "D65", wl), method="CIE 2000")
        excess = d_compact - d_maketx
        print(json.dumps({"texture": name, "input": reference,
                          "d65_de00_compact_mean": round(float(d_compact.mean()), 5),
                          "d65_de00_maketx_mean": round(float(d_maketx.mean()), 5),
                          "d65_de00_excess_max": round(float(excess.max()), 5),
                          "texels_over_0.01": int((excess > 0.01).sum())}), flush=True)

    # expand against convert of the stored colour, every level.
    stored = os.path.join(tmp, "stored.exr")
    keep = [c for c in ("R", "G", "B", "A") if c in cn]
    write_float(stored, keep, cp[..., [cn.index(c) for c in keep]])
    reference, expanded = os.path.join(tmp, "reference.exr"), os.path.join(tmp, "expanded.exr")
    run(stored, reference)
    subprocess.run([binary, "expand", files["compact"], expanded, "-q", "--force"], check=True)
    worst, scaled, same = steps(reference, expanded)
    print(json.dumps({"texture": name, "expand_vs_convert_of_stored_max_half_steps": worst,
                      "at_the_texels_scale": scaled,
                      "identical": same}), flush=True)

    # A and F11: the compact file's decoded level 0 against the baked file (float) of the input.
    bn, bp, _ = levels(files["baked"])[0]
    want = bands(bn, bp)[0].reshape(-1, len(wl))
    shift = {}
    for light in LIGHTS:
        got = decoded_xyz(text, six, wl, light)
        theirs = np.concatenate([specconv.spectra_to_xyz(want[s : s + CHUNK], wl, illuminant=light)
                                 for s in range(0, len(want), CHUNK)])
        d = colour.delta_E(lab(theirs, light, wl), lab(got, light, wl), method="CIE 2000")
        shift[light] = [round(float(np.mean(d)), 4), round(float(np.percentile(d, 99)), 3), round(float(np.max(d)), 3)]
    print(json.dumps({"texture": name, "compact_vs_baked_de00_mean_p99_max": shift}), flush=True)

    # The smaller levels: the texel form of the filtered colour against the filtered spectra.
    small = [(c, b) for c, b in zip(levels(files["compact"])[1:], levels(files["baked"])[1:])]
    six = np.concatenate([specconv.compact.unstore(text, p[..., [n.index(c) for c in STORED]]).reshape(-1, 6)
                          for (n, p, _), _ in small])
    want = np.concatenate([bands(n, p)[0].reshape(-1, len(wl)) for _, (n, p, _) in small])
    mip = {}
    for light in LIGHTS:
        got = decoded_xyz(text, six, wl, light)
        theirs = specconv.spectra_to_xyz(want, wl, illuminant=light)
        d = colour.delta_E(lab(theirs, light, wl), lab(got, light, wl), method="CIE 2000")
        mip[light] = [round(float(np.mean(d)), 4), round(float(np.percentile(d, 99)), 3), round(float(np.max(d)), 3)]
    print(json.dumps({"texture": name, "mip_levels_compact_vs_baked_de00_mean_p99_max": mip}), flush=True)


def main(argv):
    binary, rest = argv[0], argv[1:]
    jobs = []
    while rest:
        if rest[0] == "--full":
            jobs.append((rest[1], True))
            rest = rest[2:]
        else:
            jobs.append((rest[0], False))
            rest = rest[1:]
    for tx, full in jobs:
        with tempfile.TemporaryDirectory() as tmp:
            measure(binary, tx, full, tmp)


if __name__ == "__main__":
    main(sys.argv[1:])
