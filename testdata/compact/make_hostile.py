"""Writes testdata/compact/hostile/: header texts of the compact layout (docs/compact.md, "The
header text") that every decoder (the library, numpy, the C header) reads the same way, and
verdicts.txt, a line a case: `NAME accept VALUES` (VALUES: values/VALUES.txt, the bands and
each texel's spectrum) or `NAME refuse`. Run from the repository root:

    python3 testdata/compact/make_hostile.py
"""

import os

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "hostile")

# A model of three bands and two leaves, small enough to decode by hand: the leaf below
# x = 0.3 gives (X, Y, Z), the one above (Z, Y, X) + λ_dark·0.25.
MAP0 = "map 0 1 0 0 0 1 0 0 0 1 0 0 0"
MAP1 = "map 1 0 0 1 0 1 0 1 0 0 0.25 0.25 0.25"
BASE = [
    "specconv compact 2",
    "model tiny",
    "hash 0123456789abcdef",
    "grid 400 600 100",
    "wavelengths 400 500 600",
    "white 0.3127 0.329",
    "dark 0.01",
    "blend 0",
    "clip 1",
    "rgb 0.4124 0.3576 0.1805 0.2126 0.7152 0.0722 0.0193 0.1192 0.9505",
    "node 0 split x 0.3 1 2 0",
    "node 1 leaf 0",
    "node 2 leaf 1",
    MAP0,
    MAP1,
    "b X 0.1 0.2 0.3",
    "b Y 0 0 0",
    "b Z 0 0 0",
]

# Texels and their spectra by the rule, by hand: below the split, above it, dark (λ = 0.5),
# with u, clipped, NaN, black (the white point's leaf, λ = 0), infinite u.
TEXELS = [
    ("0.2 0.5 0.3 0 0 0", "0.2 0.5 0.3", "0.2 0.5 0.3"),
    ("0.5 0.25 0.25 0 0 0", "0.5 0.5 0.75", "0.5 0.5 0.75"),
    ("0.002 0.001 0.002 0 0 0", "0.127 0.126 0.127", "0.127 0.126 0.127"),
    ("0.2 0.5 0.3 1 0 0", "0.3 0.7 0.6", "0.2 0.5 0.3"),
    ("0.9 0.05 0.05 0 0 0", "0.3 0.3 1", "0.3 0.3 1.15"),
    ("nan 0.5 0.3 0 0 0", "nan nan nan", "nan nan nan"),
    ("0 0 0 0 0 0", "0 0 0", "0 0 0"),
    ("0.2 0.5 0.3 inf 0 0", "nan nan nan", "0.2 0.5 0.3"),
]


def text(lines, end="\n"):
    return end.join(lines) + end


def edit(old, new):
    """BASE with the line starting `old` replaced by `new` (a list: several lines, or none)."""
    out, done = [], False
    for line in BASE:
        if not done and line.startswith(old):
            out += new if isinstance(new, list) else [new]
            done = True
        else:
            out.append(line)
    assert done, old
    return text(out)


def chain(depth):
    """BASE's model as a chain of `depth` splits at x = 0.3 (values apart, so no reader
    merges them): below each, a leaf of map 0's spectra; at the end, map 1's."""
    lines = BASE[:10]
    for i in range(depth):
        above = i + 1 if i + 1 < depth else 2 * depth
        lines.append(f"node {i} split x {0.3 - i * 1e-9!r} {depth + i} {above} 0")
    for j in range(depth + 1):
        lines.append(f"node {depth + j} leaf {j}")
        body = (MAP1 if j == depth else MAP0).split(" ", 2)[2]
        lines.append(f"map {j} {body}")
    return text(lines + BASE[-3:])


ACCEPT = {
    "base": (text(BASE), "base"),
    "crlf": (text(BASE, "\r\n"), "base"),
    "no-final-newline": (text(BASE)[:-1], "base"),
    "blank-lines": (text(BASE).replace("\nclip", "\n\n\nclip"), "base"),
    "unknown-keyword": (text(BASE + ["future_line 1 2  anything\u00e9"]), "base"),
    "lines-in-any-order": (text(BASE[:1] + list(reversed(BASE[1:]))), "base"),
    "model-free-text": (edit("model", "model  Caf\u00e9 \u2603  two  spaces "), "base"),
    "number-forms": (edit("map 0", "map 0 1. 0 0 0 1E0 0 .0 0 +1 0 -0 0.0e+5"), "base"),
    "dark-1e-2": (edit("dark", "dark 1e-2"), "base"),
    "leading-zeros": (edit("node 0", "node 0 split x 0.3 01 002 0"), "base"),
    "blend-width": (
        text([l.replace("blend 0", "blend 0.02").replace(" 1 2 0", " 1 2 0.02") for l in BASE]),
        "base",
    ),
    "clip0": (edit("clip", "clip 0"), "clip0"),
    "chain-64": (chain(64), "base"),
}

REFUSE = {
    "empty": "",
    "version-1": text(["specconv compact 1"] + [l for l in BASE[1:] if not l.startswith("rgb")]),
    "version-1-with-rgb": text(["specconv compact 1"] + BASE[1:]),
    "version-3": text(["specconv compact 3"] + BASE[1:]),
    "no-rgb": edit("rgb", []),
    "rgb-short": edit("rgb", "rgb 1 0 0 0 1 0 0 0"),
    "rgb-long": edit("rgb", "rgb 1 0 0 0 1 0 0 0 1 0"),
    "rgb-nan": edit("rgb", "rgb 1 0 0 0 nan 0 0 0 1"),
    "duplicate-rgb": text(BASE + ["rgb 1 0 0 0 1 0 0 0 1"]),
    "space-before-version": " " + text(BASE),
    "grid-against-wavelengths": edit("grid", "grid 480 830 10"),
    "wavelengths-off-grid": edit("wavelengths", "wavelengths 400 500 600.0000001"),
    "wavelengths-fewer": edit("wavelengths", "wavelengths 400 500"),
    "grid-not-whole-steps": edit("grid", "grid 400 600 90"),
    "grid-backwards": edit("grid", "grid 600 400 -100"),
    "no-wavelengths": edit("wavelengths", []),
    "no-grid": edit("grid", []),
    "no-model": edit("model", []),
    "no-hash": edit("hash", []),
    "no-white": edit("white", []),
    "no-dark": edit("dark", []),
    "no-blend": edit("blend", []),
    "no-clip": edit("clip", []),
    "no-b-z": edit("b Z", []),
    "no-nodes": text([l for l in BASE if not l.startswith("node")]),
    "no-maps": text([l for l in BASE if not l.startswith("map")]),
    "hash-short": edit("hash", "hash 0123"),
    "hash-upper": edit("hash", "hash 0123456789ABCDEF"),
    "tab-dark": edit("dark", "\tdark 0.01"),
    "tab-separated": edit("dark", "dark\t0.01"),
    "leading-space": edit("dark", " dark 0.01"),
    "space-only-line": text(BASE).replace("\nclip", "\n \nclip"),
    "double-space": edit("white", "white 0.3127  0.329"),
    "trailing-space": edit("clip", "clip 1 "),
    "cr-inside": edit("clip", "clip 1\r\r"),
    "nul-in-model": edit("model", "model ti\x00ny"),
    "uppercase-keyword": edit("dark", "Dark 0.01"),
    "tab-in-unknown-line": text(BASE + ["future_line\tx"]),
    "map-nan": edit("map 1", "map 1 NaN 0 1 0 1 0 1 0 0 0.25 0.25 0.25"),
    "map-inf": edit("map 1", "map 1 inf 0 1 0 1 0 1 0 0 0.25 0.25 0.25"),
    "map-overflow": edit("map 1", "map 1 1e999 0 1 0 1 0 1 0 0 0.25 0.25 0.25"),
    "map-hex": edit("map 1", "map 1 0x0p0 0 1 0 1 0 1 0 0 0.25 0.25 0.25"),
    "map-underscore": edit("map 1", "map 1 0_0 0 1 0 1 0 1 0 0 0.25 0.25 0.25"),
    "map-arabic-digit": edit("map 1", "map 1 \u0660 0 1 0 1 0 1 0 0 0.25 0.25 0.25"),
    "map-short": edit("map 1", "map 1 0 0 1 0 1 0 1 0 0 0.25 0.25"),
    "map-long": edit("map 1", "map 1 0 0 1 0 1 0 1 0 0 0.25 0.25 0.25 0"),
    "map-twice": edit("map 1", ["map 0 0 0 1 0 1 0 1 0 0 0.25 0.25 0.25"]),
    "map-index-signed": edit("map 1", "map +1 0 0 1 0 1 0 1 0 0 0.25 0.25 0.25"),
    "map-index-huge": edit("map 1", "map 18446744073709551617 0 0 1 0 1 0 1 0 0 0.25 0.25 0.25"),
    "white-inf": edit("white", "white inf 0.329"),
    "white-one-number": edit("white", "white 0.3127"),
    "dark-other": edit("dark", "dark 0.02"),
    "dark-nan": edit("dark", "dark nan"),
    "blend-negative": edit("blend", "blend -0.01"),
    "blend-too-wide": edit("blend", "blend 0.6"),
    "blend-two-numbers": edit("blend", "blend 0 0"),
    "blend-0-width-not-0": edit("node 0", "node 0 split x 0.3 1 2 0.02"),
    "width-below-blend": text(
        [l.replace("blend 0", "blend 0.02").replace(" 1 2 0", " 1 2 0.01") for l in BASE]
    ),
    "clip-2": edit("clip", "clip 2"),
    "clip-1.0": edit("clip", "clip 1.0"),
    "clip-two-fields": edit("clip", "clip 1 1"),
    "clip-empty": edit("clip", "clip"),
    "duplicate-dark": text(BASE + ["dark 0.01"]),
    "duplicate-white": text(BASE + ["white 0.3127 0.329"]),
    "duplicate-model": text(BASE + ["model tiny"]),
    "duplicate-grid": text(BASE + ["grid 400 600 100"]),
    "duplicate-wavelengths": text(BASE + ["wavelengths 400 500 600"]),
    "duplicate-b-x": text(BASE + ["b X 0.1 0.2 0.3"]),
    "duplicate-node": text(BASE + ["node 2 leaf 1"]),
    "b-w": edit("b Z", "b W 0 0 0"),
    "b-short": edit("b Y", "b Y 0 0"),
    "cycle": edit("node 0", "node 0 split x 0.3 0 2 0"),
    "shared-child": text(BASE[:10] + ["node 0 split x 0.3 1 1 0", "node 1 leaf 0", "node 2 leaf 1"] + BASE[13:]),
    "unreached-node": text(BASE + ["node 3 leaf 0"]),
    "leaf-map-missing": edit("node 2", "node 2 leaf 2"),
    "leaf-map-twice": edit("node 2", "node 2 leaf 0"),
    "child-missing": edit("node 0", "node 0 split x 0.3 1 3 0"),
    "axis-z": edit("node 0", "node 0 split z 0.3 1 2 0"),
    "split-value-nan": edit("node 0", "node 0 split x nan 1 2 0"),
    "node-kind-other": edit("node 2", "node 2 leaves 1"),
    "chain-65": chain(65),
}


def main():
    os.makedirs(os.path.join(HERE, "values"), exist_ok=True)
    for name in os.listdir(HERE):
        if name.endswith(".txt") and name != "verdicts.txt":
            os.remove(os.path.join(HERE, name))
    verdicts = []
    for name, (t, values) in ACCEPT.items():
        verdicts.append(f"{name} accept {values}")
        with open(os.path.join(HERE, name + ".txt"), "w", encoding="utf-8", newline="") as f:
            f.write(t)
    for name, t in REFUSE.items():
        verdicts.append(f"{name} refuse")
        with open(os.path.join(HERE, name + ".txt"), "w", encoding="utf-8", newline="") as f:
            f.write(t)
    with open(os.path.join(HERE, "verdicts.txt"), "w") as f:
        f.write("\n".join(verdicts) + "\n")
    for k, values in enumerate(["base", "clip0"]):
        lines = ["bands 400 500 600"] + [f"{t} = {r[k]}" for t, *r in TEXELS]
        with open(os.path.join(HERE, "values", values + ".txt"), "w") as f:
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
