#!/usr/bin/python3
"""The hostile round of issue 45, black box: attacks on the classes of that issue, run against a
built `specconv`, each judged by what a careless or hostile user must be able to rely on (no
input replaced, no forged provenance shown, no crash or temporary left, metadata bounded and
valid UTF-8, ...), never by the wording of a message.

    /usr/bin/python3 scripts/hostile_round.py [--bin target/release/specconv] [--only CLASS]

Class 15 (`asset`, issue 57) builds its stages with the interpreter of SPECCONV_USD_PYTHON
(usd-core and MaterialX), as CI sets it. Prints one line per failed case and a table of cases and failures per class; exits 1 when any
case failed. Needs ../shared/spectra, oiiotool and Debian's OpenImageIO Python bindings
(/usr/bin/python3). Each command runs with a 4 GiB address-space limit, so a command that would
take the machine's memory fails (as a signal) instead.
"""

import argparse
import hashlib
import os
import re
import resource
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import zlib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "spectra"
IMAGES = ROOT / "testdata" / "images"
MEMORY_LIMIT = 4 << 30
# The built-in model `open`'s sets, as ../shared/spectra names them.
OPEN_SETS = [
    "usgs_splib07a_vegetation_380-780_5nm.csv",
    "usgs_splib07a_manmade_380-780_5nm.csv",
    "usgs_splib07a_soils_380-780_5nm.csv",
    "usgs_splib07a_minerals_380-780_5nm.csv",
    "rhododendron_leaves_380-780_5nm.csv",
    "nist_cqs90_vs_380-780_5nm.csv",
    "colour_pmc_400-700_5nm.csv",
    "hyppigments_405-780_5nm.csv",
]


# Cases whose fix has not landed, each with its issue: run and reported, not failed on.
KNOWN_OPEN: tuple = ()


class Round:
    def __init__(self, binary, work):
        self.bin = str(binary)
        self.work = Path(work)
        self.results = {}
        self.open = []

    def run(self, *args, cwd=None, timeout=600):
        def limit():
            resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))

        started = time.monotonic()
        p = subprocess.run(
            [self.bin, *map(str, args)],
            cwd=cwd or self.work,
            capture_output=True,
            timeout=timeout,
            preexec_fn=limit,
        )
        p.seconds = time.monotonic() - started
        p.text = (p.stdout + p.stderr).decode("utf-8", "replace")
        return p

    def case(self, cls, name, failure):
        """Records a case of class `cls`: `failure` is None when it held, else why not. A case
        of KNOWN_OPEN is counted apart: said when it fails, and when it starts to hold."""
        if f"{cls}: {name}".endswith(KNOWN_OPEN):
            self.open.append((f"[{cls}] {name}", failure))
            return
        passed, failed = self.results.get(cls, (0, 0))
        if failure is None:
            self.results[cls] = (passed + 1, failed)
        else:
            self.results[cls] = (passed, failed + 1)
            print(f"FAIL [{cls}] {name}: {failure}")

    def fresh(self, name):
        d = self.work / name
        shutil.rmtree(d, ignore_errors=True)
        d.mkdir(parents=True)
        return d


def digest(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def crashed(p):
    """Why a finished command counts as a crash (a signal, a panic), else None."""
    if p.returncode < 0 or p.returncode >= 128:
        return f"killed or aborted (status {p.returncode})"
    if "panicked" in p.text or "RUST_BACKTRACE" in p.text:
        return "panicked: " + p.text[-300:]
    return None


def leftovers(folder, keep=()):
    """Files in `folder` that look like a writer's temporaries."""
    names = []
    for f in Path(folder).rglob("*"):
        if f.is_file() and f.name not in keep and (".tmp" in f.name or f.name.startswith(".")):
            names.append(f.name)
    return names


# ---- PNG writing (text chunks the way a hostile or foreign tool writes them) -------------------


def png(path, width=16, height=16, channels=3, chunks=()):
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    colour = {1: 0, 3: 2, 4: 6}[channels]
    rows = b"".join(
        b"\0" + bytes((x * 13 + y * 7 + c * 50) % 256 for x in range(width) for c in range(channels))
        for y in range(height)
    )
    out = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour, 0, 0, 0))
    for kind, data in chunks:
        out += chunk(kind, data)
    out += chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")
    Path(path).write_bytes(out)


def text(keyword, value_latin1):
    return (b"tEXt", keyword.encode("latin-1") + b"\0" + value_latin1)


def ztext(keyword, value_latin1):
    return (b"zTXt", keyword.encode("latin-1") + b"\0\0" + zlib.compress(value_latin1))


def itext(keyword, value):
    return (b"iTXt", keyword.encode("latin-1") + b"\0\0\0\0\0" + value.encode("utf-8"))


def attributes(path):
    """The header attributes of `path` as OpenImageIO's Python bindings read them."""
    script = (
        "import sys, json, OpenImageIO as o\n"
        "i = o.ImageInput.open(sys.argv[1]); s = i.spec()\n"
        "print(json.dumps({a.name: str(a.value) for a in s.extra_attribs}))\n"
    )
    p = subprocess.run(["/usr/bin/python3", "-c", script, str(path)], capture_output=True)
    if p.returncode != 0:
        return None
    import json

    return json.loads(p.stdout.decode("utf-8", "surrogateescape"))


# ---- 1. --force never replaces a file the same command reads ----------------------------------


def spellings(folder, name):
    """Ways to name folder/name from inside folder: as given, ./, absolute, a symbolic link, a
    hard link, `..`."""
    target = Path(folder) / name
    link = Path(folder) / ("link_" + name)
    hard = Path(folder) / ("hard_" + name)
    if not link.exists():
        link.symlink_to(target.name)
    if not hard.exists():
        os.link(target, hard)
    return {
        "plain": name,
        "dot": "./" + name,
        "absolute": str(target.resolve()),
        "symlink": link.name,
        "hardlink": hard.name,
        "dotdot": f"../{Path(folder).name}/{name}",
    }


def force_never_replaces_an_input(r):
    d = r.fresh("force")
    # A set whose file name ends in .json, so that a model output may name it.
    shutil.copy(SHARED / "colorchecker_n_ohta_380-780_5nm.csv", d / "cc.json")
    small = ["--clusters", "2", "--min-cluster-size", "4", "--hold-ends"]
    p = r.run("train", "--spectra", "cc.json", *small, "--commercial", "yes", "-o", "m.json", cwd=d)
    if p.returncode != 0:
        r.case("1 force", "setup train", p.text[-300:])
        return
    shutil.copy(d / "m.json", d / "m0.json")
    targets = {
        "spectra": ["train", "--spectra", "cc.json", *small, "--force", "-o"],
        "with model": ["train", "--with", "m.json", "--with-data", ".", "--force", "-o"],
        "recorded set": ["train", "--with", "m.json", "--with-data", ".", "--force", "-o"],
    }
    for what, command in targets.items():
        name = "cc.json" if what != "with model" else "m.json"
        control = r.run(*command, "control.json", cwd=d)
        r.case("1 force", f"{what}: the same command to a new file works",
               None if control.returncode == 0 else control.text[-300:])
        for spelling, path in spellings(d, name).items():
            shutil.copy(SHARED / "colorchecker_n_ohta_380-780_5nm.csv", d / "cc.json")
            shutil.copy(d / "m0.json", d / "m.json")
            before = digest(d / name)
            p = r.run(*command, path, cwd=d)
            failure = crashed(p)
            if failure is None and digest(d / name) != before:
                failure = f"replaced the {what} it read (exit {p.returncode})"
            elif failure is None and p.returncode == 0:
                failure = "exit 0 though the output is an input"
            r.case("1 force", f"train -o {what} as {spelling}", failure)
    # The conversion's own rule, the same attack.
    shutil.copy(IMAGES / "float_scanline.exr", d / "in.exr")
    for spelling, path in spellings(d, "in.exr").items():
        before = digest(d / "in.exr")
        p = r.run("convert", "in.exr", path, "--force", cwd=d)
        failure = crashed(p)
        if failure is None and digest(d / "in.exr") != before:
            failure = "replaced its input"
        r.case("1 force", f"convert -o input as {spelling}", failure)


# ---- 2. recorded sets are verified, not trusted by name -------------------------------------


def recorded_sets_are_verified(r):
    d = r.fresh("sets")
    good = d / "good"
    good.mkdir()
    for name in OPEN_SETS:
        shutil.copy(SHARED / name, good / name)
    p = r.run("train", "--with", "open", "--with-data", "good", "-o", "ok.json", cwd=d)
    r.case("2 sets", "the true sets are taken", None if p.returncode == 0 else p.text[-300:])
    munsell = (SHARED / "munsell1269_matte_380-800_1nm.csv").read_bytes()
    for i, name in enumerate(OPEN_SETS):
        for how in ("other spectra", "one value changed"):
            fake = d / f"fake{i}_{how.split()[0]}"
            shutil.copytree(good, fake)
            if how == "other spectra":
                (fake / name).write_bytes(munsell)
            else:
                lines = (fake / name).read_text().splitlines()
                cells = lines[5].split(",")
                cells[3] = str(float(cells[3]) * 0.5)
                lines[5] = ",".join(cells)
                (fake / name).write_text("\n".join(lines) + "\n")
            out = fake.name + ".json"
            p = r.run("train", "--with", "open", "--with-data", fake.name, "-o", out, cwd=d)
            failure = crashed(p)
            if failure is None and p.returncode == 0:
                failure = "a set whose content differs was taken under its recorded name and terms"
            r.case("2 sets", f"{name}: {how}", failure)


# ---- 3. provenance cannot be forged on screen ------------------------------------------------

SEPARATORS = ["\n", "\r", "\r\n", "\x0b", "\x0c", "\x1b[2K\r", "\u2028", "\u2029", "\x85", "\x00"]


def provenance_is_shown_as_written(r):
    d = r.fresh("forged")
    shutil.copy(SHARED / "colorchecker_n_ohta_380-780_5nm.csv", d / "cc.csv")
    for i, sep in enumerate(SEPARATORS):
        forged = f"ours{sep}specconvSource: FORGED.png{sep}commercial use: yes"
        model = f"m{i}.json"
        try:
            p = r.run(
                "train", "--spectra", "cc.csv", "--clusters", "2", "--min-cluster-size", "4",
                "--hold-ends", "--commercial", "no", "--licence", forged, "-o", model, cwd=d,
            )
        except ValueError:  # a NUL cannot be an argument at all
            r.case("3 forged", f"licence with {sep!r}", None)
            continue
        if p.returncode != 0:
            # Refused at the door: nothing forged can be shown.
            r.case("3 forged", f"licence with {sep!r} (refused)", crashed(p))
            continue
        out = f"o{i}.exr"
        c = r.run("convert", "--model", model, IMAGES / "srgb8.png", out, cwd=d)
        shown = {"models": r.run("models", model, cwd=d).text}
        if c.returncode == 0:
            shown["info"] = r.run("info", out, cwd=d).text
        for printer, output in shown.items():
            lines = output.replace("\r\n", "\n").split("\n")
            bad = [l for l in lines if "FORGED" in l and "ours" not in l]
            bad += [l for l in lines if "\r" in l or "\x1b" in l or "\u2028" in l or "\x0b" in l]
            failure = f"{len(bad)} forged line(s): {bad[:2]!r}" if bad else None
            r.case("3 forged", f"{printer} of a licence with {sep!r}", failure)
    # Input attributes that imitate provenance.
    src = d / "src.exr"
    imitations = ["specconvSource", "specconvCommercialUse", "SpecconvSource", "SPECCONVSOURCE",
                  "specconv:Source", "specconvModel", "specconvSettings", "specconvLicence"]
    args = ["oiiotool", IMAGES / "float_scanline.exr"]
    for name in imitations:
        args += ["--attrib", name, "FORGED"]
    subprocess.run([*map(str, args), "-o", str(src)], check=True)
    p = r.run("convert", "src.exr", "out.exr", cwd=d)
    if p.returncode != 0:
        r.case("3 forged", "input attributes imitating provenance", "refused: " + p.text[-200:])
        return
    attrs = attributes(d / "out.exr") or {}
    for name in imitations:
        forged = [k for k, v in attrs.items() if k.lower() == name.lower() and "FORGED" in v]
        r.case("3 forged", f"input attribute {name}", f"carried as {forged}" if forged else None)


# ---- 4–6. metadata carried from inputs --------------------------------------------------------


def metadata_is_bounded(r):
    d = r.fresh("bounds")
    for count, size in [(300, 64 << 10), (2000, 1 << 10), (1, 16 << 20), (40, 1 << 20), (5000, 16)]:
        name = f"z{count}x{size}.png"
        chunks = [ztext(f"Note{i}", os.urandom(size // 2).hex().encode()[:size]) for i in range(count)]
        png(d / name, chunks=chunks)
        out = d / f"out_{count}_{size}"
        out.mkdir()
        p = r.run("convert", name, "-o", out.name, cwd=d)
        failure = crashed(p) or (None if p.returncode == 0 else "refused: " + p.text[-200:])
        outputs = list(out.glob("*.exr"))
        if failure is None and outputs:
            header = outputs[0].stat().st_size
            if header > 4 << 20:
                failure = f"output of {header >> 20} MB for a 16x16 texture"
        if failure is None and leftovers(out):
            failure = f"temporaries left: {leftovers(out)}"
        r.case("4 bounds", f"{count} zTXt of {size} B", failure)


def metadata_is_utf8(r):
    d = r.fresh("utf8")
    cases = {
        "iTXt UTF-8": (itext("Artist", "山田 太郎 — Café ☃"), "山田 太郎 — Café ☃"),
        "tEXt Latin-1": (text("Artist", "Café crème".encode("latin-1")), "Café crème"),
        "zTXt Latin-1": (ztext("Copyright", "© Ünïcødé".encode("latin-1")), "© Ünïcødé"),
        "tEXt ASCII": (text("Artist", b"plain"), "plain"),
        "iTXt invalid UTF-8": ((b"iTXt", b"Artist\0\0\0\0\0\xff\xfe bad"), None),
    }
    for what, (chunk, expected) in cases.items():
        name = what.replace(" ", "_").replace("-", "") + ".png"
        png(d / name, chunks=[chunk])
        p = r.run("convert", name, name + ".exr", cwd=d)
        failure = crashed(p) or (None if p.returncode == 0 else "refused: " + p.text[-200:])
        if failure is None:
            raw = (d / (name + ".exr")).read_bytes()
            attrs = attributes(d / (name + ".exr")) or {}
            key = "Copyright" if "zTXt" in what else "Artist"
            value = attrs.get(key)
            if expected is not None and value is not None and value != expected:
                failure = f"{key} came out as {value!r}"
            elif expected is None and value is not None and "\udcff" in value:
                failure = "invalid UTF-8 carried"
            elif b"\xff\xfe bad" in raw:
                failure = "invalid UTF-8 bytes in the output header"
        r.case("5 utf-8", what, failure)


EXR_NAMES = [
    "channels", "compression", "dataWindow", "displayWindow", "lineOrder", "pixelAspectRatio",
    "screenWindowCenter", "screenWindowWidth", "tiles", "view", "type", "name", "version",
    "chunkCount", "maxSamplesPerPixel", "multiView", "envmap", "deepImageState", "chromaticities",
    "whiteLuminance", "adoptedNeutral", "wrapmodes", "owner", "comments", "capDate",
    "utcOffset", "longitude", "latitude", "altitude", "focus", "expTime", "aperture",
    "isoSpeed", "keyCode", "timeCode", "framesPerSecond", "worldToCamera", "worldToNDC",
]


def metadata_that_cannot_be_carried_is_dropped(r):
    d = r.fresh("names")
    for name in EXR_NAMES:
        src = f"{name}.png"
        png(d / src, chunks=[text(name, b"hostile value 1 2 3")])
        p = r.run("convert", src, src + ".exr", cwd=d)
        failure = crashed(p) or (None if p.returncode == 0 else "input refused: " + p.text[-200:])
        if failure is None:
            check = subprocess.run(["exrheader", str(d / (src + ".exr"))], capture_output=True)
            if check.returncode != 0:
                failure = "exrheader cannot read the output"
        r.case("6 names", f"tEXt {name}", failure)
    for name in ["studio:名前", "studio:assetId", "名前", "a b c", "x" * 300]:
        src = d / "named.exr"
        subprocess.run(["oiiotool", str(IMAGES / "float_scanline.exr"), "--attrib", name,
                        "value", "-o", str(src)], check=True, capture_output=True)
        p = r.run("convert", "named.exr", "named_out.exr", "--force", cwd=d)
        failure = crashed(p) or (None if p.returncode == 0 else "input refused: " + p.text[-200:])
        r.case("6 names", f"EXR attribute {name[:20]!r}", failure)


# ---- 7–10. compact files ----------------------------------------------------------------------


def compact_header(r, d):
    p = r.run("convert", "--layout", "compact", IMAGES / "srgb8.png", "c.exr", cwd=d)
    if p.returncode != 0:
        return None
    return attributes(d / "c.exr")["specconvCompact"]


def with_header(d, text, out):
    """d/c.exr with its compact header text replaced (through OpenImageIO, level 0 only)."""
    script = (
        "import sys, OpenImageIO as o\n"
        "b = o.ImageBuf(sys.argv[1])\n"
        "b.specmod().attribute('specconvCompact', sys.stdin.read())\n"
        "b.write(sys.argv[2])\n"
    )
    subprocess.run(["/usr/bin/python3", "-c", script, str(d / "c.exr"), str(d / out)],
                   input=text.encode(), check=True, capture_output=True)


def chain(text, depth):
    """`text` made a valid header of two bands whose tree is a chain of `depth` splits, each
    with a leaf (and a map) of its own below it."""
    keep = [l for l in text.split("\n") if l.split(" ")[0] in
            ("specconv", "model", "hash", "rgb", "white", "dark", "blend", "clip")]
    lines = keep + ["grid 380 390 10", "wavelengths 380 390"]
    for i in range(depth):
        lines.append(f"node {2 * i} split x 0.3 {2 * i + 1} {2 * i + 2} 0.02")
        lines.append(f"node {2 * i + 1} leaf {i}")
    lines.append(f"node {2 * depth} leaf {depth}")
    lines += [f"map {k} 0.1 0.1 0.1 0.1 0.1 0.1 0.2 0.2" for k in range(depth + 1)]
    lines += ["b X 0.5 0.5", "b Y 0.5 0.5", "b Z 0.5 0.5"]
    return "\n".join(lines)


def compact_files_are_read_safely(r):
    d = r.fresh("compact")
    text = compact_header(r, d)
    if text is None:
        r.case("7 depth", "setup", "convert --layout compact failed")
        return
    for depth in [100, 40_000, 200_000]:
        with_header(d, chain(text, depth), f"deep{depth}.exr")
        out = d / f"deep{depth}"
        out.mkdir()
        p = r.run("expand", f"deep{depth}.exr", out / "x.exr", cwd=d)
        failure = crashed(p)
        if failure is None and leftovers(out):
            failure = f"temporaries left: {leftovers(out)}"
        if failure is None and depth > 64 and p.returncode == 0:
            failure = f"a tree {depth} deep was accepted (the C header refuses past 64)"
        r.case("7 depth", f"chain {depth} deep", failure)
    lines = text.split("\n")
    grid = next(l for l in lines if l.startswith("grid "))
    variants = {
        "grid against wavelengths": text.replace(grid, "grid 480 830 10"),
        "tab before dark": text.replace("\ndark ", "\n\tdark "),
        "map NaN": text.replace("\nmap 3 ", "\nmap 3 NaN "),
        "duplicate line": text.replace("\nclip 1", "\nclip 1\nclip 1"),
        "clip 2": text.replace("\nclip 1", "\nclip 2"),
        "cycle": text.replace("node 4 leaf 0", "node 4 split x 0.5 0 0 0.02"),
        "missing leaf": text.replace("node 14 leaf 7", "node 14 leaf 99"),
        "empty": "",
        "version 9": text.replace("specconv compact 2", "specconv compact 9"),
        "wavelengths decreasing": text.replace("wavelengths 380 390", "wavelengths 390 380"),
        "map number 1e999": text.replace("\nmap 2 ", "\nmap 2 1e999 ", 1),
        "map number inf": text.replace("\nmap 1 ", "\nmap 1 inf ", 1),
        "node index huge": text.replace("node 14 leaf 7", "node 99999999999 leaf 7"),
        "map index huge": text.replace("\nmap 7 ", "\nmap 99999999999 "),
        "node reached twice": text.replace("node 0 split y", "node 0 split y").replace(
            "node 2 split x", "node 2 split x", 1).replace(" 7 8 0.02", " 7 7 0.02", 1),
        "b row repeated": text.replace("\nb Y ", "\nb X "),
        "blend negative": text.replace("\nblend ", "\nblend -"),
        "dark zero": "\n".join("dark 0" if l.startswith("dark ") else l for l in lines),
        "split axis z": text.replace("split y", "split z", 1),
    }
    for line in lines:
        word = line.split(" ")[0]
        if word in ("model", "hash", "grid", "wavelengths", "white", "dark", "blend", "clip", "b"):
            variants[f"line {word} repeated" if word != "b" else f"row {line[:3]} repeated"] = (
                text.replace(line, line + "\n" + line, 1))
            variants[f"line {word} missing" if word != "b" else f"row {line[:3]} missing"] = (
                text.replace(line + "\n", "", 1))
    for what, hostile in variants.items():
        with_header(d, hostile, "h.exr")
        p = r.run("expand", "h.exr", "h_out.exr", "--force", cwd=d)
        failure = crashed(p)
        # A tab or a missing line the grammar may define either way (the decoders' conformance
        # tests hold them to one verdict); anything else here is malformed.
        lenient = what == "tab before dark" or what.endswith("missing")
        if failure is None and p.returncode == 0 and not lenient:
            failure = "accepted"
        r.case("9 grammar", what, failure)


def expand_applies_the_nan_rule(r):
    d = r.fresh("nan")
    if compact_header(r, d) is None:
        r.case("10 nan", "setup", "convert --layout compact failed")
        return
    for what in ["nan", "inf", "-inf"]:
        script = (
            "import sys, OpenImageIO as o\n"
            "b = o.ImageBuf(sys.argv[1]); b.read(0, 0, True)\n"
            f"b.setpixel(5, 3, [float('{what}'), 0.1, 0.1, 0, 0, 0])\n"
            f"b.setpixel(0, 0, [0.1, 0.1, 0.1, float('{what}'), 0, 0])\n"
            "b.write(sys.argv[2])\n"
        )
        subprocess.run(["/usr/bin/python3", "-c", script, str(d / "c.exr"),
                        str(d / f"{what}.exr")], check=True, capture_output=True)
        out = f"{what}_out.exr"
        p = r.run("expand", f"{what}.exr", out, cwd=d)
        failure = crashed(p)
        if failure is None and p.returncode == 0:
            stats = subprocess.run(["oiiotool", "-a", "--stats", str(d / out)],
                                   capture_output=True, text=True).stdout
            if "NanCount" in stats and any(
                "NanCount" in l and any(c not in "0 " for c in l.split(":")[1])
                for l in stats.splitlines()
            ):
                failure = "NaN spectra written though the file says nan=refuse"
        r.case("10 nan", f"texel {what}", failure)


# ---- 8. memory estimated up front --------------------------------------------------------------


def wide_bands(text, bands):
    """`text`'s model lines with a one-leaf tree on `bands` bands from 400 nm every 0.01 nm."""
    keep = [l for l in text.split("\n") if l.split(" ")[0] in
            ("specconv", "model", "hash", "rgb", "white", "dark", "blend", "clip")]
    w = [400 + i * 0.01 for i in range(bands)]
    lines = keep + [f"grid 400 {w[-1]!r} 0.01", "wavelengths " + " ".join(map(repr, w)),
                    "node 0 leaf 0", "map 0 " + " ".join(["0.3"] * bands + ["0"] * (3 * bands))]
    lines += [f"b {c} " + " ".join(["0.1"] * bands) for c in "XYZ"]
    return "\n".join(lines)


def memory_is_estimated(r):
    """Work past the memory at hand: refused with the figure (exit 1, no crash, nothing left)."""
    d = r.fresh("memory")
    png(d / "wide.png", width=8192, height=64)
    png(d / "narrow.png", width=1024, height=64)
    out = d / "out"
    out.mkdir()

    def judge(what, p):
        failure = crashed(p)
        if failure is None and p.returncode == 0:
            failure = "exit 0: the work fitted under the limit, or was not refused"
        if failure is None and "MiB" not in p.text:
            failure = "no figure in the error: " + p.text[-200:]
        if failure is None and leftovers(out):
            failure = f"temporaries left: {leftovers(out)}"
        r.case("8 memory", what, failure)

    for extra in [[], ["--mip", "0"], ["--tile", "8", "8"], ["--tile", "64", "1"],
                  ["-d", "float", "--mip", "0"], ["-j", "1"]]:
        p = r.run("convert", "--bands", "400:700:0.01", *extra, "wide.png", out / "w.exr", cwd=d)
        judge(f"convert --bands 400:700:0.01 {' '.join(extra)} on 8192x64", p)
    p = r.run("convert", "--bands", "380:730:0.05", "wide.png", out / "w.exr", cwd=d)
    judge("convert --bands 380:730:0.05 on 8192x64", p)
    p = r.run("convert", "--layout", "compact", "narrow.png", "c.exr", cwd=d)
    if p.returncode != 0:
        r.case("8 memory", "setup", "convert --layout compact failed")
        return
    text = attributes(d / "c.exr")["specconvCompact"]
    for bands in [30_001, 20_001]:
        with_header(d, wide_bands(text, bands), f"bands{bands}.exr")
        p = r.run("expand", f"bands{bands}.exr", out / "x.exr", cwd=d)
        judge(f"expand of a {bands}-band header on 1024x64 texels", p)


# ---- 11, 13, 15. files from newer tools, what a TD expects -------------------------------------


def interop_ids_are_read(r):
    d = r.fresh("interop")
    (d / "out").mkdir()
    for ident, role in [("data", "data"), ("lin_rec709_scene", "colour"), ("lin_ap1_scene", "colour"),
                        ("lin_ap0_scene", "colour"), ("srgb_rec709_scene", "colour")]:
        src = d / f"{ident}.exr"
        subprocess.run(["oiiotool", str(IMAGES / "float_scanline.exr"), "--attrib",
                        "colorInteropID", ident, "-o", str(src)], check=True, capture_output=True)
        p = r.run("info", src.name, cwd=d)
        failure = crashed(p) or (None if p.returncode == 0 else p.text[-200:])
        chosen = next((l for l in p.text.splitlines() if l.startswith("chosen by:")), "")
        roles = next((l for l in p.text.splitlines() if l.startswith("role:")), "")
        if failure is None and "colorInteropID" not in chosen:
            failure = f"colorInteropID not the evidence ({chosen.strip()})"
        elif failure is None and role not in roles:
            failure = f"read as {roles.strip()}"
        r.case("11 interop", f"colorInteropID {ident}", failure)
        # An output never carries the input's ID: it is true of the input's pixels only.
        c = r.run("convert", "--data", "copy", src.name, "-o", "out", cwd=d)
        made = sorted((d / "out").glob(f"{ident}*"))
        failure = crashed(c) or (None if c.returncode == 0 and made else c.text[-200:])
        if failure is None:
            said = (attributes(made[0]) or {}).get("colorInteropID")
            if said not in (None, "data") or (said == "data") != (role == "data"):
                failure = f"the output says colorInteropID {said!r}"
        r.case("11 interop", f"the output of a colorInteropID {ident} input", failure)


def a_td_is_told(r):
    d = r.fresh("td")
    png(d / "grey.png", channels=1)
    (d / "out").mkdir()
    p = r.run("convert", "grey.png", "-o", "out", cwd=d)
    failure = crashed(p)
    skipped = not list((d / "out").glob("*"))
    # Named, and with the option that converts it, a colour space included.
    remedy = re.search(r"--colorspace ('[^']+'|\S+)", p.text)
    if failure is None and skipped and ("grey.png" not in p.text or not remedy):
        failure = "a skipped grey map is not named with how to convert it: " + p.text[-200:]
    elif failure is None and skipped:
        name = remedy.group(1).strip("'")
        again = r.run("convert", "--colorspace", name, "grey.png", "grey.exr", cwd=d)
        if again.returncode != 0:
            failure = f"the option it names does not convert it: {again.text[-200:]}"
    r.case("13 grey", "one-channel sRGB PNG", failure)
    # maketx's own spellings (OpenImageIO 2.4's maketx --help; it has no --tilesize).
    for flags in (["--nomipmap"], ["--tile", "32", "32"], ["--noresize"],
                  ["--colorconfig", ACES_CG], ["--fixnan", "none"]):
        p = r.run("convert", *flags, IMAGES / "srgb8.png", "m.exr", "--force", cwd=d)
        r.case("15 maketx", " ".join(map(str, flags)), crashed(p) or (None if p.returncode == 0 else p.text[-200:]))
    if r.run("convert", "--layout", "compact", IMAGES / "srgb8.png", "c.exr", cwd=d).returncode == 0:
        for command in (["info", "c.exr"], ["to-rgb", "c.exr", "rgb.exr"],
                        ["preview", "c.exr", "-o", "c.png"]):
            args = command
            p = r.run(*args, cwd=d)
            failure = crashed(p)
            if failure is None and "compact" not in p.text:
                failure = "does not recognise the compact file"
            elif failure is None and p.returncode != 0 and "expand" not in p.text:
                failure = "refuses without pointing to expand"
            r.case("15 compact", command[0], failure)


# ---- 12, 14. configs that decide differently; data copies ----------------------------------

ACES_CG = ROOT.parent / "shared" / "ocio" / "cg-config-v1.0.0_aces-v1.3_ocio-v2.1.ocio"


def line(output, label):
    return next((l for l in output.splitlines() if l.startswith(label)), "").strip()


def built_in_and_file_configs_agree_or_say_so(r):
    d = r.fresh("configs")
    sources = {
        "no attribute": [],
        "oiio:ColorSpace ACEScg": ["--attrib", "oiio:ColorSpace", "ACEScg"],
        "oiio:ColorSpace lin_srgb": ["--attrib", "oiio:ColorSpace", "lin_srgb"],
        "oiio:ColorSpace Linear": ["--attrib", "oiio:ColorSpace", "Linear"],
        "oiio:ColorSpace sRGB": ["--attrib", "oiio:ColorSpace", "sRGB"],
        "oiio:ColorSpace scene_linear": ["--attrib", "oiio:ColorSpace", "scene_linear"],
        "colorInteropID lin_ap1_scene": ["--attrib", "colorInteropID", "lin_ap1_scene"],
        "oiio:ColorSpace Raw": ["--attrib", "oiio:ColorSpace", "Raw"],
    }
    for what, attrib in sources.items():
        src = d / (what.replace(" ", "_").replace(":", "_") + ".exr")
        subprocess.run(["oiiotool", str(IMAGES / "float_scanline.exr"), *attrib, "-o", str(src)],
                       check=True, capture_output=True)
        built_in = r.run("--ocio", "aces", "info", src.name, cwd=d)
        from_file = r.run("--ocio", ACES_CG, "info", src.name, cwd=d)
        failure = crashed(built_in) or crashed(from_file)
        a, b = line(built_in.text, "colour space:"), line(from_file.text, "colour space:")
        if failure is None and a != b and "built" not in from_file.text.lower():
            failure = f"the built-in config says {a!r}, the same config as a file {b!r}, unsaid"
        r.case("12 configs", what, failure)


def data_copies_are_data(r):
    d = r.fresh("datacopy")
    png(d / "rough.png", channels=1)
    png(d / "mask.png", channels=3)
    for src, flags in [("rough.png", []), ("mask.png", ["--colorspace", "Raw"])]:
        out = d / ("out_" + src.split(".")[0])
        out.mkdir()
        what = src + " " + " ".join(flags)
        p = r.run("convert", "--data", "copy", *flags, src, "-o", out.name, cwd=d)
        failure = crashed(p) or (None if p.returncode == 0 else p.text[-200:])
        written = sorted(out.glob("*")) if out.exists() else []
        if failure is None and not written:
            failure = "nothing written with --data copy"
        if failure is None:
            info = r.run("info", written[0], cwd=d).text
            if "data" not in line(info, "role:"):
                failure = f"info shows it as {line(info, 'role:')!r}"
        r.case("14 data copies", what + ": its role", failure)
        named = [f.name for f in written if f.name.endswith("_spectral.exr")]
        r.case("14 data copies", what + ": its name",
               f"a data copy named as a spectral file: {named}" if named else None)


# ---- issue 57: `specconv asset` on hostile or careless assets ------------------------------


def usd_python():
    """The interpreter with usd-core and MaterialX that `asset` runs (SPECCONV_USD_PYTHON, as
    CI sets it), else None."""
    python = os.environ.get("SPECCONV_USD_PYTHON") or os.environ.get("SPECCONV_PYTHON")
    if not python:
        return None
    ok = subprocess.run([python, "-c", "import pxr.Usd, MaterialX"], capture_output=True)
    return python if ok.returncode == 0 else None


ASSET_TEXTURES = ["rock_albedo", "rock_arm", "rock_normal", "clean_albedo", "dirty_albedo",
                  "never", "shared", "wood.1001", "wood.1002", "brick_color", "brick_arm",
                  "brick_normal", "brick_height"]


def asset_setup(python, d, builder, kind):
    """The tests' textures (oiiotool checkers) and the stage or document `kind` of
    tests/asset_stages.py or tests/asset_mtlx.py (`builder`) in `d`."""
    (d / "tex").mkdir(exist_ok=True)
    for k, name in enumerate(ASSET_TEXTURES):
        subprocess.run(["oiiotool", "--pattern", "checker", "8x8", str(3 + k % 2), "-d",
                        "uint8", "-o", str(d / "tex" / f"{name}.png")], check=True)
    subprocess.run([python, str(ROOT / "tests" / builder), kind, str(d)], check=True,
                   capture_output=True)


def digests(folder):
    """Every file under `folder` with its digest."""
    return {str(f.relative_to(folder)): digest(f) for f in Path(folder).rglob("*")
            if f.is_file()}


def one_line(p):
    """Why a failed run's error is not one line without a traceback, else None."""
    errors = [l for l in p.stderr.decode("utf-8", "replace").splitlines()
              if l.startswith("specconv: error")]
    if "Traceback" in p.text:
        return "a traceback: " + p.text[-200:]
    if len(errors) != 1:
        return f"{len(errors)} error lines: {p.text[-300:]}"
    return None


def assets_are_converted_safely(r):
    python = usd_python()
    if python is None:
        r.case("15 asset", "setup", "no interpreter with usd-core and MaterialX "
                                     "(SPECCONV_USD_PYTHON)")
        return
    os.environ.setdefault("SPECCONV_USD_PYTHON", python)  # for the `asset` runs
    cls = "15 asset"

    # Item 1: an override copy in DIR that no asset run wrote is never replaced.
    d = r.fresh("asset-theirs")
    asset_setup(python, d, "asset_mtlx.py", "brick")
    (d / "out").mkdir()
    (d / "out" / "brick_spectral.mtlx").write_text("<!-- mine -->")
    for flags in [[], ["-u"], ["--force"]]:
        before = digests(d)
        p = r.run("asset", "brick.mtlx", "-o", "out", *flags, cwd=d)
        failure = crashed(p)
        if failure is None and digests(d) != before:
            failure = "a file changed: " + ", ".join(
                k for k in before if digests(d).get(k) != before[k])
        r.case(cls, f"a copy it did not write {' '.join(flags) or '(no flag)'}", failure)

    # Item 2: a stage that sublayers the layer `-o .` would write.
    d = r.fresh("asset-sublayer")
    asset_setup(python, d, "asset_stages.py", "self_sublayer")
    for flags in [[], ["-u"], ["--force"]]:
        before = digests(d)
        p = r.run("asset", "self_sublayer.usda", "-o", ".", *flags, cwd=d)
        failure = crashed(p)
        if failure is None and p.returncode == 0:
            failure = "accepted: it would write over a layer the stage reads"
        if failure is None and digests(d) != before:
            failure = "a file changed or was written"
        r.case(cls, f"its own sublayer {' '.join(flags) or '(no flag)'}", failure)

    # Item 3: a usdz's copy-out never replaces a user's file of the same name.
    d = r.fresh("asset-usdz-user")
    asset_setup(python, d, "asset_stages.py", "package")
    mine = d / "out" / "packed_usdz" / "tex" / "rock_albedo.png"
    mine.parent.mkdir(parents=True)
    mine.write_bytes(b"mine")
    for flags in [[], ["-u"], ["--force"]]:
        p = r.run("asset", "packed.usdz", "-o", "out", *flags, cwd=d)
        failure = crashed(p) or (None if mine.read_bytes() == b"mine" else "replaced")
        r.case(cls, f"a user's file where a usdz member goes {' '.join(flags) or '(no flag)'}",
               failure)

    # Item 4: usdz members `escape.png` and `../escape.png` are two files.
    d = r.fresh("asset-usdz-escape")
    asset_setup(python, d, "asset_stages.py", "escape_package")
    p = r.run("asset", "escape.usdz", "-o", "out", cwd=d)
    failure = crashed(p) or (None if p.returncode == 0 else p.text[-200:])
    copies = sorted(digest(f) for f in (d / "out").rglob("escape.png"))
    want = sorted(digest(d / "tex" / f"{n}.png") for n in ("rock_albedo", "rock_normal"))
    if failure is None and copies != want:
        failure = f"{len(copies)} copies, not the two members' bytes"
    inside = all(f.resolve().is_relative_to((d / "out").resolve())
                 for f in (d / "out").rglob("*"))
    r.case(cls, "two usdz members that differ by ..", failure or (
        None if inside else "a file outside DIR"))

    # Item 5: a normal map past the walk's limit is never uplifted as colour.
    d = r.fresh("asset-deep")
    asset_setup(python, d, "asset_stages.py", "deep")
    p = r.run("asset", "deep.usda", "-o", "out", cwd=d)
    failure = crashed(p)
    if failure is None and (d / "out" / "tex" / "rock_normal_spectral.exr").exists():
        failure = "the normal map was uplifted as colour"
    if failure is None and p.returncode == 0:
        failure = "exit 0 with a texture undecided"
    r.case(cls, "a walk past its limit", failure)

    # Item 6: a UDIM pattern read as colour and a tile of it as a normal map.
    d = r.fresh("asset-udim")
    asset_setup(python, d, "asset_stages.py", "udim_conflict")
    p = r.run("asset", "udim_conflict.usda", "-o", "out", cwd=d)
    failure = crashed(p)
    tiles = list((d / "out").rglob("wood*.exr"))
    if failure is None and (p.returncode == 0 or tiles):
        failure = f"exit {p.returncode}, {len(tiles)} tile(s) written"
    r.case(cls, "a tile read as colour and as data", failure)

    # Item 11: outputs whose names meet are told apart, the same on a second run.
    d = r.fresh("asset-stems")
    (d / "tex").mkdir()
    for name, pattern in [("a.png", "4"), ("a.tif", "2"), ("a_png.png", "3")]:
        subprocess.run(["oiiotool", "--pattern", "checker", "8x8", pattern, "-d", "uint8",
                        "-o", str(d / "tex" / name)], check=True)
    subprocess.run([python, str(ROOT / "tests" / "asset_stages.py"), "stem_clash", str(d)],
                   check=True, capture_output=True)
    p = r.run("asset", "stem_clash.usda", "-o", "out", cwd=d)
    failure = crashed(p) or (None if p.returncode == 0 else p.text[-200:])
    made = sorted(f.name for f in (d / "out").rglob("*.exr"))
    if failure is None and len(made) != 3:
        failure = f"{len(made)} outputs for three textures: {made}"
    again = r.run("asset", "stem_clash.usda", "-o", "out", "-u", cwd=d)
    if failure is None and sorted(f.name for f in (d / "out").rglob("*.exr")) != made:
        failure = "other names on a second run"
    r.case(cls, "a.png, a.tif and a_png.png", failure or crashed(again))

    # Item 12: what the readers raise is one line, never a traceback.
    d = r.fresh("asset-raise")
    (d / "tex").mkdir()
    latin = (b'#usda 1.0\ndef Shader "T"\n{\n    uniform token info:id = "UsdUVTexture"\n'
             b'    asset inputs:file = @./tex/caf\xe9.png@\n}\n')
    (d / "latin.usda").write_bytes(latin)
    p = r.run("asset", "latin.usda", "-o", "out", cwd=d)
    r.case(cls, "a Latin-1 byte in a path", crashed(p) or (
        "exit 0" if p.returncode == 0 else one_line(p)))
    for bad in ["/bin/false", "/bin/true"]:
        p = subprocess.run([r.bin, "asset", "latin.usda", "-o", "out2"], cwd=d,
                           capture_output=True, env={**os.environ, "SPECCONV_USD_PYTHON": bad})
        p.text = (p.stdout + p.stderr).decode("utf-8", "replace")
        r.case(cls, f"SPECCONV_USD_PYTHON={bad}", crashed(p) or (
            "exit 0" if p.returncode == 0 else one_line(p)))

    # Issue 56, item 2: Arnold's and RenderMan's readers, file inputs authored carelessly: a
    # number, a string path out of the folder, a PxrMultiTexture naming one file twice.
    d = r.fresh("asset-readers")
    (d / "tex").mkdir()
    subprocess.run(["oiiotool", "--pattern", "checker", "8x8", "4", "-d", "uint8", "-o",
                    str(d / "tex" / "a.png")], check=True)

    def reader_stage(name, reader, inputs, out):
        lines = ["#usda 1.0", 'def Material "M" {',
                 "    token outputs:ri:surface.connect = </M/S.outputs:out>",
                 '    def Shader "S" {', '        uniform token info:id = "PxrSurface"',
                 "        color3f inputs:diffuseColor.connect = </M/T.outputs:%s>" % out,
                 "        token outputs:out", "    }", '    def Shader "T" {',
                 '        uniform token info:id = "%s"' % reader]
        lines += ["        " + i for i in inputs] + ["        color3f outputs:%s" % out,
                                                    "    }", "}",
                                                    'def Mesh "G" (prepend apiSchemas = '
                                                    '["MaterialBindingAPI"]) {',
                                                    "    rel material:binding = </M>", "}"]
        (d / name).write_text("\n".join(lines) + "\n")

    reader_stage("int.usda", "PxrTexture", ["int inputs:filename = 3"], "resultRGB")
    p = r.run("asset", "int.usda", "-o", "out", cwd=d)
    r.case(cls, "a PxrTexture filename that is a number", crashed(p) or (
        "exit 0" if p.returncode == 0 else one_line(p)))
    reader_stage("up.usda", "arnold:image",
                 ['string inputs:filename = "../../../../../../../../../../etc/hostname"'], "out")
    p = r.run("asset", "up.usda", "-o", "out", cwd=d)
    outside = [f for f in d.rglob("*spectral*") if d / "out" not in f.parents] + \
        [f for f in Path("/etc").glob("hostname*spectral*")]
    r.case(cls, "an arnold:image string filename out of the folder", crashed(p) or (
        "wrote outside DIR: %s" % outside if outside else None))
    reader_stage("twice.usda", "PxrMultiTexture",
                 ["asset inputs:filename0 = @./tex/a.png@", "asset inputs:filename1 = @./tex/a.png@"],
                 "resultRGB")
    p = r.run("asset", "twice.usda", "-o", "out", cwd=d)
    r.case(cls, "a PxrMultiTexture naming one file twice", crashed(p) or (
        None if p.returncode == 0 and (d / "out" / "tex" / "a_spectral.exr").is_file()
        else "not converted once: " + p.text[-300:]))

    # Item 13: modules in the working directory are never imported by the reader.
    d = r.fresh("asset-stray")
    asset_setup(python, d, "asset_stages.py", "mixed")
    mark = d / "imported"
    for module in ["json", "pxr", "MaterialX"]:
        (d / f"{module}.py").write_text(f"open({str(mark)!r}, 'a').write('{module}')\n")
    p = r.run("asset", "mixed.usda", "-o", "out", "--dry-run", cwd=d)
    r.case(cls, "a stray pxr.py in the working directory", crashed(p) or (
        f"imported: {mark.read_text()}" if mark.exists() else None))

    # Item 7 and 14: a compact file's text with a NUL; a compact file given to convert.
    d = r.fresh("asset-compact")
    p = r.run("convert", "--layout", "compact", IMAGES / "srgb8.png", "c.exr", cwd=d)
    data = bytearray((d / "c.exr").read_bytes())
    key = b"specconvCompact\0string\0"
    at = data.index(key) + len(key)
    size = struct.unpack("<i", bytes(data[at:at + 4]))[0]
    data[at + 4 + size - 1] = 0
    (d / "nul.exr").write_bytes(bytes(data))
    p = r.run("expand", "nul.exr", "x.exr", cwd=d)
    failure = crashed(p) or ("accepted" if p.returncode == 0 else None)
    r.case(cls, "a NUL in a compact text", failure or (
        "wrote x.exr" if (d / "x.exr").exists() else None))
    p = r.run("convert", "c.exr", "again.exr", cwd=d)
    r.case(cls, "a compact file given to convert", crashed(p) or (
        "uplifted again" if p.returncode == 0 else None))


CLASSES = {
    "force": force_never_replaces_an_input,
    "sets": recorded_sets_are_verified,
    "forged": provenance_is_shown_as_written,
    "bounds": metadata_is_bounded,
    "utf8": metadata_is_utf8,
    "names": metadata_that_cannot_be_carried_is_dropped,
    "compact": compact_files_are_read_safely,
    "nan": expand_applies_the_nan_rule,
    "memory": memory_is_estimated,
    "interop": interop_ids_are_read,
    "td": a_td_is_told,
    "configs": built_in_and_file_configs_agree_or_say_so,
    "data": data_copies_are_data,
    "asset": assets_are_converted_safely,
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bin", default=ROOT / "target" / "release" / "specconv")
    parser.add_argument("--only", action="append", choices=sorted(CLASSES))
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="hostile-") as work:
        r = Round(Path(args.bin).resolve(), work)
        for name, attack in CLASSES.items():
            if not args.only or name in args.only:
                attack(r)
    total = failed = 0
    print(f"\n{'class':<14}{'cases':>7}{'failed':>8}")
    for cls, (ok, bad) in sorted(r.results.items(), key=lambda kv: int(kv[0].split()[0])):
        print(f"{cls:<14}{ok + bad:>7}{bad:>8}")
        total, failed = total + ok + bad, failed + bad
    print(f"{'all':<14}{total:>7}{failed:>8}")
    for case, failure in r.open:
        state = "still fails: " + failure if failure else "now holds: take it out of KNOWN_OPEN"
        print(f"known open {case}: {state}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
