"""OpenImageIO's view of an image's structure, for the tests of windows, subimages and channels.

  describe FILE        JSON list, one entry per subimage and MIP level: its data window
                       (x, y, width, height), display window, channel names and the SHA-1 of its
                       pixels read as float (equal hashes: the same pixels in the same places).
  mipmap INPUT OUTPUT  writes INPUT as a tiled, MIP-mapped OpenEXR (16x16 tiles, levels rounded
                       down, each level every 2^L-th pixel) that keeps INPUT's data and display
                       windows: maketx fills the display window instead.
  diff A B [LO HI]     JSON list, one entry per MIP level of A: its size, B's, the largest
                       difference of their pixels read as float (B's clamped into [LO, HI] when
                       given), and the smallest and largest of B's values before that.
"""
import hashlib
import json
import sys

import numpy as np
import OpenImageIO as oiio


def describe(path):
    inp = oiio.ImageInput.open(path)
    if inp is None:
        sys.exit(oiio.geterror())
    out = []
    sub = 0
    while inp.seek_subimage(sub, 0):
        level = 0
        while inp.seek_subimage(sub, level):
            s = inp.spec()
            pixels = inp.read_image(sub, level, 0, s.nchannels, "float")
            out.append(
                {
                    "subimage": sub,
                    "level": level,
                    "name": s.get_string_attribute("oiio:subimagename"),
                    "data": [s.x, s.y, s.width, s.height],
                    "display": [s.full_x, s.full_y, s.full_width, s.full_height],
                    "channels": list(s.channelnames),
                    "sha1": hashlib.sha1(pixels.tobytes()).hexdigest(),
                }
            )
            level += 1
        sub += 1
    print(json.dumps(out))


def mipmap(src, dst):
    inp = oiio.ImageInput.open(src)
    spec = inp.spec()
    pixels = inp.read_image(0, 0, 0, spec.nchannels, "float")
    out_spec = oiio.ImageSpec(spec)
    out_spec.tile_width = out_spec.tile_height = 16
    out_spec.attribute("textureformat", "Plain Texture")
    out = oiio.ImageOutput.create(dst)
    if not out.open(dst, out_spec, "create"):
        sys.exit(out.geterror())
    level, w, h = 0, spec.width, spec.height
    while True:
        step = 2**level
        if not out.write_image(pixels[: h * step : step, : w * step : step].copy()):
            sys.exit(out.geterror())
        if w == 1 and h == 1:
            break
        level, w, h = level + 1, max(w // 2, 1), max(h // 2, 1)
        level_spec = oiio.ImageSpec(out_spec)
        level_spec.width, level_spec.height = w, h
        if not out.open(dst, level_spec, "AppendMIPLevel"):
            sys.exit(out.geterror())
    out.close()


def diff(a_path, b_path, limits):
    a, b = oiio.ImageInput.open(a_path), oiio.ImageInput.open(b_path)
    if a is None or b is None:
        sys.exit(oiio.geterror())
    out = []
    level = 0
    while a.seek_subimage(0, level):
        x = a.read_image(0, level, 0, a.spec().nchannels, "float")
        entry = {"level": level, "size": [a.spec().width, a.spec().height], "other": None}
        if b.seek_subimage(0, level):
            y = b.read_image(0, level, 0, b.spec().nchannels, "float")
            entry["other"] = [b.spec().width, b.spec().height]
            entry["min"], entry["max"] = float(y.min()), float(y.max())
            if limits:
                y = np.clip(y, *limits)
            if x.shape == y.shape:
                entry["max_difference"] = float(np.abs(x - y).max())
        out.append(entry)
        level += 1
    print(json.dumps(out))


if __name__ == "__main__":
    if sys.argv[1] == "describe":
        describe(sys.argv[2])
    elif sys.argv[1] == "mipmap":
        mipmap(sys.argv[2], sys.argv[3])
    elif sys.argv[1] == "diff":
        diff(sys.argv[2], sys.argv[3], [float(v) for v in sys.argv[4:6]])
    else:
        sys.exit(__doc__)
