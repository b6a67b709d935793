#!/usr/bin/env python3
"""Writes specconv's built-in OCIO configs for OpenColorIO 2.1: cg.ocio and studio.ocio.

OpenColorIO 2.2 and later compile in the Academy's ACES CG and Studio configs (v1.0.0,
ACES 1.3, OCIO 2.1) and serve them as `ocio://cg-config-v1.0.0_aces-v1.3_ocio-v2.1`,
`ocio://studio-config-v1.0.0_aces-v1.3_ocio-v2.1`, `ocio://cg-config-latest`,
`ocio://studio-config-latest` and `ocio://default` (the CG config). Debian 12 has OCIO 2.1,
which ships none, so specconv writes configs with the same colour spaces, aliases, roles,
displays, views, view transforms, looks, named transforms and file rules, built here from
facts:

- names and aliases of the configs above (they are what users type);
- OCIO 2.1's built-in transforms, by name (ACES, ADX, Canon, displays, output transforms);
- every matrix computed here, in exact rational arithmetic, from the published chromaticities
  of its primaries and white point (sources in PRIMARIES), adapted from one white to the
  other by the von Kries method in the cone space the camera vendor uses (CAT02 or
  Bradford, see CAT);
- every log curve's OCIO parameters computed from the constants its vendor publishes
  (sources at each curve).

Only the Python standard library is needed:

    python3 scripts/make_configs.py cg > ffi/ocio/config/cg.ocio
    python3 scripts/make_configs.py studio > ffi/ocio/config/studio.ocio

The tests (ffi/ocio/tests/ocio/official.rs) compare both configs with the official files,
name for name and result for result.
"""

import math
import sys
from fractions import Fraction as F

# ---------------------------------------------------------------------------------------
# Colorimetry

# CIE 1931 xy of white points.
D65 = (F("0.3127"), F("0.3290"))  # as rounded in ITU-R BT.709-6 and BT.2020-2
ACES_WHITE = (F("0.32168"), F("0.33767"))  # SMPTE ST 2065-1:2012, Table 1

# CIE 1931 xy of red, green, blue and white.
PRIMARIES = {
    # SMPTE ST 2065-1:2012 (ACES2065-1), Table 1.
    "AP0": (("0.7347", "0.2653"), ("0.0", "1.0"), ("0.0001", "-0.0770"), ACES_WHITE),
    # Academy S-2014-004 (ACEScg), section 4.1.
    "AP1": (("0.713", "0.293"), ("0.165", "0.830"), ("0.128", "0.044"), ACES_WHITE),
    # ITU-R BT.709-6, Item 1.4 (also IEC 61966-2-1 sRGB).
    "Rec.709": (("0.64", "0.33"), ("0.30", "0.60"), ("0.15", "0.06"), D65),
    # SMPTE EG 432-1:2010 (P3 primaries with the D65 white point).
    "P3-D65": (("0.680", "0.320"), ("0.265", "0.690"), ("0.150", "0.060"), D65),
    # ITU-R BT.2020-2, Table 3.
    "Rec.2020": (("0.708", "0.292"), ("0.170", "0.797"), ("0.131", "0.046"), D65),
    # ARRI, "ALEXA Log C Curve - Usage in VFX" (2017), ALEXA Wide Gamut.
    "ARRI Wide Gamut 3": (("0.6840", "0.3130"), ("0.2210", "0.8480"),
                          ("0.0861", "-0.1020"), D65),
    # Cooper & Brendel, "ARRI LogC4 Logarithmic Color Space Specification" (2022).
    "ARRI Wide Gamut 4": (("0.7347", "0.2653"), ("0.1424", "0.8576"),
                          ("0.0991", "-0.0308"), D65),
    # Blackmagic Design, "Blackmagic Generation 5 Color Science" (2021); its own white.
    "Blackmagic Wide Gamut": (("0.7177215", "0.3171181"), ("0.2280410", "0.8615690"),
                              ("0.1005841", "-0.0820452"),
                              (F("0.3127170"), F("0.3290312"))),
    # Blackmagic Design, "DaVinci Resolve 17 Wide Gamut Intermediate" (2020).
    "DaVinci Wide Gamut": (("0.8000", "0.3130"), ("0.1682", "0.9877"),
                           ("0.0790", "-0.1155"), D65),
    # Canon, "EOS C500 Firmware Update" (2014), Cinema Gamut.
    "Cinema Gamut": (("0.74", "0.27"), ("0.17", "1.14"), ("0.08", "-0.10"), D65),
    # Panasonic, "VARICAM V-Log/V-Gamut" (2014).
    "V-Gamut": (("0.730", "0.280"), ("0.165", "0.840"), ("0.100", "-0.030"), D65),
    # RED, "White Paper on REDWideGamutRGB and Log3G10" (2017).
    "REDWideGamutRGB": (("0.780308", "0.304253"), ("0.121595", "1.493994"),
                        ("0.095612", "-0.084589"), D65),
    # Sony, "Technical Summary for S-Gamut3.Cine/S-Log3 and S-Gamut3/S-Log3" (v1.00).
    "S-Gamut3": (("0.730", "0.280"), ("0.140", "0.855"), ("0.100", "-0.050"), D65),
    "S-Gamut3.Cine": (("0.766", "0.275"), ("0.225", "0.800"), ("0.089", "-0.087"), D65),
    # Sony Electronics, IDT.Sony.Venice_SLog3_SGamut3.ctl and
    # IDT.Sony.Venice_SLog3_SGamut3Cine.ctl (aces-dev, 2020), primaries as derived from
    # their matrices in colour-science 0.4's colour.models.rgb.datasets.sony.
    "Venice S-Gamut3": (("0.740464264304292", "0.279364374750660"),
                        ("0.089241145423286", "0.893809528608105"),
                        ("0.110488236673827", "-0.052579333080476"), D65),
    "Venice S-Gamut3.Cine": (("0.775901871567345", "0.274502392854799"),
                             ("0.188682902773355", "0.828684937020288"),
                             ("0.101337382499301", "-0.089187517306263"), D65),
}

# Cone-response matrices for von Kries white adaptation.
CAT = {
    # Lam (1985), as in ICC.1:2010 Annex E.
    "Bradford": [["0.8951", "0.2664", "-0.1614"],
                 ["-0.7502", "1.7135", "0.0367"],
                 ["0.0389", "-0.0685", "1.0296"]],
    # CIE 159:2004 (CIECAM02).
    "CAT02": [["0.7328", "0.4296", "-0.1624"],
              ["-0.7036", "1.6975", "0.0061"],
              ["0.0030", "0.0136", "0.9834"]],
}


def xyz(xy):
    x, y = (F(v) for v in xy)
    return [x / y, F(1), (1 - x - y) / y]


def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def apply(m, v):
    return [sum(m[i][k] * v[k] for k in range(3)) for i in range(3)]


def inverse3(m):
    a, b, c = m[0]
    d, e, f = m[1]
    g, h, i = m[2]
    det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    return [
        [(e * i - f * h) / det, (c * h - b * i) / det, (b * f - c * e) / det],
        [(f * g - d * i) / det, (a * i - c * g) / det, (c * d - a * f) / det],
        [(d * h - e * g) / det, (b * g - a * h) / det, (a * e - b * d) / det],
    ]


def rgb_to_xyz(key):
    """The normalised primary matrix of SMPTE RP 177-1993: RGB (1,1,1) maps to the white
    point with Y = 1."""
    r, g, b, w = PRIMARIES[key]
    cols = [xyz(r), xyz(g), xyz(b)]
    p = [[cols[c][row] for c in range(3)] for row in range(3)]
    s = apply(inverse3(p), xyz(w))
    return [[p[row][c] * s[c] for c in range(3)] for row in range(3)]


def adaptation(src_white, dst_white, cat):
    """Von Kries adaptation in the cone space of `cat`: M^-1 diag(dst/src) M."""
    m = [[F(v) for v in row] for row in CAT[cat]]
    src, dst = apply(m, xyz(src_white)), apply(m, xyz(dst_white))
    scale = [[dst[i] / src[i] if i == j else F(0) for j in range(3)] for i in range(3)]
    return mul(inverse3(m), mul(scale, m))


def rgb_to_rgb(src, dst, cat):
    """RGB in `src` primaries to RGB in `dst` primaries, through CIE XYZ, adapting the
    white of `src` to the white of `dst` with `cat`."""
    cat_m = adaptation(PRIMARIES[src][3], PRIMARIES[dst][3], cat)
    return mul(inverse3(rgb_to_xyz(dst)), mul(cat_m, rgb_to_xyz(src)))


def num(v):
    """A number as YAML: repr() of a double round-trips exactly."""
    v = float(v)
    return repr(int(v)) if v == int(v) and abs(v) < 1e15 else repr(v)


def matrix(m):
    rows = [[num(v) for v in row] + ["0"] for row in m] + [["0", "0", "0", "1"]]
    return "!<MatrixTransform> {matrix: [" + ", ".join(v for r in rows for v in r) + "]}"


# ---------------------------------------------------------------------------------------
# Transfer functions, as OCIO transforms that decode to linear (direction: inverse).


def log_camera(base, log_side_slope, log_side_offset=None, lin_side_slope=None,
               lin_side_offset=None, lin_side_break=None, linear_slope=None):
    """A LogCameraTransform: log = log_side_slope * log_base(lin_side_slope * lin +
    lin_side_offset) + log_side_offset above lin_side_break, a straight line below (its
    slope given or, when None, continuous with the log part)."""
    params = [("base", base), ("log_side_slope", log_side_slope),
              ("log_side_offset", log_side_offset), ("lin_side_slope", lin_side_slope),
              ("lin_side_offset", lin_side_offset), ("lin_side_break", lin_side_break),
              ("linear_slope", linear_slope)]
    body = ", ".join(f"{k}: {num(v)}" for k, v in params if v is not None)
    return "!<LogCameraTransform> {" + body + ", direction: inverse}"


def arri_logc3(ei):
    """ARRI LogC3 at exposure index `ei`, from the encoding parameters of ARRI's
    "ALEXA Log C Curve - Usage in VFX" (2017) and its IDT generator (v3_IDT_maker): the
    encoding gain falls by 0.11 per three stops above EI 400, and the offset is solved so
    that code 95 of 1023 stays the black level."""
    nominal_ei, mid_grey_signal = 400, 0.01
    encoding_gain, encoding_offset = 500 / 1023 * 0.525, 400 / 1023
    cut_point = 1 / 9
    slope = 1 / (cut_point * math.log(10))
    offset = math.log10(cut_point) - slope * cut_point
    gain = ei / nominal_ei
    grey = mid_grey_signal / gain
    enc_gain = (math.log2(gain) * (0.89 - 1) / 3 + 1) * encoding_gain
    enc_offset = encoding_offset
    for _ in range(3):  # fixed-point iteration, as the generator does
        nz = ((95 / 1023 - enc_offset) / enc_gain - offset) / slope
        enc_offset = encoding_offset - math.log10(1 + nz) * enc_gain
    scale = grey * 0.18 / (mid_grey_signal * nominal_ei / ei)
    return log_camera(10, log_side_slope=enc_gain, log_side_offset=enc_offset,
                      lin_side_slope=1 / scale, lin_side_offset=nz,
                      lin_side_break=(cut_point - nz) * scale)


def arri_logc4():
    """Cooper & Brendel, "ARRI LogC4 Logarithmic Color Space Specification" (2022):
    E = (log2(a x + 64) - 6) / 14 * b + c above the cut t."""
    a = (2 ** 18 - 16) / 117.45
    b = (1023 - 95) / 1023
    c = 95 / 1023
    t = (2 ** (14 * (-c / b) + 6) - 64) / a
    return log_camera(2, log_side_slope=b / 14, log_side_offset=-6 * b / 14 + c,
                      lin_side_slope=a, lin_side_offset=64, lin_side_break=t)


def bmd_film_gen5():
    """Blackmagic Design, "Blackmagic Generation 5 Color Science" (2021):
    y = A ln(x + B) + C above x = 0.005."""
    a, b, c = 0.08692876065491224, 0.005494072432257808, 0.5300133392291939
    return log_camera(math.e, log_side_slope=a, log_side_offset=c, lin_side_offset=b,
                      lin_side_break=0.005)


def davinci_intermediate():
    """Blackmagic Design, "DaVinci Resolve 17 Wide Gamut Intermediate" (2020):
    y = (log2(x + A) + B) C above LIN_CUT, y = M x below."""
    a, b, c, m, cut = 0.0075, 7.0, 0.07329248, 10.44426855, 0.00262409
    return log_camera(2, log_side_slope=c, log_side_offset=b * c, lin_side_offset=a,
                      lin_side_break=cut, linear_slope=m)


def v_log():
    """Panasonic, "VARICAM V-Log/V-Gamut" (2014): y = c log10(x + b) + d above cut1."""
    b, c, d, cut1 = 0.00873, 0.241514, 0.598206, 0.01
    return log_camera(10, log_side_slope=c, log_side_offset=d, lin_side_offset=b,
                      lin_side_break=cut1)


def log3g10():
    """RED, "White Paper on REDWideGamutRGB and Log3G10" (2017):
    y = a log10((x + c) b + 1) above x = -c."""
    a, b, c = 0.224282, 155.975327, 0.01
    return log_camera(10, log_side_slope=a, lin_side_slope=b, lin_side_offset=b * c + 1,
                      lin_side_break=-c)


def s_log3():
    """Sony, "Technical Summary for S-Gamut3.Cine/S-Log3 and S-Gamut3/S-Log3":
    y = (420 + 261.5 log10((x + 0.01) / 0.19)) / 1023 above x = 0.01125, a straight line
    through code 95 at 0 below."""
    return log_camera(10, log_side_slope=261.5 / 1023, log_side_offset=420 / 1023,
                      lin_side_slope=1 / 0.19, lin_side_offset=0.01 / 0.19,
                      lin_side_break=0.01125,
                      linear_slope=(171.2102946929 - 95) / 0.01125 / 1023)


def gamma(value):
    return f"!<ExponentTransform> {{value: {num(value)}, style: pass_thru, direction: inverse}}"


# IEC 61966-2-1 (sRGB): a 2.4 power with a linear toe, offset 0.055.
SRGB_CURVE = "!<ExponentWithLinearTransform> {gamma: 2.4, offset: 0.055, direction: inverse}"
# ITU-R BT.709-6, Item 1.2 (camera OETF): exponent 0.45, offset 0.099.
REC709_CURVE = ("!<ExponentWithLinearTransform> "
                f"{{gamma: {num(1 / 0.45)}, offset: 0.099, direction: inverse}}")


def builtin(style):
    return f"!<BuiltinTransform> {{style: {style}}}"


# ---------------------------------------------------------------------------------------
# The configs' contents: names and aliases (what users type), and how each is built.


class Space:
    def __init__(self, name, aliases, family, encoding, description, categories=("file-io",),
                 to_ref=None, from_ref=None, display=False, isdata=False):
        self.name, self.aliases, self.family = name, aliases, family
        self.encoding, self.description, self.categories = encoding, description, categories
        self.to_ref, self.from_ref = to_ref, from_ref
        self.display, self.isdata = display, isdata


def aces_space(name, aliases, encoding, style, what, working=False):
    cats = ("file-io", "working-space") if working else ("file-io",)
    return Space(name, aliases, "ACES", encoding, what, cats,
                 to_ref=[builtin(style)] if style else None)


def utility(name, aliases, key, curve, what, family="Utility", working=False,
            encoding="sdr-video"):
    """A space with `key` primaries (D65 white unless AP1), Bradford-adapted from AP0."""
    cats = ("file-io", "working-space") if working else ("file-io",)
    steps = [matrix(rgb_to_rgb("AP0", key, "Bradford"))] + ([curve] if curve else [])
    return Space(name, aliases, family, encoding, what, cats,
                 from_ref=("AP0 to " + name, steps))


def camera(name, aliases, vendor, gamut, cat, curve, what):
    """A camera space: its log curve (if any), then its gamut to AP0, adapted to the ACES
    white with the vendor's `cat`."""
    steps = ([curve] if curve else []) + [matrix(rgb_to_rgb(gamut, "AP0", cat))]
    return Space(name, aliases, "Input/" + vendor, "log" if curve else "scene-linear", what,
                 to_ref=(name + " to ACES2065-1", steps))


def display(name, alias, encoding, style, what):
    return Space(name, [alias], "Display", encoding, what, from_ref=[builtin(style)],
                 display=True)


CIE_XYZ = Space("CIE-XYZ-D65", ["cie_xyz_d65"], "", None,
                "CIE XYZ with the D65 white at Y = 1: the display connection space.",
                categories=(), display=True)

DISPLAYS = {
    "sRGB - Display": display("sRGB - Display", "srgb_display", "sdr-video",
                              "DISPLAY - CIE-XYZ-D65_to_sRGB",
                              "sRGB display (IEC 61966-2-1 piecewise curve)."),
    "Rec.1886 Rec.709 - Display": display(
        "Rec.1886 Rec.709 - Display", "rec1886_rec709_display", "sdr-video",
        "DISPLAY - CIE-XYZ-D65_to_REC.1886-REC.709",
        "ITU-R BT.1886 curve, BT.709 primaries (HD video)."),
    "Rec.1886 Rec.2020 - Display": display(
        "Rec.1886 Rec.2020 - Display", "rec1886_rec2020_display", "sdr-video",
        "DISPLAY - CIE-XYZ-D65_to_REC.1886-REC.2020",
        "ITU-R BT.1886 curve, BT.2020 primaries (UHD video)."),
    "Rec.2100-HLG - Display": display(
        "Rec.2100-HLG - Display", "rec2100_hlg_display", "hdr-video",
        "DISPLAY - CIE-XYZ-D65_to_REC.2100-HLG-1000nit",
        "ITU-R BT.2100 HLG, 1000 nits."),
    "Rec.2100-PQ - Display": display(
        "Rec.2100-PQ - Display", "rec2100_pq_display", "hdr-video",
        "DISPLAY - CIE-XYZ-D65_to_REC.2100-PQ", "ITU-R BT.2100 PQ."),
    "ST2084-P3-D65 - Display": display(
        "ST2084-P3-D65 - Display", "st2084_p3d65_display", "hdr-video",
        "DISPLAY - CIE-XYZ-D65_to_ST2084-P3-D65", "SMPTE ST 2084 (PQ), P3-D65 primaries."),
    "P3-D60 - Display": display(
        "P3-D60 - Display", "p3d60_display", "sdr-video",
        "DISPLAY - CIE-XYZ-D65_to_G2.6-P3-D60-BFD",
        "Gamma 2.6, P3 primaries, D60 white (Bradford)."),
    "P3-D65 - Display": display(
        "P3-D65 - Display", "p3d65_display", "sdr-video",
        "DISPLAY - CIE-XYZ-D65_to_G2.6-P3-D65", "Gamma 2.6, P3-D65."),
    "P3-DCI - Display": display(
        "P3-DCI - Display", "p3_dci_display", "sdr-video",
        "DISPLAY - CIE-XYZ-D65_to_G2.6-P3-DCI-BFD",
        "Gamma 2.6, P3 primaries, DCI white (Bradford)."),
}

ACES_SPACES = [
    aces_space("ACES2065-1", ["aces2065_1", "ACES - ACES2065-1", "lin_ap0"], "scene-linear",
               None, "ACES2065-1 (SMPTE ST 2065-1: AP0 primaries, linear): the scene reference."),
    aces_space("ACEScc", ["ACES - ACEScc", "acescc_ap1"], "log", "ACEScc_to_ACES2065-1",
               "ACEScc (Academy S-2014-003: AP1 primaries, pure log)."),
    aces_space("ACEScct", ["ACES - ACEScct", "acescct_ap1"], "log", "ACEScct_to_ACES2065-1",
               "ACEScct (Academy S-2016-001: AP1 primaries, log with a linear toe).",
               working=True),
    aces_space("ACEScg", ["ACES - ACEScg", "lin_ap1"], "scene-linear", "ACEScg_to_ACES2065-1",
               "ACEScg (Academy S-2014-004: AP1 primaries, linear).", working=True),
]

ADX_SPACES = [
    aces_space("ADX10", ["Input - ADX - ADX10"], "log", "ADX10_to_ACES2065-1",
               "Academy Density Exchange, 10 bits (Academy S-2008-001)."),
    aces_space("ADX16", ["Input - ADX - ADX16"], "log", "ADX16_to_ACES2065-1",
               "Academy Density Exchange, 16 bits (Academy S-2008-001)."),
]


def camera_spaces():
    awg3, awg4 = "ARRI Wide Gamut 3", "ARRI Wide Gamut 4"
    bwg, dwg = "Blackmagic Wide Gamut", "DaVinci Wide Gamut"
    sg3, sg3c = "S-Gamut3", "S-Gamut3.Cine"
    vsg3, vsg3c = "Venice S-Gamut3", "Venice S-Gamut3.Cine"
    return [
        camera("Linear ARRI Wide Gamut 3",
               ["lin_arri_wide_gamut_3", "Input - ARRI - Linear - ALEXA Wide Gamut",
                "lin_alexawide"], "ARRI", awg3, "CAT02", None, "Linear ARRI Wide Gamut 3."),
        camera("ARRI LogC3 (EI800)",
               ["arri_logc3_ei800", "Input - ARRI - V3 LogC (EI800) - Wide Gamut",
                "logc3ei800_alexawide"], "ARRI", awg3, "CAT02", arri_logc3(800),
               "ARRI LogC3 at EI 800, ARRI Wide Gamut 3."),
        camera("Linear ARRI Wide Gamut 4", ["lin_arri_wide_gamut_4", "lin_awg4"], "ARRI",
               awg4, "CAT02", None, "Linear ARRI Wide Gamut 4."),
        camera("ARRI LogC4", ["arri_logc4"], "ARRI", awg4, "CAT02", arri_logc4(),
               "ARRI LogC4, ARRI Wide Gamut 4."),
        camera("BMDFilm WideGamut Gen5", ["bmdfilm_widegamut_gen5"], "BlackmagicDesign",
               bwg, "CAT02", bmd_film_gen5(),
               "Blackmagic Film (Generation 5), Blackmagic Wide Gamut."),
        camera("DaVinci Intermediate WideGamut", ["davinci_intermediate_widegamut"],
               "BlackmagicDesign", dwg, "CAT02", davinci_intermediate(),
               "DaVinci Intermediate, DaVinci Wide Gamut."),
        camera("Linear BMD WideGamut Gen5", ["lin_bmd_widegamut_gen5"], "BlackmagicDesign",
               bwg, "CAT02", None, "Linear Blackmagic Wide Gamut (Generation 5)."),
        camera("Linear DaVinci WideGamut", ["lin_davinci_widegamut"], "BlackmagicDesign",
               dwg, "CAT02", None, "Linear DaVinci Wide Gamut."),
        Space("CanonLog3 CinemaGamut D55",
              ["canonlog3_cinemagamut_d55",
               "Input - Canon - Canon-Log3 - Cinema Gamut Daylight", "canonlog3_cgamutday"],
              "Input/Canon", "log", "Canon Log 3, Cinema Gamut, daylight (OCIO built-in).",
              to_ref=[builtin("CANON_CLOG3-CGAMUT_to_ACES2065-1")]),
        camera("Linear CinemaGamut D55",
               ["lin_cinemagamut_d55", "Input - Canon - Linear - Canon Cinema Gamut Daylight",
                "lin_canoncgamutday"], "Canon", "Cinema Gamut", "CAT02", None,
               "Linear Canon Cinema Gamut."),
        camera("Linear V-Gamut", ["lin_vgamut", "Input - Panasonic - Linear - V-Gamut"],
               "Panasonic", "V-Gamut", "Bradford", None, "Linear Panasonic V-Gamut."),
        camera("V-Log V-Gamut", ["vlog_vgamut", "Input - Panasonic - V-Log - V-Gamut"],
               "Panasonic", "V-Gamut", "Bradford", v_log(), "Panasonic V-Log, V-Gamut."),
        camera("Linear REDWideGamutRGB",
               ["lin_redwidegamutrgb", "Input - RED - Linear - REDWideGamutRGB", "lin_rwg"],
               "RED", "REDWideGamutRGB", "Bradford", None, "Linear REDWideGamutRGB."),
        camera("Log3G10 REDWideGamutRGB",
               ["log3g10_redwidegamutrgb", "Input - RED - REDLog3G10 - REDWideGamutRGB",
                "rl3g10_rwg"], "RED", "REDWideGamutRGB", "Bradford", log3g10(),
               "RED Log3G10, REDWideGamutRGB."),
        camera("Linear S-Gamut3", ["lin_sgamut3", "Input - Sony - Linear - S-Gamut3"],
               "Sony", sg3, "CAT02", None, "Linear Sony S-Gamut3."),
        camera("Linear S-Gamut3.Cine",
               ["lin_sgamut3cine", "Input - Sony - Linear - S-Gamut3.Cine"], "Sony", sg3c,
               "CAT02", None, "Linear Sony S-Gamut3.Cine."),
        camera("Linear Venice S-Gamut3",
               ["lin_venice_sgamut3", "Input - Sony - Linear - Venice S-Gamut3"], "Sony",
               vsg3, "CAT02", None, "Linear Sony Venice S-Gamut3."),
        camera("Linear Venice S-Gamut3.Cine",
               ["lin_venice_sgamut3cine", "Input - Sony - Linear - Venice S-Gamut3.Cine"],
               "Sony", vsg3c, "CAT02", None, "Linear Sony Venice S-Gamut3.Cine."),
        camera("S-Log3 S-Gamut3", ["slog3_sgamut3", "Input - Sony - S-Log3 - S-Gamut3"],
               "Sony", sg3, "CAT02", s_log3(), "Sony S-Log3, S-Gamut3."),
        camera("S-Log3 S-Gamut3.Cine",
               ["slog3_sgamut3cine", "Input - Sony - S-Log3 - S-Gamut3.Cine",
                "slog3_sgamutcine"], "Sony", sg3c, "CAT02", s_log3(),
               "Sony S-Log3, S-Gamut3.Cine."),
        camera("S-Log3 Venice S-Gamut3",
               ["slog3_venice_sgamut3", "Input - Sony - S-Log3 - Venice S-Gamut3"], "Sony",
               vsg3, "CAT02", s_log3(), "Sony S-Log3, Venice S-Gamut3."),
        camera("S-Log3 Venice S-Gamut3.Cine",
               ["slog3_venice_sgamut3cine", "Input - Sony - S-Log3 - Venice S-Gamut3.Cine",
                "slog3_venice_sgamutcine"], "Sony", vsg3c, "CAT02", s_log3(),
               "Sony S-Log3, Venice S-Gamut3.Cine."),
        utility("Camera Rec.709", ["camera_rec709", "Utility - Rec.709 - Camera",
                                   "rec709_camera"], "Rec.709", REC709_CURVE,
                "ITU-R BT.709 camera OETF, BT.709 primaries, D65 white.",
                family="Utility/ITU"),
    ]


def utility_spaces():
    return [
        utility("Linear P3-D65", ["lin_p3d65", "Utility - Linear - P3-D65"], "P3-D65", None,
                "Linear P3 primaries, D65 white.", working=True, encoding="scene-linear"),
        utility("Linear Rec.2020", ["lin_rec2020", "Utility - Linear - Rec.2020"], "Rec.2020",
                None, "Linear ITU-R BT.2020 primaries, D65 white.", encoding="scene-linear"),
        utility("Linear Rec.709 (sRGB)",
                ["lin_rec709_srgb", "Utility - Linear - Rec.709", "lin_rec709", "lin_srgb",
                 "Utility - Linear - sRGB"], "Rec.709", None,
                "Linear ITU-R BT.709 (sRGB) primaries, D65 white.", working=True,
                encoding="scene-linear"),
        utility("Gamma 1.8 Rec.709 - Texture",
                ["g18_rec709_tx", "Utility - Gamma 1.8 - Rec.709 - Texture", "g18_rec709"],
                "Rec.709", gamma(1.8), "A pure 1.8 power, BT.709 primaries, D65 white."),
        utility("Gamma 2.2 AP1 - Texture", ["g22_ap1_tx", "g22_ap1"], "AP1", gamma(2.2),
                "A pure 2.2 power, AP1 primaries, ACES white."),
        utility("Gamma 2.2 Rec.709 - Texture",
                ["g22_rec709_tx", "Utility - Gamma 2.2 - Rec.709 - Texture", "g22_rec709"],
                "Rec.709", gamma(2.2), "A pure 2.2 power, BT.709 primaries, D65 white."),
        utility("Gamma 2.4 Rec.709 - Texture",
                ["g24_rec709_tx", "g24_rec709", "rec709_display", "Utility - Rec.709 - Display"],
                "Rec.709", gamma(2.4), "A pure 2.4 power, BT.709 primaries, D65 white."),
        utility("sRGB Encoded AP1 - Texture", ["srgb_encoded_ap1_tx", "srgb_ap1"], "AP1",
                SRGB_CURVE, "The sRGB curve, AP1 primaries, ACES white."),
        # "sRGB Encoded Rec.709 (sRGB)" is the name later ACES configs give this space;
        # specconv accepts it too.
        utility("sRGB - Texture",
                ["srgb_tx", "Utility - sRGB - Texture", "srgb_texture",
                 "Input - Generic - sRGB - Texture", "sRGB Encoded Rec.709 (sRGB)"],
                "Rec.709", SRGB_CURVE, "sRGB (IEC 61966-2-1): the sRGB curve, BT.709 "
                "primaries, D65 white.", encoding=None),
        Space("Raw", ["Utility - Raw"], "Utility", None, "Data, not colour: never converted.",
              isdata=True),
    ]


# Named transforms: curves alone, no primaries. (name, aliases, family, encoding,
# direction, transform)
CAMERA_CURVES = [
    ("ARRI LogC3 - Curve (EI800)",
     ["arri_logc3_crv_ei800", "Input - ARRI - Curve - V3 LogC (EI800)", "crv_logc3ei800"],
     "Input/ARRI", "log", "transform", arri_logc3(800)),
    ("ARRI LogC4 - Curve", ["arri_logc4_crv"], "Input/ARRI", "log", "transform",
     arri_logc4()),
    ("BMDFilm Gen5 Log - Curve", ["bmdfilm_gen5_log_crv"], "Input/BlackmagicDesign", "log",
     "transform", bmd_film_gen5()),
    ("DaVinci Intermediate Log - Curve", ["davinci_intermediate_log_crv"],
     "Input/BlackmagicDesign", "log", "transform", davinci_intermediate()),
    ("V-Log - Curve", ["vlog_crv", "Input - Panasonic - Curve - V-Log", "crv_vlog"],
     "Input/Panasonic", "log", "transform", v_log()),
    ("Log3G10 - Curve", ["log3g10_crv", "Input - RED - Curve - REDLog3G10", "crv_rl3g10"],
     "Input/RED", "log", "transform", log3g10()),
    ("S-Log3 - Curve", ["slog3_crv", "Input - Sony - Curve - S-Log3", "crv_slog3"],
     "Input/Sony", "log", "transform", s_log3()),
]
REC1886_CURVE = ("Rec.1886 - Curve", ["rec1886_crv", "Utility - Curve - Rec.1886", "crv_rec1886"],
                 "Utility", "sdr-video", "inverse_transform", gamma(2.4))
REC709_NAMED = ("Rec.709 - Curve", ["rec709_crv", "Utility - Curve - Rec.709", "crv_rec709"],
                "Utility/ITU", "sdr-video", "inverse_transform", REC709_CURVE)
SRGB_NAMED = ("sRGB - Curve", ["srgb_crv", "Utility - Curve - sRGB", "crv_srgb"], "Utility",
              "sdr-video", "inverse_transform", SRGB_CURVE)
ST2084_NAMED = ("ST-2084 - Curve", ["st_2084_crv"], "Utility", "hdr-video",
                "inverse_transform", builtin("CURVE - LINEAR_to_ST-2084"))

# View transforms: (name, OCIO 2.1 built-in from ACES2065-1 to CIE XYZ D65).
OUT = "ACES-OUTPUT - ACES2065-1_to_CIE-XYZ-D65 - "
VIEW_TRANSFORMS = {
    "ACES 1.0 - SDR Video": OUT + "SDR-VIDEO_1.0",
    "ACES 1.0 - SDR Video (D60 sim on D65)": OUT + "SDR-VIDEO-D60sim-D65_1.0",
    "ACES 1.1 - SDR Video (P3 lim)": OUT + "SDR-VIDEO-P3lim_1.1",
    "ACES 1.1 - SDR Video (Rec.709 lim)": OUT + "SDR-VIDEO-REC709lim_1.1",
    "ACES 1.1 - HDR Video (1000 nits & Rec.2020 lim)":
        OUT + "HDR-VIDEO-1000nit-15nit-REC2020lim_1.1",
    "ACES 1.1 - HDR Video (2000 nits & Rec.2020 lim)":
        OUT + "HDR-VIDEO-2000nit-15nit-REC2020lim_1.1",
    "ACES 1.1 - HDR Video (4000 nits & Rec.2020 lim)":
        OUT + "HDR-VIDEO-4000nit-15nit-REC2020lim_1.1",
    "ACES 1.1 - HDR Video (1000 nits & P3 lim)": OUT + "HDR-VIDEO-1000nit-15nit-P3lim_1.1",
    "ACES 1.1 - HDR Video (2000 nits & P3 lim)": OUT + "HDR-VIDEO-2000nit-15nit-P3lim_1.1",
    "ACES 1.1 - HDR Video (4000 nits & P3 lim)": OUT + "HDR-VIDEO-4000nit-15nit-P3lim_1.1",
    "ACES 1.0 - SDR Cinema": OUT + "SDR-CINEMA_1.0",
    "ACES 1.1 - SDR Cinema (D60 sim on D65)": OUT + "SDR-CINEMA-D60sim-D65_1.1",
    "ACES 1.1 - SDR Cinema (Rec.709 lim)": OUT + "SDR-CINEMA-REC709lim_1.1",
    "ACES 1.0 - SDR Cinema (D60 sim on DCI)": OUT + "SDR-CINEMA-D60sim-DCI_1.0",
    "ACES 1.1 - SDR Cinema (D65 sim on DCI)": OUT + "SDR-CINEMA-D65sim-DCI_1.1",
    "ACES 1.1 - HDR Cinema (108 nits & P3 lim)": OUT + "HDR-CINEMA-108nit-7.2nit-P3lim_1.1",
    # Colorimetric, no tone mapping: the link from the scene reference to the display
    # reference, and the route specconv takes to CIE XYZ.
    "Un-tone-mapped": "UTILITY - ACES-AP0_to_CIE-XYZ-D65_BFD",
}

GAMUT_COMPRESSION = ("ACES 1.3 Reference Gamut Compression", "ACES2065-1",
                     "ACES-LMT - ACES 1.3 Reference Gamut Compression")

# Each config: its displays with their views (in order), and its parts.
CG_DISPLAYS = {
    "sRGB - Display": ["ACES 1.0 - SDR Video", "Un-tone-mapped"],
    "Rec.1886 Rec.709 - Display": ["ACES 1.0 - SDR Video", "Un-tone-mapped"],
    "Rec.2100-PQ - Display": ["ACES 1.1 - HDR Video (1000 nits & Rec.2020 lim)",
                              "Un-tone-mapped"],
    "ST2084-P3-D65 - Display": ["ACES 1.1 - HDR Video (1000 nits & P3 lim)", "Un-tone-mapped"],
    "P3-D65 - Display": ["ACES 1.0 - SDR Cinema", "Un-tone-mapped"],
}
STUDIO_DISPLAYS = {
    "sRGB - Display": ["ACES 1.0 - SDR Video", "ACES 1.0 - SDR Video (D60 sim on D65)",
                       "Un-tone-mapped"],
    "Rec.1886 Rec.709 - Display": ["ACES 1.0 - SDR Video",
                                   "ACES 1.0 - SDR Video (D60 sim on D65)", "Un-tone-mapped"],
    "Rec.1886 Rec.2020 - Display": ["ACES 1.0 - SDR Video", "ACES 1.1 - SDR Video (P3 lim)",
                                    "ACES 1.1 - SDR Video (Rec.709 lim)", "Un-tone-mapped"],
    "Rec.2100-HLG - Display": ["ACES 1.1 - HDR Video (1000 nits & Rec.2020 lim)",
                               "Un-tone-mapped"],
    "Rec.2100-PQ - Display": ["ACES 1.1 - HDR Video (1000 nits & Rec.2020 lim)",
                              "ACES 1.1 - HDR Video (2000 nits & Rec.2020 lim)",
                              "ACES 1.1 - HDR Video (4000 nits & Rec.2020 lim)",
                              "Un-tone-mapped"],
    "ST2084-P3-D65 - Display": ["ACES 1.1 - HDR Video (1000 nits & P3 lim)",
                                "ACES 1.1 - HDR Video (2000 nits & P3 lim)",
                                "ACES 1.1 - HDR Video (4000 nits & P3 lim)",
                                "ACES 1.1 - HDR Cinema (108 nits & P3 lim)", "Un-tone-mapped"],
    "P3-D60 - Display": ["ACES 1.0 - SDR Cinema", "Un-tone-mapped"],
    "P3-D65 - Display": ["ACES 1.0 - SDR Cinema", "ACES 1.1 - SDR Cinema (D60 sim on D65)",
                         "ACES 1.1 - SDR Cinema (Rec.709 lim)", "Un-tone-mapped"],
    "P3-DCI - Display": ["ACES 1.0 - SDR Cinema (D60 sim on DCI)",
                         "ACES 1.1 - SDR Cinema (D65 sim on DCI)", "Un-tone-mapped"],
}

CONFIGS = {
    "cg": {
        "name": "specconv-cg-config-v1.0.0_aces-v1.3_ocio-v2.1",
        "what": "ACES CG config v1.0.0 (cg-config-v1.0.0_aces-v1.3_ocio-v2.1)",
        "displays": CG_DISPLAYS,
        "spaces": lambda: ACES_SPACES + utility_spaces(),
        "named": [REC1886_CURVE, SRGB_NAMED],
    },
    "studio": {
        "name": "specconv-studio-config-v1.0.0_aces-v1.3_ocio-v2.1",
        "what": "ACES Studio config v1.0.0 (studio-config-v1.0.0_aces-v1.3_ocio-v2.1)",
        "displays": STUDIO_DISPLAYS,
        "spaces": lambda: ACES_SPACES + ADX_SPACES + camera_spaces() + utility_spaces(),
        "named": CAMERA_CURVES + [REC1886_CURVE, REC709_NAMED, SRGB_NAMED, ST2084_NAMED],
    },
}

# ---------------------------------------------------------------------------------------
# YAML


def quote(s):
    """A flow-style YAML scalar."""
    plain = s and not any(c in s for c in ":,[]{}#&*!|>'\"%@`") and s == s.strip()
    return s if plain else '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


def flow(items):
    return "[" + ", ".join(quote(i) for i in items) + "]"


def transform_lines(key, value):
    if isinstance(value, tuple):  # (group name, steps)
        name, steps = value
        return [f"    {key}: !<GroupTransform>", f"      name: {name}", "      children:"] + [
            f"        - {s}" for s in steps]
    if len(value) == 1:
        return [f"    {key}: {value[0]}"]
    return [f"    {key}: !<GroupTransform>", "      children:"] + [
        f"        - {s}" for s in value]


EMPTY = '""'


def space_yaml(cs):
    lines = ["  - !<ColorSpace>", f"    name: {cs.name}", f"    aliases: {flow(cs.aliases)}",
             f"    family: {quote(cs.family) if cs.family else EMPTY}",
             '    equalitygroup: ""', "    bitdepth: 32f",
             f"    description: {quote(cs.description)}",
             f"    isdata: {'true' if cs.isdata else 'false'}"]
    if cs.categories:
        lines.append(f"    categories: {flow(cs.categories)}")
    if cs.encoding:
        lines.append(f"    encoding: {cs.encoding}")
    lines.append("    allocation: uniform")
    ref = "display" if cs.display else "scene"
    if cs.to_ref:
        lines += transform_lines(f"to_{ref}_reference", cs.to_ref)
    if cs.from_ref:
        lines += transform_lines(f"from_{ref}_reference", cs.from_ref)
    return "\n".join(lines)


def named_yaml(entry):
    name, aliases, family, encoding, key, transform = entry
    return "\n".join([
        "  - !<NamedTransform>", f"    name: {name}", f"    aliases: {flow(aliases)}",
        f"    family: {family}", "    categories: [file-io]", f"    encoding: {encoding}",
        f"    {key}: {transform}"])


def config_yaml(kind):
    c = CONFIGS[kind]
    displays = c["displays"]
    views = [v for v in VIEW_TRANSFORMS if any(v in vs for vs in displays.values())]
    out = [f"""# specconv's built-in {kind.upper()} config for OpenColorIO 2.1, after the Academy's
# {c['what']}.
# Generated by scripts/make_configs.py from published primaries, curves and OCIO's
# built-in transforms; do not edit by hand.
ocio_profile_version: 2.1

environment:
  {{}}
search_path: ""
strictparsing: true
luma: [0.2126, 0.7152, 0.0722]
name: {c['name']}
description: specconv's {kind} config, after the Academy's {c['what']}

roles:
  aces_interchange: ACES2065-1
  cie_xyz_d65_interchange: CIE-XYZ-D65
  color_picking: sRGB - Texture
  color_timing: ACEScct
  compositing_log: ACEScct
  data: Raw
  matte_paint: sRGB - Texture
  scene_linear: ACEScg
  texture_paint: ACEScct

file_rules:
  - !<Rule> {{name: Default, colorspace: ACES2065-1}}

shared_views:"""]
    for v in views:
        out.append(f"  - !<View> {{name: {v}, view_transform: {v}, "
                   "display_colorspace: <USE_DISPLAY_NAME>}")
    out.append("\ndisplays:")
    for d, vs in displays.items():
        out += [f"  {d}:", "    - !<View> {name: Raw, colorspace: Raw}",
                f"    - !<Views> [{', '.join(vs)}]"]
    # Display colour spaces stay active (the official files list them as inactive) so
    # that `specconv colorspaces` shows them; they are valid --colorspace values.
    out += ["", f"active_displays: [{', '.join(displays)}]",
            f"active_views: [{', '.join(views + ['Raw'])}]",
            "inactive_colorspaces: []", "", "looks:"]
    name, process, style = GAMUT_COMPRESSION
    out += ["  - !<Look>", f"    name: {name}", f"    process_space: {process}",
            "    description: Compresses scene values from common cameras into the AP1 gamut.",
            f"    transform: {builtin(style)}", "", "default_view_transform: Un-tone-mapped",
            "", "view_transforms:"]
    for v in views:
        out += ["  - !<ViewTransform>", f"    name: {v}",
                f"    from_scene_reference: {builtin(VIEW_TRANSFORMS[v])}", ""]
    out.append("display_colorspaces:")
    for cs in [CIE_XYZ] + [DISPLAYS[d] for d in displays]:
        out += [space_yaml(cs), ""]
    out.append("colorspaces:")
    for cs in c["spaces"]():
        out += [space_yaml(cs), ""]
    out.append("named_transforms:")
    for entry in c["named"]:
        out += [named_yaml(entry), ""]
    return "\n".join(out).rstrip() + "\n"


def main():
    if len(sys.argv) != 2 or sys.argv[1] not in CONFIGS:
        sys.exit(f"usage: {sys.argv[0]} {'|'.join(CONFIGS)} > CONFIG.ocio")
    sys.stdout.write(config_yaml(sys.argv[1]))


if __name__ == "__main__":
    main()
