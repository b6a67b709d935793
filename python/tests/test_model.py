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
    # The same model; the file's set is known by its content (hash, terms), the arrays' by
    # nothing, whatever their source is called.
    py_set, cli_set = ours["training"].pop("sets")[0], theirs["training"].pop("sets")[0]
    assert ours == theirs
    assert "sha256" not in py_set and len(cli_set.pop("sha256")) == 64
    assert "non-commercial" in cli_set["licence"] and py_set["licence"].startswith("unknown")
    assert {k: v for k, v in py_set.items() if k not in ("licence", "commercial", "attribution")} \
        == {k: v for k, v in cli_set.items() if k not in ("licence", "commercial", "attribution")}
    assert model.clusters == 8 and model.wavelengths.size == 36
    assert "unknown" in model.sources
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
    with pytest.raises(specconv.OptionError, match="open, extended, paper, broad"):
        specconv.Model.builtin("munsell")
    with pytest.raises(specconv.FileError):
        specconv.Model.load("/nonexistent/model.json")
    with pytest.raises(specconv.OptionError, match="2-D"):
        specconv.Model.train(np.zeros(36), np.arange(380, 731, 10.0))
    with pytest.raises(specconv.OptionError, match="weight"):
        specconv.Model.train(np.full((40, 36), 0.5), np.arange(380, 731, 10.0),
                             weights=np.zeros(40))


def test_a_studio_model_on_top_of_open_is_the_cli_s_and_says_its_terms(tmp_path, shared, cli):
    # A studio's swatches (the ColorChecker standing in for them), its own for commercial use,
    # weighted 8x on top of the open model's data: the model `specconv train --with` makes.
    path = shared / "spectra" / "colorchecker_n_ohta_380-780_5nm.csv"
    table = np.genfromtxt(path, delimiter=",", names=True)
    names = table.dtype.names
    wl, spectra = table[names[0]], np.stack([table[n] for n in names[1:]])
    cli("train", "--spectra", path, "--weights", "8", "--licence", "ours", "--commercial", "yes",
        "--with", "open", "--with-data", shared / "spectra", "-o", tmp_path / "cli.json")
    model = specconv.Model.train(spectra, wl, source=path.name, licence="ours",
                                 commercial="yes", with_model="open",
                                 with_data=shared / "spectra", weight=8)
    model.save(tmp_path / "py.json")
    ours, theirs = json.loads((tmp_path / "py.json").read_text()), json.loads(
        (tmp_path / "cli.json").read_text())
    # The open model's sets keep their hashes; the arrays have none, the CLI's file has its own.
    assert all(len(s["sha256"]) == 64 for s in ours["training"]["sets"][:-1])
    assert len(theirs["training"]["sets"][-1].pop("sha256")) == 64
    assert ours == theirs
    assert model.commercial == "yes"
    assert "USGS Spectral Library Version 7" in model.attribution
    assert "commercial use: yes" in model.description
    # The built-in models say theirs: the Munsell data are for non-commercial use only.
    assert specconv.Model.builtin("extended").commercial == "no"
    assert specconv.Model.builtin("open").commercial == "yes"
    assert specconv.Model.train(spectra, wl).commercial == "unstated"
    with pytest.raises(specconv.OptionError, match="go together"):
        specconv.Model.train(spectra, wl, with_model="open")
    with pytest.raises(specconv.OptionError, match="one weight"):
        specconv.Model.train(spectra, wl, with_model="open", with_data=shared / "spectra",
                             weights=np.ones(len(spectra)))
    with pytest.raises(specconv.OptionError, match="commercial"):
        specconv.Model.train(spectra, wl, commercial="perhaps")
    with pytest.raises(specconv.FileError, match="cannot read spectra file"):
        specconv.Model.train(spectra, wl, with_model="open", with_data=tmp_path)


def _colorchecker(shared):
    path = shared / "spectra" / "colorchecker_n_ohta_380-780_5nm.csv"
    table = np.genfromtxt(path, delimiter=",", names=True)
    names = table.dtype.names
    return path, table[names[0]], np.stack([table[n] for n in names[1:]])


def test_the_default_model_is_open_and_its_outputs_may_be_shipped(tmp_path, png):
    import OpenImageIO as oiio

    assert specconv.Model.builtin_names()[0] == "open"
    assert specconv.Model.builtin().commercial == "yes"
    (record,) = specconv.convert(png[0], tmp_path / "a.exr")
    assert record["model"].startswith("built-in open (")
    assert record["model"].endswith("commercial use: yes)")
    spec = oiio.ImageInput.open(str(tmp_path / "a.exr")).spec()
    assert spec.getattribute("specconvCommercialUse") == "yes"
    assert "CC BY 4.0" in spec.getattribute("specconvModelAttribution")


def test_the_site_default_model_reaches_python(tmp_path, png, monkeypatch):
    xyz = np.array([[0.2, 0.3, 0.4], [0.05, 0.04, 0.3]])
    paper = specconv.uplift(xyz, specconv.Model.builtin("paper"))
    monkeypatch.setenv("SPECCONV_MODEL", "paper")
    (record,) = specconv.convert(png[0], tmp_path / "a.exr")
    assert record["model"].startswith("built-in paper (8 clusters")
    np.testing.assert_array_equal(specconv.uplift(xyz), paper)
    monkeypatch.setenv("SPECCONV_MODEL", "")
    assert not np.array_equal(specconv.uplift(xyz), paper)
    monkeypatch.setenv("SPECCONV_MODEL", "papers")
    with pytest.raises(specconv.Error, match=r"\$SPECCONV_MODEL"):
        specconv.uplift(xyz)
    with pytest.raises(specconv.Error, match=r"\$SPECCONV_MODEL"):
        specconv.convert(png[0], tmp_path / "b.exr")
    assert not (tmp_path / "b.exr").exists()


def test_evaluate_is_eval_with_its_colour_shift(shared, cli):
    path, wl, spectra = _colorchecker(shared)
    want = json.loads(cli("eval", "--spectra", path, "--model", "extended", "--json").stdout)
    got = specconv.evaluate(spectra, wl, specconv.Model.builtin("extended"), bounded=False)
    assert got["count"] == want["count"] == 24
    assert got["delta_e"] == pytest.approx(want["delta_e"], rel=1e-12)
    assert [s["illuminant"] for s in got["colour_shift"]] == ["A", "FL11"]
    for mine, theirs in zip(got["colour_shift"], want["colour_shift"]):
        assert mine["illuminant"] == theirs["illuminant"]
        for key in ("mean", "p95", "max"):
            assert mine[key] == pytest.approx(theirs[key], rel=1e-12)
    per = np.asarray(got["per_spectrum"]["colour_shift"]["A"])
    assert got["colour_shift"][0]["p95"] == pytest.approx(np.percentile(per, 95), rel=1e-12)
    assert got["colour_shift"][0]["max"] == per.max()
    # Any light by name; bounded by default, as convert writes.
    d50 = specconv.evaluate(spectra, wl, under=["D50"])
    assert [s["illuminant"] for s in d50["colour_shift"]] == ["D50"]
    assert d50["method"] == "otsu2018+bounded" and d50["in_unit_range"] == 1.0
    with pytest.raises(specconv.OptionError, match="F13"):
        specconv.evaluate(spectra, wl, under=["F13"])
