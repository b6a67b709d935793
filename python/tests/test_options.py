"""specconv.convert's keywords against the library's one description of a conversion
(specconv.options(), the same table the command line is checked against): every option is a
keyword, every keyword is an option or the front-end's own, defaults are the library's, the stub
says the same, and a choice takes exactly the library's names and spellings."""
import ast
import inspect
import pathlib

import pytest

import specconv

# convert's keywords that are not options of a conversion: what to convert, where to, and how
# the call reports.
FRONT_END = {"inputs", "outputs", "output_template", "update", "errors", "progress"}

OPTIONS = {o["name"]: o for o in specconv.options()}


def as_text(name, value):
    """A keyword's default in the library's text form (Options::text)."""
    if value is None:
        return None
    if name == "tile":
        return "%dx%d" % value
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def stub_keywords():
    """convert's keywords, defaults and Literal choices as the stub (_specconv.pyi) writes them."""
    stub = pathlib.Path(specconv.__file__).with_name("_specconv.pyi")
    tree = ast.parse(stub.read_text())
    fn = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "convert")
    out = {}
    for arg, default in zip(fn.args.kwonlyargs, fn.args.kw_defaults):
        literals = [
            n.value
            for n in ast.walk(arg.annotation)
            if isinstance(n, ast.Constant) and isinstance(n.value, str)
        ] if "Literal" in ast.unparse(arg.annotation) else None
        out[arg.arg] = (ast.literal_eval(default) if default is not None else None, literals)
    return out


def test_the_runtime_takes_the_front_ends_keywords_and_the_options():
    sig = inspect.signature(specconv.convert)
    named = {n for n, p in sig.parameters.items() if p.kind != inspect.Parameter.VAR_KEYWORD}
    assert named == FRONT_END
    assert any(p.kind == inspect.Parameter.VAR_KEYWORD for p in sig.parameters.values())


def test_the_stub_says_what_the_library_defines():
    stub = stub_keywords()
    assert set(stub) - FRONT_END == set(OPTIONS)
    for name, option in OPTIONS.items():
        default, literals = stub[name]
        if name == "blend":
            assert default == pytest.approx(float(option["default"]))
        else:
            assert as_text(name, default) == option["default"], name
        if literals is not None and name != "tile":  # tile's one word: "scanline"
            assert option["choices"] is not None, name
            spellings = set(option["choices"]) | set(option["aliases"])
            assert set(option["choices"]) <= set(literals) <= spellings, name


def test_an_unknown_keyword_is_a_type_error_that_lists_the_options(tmp_path):
    with pytest.raises(TypeError) as e:
        specconv.convert(tmp_path / "a.png", tmp_path / "a.exr", fixnan="box3")
    assert "fixnan" in str(e.value) and "non_finite" in str(e.value)


def test_every_default_given_explicitly_is_accepted(tmp_path):
    """Each option at the stub's default gets as far as the missing input."""
    missing = tmp_path / "missing.png"
    for name, (default, _) in stub_keywords().items():
        if name in FRONT_END:
            continue
        with pytest.raises(specconv.Error) as e:
            specconv.convert(missing, tmp_path / "out.exr", **{name: default})
        assert not isinstance(e.value, specconv.OptionError), (name, str(e.value))


def test_none_is_refused_where_an_option_cannot_be_unset(tmp_path):
    # tile=None meant scanlines once; now scanlines are tile="scanline".
    with pytest.raises(specconv.OptionError, match="tile cannot be None"):
        specconv.convert(tmp_path / "a.png", tmp_path / "a.exr", tile=None)
    with pytest.raises(specconv.OptionError, match="bounded takes True or False"):
        specconv.convert(tmp_path / "a.png", tmp_path / "a.exr", bounded=1)
    with pytest.raises(specconv.OptionError, match="threads must be a whole number"):
        specconv.convert(tmp_path / "a.png", tmp_path / "a.exr", threads=-1)


@pytest.mark.parametrize(
    "name", sorted(n for n, o in OPTIONS.items() if o["choices"] and n != "mip")
)
def test_a_choice_takes_the_librarys_names_and_no_other(tmp_path, name):
    option = OPTIONS[name]
    missing = tmp_path / "missing.png"
    spellings = option["choices"] + option["aliases"]
    if name == "method":  # building jakob2019's tables or a PCA model takes minutes
        spellings = [option["default"]]
    for spelling in spellings:
        # A valid name gets as far as the input, which does not exist.
        with pytest.raises(specconv.Error) as e:
            specconv.convert(missing, tmp_path / "out.exr", **{name: spelling})
        assert "unknown" not in str(e.value), (name, spelling, str(e.value))
    with pytest.raises(specconv.OptionError) as e:
        specconv.convert(missing, tmp_path / "out.exr", **{name: "bogus"})
    message = str(e.value)
    assert "bogus" in message and all(c in message for c in option["choices"]), message


@pytest.mark.parametrize("keywords, says", [
    ({"tile": (1, 2, 3)}, "tile takes (width, height) or 'scanline', not tuple"),
    ({"tile": "12x"}, "'12x' is neither a tile size WxH nor `scanline`"),
    ({"zip_level": True}, "zip_level takes a whole number, not bool"),
    ({"threads": 2**70}, "threads must be a whole number from 0"),
    ({"blend": "0.1"}, "blend takes a number, not str"),
    ({"alpha": True}, "unknown alpha 'true'"),
    ({"mip": "banana"}, "unknown MIP levels 'banana'"),
    ({"colorspace": 3}, "colorspace takes a str, not int"),
])
def test_a_value_of_the_wrong_kind_is_an_option_error_naming_the_keyword(tmp_path, keywords, says):
    with pytest.raises(specconv.OptionError) as e:
        specconv.convert(tmp_path / "a.png", tmp_path / "a.exr", **keywords)
    assert says in str(e.value), str(e.value)


def test_errors_takes_raise_or_record_in_convert_and_convert_asset(tmp_path):
    """One reading of `errors=` for both batch functions: anything else is refused by name,
    before any input or stage is read."""
    for call in (
        lambda: specconv.convert(["missing.png"], str(tmp_path), errors="ignore"),
        lambda: specconv.convert_asset("missing.usda", str(tmp_path), errors="ignore"),
    ):
        with pytest.raises(specconv.OptionError, match="'raise' or 'record', not 'ignore'"):
            call()
    assert list(tmp_path.iterdir()) == []
