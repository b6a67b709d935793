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
        out.append({"level": level, "identical": float((pa.view(signed) == pb.view(signed)).mean()), "max_steps": int(d.max()), "samples": int(d.size), "pixels_beyond_one": beyond})
    print(json.dumps(out))


STORED = ("R", "G", "B", "U.0", "U.1", "U.2", "UF.0", "UF.1", "UF.2")


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
    {"chart": chart, "steps": steps, "stored": stored, "dump": dump, "make": make, "nans": nans}[sys.argv[1]](*sys.argv[2:])
