"""Compact files written by two specconv binaries, compared value for value: for changes that
must not move a stored bit (the speed of the half-colour search, docs/compact.md "Cost").

  python scripts/same_compact.py OLD_SPECCONV NEW_SPECCONV [TEXTURE ...]

Inputs, made here: an 8-bit ramp holding every code of each channel (4,194,304 codes), random
float32 colours (HDR, negative, tiny, NaN, ±inf, beyond half's range), and the TEXTUREs given
(the .tx files of scripts/bench_textures.sh). Each is converted with `--layout compact` by both
binaries, at half and at `-d float`, the first texture also with `--bands 400:700:5`. Every
channel of every MIP level is read through OpenImageIO and compared by its bits (NaN payloads
too), and the files byte for byte. Prints one line per conversion; exit status 1 on any
difference.
"""
import os
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio


def write(path, pixels, kind):
    spec = oiio.ImageSpec(pixels.shape[1], pixels.shape[0], pixels.shape[2], kind)
    out = oiio.ImageOutput.create(path)
    out.open(path, spec)
    out.write_image(pixels)
    out.close()


def inputs(work):
    """The made inputs: every 8-bit code, and hostile floats (linear, no colour space)."""
    y, x = np.mgrid[0:2048, 0:2048]
    ramp = np.stack([x % 256, y % 256, 32 * (x // 256) + 4 * (y // 256)], axis=-1)
    write(f"{work}/ramp.png", ramp.astype(np.uint8), oiio.UINT8)
    rng = np.random.default_rng(47)
    n = 512 * 512
    scale = rng.choice([1e-6, 1e-3, 0.1, 1.0, 1.0, 16.0, 1e3, 1e5], size=(n, 1))
    v = rng.uniform(-0.3, 1.2, size=(n, 3)) * scale
    specials = [np.nan, np.inf, -np.inf, 65504.0, 65520.0, -7e4, 1e-8, -0.0, 0.0]
    v[rng.integers(0, n, 4000), rng.integers(0, 3, 4000)] = rng.choice(specials, 4000)
    write(f"{work}/floats.exr", v.reshape(512, 512, 3).astype(np.float32), oiio.FLOAT)
    return [(f"{work}/ramp.png", []), (f"{work}/floats.exr", ["--fixnan", "keep"])]


def levels(path):
    inp = oiio.ImageInput.open(path)
    out, level = [], 0
    while inp.seek_subimage(0, level):
        s = inp.spec()
        out.append((list(s.channelnames), inp.read_image(0, level, 0, s.nchannels, "float")))
        level += 1
    inp.close()
    return out


def same(a, b):
    """'' when every channel of every level has the same bits, else what differs."""
    la, lb = levels(a), levels(b)
    if len(la) != len(lb):
        return f"{len(la)} levels against {len(lb)}"
    for i, ((na, pa), (nb, pb)) in enumerate(zip(la, lb)):
        if na != nb or pa.shape != pb.shape:
            return f"level {i}: channels {na} {pa.shape} against {nb} {pb.shape}"
        diff = pa.view(np.uint32) != pb.view(np.uint32)
        if diff.any():
            per = {na[c]: int(diff[..., c].sum()) for c in range(len(na)) if diff[..., c].any()}
            return f"level {i}: values differ {per}"
    return ""


def main():
    old, new, textures = sys.argv[1], sys.argv[2], sys.argv[3:]
    bad = 0
    with tempfile.TemporaryDirectory() as work:
        cases = inputs(work) + [(t, []) for t in textures]
        runs = []
        for path, extra in cases:
            for depth in ([], ["-d", "float"]):
                runs.append((path, extra + depth))
        if textures:
            runs.append((textures[0], ["--bands", "400:700:5"]))
        for k, (path, args) in enumerate(runs):
            outs = []
            for side, binary in (("old", old), ("new", new)):
                out = f"{work}/{side}{k}.exr"
                cmd = [binary, "convert", "--layout", "compact", "--progress", "never", path, out, *args]
                subprocess.run(cmd, check=True, capture_output=True)
                outs.append(out)
            why = same(*outs)
            with open(outs[0], "rb") as f0, open(outs[1], "rb") as f1:
                bytes_same = f0.read() == f1.read()
            texels = sum(p.shape[0] * p.shape[1] for _, p in levels(outs[0]))
            name = os.path.basename(path)
            verdict = "same" if not why else f"DIFFERENT: {why}"
            print(f"{name} {' '.join(args) or '(half)'}: {texels} texels, values {verdict}, bytes {'same' if bytes_same else 'differ'}")
            bad += bool(why)
            for o in outs:
                os.remove(o)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
