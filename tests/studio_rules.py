"""Writes the files of a typical asset into OUTDIR with oiiotool, and prints, as JSON, what
tools outside specconv make of each under the studio config CONFIG (tests/it/studio.rs):

- PyOpenColorIO's `Config.getColorSpaceFromFilepath` (the colour space OCIO's file rules give
  the path) and `filepathOnlyMatchesDefaultRule` (whether only the Default rule matched);
- OpenImageIO's `oiio:ColorSpace` for the file as read (what oiiotool's --colorconvert and
  maketx take the file to be; OpenImageIO 2.4 consults no file rule);
- the PNG colour chunks, read from the bytes.

The PNGs are written as oiiotool writes any PNG it read from an sRGB file (`sRGB`, `gAMA`
45455, Rec.709 `cHRM`), data maps included; one more has its `gAMA` replaced by 1/1.8, a real
disagreement with its `sRGB` chunk.

    python3 tests/studio_rules.py OUTDIR CONFIG
"""
import json
import os
import struct
import subprocess
import sys
import zlib

import OpenImageIO as oiio
import PyOpenColorIO as ocio

out_dir, config_path = sys.argv[1], sys.argv[2]

AP1 = "0.713,0.293,0.165,0.830,0.128,0.044,0.32168,0.33767"
REC2020 = "0.708,0.292,0.170,0.797,0.131,0.046,0.3127,0.3290"

# name, channels, pixel type, value, extra oiiotool arguments.
FILES = [
    ("rock_normal.png", 3, "uint8", "0.5,0.5,1.0", ["--attrib", "oiio:ColorSpace", "sRGB"]),
    ("rock_mask.png", 1, "uint8", "0.7", ["--attrib", "oiio:ColorSpace", "sRGB"]),
    ("rock_ao.png", 3, "uint8", "0.8,0.8,0.8", ["--attrib", "oiio:ColorSpace", "sRGB"]),
    ("rock_albedo.png", 3, "uint8", "0.6,0.4,0.2", ["--attrib", "oiio:ColorSpace", "sRGB"]),
    ("rock_roughness.png", 1, "uint8", "0.4", ["--attrib", "oiio:ColorSpace", "sRGB"]),
    ("rock_rough.exr", 1, "half", "0.4", []),
    ("rock_spec_ap1.exr", 1, "half", "0.4", ["--attrib:type=float[8]", "chromaticities", AP1]),
    ("fog_acescg.exr", 1, "half", "0.4", []),
    ("wall_acescg.exr", 3, "half", "0.3,0.2,0.1", []),
    ("tiles_acescg.exr", 3, "half", "0.3,0.2,0.1", ["--attrib:type=float[8]", "chromaticities", REC2020]),
    ("plate_ap1.exr", 3, "half", "0.3,0.2,0.1", ["--attrib:type=float[8]", "chromaticities", AP1]),
    ("plate.exr", 3, "half", "0.3,0.2,0.1", []),
]


def chunks(path):
    """The PNG chunks before IDAT, as (kind, data)."""
    data = open(path, "rb").read()
    i, out = 8, []
    while i < len(data):
        (n,) = struct.unpack(">I", data[i : i + 4])
        kind = data[i + 4 : i + 8]
        if kind == b"IDAT":
            break
        out.append((kind.decode(), data[i + 8 : i + 8 + n]))
        i += 12 + n
    return out


def with_gama(src, dst, gamma):
    """`src` with its gAMA chunk's value replaced (a valid CRC written)."""
    data = bytearray(open(src, "rb").read())
    at = data.find(b"gAMA")
    body = b"gAMA" + struct.pack(">I", gamma)
    data[at : at + 8] = body
    data[at + 8 : at + 12] = struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
    open(dst, "wb").write(bytes(data))


def png_colour(path):
    out = {}
    for kind, body in chunks(path):
        if kind == "sRGB":
            out["sRGB"] = True
        elif kind == "gAMA":
            out["gAMA"] = struct.unpack(">I", body)[0]
        elif kind == "cHRM":
            out["cHRM"] = list(struct.unpack(">8I", body))
    return out


config = ocio.Config.CreateFromFile(config_path)
report = []
paths = []
for name, channels, fmt, value, extra in FILES:
    path = os.path.join(out_dir, name)
    subprocess.run(
        ["oiiotool", "--pattern", "constant:color=" + value, "8x8", str(channels), "-d", fmt]
        + extra
        + ["-o", path],
        check=True,
    )
    paths.append(path)
disagreeing = os.path.join(out_dir, "gamma18_albedo.png")
with_gama(os.path.join(out_dir, "rock_albedo.png"), disagreeing, 55556)
paths.append(disagreeing)

for path in paths:
    spec = oiio.ImageInput.open(path).spec()
    entry = {
        "file": path,
        "name": os.path.basename(path),
        # (name, rule index) in PyOpenColorIO 2.1.
        "ocio": config.getColorSpaceFromFilepath(path)[0],
        "ocio_only_default": config.filepathOnlyMatchesDefaultRule(path),
        "oiio_colorspace": spec.get_string_attribute("oiio:ColorSpace"),
        "channels": spec.nchannels,
    }
    if path.endswith(".png"):
        entry["png"] = png_colour(path)
    report.append(entry)
print(json.dumps(report))
