"""The package's keywords held to the library's definitions (issue 58, item 1).

`convert`'s keywords and their stub are made from the definitions (`specconv.options()`);
the other functions' are written by hand in their Rust signatures and in the stub. These
tests hold them together: every function of the stub has the runtime's parameters, and a
keyword named as an option of the definitions takes that option's default, or is listed in
DIFFERENT with why it is another thing.
"""

import ast
import inspect
from pathlib import Path

import specconv

STUB = Path(specconv.__file__).with_name("_specconv.pyi")

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
