#!/usr/bin/env python3
"""Reference spectra from colour-science's implementations of the baselines, for
crates/spectral/tests/spectral/colour_science.rs.

    python3 -m venv venv && venv/bin/pip install colour-science==0.4.7 scipy
    venv/bin/python scripts/colour_science_reference.py testdata/colour_science/reference.json

Inputs: the 24 ColorChecker colours (colour-science's "ColorChecker24 - After November 2014",
D50 xyY, adapted to D65 with CAT02 and taken to linear sRGB) and 40 random in-gamut linear sRGB
colours (seed 5), all in [0, 1]. Conventions are colour-science's defaults: Smits from linear
RGB (sRGB primaries, white E), Meng 2015 and Jakob 2019 from XYZ (Y = 1 for white) with the CIE
1931 2° observer and D65 on 360-780 nm at 5 nm.
"""
import json
import sys

import numpy as np
import colour
from colour.recovery import (
    RGB_to_sd_Smits1999,
    XYZ_to_sd_Meng2015,
    XYZ_to_sd_Jakob2019,
)

srgb = colour.RGB_COLOURSPACES["sRGB"]
cc = colour.CCS_COLOURCHECKERS["ColorChecker24 - After November 2014"]
rgbs = []
for xyy in cc.data.values():
    xyz = colour.xyY_to_XYZ(xyy)
    rgb = colour.XYZ_to_RGB(xyz, srgb, cc.illuminant, chromatic_adaptation_transform="CAT02")
    rgbs.append(np.clip(rgb, 0, 1))
rng = np.random.default_rng(5)
rgbs += list(rng.uniform(0.02, 0.98, (40, 3)))

out = {"colour_science": colour.__version__, "smits1999": [], "meng2015": [], "jakob2019": []}
for rgb in rgbs:
    sd = RGB_to_sd_Smits1999(rgb)
    out["smits1999"].append(
        {"rgb": list(rgb), "wavelengths": list(sd.wavelengths), "values": list(sd.values)}
    )
    # XYZ of the linear sRGB colour (D65 white, Y = 1).
    xyz = colour.RGB_to_XYZ(rgb, srgb)
    sd = XYZ_to_sd_Meng2015(xyz)
    out["meng2015"].append(
        {"xyz": list(xyz), "wavelengths": list(sd.wavelengths), "values": list(sd.values)}
    )
    sd, err = XYZ_to_sd_Jakob2019(xyz, additional_data=True)
    out["jakob2019"].append(
        {
            "xyz": list(xyz),
            "delta_e76": err,
            "wavelengths": list(sd.wavelengths),
            "values": list(sd.values),
        }
    )

with open(sys.argv[1], "w") as f:
    json.dump(out, f, indent=0)
    f.write("\n")
