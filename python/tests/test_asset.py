"""specconv.convert_asset (docs/assets.md): the command line's `asset`, from Python. Stages are
built with usd-core (tests/asset_stages.py); without usd-core these tests are skipped unless
SPECCONV_REQUIRE_USD is set (CI sets it)."""
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

import specconv

HAS_USD = importlib.util.find_spec("pxr") is not None
if not HAS_USD and os.environ.get("SPECCONV_REQUIRE_USD"):
    raise RuntimeError("SPECCONV_REQUIRE_USD is set but this Python has no usd-core")
pytestmark = pytest.mark.skipif(not HAS_USD, reason="usd-core (pip install usd-core) missing")

STAGES = Path(__file__).resolve().parents[2] / "tests" / "asset_stages.py"


def build(tmp_path, kind):
    tex = tmp_path / "tex"
    tex.mkdir()
    for name in ("rock_albedo", "rock_arm", "rock_normal", "clean_albedo", "dirty_albedo",
                 "never", "shared", "wood.1001", "wood.1002"):
        subprocess.run(["oiiotool", "--pattern", "checker", "8x8", "4", "-d", "uint8",
                        "-o", str(tex / (name + ".png"))], check=True)
    subprocess.run(["oiiotool", "--pattern", "checker", "8x8", "3", "-d", "half",
                    "-o", str(tex / "wood_acescg.exr")], check=True)
    if kind == "basic":
        # The basic stage reads ../outside/sky.png: callers give it a folder of its own.
        (tmp_path.parent / "outside").mkdir(exist_ok=True)
        subprocess.run(["oiiotool", "--pattern", "checker", "8x8", "3", "-d", "uint8",
                        "-o", str(tmp_path.parent / "outside" / "sky.png")], check=True)
    subprocess.run([sys.executable, str(STAGES), kind, str(tmp_path)], check=True)


def test_convert_asset_gives_the_records_and_layer_of_the_command_line(tmp_path):
    shot = tmp_path / "shot"
    shot.mkdir()
    build(shot, "basic")
    out = tmp_path / "out"
    records = specconv.convert_asset(shot / "shot.usda", out)
    by_name = {Path(r["input"]).name: r for r in records}
    assert by_name["rock_albedo.png"]["status"] == "ok"
    assert by_name["rock_albedo.png"]["asset"]["rule"] == "source-color-space"
    assert by_name["rock_arm.png"]["status"] == "data"
    assert by_name["wood_acescg.exr"]["colorspace"] == "ACEScg"
    assert "clean_albedo.png" not in by_name
    from pxr import Usd, UsdShade
    stage = Usd.Stage.Open(str(out / "shot_spectral.usda"))
    # RGB renderers read the stage's own network; the render context `spectral` the copy
    # that reads the spectral files (issue 56, item 1).
    rock = UsdShade.Material(stage.GetPrimAtPath("/World/Rock/Looks/Rock"))
    assert rock.ComputeSurfaceSource("")[0].GetPath() == "/World/Rock/Looks/Rock/Surface"
    assert rock.ComputeSurfaceSource("spectral")[0].GetPath() == \
        "/World/Rock/Looks/Rock/Surface_spectral"
    original = stage.GetPrimAtPath("/World/Rock/Looks/Rock/Albedo").GetAttribute("inputs:file")
    assert original.Get().path == "./tex/rock_albedo.png"
    albedo = stage.GetPrimAtPath("/World/Rock/Looks/Rock/Albedo_spectral").GetAttribute(
        "inputs:file")
    assert albedo.Get().path == "./tex/rock_albedo_spectral.exr"
    assert Path(albedo.Get().resolvedPath) == out / "tex" / "rock_albedo_spectral.exr"
    # The same decisions as the command line's dry run.
    dry = specconv.convert_asset(shot / "shot.usda", tmp_path / "dry", dry_run=True)
    assert not (tmp_path / "dry").exists()
    assert sorted(d["rule"] for d in dry) == sorted(
        {Path(r["asset"]["texture"]).name: r["asset"]["rule"] for r in records}.values())


def test_a_conflict_raises_naming_both_uses(tmp_path):
    build(tmp_path, "conflict")
    with pytest.raises(specconv.InputError, match="/Looks/A/Surface.*/Looks/B/Surface"):
        specconv.convert_asset(tmp_path / "conflict.usda", tmp_path / "out")
    records = specconv.convert_asset(tmp_path / "conflict.usda", tmp_path / "out2",
                                     errors="record")
    assert [r["status"] for r in records] == ["failed"]
    assert records[0]["asset"]["rule"] == "conflict"


def test_colorspace_is_refused(tmp_path):
    build(tmp_path, "missing")
    with pytest.raises(specconv.OptionError, match="colorspace"):
        specconv.convert_asset(tmp_path / "missing.usda", tmp_path / "out",
                               colorspace="ACEScg")


HAS_MTLX = importlib.util.find_spec("MaterialX") is not None
if not HAS_MTLX and os.environ.get("SPECCONV_REQUIRE_USD"):
    raise RuntimeError("SPECCONV_REQUIRE_USD is set but this Python has no MaterialX")


@pytest.mark.skipif(not HAS_MTLX, reason="MaterialX (pip install MaterialX) missing")
def build_brick(tmp_path):
    """tests/asset_mtlx.py's brick.mtlx in `tmp_path`, with the textures it reads."""
    tex = tmp_path / "tex"
    tex.mkdir()
    for name in ("brick_color", "brick_arm", "brick_normal", "brick_height", "wood.1001",
                 "wood.1002", "never"):
        subprocess.run(["oiiotool", "--pattern", "checker", "8x8", "4", "-d", "uint8",
                        "-o", str(tex / (name + ".png"))], check=True)
    subprocess.run([sys.executable, str(STAGES.parent / "asset_mtlx.py"), "brick",
                    str(tmp_path)], check=True)


def test_convert_asset_takes_a_materialx_document_and_writes_its_copy(tmp_path):
    build_brick(tmp_path)
    out = tmp_path / "out"
    records = specconv.convert_asset(tmp_path / "brick.mtlx", out)
    by_name = {Path(r["input"]).name: r for r in records}
    assert by_name["brick_color.png"]["status"] == "ok"
    assert by_name["brick_color.png"]["asset"]["rule"] == "materialx-colorspace"
    assert by_name["brick_color.png"]["colorspace"] == "sRGB - Texture"
    assert by_name["brick_arm.png"]["status"] == "data"
    assert by_name["wood.1002.png"]["colorspace"] == "ACEScg"
    import MaterialX as mx
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(out / "brick_spectral.mtlx"))
    file = doc.getDescendant("NG_brick/color").getInput("file")
    assert file.getValueString() == "./tex/brick_color_spectral.exr"
    assert file.getAttribute("specconv_original") == "brick_color.png"
    assert (out / "tex" / "brick_color_spectral.exr").is_file()


def test_convert_asset_never_replaces_a_file_it_did_not_write(tmp_path):
    """Issue 57, item 1: a file where the override copy goes, not written by an asset run,
    is kept, update or overwrite; the run converts nothing."""
    build_brick(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    theirs = out / "brick_spectral.mtlx"
    theirs.write_text("<!-- mine -->")
    for flags in ({}, {"update": True}, {"overwrite": True}):
        with pytest.raises(specconv.OutputExistsError, match="did not write it"):
            specconv.convert_asset(tmp_path / "brick.mtlx", out, **flags)
        assert theirs.read_text() == "<!-- mine -->"
    assert sorted(p.name for p in out.iterdir()) == ["brick_spectral.mtlx"]


def test_a_layer_the_stage_sublayers_is_never_written_over(tmp_path):
    """Issue 57, item 2: converted into its own folder, a stage that sublayers its own layer's
    name would have that layer written over; refused, update or overwrite, nothing changed."""
    build(tmp_path, "self_sublayer")
    files = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    for flags in ({}, {"update": True}, {"overwrite": True}):
        with pytest.raises(specconv.Error, match="is a file the stage reads"):
            specconv.convert_asset(tmp_path / "self_sublayer.usda", tmp_path, **flags)
        assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()} == files


def test_two_usdz_members_that_differ_by_dots_stay_two_files(tmp_path):
    """Issue 57, item 4: `escape.png` and `../escape.png` in one usdz: two copies inside DIR,
    each with its member's bytes, two outputs."""
    build(tmp_path, "escape_package")
    out = tmp_path / "out"
    records = specconv.convert_asset(tmp_path / "escape.usdz", out)
    inputs = {Path(r["input"]) for r in records}
    assert len(inputs) == 2 and all(p.is_relative_to(out) for p in inputs)
    want = {(tmp_path / "tex" / f"{n}.png").read_bytes() for n in ("rock_albedo", "rock_normal")}
    assert {p.read_bytes() for p in inputs} == want
    assert len({r["output"] for r in records}) == 2


def test_a_walk_that_gives_up_decides_nothing(tmp_path):
    """Issue 57, item 5: a normal map past the walk's limit is undecided, never colour."""
    build(tmp_path, "deep")
    records = specconv.convert_asset(tmp_path / "deep.usda", tmp_path / "out", errors="record")
    normal = next(r for r in records if Path(r["input"]).name == "rock_normal.png")
    assert normal["asset"]["rule"] == "undecided" and normal["status"] == "failed"
    assert not (tmp_path / "out" / "tex" / "rock_normal_spectral.exr").exists()


def test_outputs_whose_names_meet_are_told_apart(tmp_path):
    """Issue 57, item 11: a.png, a.tif and a_png.png, all colour: three outputs."""
    (tmp_path / "tex").mkdir()
    for name, pattern in (("a.png", "4"), ("a.tif", "2"), ("a_png.png", "3")):
        subprocess.run(["oiiotool", "--pattern", "checker", "8x8", pattern, "-d", "uint8",
                        "-o", str(tmp_path / "tex" / name)], check=True)
    subprocess.run([sys.executable, str(STAGES), "stem_clash", str(tmp_path)], check=True)
    records = specconv.convert_asset(tmp_path / "stem_clash.usda", tmp_path / "out")
    outputs = {r["output"] for r in records}
    assert len(outputs) == 3 and all(Path(o).is_file() for o in outputs)


def test_a_reader_failure_is_one_line(tmp_path):
    """Issue 57, item 12: a Latin-1 byte in a texture path is said in one line naming where."""
    (tmp_path / "latin.usda").write_bytes(
        b'#usda 1.0\ndef Shader "T"\n{\n    uniform token info:id = "UsdUVTexture"\n'
        b'    asset inputs:file = @./tex/caf\xe9.png@\n}\n')
    with pytest.raises(specconv.Error) as e:
        specconv.convert_asset(tmp_path / "latin.usda", tmp_path / "out")
    message = str(e.value)
    assert "not text in its encoding" in message and "</T.inputs:file>" in message
    assert "\n" not in message.strip() and "Traceback" not in message


def test_unknown_shaders_that_read_files_are_records_and_fail_under_strict(tmp_path):
    """Issue 56, item 2: a shader no definition specconv knows has is no silent success: each
    file it reads is a record with status `unknown-shader`; `strict` (a warning fails) raises.
    Arnold's and RenderMan's texture nodes are known (their tables): converted."""
    build(tmp_path, "foreign")
    records = specconv.convert_asset(tmp_path / "foreign.usda", tmp_path / "out")
    unknown = [r for r in records if r["status"] == "unknown-shader"]
    assert [r["asset"]["shader"] for r in unknown] == ["studio:projector"]
    converted = sorted(os.path.basename(r["output"]) for r in records if r["status"] == "ok")
    assert converted == ["dirty_albedo_spectral.exr", "rock_albedo_spectral.exr"]
    uses = [u for r in records if r["status"] == "ok" for u in r["asset"]["uses"]]
    assert sorted((u["input"], u["input_type"]) for u in uses) == \
        [("base_color", "RGB"), ("diffuseColor", "color")]
    with pytest.raises(specconv.InputError, match="unknown shader studio:projector"):
        specconv.convert_asset(tmp_path / "foreign.usda", tmp_path / "strict", strict=True)
