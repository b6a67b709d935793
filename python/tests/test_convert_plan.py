"""specconv.convert's plan is the command line's (one library, specconv_conversion::plan): UDIM
patterns, output templates, outputs that must be OpenEXR, two inputs for one output named, an
output that is an input refused by any name; the same files and bytes as `specconv convert`."""
import os

import numpy as np
import pytest

import specconv
from conftest import leftovers, texture, write_image


def tiles(directory, numbers=(1011, 1001, 1002)):
    """A UDIM set wood.NNNN.png, written out of tile order."""
    directory.mkdir(exist_ok=True)
    for k, n in enumerate(numbers):
        pixels = np.round(texture(h=8, w=8, seed=k) * 255) / 255
        write_image(directory / f"wood.{n}.png", pixels)
    return directory / "wood.<UDIM>.png"


def test_a_udim_pattern_through_a_template_converts_every_tile_in_tile_order(tmp_path, cli):
    pattern = tiles(tmp_path / "tex")
    out = tmp_path / "out"
    out.mkdir()
    template = str(out / "{stem}_spectral.{udim}.exr")
    records = specconv.convert(pattern, output_template=template, mip=False)
    assert [r["input"] for r in records] == [
        str(tmp_path / "tex" / f"wood.{n}.png") for n in (1001, 1002, 1011)]
    assert [r["output"] for r in records] == [
        str(out / f"wood_spectral.{n}.exr") for n in (1001, 1002, 1011)]
    assert all(r["status"] == "ok" for r in records)
    # The command line plans the same files and writes the same bytes.
    theirs = tmp_path / "cli"
    theirs.mkdir()
    cli(pattern, "--output-template", str(theirs / "{stem}_spectral.{udim}.exr"), "--mip", "0")
    for n in (1001, 1002, 1011):
        name = f"wood_spectral.{n}.exr"
        assert (out / name).read_bytes() == (theirs / name).read_bytes()
    # {tile}, and a pattern among plain inputs, with update.
    again = specconv.convert([pattern], output_template=template, mip=False, update=True)
    assert [r["status"] for r in again] == ["skipped"] * 3
    uv = specconv.convert(pattern, output_template=str(out / "{stem}_{tile}.exr"), mip=False)
    assert [os.path.basename(r["output"]) for r in uv] == [
        "wood_u1_v1.exr", "wood_u2_v1.exr", "wood_u1_v2.exr"]


def test_a_pattern_into_listed_outputs_names_its_tiles_with_the_token(tmp_path, png):
    path, _ = png
    pattern = tiles(tmp_path / "tex", numbers=(1001, 1002))
    records = specconv.convert([path, pattern],
                               [tmp_path / "albedo.exr", tmp_path / "w_spectral.<UDIM>.exr"],
                               mip=False)
    assert [os.path.basename(r["output"]) for r in records] == [
        "albedo.exr", "w_spectral.1001.exr", "w_spectral.1002.exr"]
    # Without the token, every tile would be written over one file.
    with pytest.raises(specconv.OptionError, match=r"UDIM pattern \(2 tiles\).*output_template"):
        specconv.convert(pattern, tmp_path / "w.exr")
    with pytest.raises(specconv.OptionError, match="no UDIM pattern"):
        specconv.convert(path, tmp_path / "a.<UDIM>.exr")
    with pytest.raises(specconv.FileError, match="no UDIM tile matches"):
        specconv.convert(tmp_path / "tex" / "oak.<UDIM>.png", tmp_path / "o.<UDIM>.exr")


def test_careless_plans_are_refused_before_anything_is_written(tmp_path, png):
    path, pixels = png
    (tmp_path / "sub").mkdir()
    other = write_image(tmp_path / "sub" / "albedo.png", pixels)
    before = sorted(p.name for p in tmp_path.iterdir())
    # Two inputs, one output: both named.
    with pytest.raises(specconv.OptionError) as e:
        specconv.convert([path, other], tmp_path)
    assert f"{path} and {other} would both write" in str(e.value)
    with pytest.raises(specconv.OptionError, match="would both write"):
        specconv.convert([path, other], output_template=str(tmp_path / "{stem}.exr"))
    # Not OpenEXR.
    with pytest.raises(specconv.OptionError, match="ending in .exr"):
        specconv.convert(path, tmp_path / "albedo.tif")
    with pytest.raises(specconv.OptionError, match="ending in .exr"):
        specconv.convert(path, output_template="{dir}/{stem}.png")
    # An unknown template field, both outputs and a template, neither.
    with pytest.raises(specconv.OptionError, match=r"unknown field \{stme\}"):
        specconv.convert(path, output_template="{dir}/{stme}.exr")
    with pytest.raises(specconv.OptionError, match="not both"):
        specconv.convert(path, tmp_path / "a.exr", output_template="{dir}/{stem}.exr")
    with pytest.raises(specconv.OptionError, match="output_template"):
        specconv.convert(path)
    # An output that is an input, through a link and through `..`.
    link = tmp_path / "link.exr"
    link.symlink_to(path)
    for output in (link, tmp_path / "sub" / ".." / "link.exr"):
        with pytest.raises(specconv.FileError, match="is the input"):
            specconv.convert(path, output, overwrite=True)
    os.link(path, tmp_path / "hard.exr")
    with pytest.raises(specconv.FileError, match="is the input"):
        specconv.convert([other, path], [tmp_path / "x.exr", tmp_path / "hard.exr"], overwrite=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(before + ["hard.exr", "link.exr"])
    assert leftovers(tmp_path) == []
