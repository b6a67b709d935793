"""Compact textures (docs/compact.md) checked through OpenImageIO, outside our reader.

  chart OUT         writes a float OpenEXR (linear Rec.709, 8x6) of colours of every kind:
                    greys, saturated primaries beyond sRGB, negative components, HDR, black,
                    NaN, a tiny dark colour, and a ramp.
  steps A B         JSON list, one entry per MIP level of A and B (two spectral files of the
                    same channels): the fraction of samples stored identically and the largest
                    difference in half steps at the value (at least 2e-6), NaN equal to NaN,
                    and the pixels with a sample more than one step apart.
  stored C OUT      level 0's stored colour of the compact file C (R G B, and A) as a float
                    OpenEXR without chromaticities (linear Rec.709, the working space): what
                    `convert` bakes as the reference of C (docs/compact.md).
  dump C B PREFIX   level 0 of a compact file C and of the spectral file B as text for
                    tests/c/decode_check.c: PREFIX.header (the specconvCompact text),
                    PREFIX.texels ("count 9", then R G B U.0 U.1 U.2 UF.0 UF.1 UF.2 a line) and
                    PREFIX.baked ("count bands", the wavelengths, then the T. bands a line),
                    every float32 in 9 digits, which read back to the same float.
  make OUT TEXT SETTINGS
                    a compact file of 4x2 texels (one with a NaN X, one with an infinite Y)
                    whose specconvCompact is the file TEXT's bytes and specconvSettings is
                    SETTINGS: hostile headers and NaN rules for `specconv expand`.
  nans FILE         JSON: per MIP level of FILE, how many samples are NaN or infinite.
  inputs DIR        writes into DIR inputs whose every value is known exactly: codes.png (8-bit,
                    256x3, every code in every channel); the same with Little CMS's own sRGB
                    profile (codes_srgb_icc.png), with Debian's sRGB.icc, which is 4e-4 off
                    sRGB near black and white (codes_debian_icc.png), and with a Display P3
                    profile Little CMS makes (P3 primaries, D65, the sRGB curve:
                    codes_p3_icc.png); and linear.exr (float, 256x256, random values in
                    [-0.1, 1.5], linear Rec.709: no chromaticities).
  halves C INPUT [TIE]
                    JSON: the colour level 0 of compact file C stores against INPUT's own
                    colour (an 8-bit file's codes through the sRGB curve in double, as float32;
                    a float file's values): the channels that differ from its nearest half and
                    by how many half steps at most, the values that are neither half around
                    it, the texels stored farther in CIEDE2000 (colour-science, the working
                    space's white) than the nearest of the eight combinations of halves around
                    it and TIE, and those moved off the nearest halves where these were within
                    TIE of the nearest.
"""
import json
import sys

import numpy as np
import OpenImageIO as oiio


def chart(out):
    nan = float("nan")
    rows = [
        [[0.18, 0.18, 0.18], [1, 1, 1], [0, 0, 0], [0.9, 0.02, 0.01], [0.01, 0.9, 0.02], [0.02, 0.01, 0.9], [1.5, 0.1, -0.2], [-0.3, 0.6, 0.2]],
        [[12, 10, 8], [300, 20, 1], [1e-4, 2e-4, 1e-4], [-0.1, -0.2, -0.05], [nan, 0.2, 0.3], [0.2, nan, nan], [0.5, 0.5, 0.0], [0.0, 0.4, 0.9]],
    ]
    rows += [[[i / 7, (7 - i) / 7, (i * 3 % 8) / 7] for i in range(8)] for _ in range(4)]
    pixels = np.array(rows, dtype=np.float32)
    spec = oiio.ImageSpec(8, 6, 3, "float")
    o = oiio.ImageOutput.create(out)
    o.open(out, spec)
    o.write_image(pixels)
    o.close()


def levels(path):
    inp = oiio.ImageInput.open(path)
    if inp is None:
        sys.exit(oiio.geterror())
    out, level = [], 0
    while inp.seek_subimage(0, level):
        s = inp.spec()
        kind = "half" if s.format == oiio.HALF else "float"
        out.append((list(s.channelnames), inp.read_image(0, level, 0, s.nchannels, kind)))
        level += 1
    inp.close()
    return out


def steps(a, b):
    out = []
    for level, ((na, pa), (nb, pb)) in enumerate(zip(levels(a), levels(b))):
        if na != nb or pa.shape != pb.shape or pa.dtype != pb.dtype:
            sys.exit(f"level {level}: {na} {pa.shape} {pa.dtype} against {nb} {pb.shape} {pb.dtype}")
        signed = np.int16 if pa.dtype == np.float16 else np.int32
        ia, ib = pa.view(signed).astype(np.int64), pb.view(signed).astype(np.int64)
        # Steps apart on the number line of the type (sign-magnitude to ordered integers).
        ia = np.where(ia < 0, -(ia & (2 ** (8 * pa.itemsize - 1) - 1)), ia)
        ib = np.where(ib < 0, -(ib & (2 ** (8 * pa.itemsize - 1) - 1)), ib)
        nan = np.isnan(pa.astype(np.float32)) & np.isnan(pb.astype(np.float32))
        d = np.where(nan, 0, np.abs(ia - ib))
        # The difference in half steps at the value (2^-10 of its power of two), rounded up;
        # near 0 (half's subnormals, float's tiny values) in steps of 2e-6: float32's rounding
        # of u, which filters with negative lobes carry into small values.
        fa, fb = pa.astype(np.float64), pb.astype(np.float64)
        spacing = 2.0 ** (np.floor(np.log2(np.maximum(np.abs(fa), 2.0 ** -14))) - 10)
        spacing = np.maximum(spacing, 2e-6)
        d = np.where(nan | (d == 0), 0, np.ceil(np.abs(fa - fb) / spacing - 1e-9)).astype(np.int64)
        beyond = int((d > 1).any(axis=-1).sum())
        gap = np.where(nan, 0.0, np.abs(fa - fb))
        # The same in half steps at the texel's scale (issue 55, decision 4): at the larger of
        # the value and the pixel's largest band (alpha apart), in the reference `a`.
        bands = [i for i, n in enumerate(na) if n != "A"]
        peak = np.nanmax(np.abs(fa[..., bands]), axis=-1, keepdims=True, initial=0.0)
        scaled = 2.0 ** (np.floor(np.log2(np.maximum(np.maximum(np.abs(fa), peak),
                                                     2.0 ** -14))) - 10)
        ds = np.where(nan | (d == 0), 0, np.ceil(np.abs(fa - fb) / scaled - 1e-9)).astype(np.int64)
        out.append({"level": level, "identical": float((pa.view(signed) == pb.view(signed)).mean()), "max_steps": int(d.max()), "max_abs": float(np.nanmax(gap)) if gap.size else 0.0, "samples": int(d.size), "pixels_beyond_one": beyond, "max_steps_scaled": int(ds.max()), "pixels_beyond_one_scaled": int((ds > 1).any(axis=-1).sum())})
    print(json.dumps(out))


STORED = ("R", "G", "B", "U.0", "U.1", "U.2", "UF.0", "UF.1", "UF.2")


def write_image(path, pixels, kind, attrs=()):
    spec = oiio.ImageSpec(pixels.shape[1], pixels.shape[0], pixels.shape[2], kind)
    for name, t, v in attrs:
        spec.attribute(name, t, v)
    o = oiio.ImageOutput.create(path)
    if not o.open(path, spec) or not o.write_image(pixels):
        sys.exit(o.geterror())
    o.close()


def lcms_profile(primaries):
    """An ICC profile Little CMS makes, D65 and the sRGB curve: its own sRGB (cmsCreate_sRGBProfile)
    without primaries, else those primaries."""
    import ctypes
    import ctypes.util

    lcms = ctypes.CDLL(ctypes.util.find_library("lcms2"))
    lcms.cmsBuildParametricToneCurve.restype = ctypes.c_void_p
    lcms.cmsCreateRGBProfile.restype = ctypes.c_void_p
    lcms.cmsCreate_sRGBProfile.restype = ctypes.c_void_p
    if primaries is None:
        h = lcms.cmsCreate_sRGBProfile()
    else:
        xyy = ctypes.c_double * 3
        curve = lcms.cmsBuildParametricToneCurve(
            None, 4, (ctypes.c_double * 5)(2.4, 1 / 1.055, 0.055 / 1.055, 1 / 12.92, 0.04045))
        white = xyy(0.3127, 0.3290, 1.0)
        rgb = (xyy * 3)(*(xyy(x, y, 1.0) for x, y in primaries))
        curves = (ctypes.c_void_p * 3)(curve, curve, curve)
        h = lcms.cmsCreateRGBProfile(ctypes.byref(white), ctypes.byref(rgb), curves)
    size = ctypes.c_uint32(0)
    lcms.cmsSaveProfileToMem(ctypes.c_void_p(h), None, ctypes.byref(size))
    buf = ctypes.create_string_buffer(size.value)
    lcms.cmsSaveProfileToMem(ctypes.c_void_p(h), buf, ctypes.byref(size))
    return buf.raw[: size.value]


def inputs(out):
    v = np.arange(256)
    codes = np.stack([np.stack([v, 255 - v, (v * 37) % 256], -1),
                      np.stack([(v * 101) % 256, v, 255 - v], -1),
                      np.stack([255 - v, (v * 73) % 256, v], -1)]).astype(np.uint8)
    write_image(f"{out}/codes.png", codes, "uint8")
    icc = lambda b: [("ICCProfile", oiio.TypeDesc(f"uint8[{len(b)}]"), np.frombuffer(b, np.uint8))]  # noqa: E731
    write_image(f"{out}/codes_srgb_icc.png", codes, "uint8", icc(lcms_profile(None)))
    write_image(f"{out}/codes_debian_icc.png", codes, "uint8", icc(open("/usr/share/color/icc/sRGB.icc", "rb").read()))
    p3 = ((0.680, 0.320), (0.265, 0.690), (0.150, 0.060))
    write_image(f"{out}/codes_p3_icc.png", codes, "uint8", icc(lcms_profile(p3)))
    rng = np.random.default_rng(47)
    write_image(f"{out}/linear.exr", (rng.random((256, 256, 3)) * 1.6 - 0.1).astype(np.float32), "float")


def halves(compact, source, tie="0"):
    names, pixels = levels(compact)[0]
    got = pixels[..., [names.index(c) for c in "RGB"]].astype(np.float64)
    inp = oiio.ImageInput.open(source)
    integer = inp.spec().format == oiio.UINT8
    v = inp.read_image(0, 0, 0, 3, "uint8" if integer else "float").astype(np.float64)
    inp.close()
    if integer:
        v = v / 255.0
        v = np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)
    v32 = v.astype(np.float32)
    want = v32.astype(np.float16).astype(np.float64)
    spacing = 2.0 ** (np.floor(np.log2(np.maximum(np.abs(want), 2.0**-14))) - 10)
    # The halves around each value, and the combination nearest its colour in CIEDE2000
    # (colour-science), against the one stored.
    import colour

    text = levels_header(compact)
    m = np.array([float(x) for x in next(li for li in text.splitlines() if li.startswith("rgb ")).split()[1:]]).reshape(3, 3)
    near = v32.astype(np.float16)
    beyond = np.where(near.astype(np.float32) == v32, near,
                      np.nextafter(near, np.where(v32 > near.astype(np.float32), np.inf, -np.inf).astype(np.float16)))
    white = m @ np.ones(3)
    lab = lambda rgb: colour.XYZ_to_Lab((rgb.astype(np.float32).astype(np.float64) @ m.T).astype(np.float32)  # noqa: E731
                                        .astype(np.float64) / white[1], colour.XYZ_to_xy(white))
    target = colour.XYZ_to_Lab((v32.astype(np.float64) @ m.T) / white[1], colour.XYZ_to_xy(white))
    best = np.full(v.shape[:-1], np.inf)
    for pick in range(8):
        c = np.stack([np.where(pick >> i & 1, beyond[..., i], near[..., i]) for i in range(3)], -1)
        best = np.minimum(best, colour.delta_E(target, lab(c), method="CIE 2000"))
    mine = colour.delta_E(target, lab(got), method="CIE 2000")
    nearest = colour.delta_E(target, lab(want), method="CIE 2000")
    moved = (got != want).any(-1)
    # Each stored value is one of the two halves around the input's.
    bracket = (got == want) | (got == beyond.astype(np.float64))
    print(json.dumps({"differ": int((got != want).sum()), "channels": int(got.size),
                      "texels_moved": int(moved.sum()), "texels": int(moved.size),
                      "not_a_half_around": int((~bracket).sum()),
                      "max_steps": float(np.max(np.abs(got - want) / spacing)),
                      "farther_than_nearest_colour": int((mine > best + float(tie) + 1e-9).sum()),
                      "most_beyond_nearest_colour": float(np.max(mine - best)),
                      "moved_without_gain": int((moved & (nearest <= best + float(tie) - 1e-9)).sum()),
                      "most_gain": float(np.max(nearest - mine))}))


def levels_header(path):
    inp = oiio.ImageInput.open(path)
    text = inp.spec().get_string_attribute("specconvCompact")
    inp.close()
    return text


def stored(compact, out):
    names, pixels = levels(compact)[0]
    keep = [c for c in ("R", "G", "B", "A") if c in names]
    p = np.ascontiguousarray(pixels.astype(np.float32)[..., [names.index(c) for c in keep]])
    spec = oiio.ImageSpec(p.shape[1], p.shape[0], len(keep), "float")
    spec.channelnames = keep
    if "A" in keep:
        spec.alpha_channel = len(keep) - 1
    o = oiio.ImageOutput.create(out)
    if not o.open(out, spec) or not o.write_image(p):
        sys.exit(o.geterror())
    o.close()


def dump(compact, baked, prefix):
    (cn, cp), (bn, bp) = levels(compact)[0], levels(baked)[0]
    inp = oiio.ImageInput.open(compact)
    text = inp.spec().getattribute("specconvCompact")
    inp.close()
    if not isinstance(text, str):
        sys.exit(f"{compact}: no specconvCompact attribute")
    with open(prefix + ".header", "w") as f:
        f.write(text)
    t = cp.astype(np.float32)[..., [cn.index(c) for c in STORED]]
    t = t.reshape(-1, 9)
    np.savetxt(prefix + ".texels", t, fmt="%.9g", header=f"{len(t)} 9", comments="")
    # The T. channels (T.<nm>nm, a comma for a decimal point) by increasing wavelength.
    bands = sorted((float(n[2:-2].replace(",", ".")), i) for i, n in enumerate(bn) if n.startswith("T."))
    b = bp.astype(np.float32)[..., [i for _, i in bands]].reshape(-1, len(bands))
    wl = " ".join(repr(w) for w, _ in bands)
    np.savetxt(prefix + ".baked", b, fmt="%.9g", header=f"{len(b)} {len(bands)}\n{wl}", comments="")


def make(out, text_file, settings, width="4", height="2"):
    """A compact file of `width`×`height` texels (two of them NaN and infinite) with `text`."""
    with open(text_file, encoding="utf-8", newline="") as f:
        text = f.read()
    names = STORED
    width, height = int(width), int(height)
    spec = oiio.ImageSpec(width, height, len(names), "float")
    spec.channelnames = names
    spec.attribute("specconvLayout", "compact 2")
    spec.attribute("specconvCompact", text)
    spec.attribute("specconvSettings", settings)
    spec.attribute("specconvExpand", "sample=half rounding=nearest compression=zip filter=box")
    px = np.zeros((height, width, 9), dtype=np.float32)
    px[..., :3] = (0.2, 0.3, 0.25)
    px[0, 1, 0] = float("nan")
    px[1, 2, 1] = float("inf")
    o = oiio.ImageOutput.create(out)
    if not o.open(out, spec) or not o.write_image(px):
        sys.exit(o.geterror())
    o.close()


def nans(path):
    counts = []
    for _, p in levels(path):
        counts.append(int((~np.isfinite(p.astype(np.float32))).sum()))
    json.dump(counts, sys.stdout)


if __name__ == "__main__":
    {"chart": chart, "steps": steps, "stored": stored, "dump": dump, "make": make, "nans": nans,
     "inputs": inputs, "halves": halves}[sys.argv[1]](*sys.argv[2:])
