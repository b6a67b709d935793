"""Issue 31: the Python package held to the command line's rules. A model or spectral file is
written only under a name of its kind, never over an existing file without overwrite=True,
never into a FIFO or device; a FIFO is never opened for reading; wavelengths and emission units
are the library's; every bad argument is a specconv.Error (paths as bytes accepted, as
os.fspath gives them)."""
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import specconv
from conftest import leftovers


def run_python(script, timeout=30):
    """`script` in a fresh interpreter with this package; a hang is a failure, not a hung suite."""
    try:
        return subprocess.run([sys.executable, "-c", textwrap.dedent(script)],
                              capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        pytest.fail(f"still running after {timeout} s:\n{script}")


# Item 5: Model.save replaced any file, a texture included; train -o replaced a model.

def test_a_model_is_never_saved_over_a_texture(tmp_path):
    victim = tmp_path / "victim.png"
    victim.write_bytes(b"\x89PNG texture")
    model = specconv.Model.builtin()
    for overwrite in (False, True):
        with pytest.raises(specconv.OptionError, match=r"wrong extension.*ending in \.json"):
            model.save(victim, overwrite=overwrite)
    assert victim.read_bytes() == b"\x89PNG texture"
    with pytest.raises(specconv.OptionError, match="ending in .json"):
        model.save(tmp_path / "model")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["victim.png"]


def test_a_model_replaces_an_existing_one_only_with_overwrite(tmp_path):
    path = tmp_path / "studio.json"
    specconv.Model.builtin("paper").save(path)
    before = path.read_bytes()
    with pytest.raises(specconv.OutputExistsError, match="overwrite=True") as e:
        specconv.Model.builtin("broad").save(path)
    assert isinstance(e.value, FileExistsError)
    assert path.read_bytes() == before
    specconv.Model.builtin("broad").save(path, overwrite=True)
    assert specconv.Model.load(path).clusters == specconv.Model.builtin("broad").clusters
    assert path.read_bytes() != before
    assert leftovers(tmp_path) == []


def test_a_model_is_never_written_into_a_fifo(tmp_path):
    fifo = tmp_path / "m.json"
    os.mkfifo(fifo)
    p = run_python(f"""
        import specconv
        try:
            specconv.Model.builtin().save({str(fifo)!r}, overwrite=True)
        except specconv.FileError as e:
            print("refused:", e)
    """)
    assert "refused:" in p.stdout and "FIFO" in p.stdout, p.stdout + p.stderr
    assert leftovers(tmp_path) == []


# Item 6: read_spectral on a FIFO hung.

def test_read_spectral_refuses_a_fifo_without_opening_it(tmp_path):
    fifo = tmp_path / "spectral.exr"
    os.mkfifo(fifo)
    p = run_python(f"""
        import specconv
        try:
            specconv.read_spectral({str(fifo)!r})
        except specconv.FileError as e:
            print("refused:", e)
    """)
    assert "refused:" in p.stdout and "a FIFO (named pipe), not a file" in p.stdout, \
        p.stdout + p.stderr
    for special in ("/dev/zero", str(tmp_path)):
        with pytest.raises(specconv.FileError, match="not a file"):
            specconv.read_spectral(special)


# Item 7: NaN wavelengths made a T.NaNnm channel; unknown emission units were written.

@pytest.mark.parametrize("wavelengths,says", [
    ([400.0, float("nan"), 600.0], "wavelength 1 is NaN nm"),
    ([400.0, float("inf"), 600.0], "wavelength 1 is inf nm"),
    ([0.0, 500.0, 600.0], "above 0"),
    ([-400.0, 500.0, 600.0], "above 0"),
    ([600.0, 500.0, 400.0], "must increase"),
])
def test_wavelengths_that_name_no_band_are_refused(tmp_path, wavelengths, says):
    with pytest.raises(specconv.OptionError, match=says):
        specconv.write_spectral(tmp_path / "x.exr", wavelengths, np.ones((2, 2, 3)))
    assert list(tmp_path.iterdir()) == []


def test_emission_is_the_library_s_and_recorded(tmp_path):
    with pytest.raises(specconv.OptionError, match="emission.*reference.*photometric"):
        specconv.write_spectral(tmp_path / "bogus.exr", [500.0, 600.0], np.ones((2, 2, 2)),
                                emission="bogus")
    assert list(tmp_path.iterdir()) == []
    path = tmp_path / "light.exr"
    specconv.write_spectral(path, [500.0, 600.0], np.ones((2, 2, 2)), emission="photometric")
    image = specconv.read_spectral(path)
    assert image.kind == "emission" and image.units == "W.m^-2.sr^-1"
    assert image.attributes["specconvEmissionUnits"] == "photometric"


def test_the_old_name_emission_units_still_works_and_warns(tmp_path):
    """write_spectral's keyword is convert's `emission`; the old `emission_units` warns."""
    path = tmp_path / "old.exr"
    with pytest.warns(DeprecationWarning, match="emission_units is now emission"):
        specconv.write_spectral(path, [500.0, 600.0], np.ones((2, 2, 2)),
                                emission_units="photometric")
    assert specconv.read_spectral(path).attributes["specconvEmissionUnits"] == "photometric"
    with pytest.raises(specconv.OptionError, match="one keyword"):
        specconv.write_spectral(tmp_path / "both.exr", [500.0, 600.0], np.ones((2, 2, 2)),
                                emission="reference", emission_units="reference")
    assert not (tmp_path / "both.exr").exists()


# Python writes follow the command line's rules: extension, kind, no replacing.

def test_write_spectral_writes_only_exr_names_and_never_into_special_files(tmp_path):
    victim = tmp_path / "victim.png"
    victim.write_bytes(b"texture")
    for name in (victim, tmp_path / "out.tif", "-"):
        with pytest.raises(specconv.OptionError, match=r"ending in \.exr"):
            specconv.write_spectral(name, [500.0], np.ones((1, 1, 1)), overwrite=True)
    assert victim.read_bytes() == b"texture"
    fifo = tmp_path / "f.exr"
    os.mkfifo(fifo)
    p = run_python(f"""
        import numpy as np, specconv
        try:
            specconv.write_spectral({str(fifo)!r}, [500.0], np.ones((1, 1, 1)), overwrite=True)
        except specconv.FileError as e:
            print("refused:", e)
    """)
    assert "refused:" in p.stdout and "FIFO" in p.stdout, p.stdout + p.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.exr", "victim.png"]


# Smaller: negative counts, bytes paths, complex arrays, a device as a config.

def test_negative_counts_are_option_errors_naming_the_keyword(tmp_path, png):
    out = tmp_path / "o.exr"
    for kw in ({"threads": -1}, {"tile": (-64, 64)}, {"zip_level": -1}):
        (name,) = kw
        with pytest.raises(specconv.OptionError, match=f"{name} must be a whole number"):
            specconv.convert(png[0], out, **kw)
    # Empty tiles: the remedy names scanlines as the keyword takes them.
    with pytest.raises(specconv.OptionError, match='tile="scanline"'):
        specconv.convert(png[0], out, tile=(0, 0))
    # Past the type, the library's own range: a deflate level is 0 to 9.
    with pytest.raises(specconv.OptionError, match="zip_level: '300' is not a deflate level 0–9"):
        specconv.convert(png[0], out, zip_level=300)
    with pytest.raises(specconv.OptionError, match="level must be a whole number from 0"):
        specconv.read_spectral(tmp_path / "x.exr", level=-1)
    with pytest.raises(specconv.OptionError, match="tile must be"):
        specconv.write_spectral(out, [500.0], np.ones((1, 1, 1)), tile=(-1, 8))
    with pytest.raises(specconv.OptionError, match="clusters must be"):
        specconv.Model.train(np.full((40, 36), 0.5), np.arange(380, 731, 10.0), clusters=-2)
    assert not out.exists()


def test_paths_as_bytes_are_paths(tmp_path, png):
    name = os.fsencode(tmp_path) + b"/caf\xe9.exr"  # not UTF-8: any bytes name a file on Unix
    specconv.write_spectral(name, [500.0, 600.0], np.full((1, 2, 2), 0.5))
    assert specconv.read_spectral(name).values.shape == (1, 2, 2)
    out = os.fsencode(tmp_path / "o.exr")
    specconv.convert(os.fsencode(png[0]), out)
    assert specconv.read_spectral(out).kind == "reflectance"
    specconv.Model.builtin().save(os.fsencode(tmp_path / "m.json"))
    assert specconv.Model.load(os.fsencode(tmp_path / "m.json")).clusters > 0
    with pytest.raises(specconv.OptionError, match="a path is a str, bytes or os.PathLike"):
        specconv.read_spectral(42)


def test_complex_values_are_refused_not_truncated(tmp_path):
    xyz = np.array([[0.2, 0.3, 0.1]]) + 1e-3j
    with pytest.raises(specconv.OptionError, match="complex"):
        specconv.uplift(xyz)
    with pytest.raises(specconv.OptionError, match="complex"):
        specconv.write_spectral(tmp_path / "c.exr", [500.0], np.ones((1, 1, 1)) * (1 + 1j))
    assert list(tmp_path.iterdir()) == []


def test_a_device_as_a_config_is_named_as_what_it_is():
    with pytest.raises(specconv.Error, match="/dev/zero: a character device, not a config file"):
        specconv.rgb_to_xyz(np.zeros((1, 3)), "sRGB - Texture", config="/dev/zero")
