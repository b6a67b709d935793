"""The package loads OpenImageIO through the shim installed beside its extension module, at the
first image read, not at import (docs/install.md), and never from memory or /tmp (issue 30)."""
import os
import pathlib
import subprocess
import sys

from conftest import ROOT

CHILD = """
import pathlib, sys
import specconv, specconv._specconv as module

def mapped():
    return {line.split()[-1] for line in open("/proc/self/maps") if "/" in line}

at_import = sorted(p for p in mapped() if "OpenImageIO" in p or "specconv_oiio" in p)
specconv.convert(sys.argv[1], sys.argv[2])
shims = sorted(p for p in mapped() if "specconv_oiio" in p)
print(at_import, shims, pathlib.Path(module.__file__).resolve().parent, sep="\\n")
"""


def test_import_loads_no_openimageio_and_a_read_opens_the_shim_beside_the_module(tmp_path):
    # A process of its own: the tests' own process has OpenImageIO's Python bindings loaded.
    # TMPDIR names no folder: nothing may need one.
    out = subprocess.run(
        [sys.executable, "-c", CHILD, str(ROOT / "testdata/images/srgb8.png"),
         str(tmp_path / "out.exr")],
        capture_output=True, text=True, env={**os.environ, "TMPDIR": str(tmp_path / "missing")},
    )
    assert out.returncode == 0, out.stderr
    at_import, shims, package = out.stdout.splitlines()
    assert at_import == "[]"
    assert shims == repr([str(pathlib.Path(package) / "libspecconv_oiio.so")])
    assert (tmp_path / "out.exr").is_file()
