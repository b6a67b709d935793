"""Shared fixtures of the package's tests: the specconv command (the same build), ../shared,
the layout reference's integration (tests/fichet_reference.py) and small real images made with
OpenImageIO's Python bindings."""
import os
import pathlib
import shutil
import subprocess
import sys
import warnings

import numpy as np
import pytest

warnings.simplefilter("ignore")

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared"
sys.path.insert(0, str(ROOT / "tests"))


@pytest.fixture(autouse=True)
def _no_site_model(monkeypatch):
    """Hermetic: the site default model of the machine running the tests changes nothing (a
    test that sets $SPECCONV_MODEL does so itself)."""
    monkeypatch.delenv("SPECCONV_MODEL", raising=False)


def _binary():
    """The specconv command: $SPECCONV_BIN, else the workspace's debug, else release build."""
    if os.environ.get("SPECCONV_BIN"):
        return os.environ["SPECCONV_BIN"]
    for profile in ("debug", "release"):
        path = ROOT / "target" / profile / "specconv"
        if path.exists():
            return str(path)
    return shutil.which("specconv")


@pytest.fixture(scope="session")
def cli():
    """Runs the specconv command; returns the completed process."""
    binary = _binary()
    if binary is None:
        pytest.fail("no specconv binary: build it (cargo build) or set SPECCONV_BIN")

    def run(*args, check=True):
        p = subprocess.run([binary, *map(str, args)], capture_output=True)
        if check and p.returncode != 0:
            raise AssertionError(f"specconv {args} failed: {p.stderr.decode()}")
        return p

    return run


@pytest.fixture(scope="session")
def shared():
    if not SHARED.is_dir():
        pytest.fail(f"{SHARED} (the measured spectra and CIE tables) must sit beside the checkout")
    return SHARED


def write_image(path, pixels, fmt="uint8"):
    """Writes `pixels` (h, w, c floats) with OpenImageIO, as oiiotool would."""
    import OpenImageIO as oiio

    h, w, c = pixels.shape
    spec = oiio.ImageSpec(w, h, c, fmt)
    out = oiio.ImageOutput.create(str(path))
    assert out is not None, oiio.geterror()
    assert out.open(str(path), spec), out.geterror()
    assert out.write_image(np.ascontiguousarray(pixels, dtype=np.float32)), out.geterror()
    out.close()
    return path


def texture(h=23, w=37, seed=7):
    """A smooth sRGB texture with saturated corners: a gradient plus a few solid patches."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:h, 0:w]
    img = np.stack([x / (w - 1), y / (h - 1), 0.5 + 0.4 * np.sin(x * 0.3 + y * 0.2)], axis=-1)
    img[:4, :4] = (0.9, 0.1, 0.1)
    img[-4:, -4:] = (0.1, 0.2, 0.9)
    img += rng.uniform(-0.02, 0.02, img.shape)
    return np.clip(img, 0, 1)


@pytest.fixture
def png(tmp_path):
    """An 8-bit sRGB PNG written by OpenImageIO, and the float values it holds."""
    pixels = np.round(texture() * 255) / 255
    return write_image(tmp_path / "albedo.png", pixels), pixels


def read_oiio(path, subimage=0, miplevel=0):
    """Every channel of a file as OpenImageIO reads it: (names, float32 array (h, w, c))."""
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    assert inp is not None, oiio.geterror()
    assert inp.seek_subimage(subimage, miplevel)
    spec = inp.spec()
    data = inp.read_image(subimage, miplevel, 0, spec.nchannels, "float")
    names = list(spec.channelnames)
    inp.close()
    return names, np.asarray(data).reshape(spec.height, spec.width, spec.nchannels)


def leftovers(directory):
    """Temporary files a writer left (`.NAME.specconv-….tmp`)."""
    return sorted(p.name for p in pathlib.Path(directory).iterdir() if ".specconv-" in p.name)
