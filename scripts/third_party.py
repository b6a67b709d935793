#!/usr/bin/env python3
"""Writes THIRD-PARTY.md (python/THIRD-PARTY.md links to it, so the Python wheel carries it in
its .dist-info/licenses/): the licences of every third-party crate in Cargo.lock with their full
texts, the system libraries linked at run time, and the terms of the training data.

    python3 scripts/third_party.py           # regenerate it
    python3 scripts/third_party.py --check   # exit 1 when it is not what the script would write

Reads each crate's Cargo.toml and licence files from cargo's registry cache ($CARGO_HOME, else
~/.cargo, registry/src/*/NAME-VERSION/); runs `cargo fetch --locked` first when some are missing
(that downloads, it builds nothing). Python 3.11 standard library only.
"""
import argparse
import glob
import os
import pathlib
import re
import subprocess
import sys
import tomllib

ROOT = pathlib.Path(__file__).resolve().parent.parent
# python/THIRD-PARTY.md is a link to it: maturin packs only files under python/.
OUTPUTS = [ROOT / "THIRD-PARTY.md"]
DATA_NOTICES = ROOT / "crates" / "spectral" / "notices"
SPECTRA_README = ROOT.parent / "shared" / "spectra" / "README.md"

# A crate's licence files: regular files at its root whose names start so (any case).
LICENCE_FILE = re.compile(r"^(licen[cs]e|copying|notice|unlicense)", re.IGNORECASE)

# System libraries specconv links or opens at run time; the wheel carries none of them (it
# carries libspecconv_oiio.so, specconv's own shim, which links the system's OpenImageIO).
RUNTIME_LIBRARIES = [
    ("OpenImageIO", "libopenimageio2.4",
     "BSD-3-Clause for its code (Debian's copyright file calls it \"BSD-Modified\"), some files "
     "under Apache-2.0 and other terms: see Debian's copyright file",
     "reads every image, through libspecconv_oiio.so (specconv's shim, which the wheel "
     "carries and which links the system's OpenImageIO)"),
    ("OpenColorIO", "libopencolorio2.1", "BSD-3-Clause",
     "colour management (`--ocio`, `rgb_to_xyz`)"),
    ("Little CMS", "liblcms2-2", "MIT",
     "ICC profiles; linked from the system where pkg-config finds it (the build's Debian "
     "packages include liblcms2-dev), else the crate lcms2-sys compiles in its bundled copy, "
     "whose MIT licence is that crate's `vendor/LICENSE`"),
]

def fail(message, status=2):
    print(f"third_party.py: {message}", file=sys.stderr)
    sys.exit(status)


def version_key(version):
    """Sorts 0.10.1 after 0.9.5: numbers as numbers, the rest as text."""
    return [(0, int(part), "") if part.isdigit() else (1, 0, part)
            for part in re.split(r"[.+-]", version)]


def third_party_packages():
    """(name, version) of every Cargo.lock package from a registry, sorted."""
    lock = tomllib.loads((ROOT / "Cargo.lock").read_text(encoding="utf-8"))
    packages = []
    for package in lock.get("package", []):
        name, version, source = package["name"], package["version"], package.get("source")
        if source is None or name.startswith("specconv"):
            continue  # the workspace's own and path crates
        if not source.startswith(("registry+", "sparse+")):
            fail(f"{name} {version} comes from {source}: only registry crates are handled")
        packages.append((name, version))
    return sorted(set(packages), key=lambda p: (p[0], version_key(p[1])))


def registry_dirs():
    cargo_home = pathlib.Path(os.environ.get("CARGO_HOME") or pathlib.Path.home() / ".cargo")
    return sorted(pathlib.Path(p) for p in glob.glob(str(cargo_home / "registry" / "src" / "*")))


def source_dir(name, version, registries):
    for registry in registries:
        candidate = registry / f"{name}-{version}"
        if (candidate / "Cargo.toml").is_file():
            return candidate
    return None


def find_sources(packages):
    """{(name, version): folder}; fetches with cargo once when some are missing."""
    def lookup():
        registries = registry_dirs()
        return {p: source_dir(*p, registries) for p in packages}

    found = lookup()
    missing = [p for p, d in found.items() if d is None]
    if missing:
        print(f"third_party.py: {len(missing)} crate sources missing "
              f"(e.g. {missing[0][0]} {missing[0][1]}): running cargo fetch --locked",
              file=sys.stderr)
        try:
            subprocess.run(["cargo", "fetch", "--locked", "--manifest-path",
                            str(ROOT / "Cargo.toml")], check=True)
        except (OSError, subprocess.CalledProcessError) as e:
            fail(f"cargo fetch --locked failed ({e}); the crates' sources are needed")
        found = lookup()
        missing = [p for p, d in found.items() if d is None]
        if missing:
            fail("no source for " + ", ".join(f"{n} {v}" for n, v in missing)
                 + " under $CARGO_HOME/registry/src even after cargo fetch")
    return found


def read_text(path):
    """A licence text as printed: line endings made \\n, trailing whitespace at the end trimmed."""
    data = path.read_bytes()
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    return text.replace("\r\n", "\n").replace("\r", "\n").rstrip()


def crate_licences(folder):
    """(declared licence expression or None, [(file name, text)])."""
    manifest = tomllib.loads((folder / "Cargo.toml").read_text(encoding="utf-8"))
    package = manifest.get("package", {})
    expression = package.get("license")
    names = sorted(p.name for p in folder.iterdir()
                   if p.is_file() and LICENCE_FILE.match(p.name))
    licence_file = package.get("license-file")
    if licence_file and (folder / licence_file).is_file() and licence_file not in names:
        names.append(licence_file)
    if expression is None:
        expression = f"(none declared; license-file = {licence_file})" if licence_file \
            else "(none declared)"
    return expression, [(name, read_text(folder / name)) for name in names]


def fence(text):
    """A code fence longer than any run of backticks in the text."""
    longest = max((len(m) for m in re.findall(r"`+", text)), default=0)
    return "`" * max(3, longest + 1)


def verbatim(text):
    f = fence(text)
    return f"{f}text\n{text}\n{f}\n"


def data_sets():
    """The sets ../shared/spectra/README.md lists, each with its origin and terms as that README
    states them (its table's first and last cells): one source for the data's terms."""
    if not SPECTRA_README.is_file():
        fail(f"{SPECTRA_README} not found: the data sets' terms are read from it "
             "(../shared beside the checkout)")
    rows = []
    for line in SPECTRA_README.read_text(encoding="utf-8").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) >= 2 and re.fullmatch(r"[\w.+-]+\.csv", cells[0]):
            rows.append((cells[0], cells[-1]))
    if not rows:
        fail(f"{SPECTRA_README} lists no data sets in its table")
    return rows


def render():
    packages = third_party_packages()
    sources = find_sources(packages)
    
    crates = []  # (name, version, expression, [(file, text)])
    for name, version in packages:
        expression, files = crate_licences(sources[(name, version)])
        crates.append((name, version, expression, files))

    # Identical texts once: {text: [(name, version, file)]}, numbered by their first user.
    users = {}
    for name, version, _, files in crates:
        for file, text in files:
            users.setdefault(text, []).append((name, version, file))
    groups = sorted(users.items(), key=lambda item: (
        item[1][0][0], version_key(item[1][0][1]), item[1][0][2], item[0]))
    number = {text: i + 1 for i, (text, _) in enumerate(groups)}

    out = []
    w = out.append
    w("# Third-party licences and notices\n\n")
    w("This file lists the licences of the third-party code specconv is built from (every "
      "crate of `Cargo.lock` other than the workspace's own), with their full texts; the "
      "system libraries it uses at run time; and the terms of the measured spectra its "
      "built-in models are trained on, with their notices. The Python wheel carries it in "
      "its `.dist-info/licenses/`.\n\n")
    w("It is generated: `python3 scripts/third_party.py` regenerates it (`python/THIRD-PARTY.md`, "
      "the one the wheel packs, links to it); `python3 scripts/third_party.py --check` fails "
      "when it is out of date. Do not edit it by hand.\n\n")
    w("`Cargo.lock` holds the crates of every platform, so some listed here (Windows, macOS, "
      "WebAssembly) are never compiled into a Linux build.\n\n")

    w("## Crates\n\n")
    w(f"{len(crates)} crates. The licence column is each crate's `license` field as its "
      "Cargo.toml declares it (older crates write `/` for `OR`); the texts column links to "
      "the licence files the crate ships, below.\n\n")
    w("| crate | version | licence (SPDX) | texts |\n|---|---|---|---|\n")
    for name, version, expression, files in crates:
        texts = ", ".join(f"[{n}](#text-{n})" for n in sorted({number[t] for _, t in files})) \
            or "no licence file"
        w(f"| {name} | {version} | {expression} | {texts} |\n")
    w("\n")

    missing = [(n, v, e) for n, v, e, files in crates if not files]
    if missing:
        w("### Crates without a licence file\n\n")
        w("These crates' packages hold no licence file at their root (LICENSE\\*, LICENCE\\*, "
          "COPYING\\*, NOTICE\\*, UNLICENSE); their licence is known only from the SPDX "
          "expression they declare:\n\n")
        for name, version, expression in missing:
            w(f"- {name} {version}: {expression}\n")
        w("\n")

    w("## Licence texts\n\n")
    w(f"{len(groups)} distinct texts, each given once, verbatim (line endings made LF and "
      "trailing whitespace at the end of a file trimmed), with the crates whose file it is.\n\n")
    for text, shared_by in groups:
        n = number[text]
        w(f'<a id="text-{n}"></a>\n\n### Text {n}\n\n')
        w("Used by: " + ", ".join(f"{name} {version} (`{file}`)"
                                  for name, version, file in shared_by) + ".\n\n")
        w(verbatim(text))
        w("\n")

    w("## Libraries linked at run time\n\n")
    w("specconv uses these system libraries at run time. They are **not redistributed**: "
      "neither the repository nor the Python wheel contains them (the wheel's "
      "`libspecconv_oiio.so` is specconv's own shim, which links the system's OpenImageIO); "
      "the machine installs them from its distribution, under their own terms. The Debian 12 "
      "package named holds those terms in its copyright file.\n\n")
    w("| library | Debian 12 package | licence | used for | terms |\n|---|---|---|---|---|\n")
    for library, package, licence, use in RUNTIME_LIBRARIES:
        w(f"| {library} | {package} | {licence} | {use} | "
          f"`/usr/share/doc/{package}/copyright` |\n")
    w("\n")

    w("## Training data\n\n")
    w("The built-in models (crates/spectral/models) are derived from measured reflectance "
      "spectra; their sets and terms, per model, are in docs/licences.md, and every output "
      "states them. The sets of `../shared/spectra` (its README.md describes them) and their "
      "terms as that README states them:\n\n")
    w("| data set | origin, terms and credit |\n|---|---|\n")
    for name, origin in data_sets():
        w(f"| `{name}` | {origin} |\n")
    w("\n")
    notices = sorted(p for p in DATA_NOTICES.iterdir() if p.is_file())
    w("### Data notices\n\n")
    w("The licence texts of data sets the built-in models are derived from "
      "(crates/spectral/notices/, verbatim; `specconv models` prints them too):\n\n")
    for path in notices:
        w(f"#### {path.name}\n\n")
        w(verbatim(read_text(path)))
        w("\n")

    return "".join(out).rstrip("\n") + "\n", len(crates), len(groups)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 when THIRD-PARTY.md is not what this script "
                             "would write")
    args = parser.parse_args()

    text, n_crates, n_texts = render()
    if args.check:
        stale = [p for p in OUTPUTS
                 if not p.is_file() or p.read_text(encoding="utf-8") != text]
        if stale:
            names = ", ".join(str(p.relative_to(ROOT)) for p in stale)
            print(f"third_party.py --check: {names} not up to date with Cargo.lock, the crates' "
                  "licence files and the data notices: run `python3 scripts/third_party.py` "
                  "and commit the result", file=sys.stderr)
            sys.exit(1)
        print(f"third_party.py --check: THIRD-PARTY.md is up to date "
              f"({n_crates} crates, {n_texts} distinct licence texts)")
        return
    for path in OUTPUTS:
        path.write_text(text, encoding="utf-8")
    print(f"wrote {', '.join(str(p.relative_to(ROOT)) for p in OUTPUTS)}: {len(text.encode())} "
          f"bytes, {n_crates} crates, {n_texts} distinct licence texts")


if __name__ == "__main__":
    main()
