"""read_spectral and write_spectral against OpenImageIO's Python bindings: files in the
Fichet 2021 layout written by one and read by the other."""
import numpy as np
import OpenImageIO as oiio
import pytest

import specconv
from conftest import leftovers, read_oiio


def write_fichet_with_oiio(path, names, values, attributes=()):
    """A spectral file as another tool writes it: scanlines, float, OpenImageIO's writer."""
    h, w, c = values.shape
    spec = oiio.ImageSpec(w, h, c, "float")
    spec.channelnames = tuple(names)
    spec.attribute("spectralLayoutVersion", "1.0")
    for k, v in attributes:
        spec.attribute(k, v)
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec), out.geterror()
    assert out.write_image(np.ascontiguousarray(values, dtype=np.float32)), out.geterror()
    out.close()


def test_reads_a_file_oiio_wrote_with_any_wavelength_names(tmp_path):
    # Wavelengths as the layout allows them: nm with a comma, metres with an exponent, and out
    # of order (OpenEXR sorts channels by name: readers take wavelengths from names).
    names = ["T.550,5nm", "T.4.5e-07m", "T.650nm", "A"]
    rng = np.random.default_rng(2)
    values = rng.uniform(0, 1, (5, 6, 4)).astype(np.float32)
    path = tmp_path / "other.exr"
    write_fichet_with_oiio(path, names, values)
    image = specconv.read_spectral(path)
    assert image.kind == "reflectance" and image.units is None and image.levels == 1
    np.testing.assert_allclose(image.wavelengths, [450.0, 550.5, 650.0])
    np.testing.assert_array_equal(image.values, values[..., [1, 0, 2]])
    np.testing.assert_array_equal(image.alpha, values[..., 3])
    assert image.attributes["spectralLayoutVersion"] == "1.0"


def test_reads_emission_with_its_units(tmp_path):
    names = [f"S0.{w},000000nm" for w in (400, 500, 600)]
    values = np.full((2, 3, 3), 7.5, np.float32)
    path = tmp_path / "light.exr"
    write_fichet_with_oiio(path, names, values, [("emissiveUnits", "W.m^-2.sr^-1")])
    image = specconv.read_spectral(path)
    assert image.kind == "emission" and image.units == "W.m^-2.sr^-1"
    assert image.alpha is None
    np.testing.assert_array_equal(image.values, values)


def test_oiio_reads_what_write_spectral_wrote(tmp_path):
    wl = np.array([400.0, 452.5, 500.0, 700.0])
    rng = np.random.default_rng(5)
    values = rng.uniform(0, 1, (9, 13, 4)).astype(np.float32)
    alpha = rng.uniform(0, 1, (9, 13)).astype(np.float32)
    path = tmp_path / "ours.exr"
    specconv.write_spectral(path, wl, values, alpha=alpha, sample="float", tile=(8, 4),
                            attributes={"specconvNote": "from numpy"})
    names, pixels = read_oiio(path)
    assert names == ["A", "T.400,000000nm", "T.452,500000nm", "T.500,000000nm",
                     "T.700,000000nm"]
    np.testing.assert_array_equal(pixels[..., 1:], values)
    np.testing.assert_array_equal(pixels[..., 0], alpha)
    spec = oiio.ImageInput.open(str(path)).spec()
    assert spec.getattribute("spectralLayoutVersion") == "1.0"
    assert spec.getattribute("specconvNote") == "from numpy"
    assert spec.tile_width == 8 and spec.tile_height == 4
    # Half, as convert writes by default: values rounded as numpy rounds to float16.
    specconv.write_spectral(tmp_path / "half.exr", wl, values)
    np.testing.assert_array_equal(read_oiio(tmp_path / "half.exr")[1],
                                  values.astype(np.float16).astype(np.float32))


def test_emission_is_written_with_its_units(tmp_path):
    path = tmp_path / "light.exr"
    specconv.write_spectral(path, [500.0, 600.0], np.ones((2, 2, 2)),
                            emission="normalised", tile=None)
    names, _ = read_oiio(path)
    assert names == ["S0.500,000000nm", "S0.600,000000nm"]
    spec = oiio.ImageInput.open(str(path)).spec()
    # The layout's units, and the convention as convert records it (to-rgb reads it back).
    assert spec.getattribute("emissiveUnits") == "W.m^-2.sr^-1"
    assert spec.getattribute("specconvEmissionUnits") == "normalised"


def test_levels_of_a_converted_texture_are_oiio_s(tmp_path, png):
    path, _ = png
    out = tmp_path / "albedo_spectral.exr"
    specconv.convert(path, out)
    inp = oiio.ImageInput.open(str(out))
    levels = 0
    while inp.seek_subimage(0, levels):
        levels += 1
    inp.close()
    image = specconv.read_spectral(out)
    assert image.levels == levels == 6
    for level in (1, levels - 1):
        names, pixels = read_oiio(out, 0, level)
        lv = specconv.read_spectral(out, level=level)
        bands = [i for i, n in enumerate(names) if n.startswith("T.")]
        np.testing.assert_array_equal(lv.values, pixels[..., bands])
    with pytest.raises(specconv.FileError, match="MIP level 6 does not exist; the file has 6"):
        specconv.read_spectral(out, level=6)


def test_bad_writes_raise_and_leave_nothing(tmp_path):
    path = tmp_path / "x.exr"
    specconv.write_spectral(path, [500.0], np.zeros((1, 1, 1)))
    before = path.read_bytes()
    with pytest.raises(specconv.OutputExistsError) as e:
        specconv.write_spectral(path, [500.0], np.ones((1, 1, 1)))
    assert isinstance(e.value, FileExistsError)
    assert path.read_bytes() == before
    with pytest.raises(specconv.OptionError, match="shape"):
        specconv.write_spectral(tmp_path / "y.exr", [500.0, 600.0], np.ones((2, 2, 3)))
    with pytest.raises(specconv.OptionError):
        specconv.write_spectral(tmp_path / "z.exr", [500.0, 500.0], np.ones((1, 1, 2)))
    with pytest.raises(specconv.FileError):
        specconv.write_spectral(tmp_path / "no" / "dir.exr", [500.0], np.ones((1, 1, 1)))
    with pytest.raises(specconv.FileError) as e:
        specconv.read_spectral(tmp_path / "missing.exr")
    assert isinstance(e.value, OSError)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.exr"]
    assert leftovers(tmp_path) == []
