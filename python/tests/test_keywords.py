"""The package's keywords held to the library's definitions (issue 58, item 1).

`convert`'s keywords and their stub are made from the definitions (`specconv.options()`);
the other functions' are written by hand in their Rust signatures (pyo3 takes a signature
only as written) and in the stub. These tests hold them together: every function of the
stub has the runtime's parameters; a keyword named as an option of the definitions takes
that option's default, or is listed in DIFFERENT with why it is another thing; and a
keyword of a function that does a command's job takes the default of that command's flag of
the same name (docs/commands.md, made from the command line's definitions), or is listed in
FRONT_ENDS_DIFFER with why.
"""

import ast
import inspect
import re
from pathlib import Path

import specconv

STUB = Path(specconv.__file__).with_name("_specconv.pyi")
# Every command's flags with their defaults, made from the command line's definitions.
COMMANDS = Path(__file__).resolve().parents[2] / "docs" / "commands.md"

# The functions that do what a command does: function -> command.
SAME_JOB = {"train": "train", "evaluate": "eval", "convert_asset": "asset"}

# (function, keyword): why its default is not its command's flag's.
FRONT_ENDS_DIFFER = {
    ("evaluate", "bounded"): "eval measures the method as named (the paper's Table 1) unless "
    "--bounded; evaluate() measures what convert writes (the option's default): the team's call",
}

# (function, keyword): why it is not the option of that name.
DIFFERENT = {
    ("write_spectral", "alpha"): "the alpha channel's values, not how alpha is read",
    ("train", "bands"): "the grid a model is trained on, not an output grid",
}


def stub_functions():
    """(name, ast.FunctionDef) of every function and method in the stub."""
    tree = ast.parse(STUB.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef):
            yield node.name, node


def stub_keywords(node):
    """{parameter: default (a literal, or Ellipsis where none is written)}."""
    args = node.args
    positional = args.posonlyargs + args.args
    defaults = [None] * (len(positional) - len(args.defaults)) + list(args.defaults)
    out = {}
    for a, d in list(zip(positional, defaults)) + list(zip(args.kwonlyargs, args.kw_defaults)):
        out[a.arg] = ast.literal_eval(d) if d is not None else Ellipsis
    return out


def runtime(name):
    for owner in (specconv, specconv.Model):
        f = getattr(owner, name, None)
        if callable(f):
            return f
    return None


def as_python(option, text):
    """An option's default text (`specconv.options()`) as a Python value."""
    if text is None:
        return None
    if text in ("true", "false"):
        return text == "true"
    if "x" in text and all(p.isdigit() for p in text.split("x")):
        return tuple(int(p) for p in text.split("x"))
    try:
        return float(text)
    except ValueError:
        return text


def test_the_stub_has_the_runtime_s_parameters_and_defaults():
    checked = 0
    for name, node in stub_functions():
        f = runtime(name)
        if f is None or name.startswith("_") or name == "convert":
            continue
        try:
            signature = inspect.signature(f)
        except (TypeError, ValueError):
            continue
        written = stub_keywords(node)
        written.pop("self", None)
        params = {p: v.default for p, v in signature.parameters.items()
                  if v.kind not in (v.VAR_KEYWORD, v.VAR_POSITIONAL) and p != "self"}
        wanted = {p for p in written if node.args.kwarg is None or p != node.args.kwarg.arg}
        assert set(params) == wanted, f"{name}: runtime {sorted(params)}, stub {sorted(wanted)}"
        for p, default in params.items():
            # pyo3 shows a default it cannot write as a literal as `...`.
            if default is inspect.Parameter.empty or default is Ellipsis:
                continue
            assert written[p] == default, f"{name}({p}=): runtime {default!r}, stub {written[p]!r}"
        checked += 1
    assert checked >= 10, checked


def test_a_keyword_named_as_an_option_takes_its_default():
    options = {o["name"]: as_python(o["name"], o["default"]) for o in specconv.options()}
    seen = set()
    checked = 0
    for name, node in stub_functions():
        if name == "convert":
            continue
        for keyword, default in stub_keywords(node).items():
            if keyword not in options or default is Ellipsis:
                continue
            if (name, keyword) in DIFFERENT:
                seen.add((name, keyword))
                assert default != options[keyword], f"{name}({keyword}=) is the option now"
                continue
            assert default == options[keyword], (
                f"{name}({keyword}={default!r}): the option's default is {options[keyword]!r}"
            )
            checked += 1
    assert seen == set(DIFFERENT), set(DIFFERENT) - seen
    assert checked >= 10, checked


def command_defaults(command):
    """{keyword: default} of a command's flags, from docs/commands.md (made from the
    definitions): the long name with `_` for `-`, flags without a default left out."""
    section = re.search(rf"^##+ `specconv {command}`\n(.*?)(?=^##|\Z)", COMMANDS.read_text(),
                        re.S | re.M)
    assert section, command
    out = {}
    for row in re.findall(r"^\| `([^`]*)` \| ([^|]*) \|", section.group(1), re.M):
        flag, default = row[0].split(" ")[0], row[1].strip()
        if flag.split("/")[-1].startswith("--") and default:
            out[flag.split("/")[-1][2:].replace("-", "_")] = as_python(None, default)
    return out


def test_a_keyword_named_as_its_command_s_flag_takes_its_default():
    checked = 0
    seen = set()
    functions = dict(stub_functions())
    for function, command in SAME_JOB.items():
        flags = command_defaults(command)
        assert flags, command
        for keyword, default in stub_keywords(functions[function]).items():
            if keyword not in flags or default in (Ellipsis, None):
                continue
            if (function, keyword) in FRONT_ENDS_DIFFER:
                seen.add((function, keyword))
                assert default != flags[keyword], f"{function}({keyword}=) is the flag's now"
                continue
            assert default == flags[keyword], (
                f"{function}({keyword}={default!r}): `specconv {command}` defaults to "
                f"{flags[keyword]!r}"
            )
            checked += 1
    assert seen == set(FRONT_ENDS_DIFFER), set(FRONT_ENDS_DIFFER) - seen
    assert checked >= 5, checked
