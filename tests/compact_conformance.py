"""The numpy decoder (python/specconv/compact.py of this tree, not an installed one) on the
conformance texts of testdata/compact/hostile/ (tests/it/compact.rs compares its answers with
the library's and the C header's):

    compact_conformance.py LIMITS_JSON HOSTILE_DIR

LIMITS_JSON: the grammar's limits as the library states them (what the extension's
compact_limits() returns), given by the caller so that this tree's decoder runs without
building the extension. Prints a JSON object: per case, "refused" (the reason) or "bands" and
"values" (each texel of values/VALUES.txt decoded; NaN as null).
"""

import importlib.util
import json
import math
import os
import sys
import types

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def load_compact(limits):
    # The package without its extension: compact.py asks the extension for the limits only.
    package = types.ModuleType("specconv")
    package.__path__ = [os.path.join(ROOT, "python", "specconv")]
    extension = types.ModuleType("specconv._specconv")
    extension.compact_limits = lambda: dict(limits)
    sys.modules["specconv"], sys.modules["specconv._specconv"] = package, extension
    spec = importlib.util.spec_from_file_location(
        "specconv.compact", os.path.join(ROOT, "python", "specconv", "compact.py")
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules["specconv.compact"] = module
    spec.loader.exec_module(module)
    return module


def main():
    compact = load_compact(json.loads(sys.argv[1]))
    here = sys.argv[2]
    out = {}
    for line in open(os.path.join(here, "verdicts.txt")):
        name, verdict, *values = line.split()
        with open(os.path.join(here, name + ".txt"), encoding="utf-8", newline="") as f:
            text = f.read()
        try:
            header = compact.parse(text)
        except ValueError as e:
            out[name] = {"refused": str(e)}
            continue
        texels = []
        table = values[0] if values else "base"
        for row in open(os.path.join(here, "values", table + ".txt")).read().splitlines()[1:]:
            texels.append([float(v) for v in row.split(" = ")[0].split()])
        r = compact.decode(header, texels)
        out[name] = {
            "bands": header.wavelengths.tolist(),
            "values": [[None if math.isnan(v) else v for v in t] for t in r.tolist()],
        }
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
