"""Writes the input images of tests/it/colour.rs into OUTDIR and prints, as JSON, the CIE XYZ
(D65 white, Y = 1) each pixel has, computed without specconv:

- OpenEXR files (Python OpenImageIO) with the `chromaticities` of Rec.709, AP0 (with
  `acesImageContainerFlag`), AP1, Rec.2020, P3-D65, CIE XYZ (white E), one arbitrary set, and
  none (OpenEXR's default: Rec.709, D65). Reference: colour-science's RGB_to_XYZ with Bradford
  adaptation to D65.
- 8-bit PNG, JPEG and TIFF files embedding ICC profiles: Debian's icc-profiles-free
  compatibleWithAdobeRGB1998.icc and sRGB.icc, and Display P3 and ProPhoto profiles that
  Little CMS makes from their published primaries. Reference: Little CMS itself (liblcms2
  through ctypes, relative colorimetric to XYZ D50, double precision) on the pixels as
  OpenImageIO decodes them, then colour-science's Bradford adaptation from the PCS white to D65.

    python3 tests/colour_rule_images.py OUTDIR
"""
import ctypes
import ctypes.util
import json
import os
import sys
import warnings

warnings.simplefilter("ignore")
import numpy as np  # noqa: E402
import colour  # noqa: E402
import OpenImageIO as oiio  # noqa: E402

out_dir = sys.argv[1]
D65 = np.array([0.3127, 0.3290])
D65_XYZ = colour.xy_to_XYZ(D65)

# Linear colours well inside the object-colour solid, so that the uplift keeps them exactly.
LINEAR = np.array(
    [
        [0.40, 0.35, 0.30],
        [0.20, 0.25, 0.30],
        [0.50, 0.50, 0.50],
        [0.10, 0.12, 0.08],
        [0.30, 0.20, 0.15],
        [0.15, 0.30, 0.20],
    ]
)

CHROMATICITIES = {
    "rec709": [0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290],
    "ap0": [0.7347, 0.2653, 0.0, 1.0, 0.0001, -0.0770, 0.32168, 0.33767],
    "ap1": [0.713, 0.293, 0.165, 0.830, 0.128, 0.044, 0.32168, 0.33767],
    "rec2020": [0.708, 0.292, 0.170, 0.797, 0.131, 0.046, 0.3127, 0.3290],
    "p3d65": [0.680, 0.320, 0.265, 0.690, 0.150, 0.060, 0.3127, 0.3290],
    "xyz_e": [1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0 / 3.0, 1.0 / 3.0],
    "arbitrary": [0.66, 0.31, 0.21, 0.71, 0.155, 0.07, 0.3457, 0.3585],
}


def write(path, pixels, fmt, attributes=()):
    h, w = 1, len(pixels)
    spec = oiio.ImageSpec(w, h, pixels.shape[-1], fmt)
    for name, typ, value in attributes:
        spec.attribute(name, typ, value)
    o = oiio.ImageOutput.create(path)
    assert o is not None and o.open(path, spec), oiio.geterror()
    o.write_image(pixels.reshape(h, w, -1))
    o.close()


def read(path):
    i = oiio.ImageInput.open(path)
    px = i.read_image(oiio.FLOAT)
    i.close()
    return np.asarray(px, dtype=np.float64).reshape(-1, 3)


result = {"exr": [], "icc": []}
for case, c in list(CHROMATICITIES.items()) + [("none", None)]:
    path = os.path.join(out_dir, f"chroma_{case}.exr")
    attrs = []
    if c is not None:
        attrs.append(("chromaticities", oiio.TypeDesc("float[8]"), c))
    if case == "ap0":
        attrs.append(("acesImageContainerFlag", oiio.TypeDesc("int"), 1))
    write(path, LINEAR.astype(np.float32), oiio.FLOAT, attrs)
    c = c or CHROMATICITIES["rec709"]
    space = colour.RGB_Colourspace(case, np.reshape(c[:6], (3, 2)), np.array(c[6:]))
    # Stored as float: the reference takes the same float32 values and chromaticities.
    space = colour.RGB_Colourspace(
        case,
        np.reshape(np.float32(c[:6]), (3, 2)).astype(np.float64),
        np.float32(c[6:]).astype(np.float64),
    )
    xyz = colour.RGB_to_XYZ(
        LINEAR.astype(np.float32).astype(np.float64),
        space,
        illuminant=D65,
        chromatic_adaptation_transform="Bradford",
    )
    result["exr"].append({"file": path, "case": case, "xyz": xyz.tolist()})

# Little CMS through ctypes: the reference for ICC profiles.
lcms = ctypes.CDLL(ctypes.util.find_library("lcms2"))
lcms.cmsOpenProfileFromMem.restype = ctypes.c_void_p
lcms.cmsOpenProfileFromMem.argtypes = [ctypes.c_char_p, ctypes.c_uint32]
lcms.cmsCreateXYZProfile.restype = ctypes.c_void_p
lcms.cmsCreateTransform.restype = ctypes.c_void_p
lcms.cmsCreateTransform.argtypes = [ctypes.c_void_p, ctypes.c_uint32] * 2 + [ctypes.c_uint32] * 2
lcms.cmsDoTransform.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_uint32]
lcms.cmsBuildParametricToneCurve.restype = ctypes.c_void_p
lcms.cmsBuildParametricToneCurve.argtypes = [ctypes.c_void_p, ctypes.c_int32, ctypes.c_double * 5]
lcms.cmsBuildGamma.restype = ctypes.c_void_p
lcms.cmsBuildGamma.argtypes = [ctypes.c_void_p, ctypes.c_double]
lcms.cmsCreateRGBProfile.restype = ctypes.c_void_p
lcms.cmsCreateRGBProfile.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p]
lcms.cmsSaveProfileToMem.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.POINTER(ctypes.c_uint32)]
# lcms2.h: TYPE_RGB_DBL = FLOAT_SH(1)|COLORSPACE_SH(PT_RGB)|CHANNELS_SH(3)|BYTES_SH(0),
# TYPE_XYZ_DBL likewise with PT_XYZ; INTENT_RELATIVE_COLORIMETRIC = 1.
TYPE_RGB_DBL = (1 << 22) | (4 << 16) | (3 << 3)
TYPE_XYZ_DBL = (1 << 22) | (9 << 16) | (3 << 3)
PCS_D50 = np.array([0.9642, 1.0, 0.8249])


def made_profile(white, primaries, curve):
    xyy = (ctypes.c_double * 3)(*white, 1.0)
    prim = (ctypes.c_double * 9)(*[v for p in primaries for v in (*p, 1.0)])
    curves = (ctypes.c_void_p * 3)(curve, curve, curve)
    h = lcms.cmsCreateRGBProfile(xyy, prim, curves)
    size = ctypes.c_uint32(0)
    lcms.cmsSaveProfileToMem(h, None, ctypes.byref(size))
    buf = ctypes.create_string_buffer(size.value)
    lcms.cmsSaveProfileToMem(h, buf, ctypes.byref(size))
    return buf.raw[: size.value]


srgb_curve = lcms.cmsBuildParametricToneCurve(
    None, 4, (ctypes.c_double * 5)(2.4, 1 / 1.055, 0.055 / 1.055, 1 / 12.92, 0.04045)
)
profiles = {
    "adobergb": open("/usr/share/color/icc/compatibleWithAdobeRGB1998.icc", "rb").read(),
    "srgb": open("/usr/share/color/icc/sRGB.icc", "rb").read(),
    # Display P3: P3 primaries, D65, the sRGB curve (Apple's definition).
    "displayp3": made_profile(
        [0.3127, 0.3290], [[0.680, 0.320], [0.265, 0.690], [0.150, 0.060]], srgb_curve
    ),
    # ProPhoto (ROMM RGB, ISO 22028-2): D50 white, gamma 1.8.
    "prophoto": made_profile(
        [0.3457, 0.3585],
        [[0.7347, 0.2653], [0.1596, 0.8404], [0.0366, 0.0001]],
        lcms.cmsBuildGamma(None, 1.8),
    ),
}
CODES = np.array(
    [[150, 120, 100], [90, 110, 130], [128, 128, 128], [60, 70, 50], [140, 100, 80], [80, 120, 95]],
    dtype=np.uint8,
)
for name, icc in profiles.items():
    hp = lcms.cmsOpenProfileFromMem(icc, len(icc))
    assert hp, name
    t = lcms.cmsCreateTransform(hp, TYPE_RGB_DBL, lcms.cmsCreateXYZProfile(), TYPE_XYZ_DBL, 1, 0)
    assert t, name
    for ext in ["png", "jpg", "tif"]:
        path = os.path.join(out_dir, f"icc_{name}.{ext}")
        attrs = [("ICCProfile", oiio.TypeDesc(f"uint8[{len(icc)}]"), np.frombuffer(icc, np.uint8))]
        if ext == "jpg":
            attrs.append(("Compression", oiio.TypeDesc("string"), "jpeg:100"))
        write(path, CODES, oiio.UINT8, attrs)
        rgb = np.ascontiguousarray(read(path))
        pcs = np.zeros_like(rgb)
        lcms.cmsDoTransform(t, rgb.ctypes.data, pcs.ctypes.data, len(rgb))
        xyz = colour.chromatic_adaptation(pcs, PCS_D50, D65_XYZ, method="Von Kries", transform="Bradford")
        result["icc"].append({"file": path, "profile": name, "xyz": xyz.tolist()})

print(json.dumps(result))
