"""specconv.convert_asset (docs/assets.md): the command line's `asset`, from Python. Stages are
built with usd-core (tests/asset_stages.py); without usd-core these tests are skipped unless
SPECCONV_REQUIRE_USD is set (CI sets it)."""
import importlib.util
import json
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


# The reader (python/specconv/_asset_reader, docs/assets.md "The reader"): one protocol, run
# alone, and carried both ways (issue 58, item 5).
READER_DIR = Path(specconv.__file__).resolve().parent
BOOTSTRAP = (READER_DIR / "_asset_reader" / "bootstrap.py").read_text()
MODULES = ("__init__", "protocol", "shader_defs", "mtlx", "stage")


def request(stage, **more):
    from specconv._asset_reader import PROTOCOL
    return json.dumps(dict(protocol=PROTOCOL, command="read", stage=str(stage), extract=None,
                           **more))


def alone(req, cwd):
    """The reader run alone, in a child `python -I` that imports it from its folder as the
    top-level package `_asset_reader`: never the compiled module (it checks), nor specconv."""
    code = ("import sys\nsys.path.insert(0, sys.argv[1])\nimport _asset_reader\n"
            "status, out = _asset_reader.answer(sys.stdin.read())\n"
            "assert not [m for m in sys.modules if m.startswith('specconv')]\n"
            "print(out)\nsys.exit(status)\n")
    p = subprocess.run([sys.executable, "-I", "-c", code, str(READER_DIR)], input=req,
                       capture_output=True, text=True, cwd=cwd)
    return p.returncode, p.stdout, p.stderr


def as_the_program_carries_it(req, cwd, isolated=True):
    """The reader as `specconv asset` runs it: `python -I -c BOOTSTRAP NAME SOURCE …`."""
    args = [a for n in MODULES for a in (n, (READER_DIR / "_asset_reader" / (n + ".py"))
                                           .read_text())]
    p = subprocess.run([sys.executable, *(["-I"] if isolated else []), "-c", BOOTSTRAP, *args],
                       input=req, capture_output=True, text=True, cwd=cwd)
    return p.returncode, p.stdout, p.stderr


def stage_and_document(tmp_path):
    """tests/asset_stages.py's basic stage and tests/asset_mtlx.py's brick document."""
    shot, brick = tmp_path / "shot", tmp_path / "brick"
    shot.mkdir()
    brick.mkdir()
    build(shot, "basic")
    build_brick(brick)
    return shot / "shot.usda", brick / "brick.mtlx"


def test_the_reader_runs_alone_and_answers_in_its_protocol(tmp_path):
    shot = tmp_path / "shot"
    shot.mkdir()
    build(shot, "basic")
    status, out, err = alone(request(shot / "shot.usda"), tmp_path)
    assert status == 0, err
    answer = json.loads(out)
    assert answer["protocol"] == 1
    assert answer["stage"] == str(shot / "shot.usda") and answer["composition_errors"] == []
    assert {"materials", "bound_prims", "textures", "references", "read_files",
            "unknown"} <= set(answer)
    albedo = next(t for t in answer["textures"] if t["authored"] == "./tex/rock_albedo.png")
    assert albedo["node_id"] == "UsdUVTexture" and albedo["resolved"] == \
        str(shot / "tex" / "rock_albedo.png")
    assert {u["input"] for u in albedo["uses"]} == {"diffuseColor", "opacity"}
    # Another protocol, or a request that is none, is refused in the protocol's words.
    status, out, _ = alone(request(shot / "shot.usda").replace('"protocol": 1', '"protocol": 2'),
                           tmp_path)
    assert status == 2 and json.loads(out)["error"] == "protocol"
    assert "protocol 2" in json.loads(out)["detail"]


def test_both_carriers_give_the_same_answer(tmp_path):
    """In this interpreter (the package's carrier) and in a child `python -I` given the
    sources (the program's), the same stage's answer is the same, and a second read in one
    interpreter does not carry the first's files over."""
    from specconv._asset_reader import answer
    for stage in stage_and_document(tmp_path):
        status, out, err = as_the_program_carries_it(request(stage), tmp_path)
        assert status == 0, err
        assert answer(request(stage)) == (0, out.strip())
        assert answer(request(stage)) == (0, out.strip())


def test_the_program_and_the_package_plan_a_stage_alike(tmp_path, cli, monkeypatch):
    """`specconv asset --dry-run --json` (the child carrier) and `convert_asset(dry_run=True)`
    (in process): the same decisions, member for member."""
    monkeypatch.setenv("SPECCONV_USD_PYTHON", sys.executable)
    for stage in stage_and_document(tmp_path):
        out = tmp_path / "out"
        p = cli("asset", stage, "-o", out, "--dry-run", "--json")
        lines = [json.loads(line) for line in p.stdout.decode().splitlines()]
        assert lines and lines == specconv.convert_asset(stage, out, dry_run=True)


def test_modules_in_the_working_directory_are_never_imported_by_the_child(tmp_path):
    """A `json.py` and a `pxr.py` where the reader runs (each would leave a mark and break
    it) are not imported by the child the program runs (-I; in process, the import path is the
    caller's own). The test's own check: a child that keeps the working directory on its path
    imports them."""
    shot = tmp_path / "shot"
    shot.mkdir()
    build(shot, "basic")
    cwd = tmp_path / "stray"
    cwd.mkdir()
    mark = tmp_path / "imported"
    for module in ("json", "pxr", "MaterialX"):
        (cwd / (module + ".py")).write_text(
            "open(%r, 'a').write(%r)\nraise SystemExit(9)\n" % (str(mark), module + "\n"))
    status, out, err = as_the_program_carries_it(request(shot / "shot.usda"), cwd)
    assert status == 0 and json.loads(out)["protocol"] == 1, err
    assert not mark.exists(), mark.read_text()
    # Without -I, `python -c` puts the working directory first: the stray modules are run.
    status, _, _ = as_the_program_carries_it(request(shot / "shot.usda"), cwd, isolated=False)
    assert status == 9 and mark.read_text() == "json\n"
