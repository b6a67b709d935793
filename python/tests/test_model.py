"""Model: built-in, loaded, trained from numpy (the same model `specconv train` makes from the
same measured spectra), saved."""
import json

import numpy as np
import pytest

import specconv


def munsell(shared):
    path = shared / "spectra" / "munsell1269_matte_380-800_1nm.csv"
    table = np.genfromtxt(path, delimiter=",", names=True)
    names = table.dtype.names
    wl = table[names[0]]
    spectra = np.stack([table[n] for n in names[1:]])
    return path, wl, spectra


def test_training_from_numpy_is_the_cli_s_model(tmp_path, shared, cli):
    path, wl, spectra = munsell(shared)
    cli("train", "--spectra", path, "-o", tmp_path / "cli.json")
    model = specconv.Model.train(spectra, wl, source=path.name)
    model.save(tmp_path / "py.json")
    ours, theirs = json.loads((tmp_path / "py.json").read_text()), json.loads(
        (tmp_path / "cli.json").read_text())
    assert ours == theirs
    assert model.clusters == 8 and model.wavelengths.size == 36
    assert "non-commercial" in model.sources
    # The paper's model is this training.
    builtin = specconv.Model.builtin("paper")
    xyz = np.array([[0.2, 0.15, 0.1], [0.05, 0.1, 0.3]])
    np.testing.assert_array_equal(specconv.uplift(xyz, model), specconv.uplift(xyz, builtin))


def test_a_saved_model_loads_and_converts_by_name(tmp_path, shared, png):
    _, wl, spectra = munsell(shared)
    model = specconv.Model.train(spectra[::3], wl, clusters=4, licence="CC0 (test)")
    with pytest.raises(specconv.OptionError, match="save it"):
        specconv.convert(png[0], tmp_path / "a.exr", model=model)
    model.save(tmp_path / "m.json")
    loaded = specconv.Model.load(tmp_path / "m.json")
    assert loaded.clusters == model.clusters and "CC0 (test)" in loaded.sources
    (record,) = specconv.convert(png[0], tmp_path / "a.exr", model=loaded)
    assert "m.json" in record["model"] and "CC0 (test)" in record["model"]


def test_model_errors():
    with pytest.raises(specconv.OptionError, match="extended, paper, broad, open"):
        specconv.Model.builtin("munsell")
    with pytest.raises(specconv.FileError):
        specconv.Model.load("/nonexistent/model.json")
    with pytest.raises(specconv.OptionError, match="2-D"):
        specconv.Model.train(np.zeros(36), np.arange(380, 731, 10.0))
    with pytest.raises(specconv.OptionError, match="weight"):
        specconv.Model.train(np.full((40, 36), 0.5), np.arange(380, 731, 10.0),
                             weights=np.zeros(40))
