"""OpenImageIO's TextureSystem reading a spectral texture, against level 0 box-filtered here.

  texture_lookup.py FILE

For each MIP level k of FILE (a power-of-two texture), looks every texel centre of level k
up through the TextureSystem with a footprint of one texel of level k (so that it reads
level k), and compares with level 0's values (read with ImageInput, as float) averaged over
2^k x 2^k blocks with numpy. Prints JSON: per level, the largest difference over texels and
channels, and how far the lookup at the texture's centre moved from level 0's. Also the
recorded oiio:AverageColor (what the TextureSystem reports as "averagecolor") against numpy's
mean of level 0.
"""
import json
import sys

import numpy as np
import OpenImageIO as oiio


def main(path):
    inp = oiio.ImageInput.open(path)
    if inp is None:
        sys.exit(oiio.geterror())
    spec = inp.spec()
    nch = spec.nchannels
    base = inp.read_image(0, 0, 0, nch, "float").reshape(spec.height, spec.width, nch)
    inp.close()

    ts = oiio.TextureSystem()
    opt = oiio.TextureOpt()
    opt.mipmode = oiio.MipMode.OneLevel
    opt.interpmode = oiio.InterpMode.Bilinear
    opt.swrap = oiio.Wrap.Clamp
    opt.twrap = oiio.Wrap.Clamp

    levels = []
    size = (spec.width, spec.height)
    k = 0
    centre0 = None
    while True:
        w, h = max(spec.width >> k, 1), max(spec.height >> k, 1)
        fx, fy = spec.width // w, spec.height // h
        box = base.reshape(h, fy, w, fx, nch).mean(axis=(1, 3))
        worst = 0.0
        for y in range(h):
            for x in range(w):
                s, t = (x + 0.5) / w, (y + 0.5) / h
                got = np.array(ts.texture(path, opt, s, t, 1.0 / w, 0.0, 0.0, 1.0 / h, nch))
                worst = max(worst, float(np.max(np.abs(got - box[y, x]))))
        centre = np.array(
            ts.texture(path, opt, 0.3, 0.6, 1.0 / w, 0.0, 0.0, 1.0 / h, nch)
        )
        if centre0 is None:
            centre0 = centre
        levels.append(
            {
                "size": [w, h],
                "max_difference": worst,
                "moved_from_level_0": float(np.max(np.abs(centre - centre0))),
            }
        )
        if w == 1 and h == 1:
            break
        k += 1
    recorded = spec.getattribute("oiio:AverageColor")
    average = [float(v) for v in recorded.split(",")] if recorded else None
    print(
        json.dumps(
            {
                "levels": levels,
                "averagecolor_difference": float(
                    np.max(np.abs(np.array(average) - base.mean(axis=(0, 1))))
                )
                if average
                else None,
                "size": size,
            }
        )
    )


if __name__ == "__main__":
    main(sys.argv[1])
