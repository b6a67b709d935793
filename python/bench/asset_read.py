"""What reading a stage costs `specconv asset`, against usd-core's own open and traversal.

    python python/bench/asset_read.py [--prims 10000] [--rounds 3]
    python python/bench/asset_read.py --mtlx [--prims 10000] [--rounds 3]

One run, one machine, with the interpreter that has usd-core: a stage of --prims meshes bound to
one material that reads one texture (tests/asset_stages.py `many`), then the best of --rounds of
(a) usd-core opening the stage and traversing it (the reference), and (b) the reader of
`specconv asset` (python/specconv/_asset_reader, imported from this checkout: open, bindings,
material networks, uses) answering one `read` request, each in a process of its own. Prints both times and their ratio (b / a), never a bare timing.

With --mtlx, a MaterialX document of --prims nodes (tests/asset_mtlx.py `many`: a quarter of
them materials, each reading one image through a multiply), against MaterialX's own read of it
and a walk over every element (the reference).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
# The folder holding the reader package, imported as `_asset_reader` (without the compiled
# module, as the program's child `python -I` runs it).
PACKAGES = ROOT / "python" / "specconv"
sys.path.insert(0, str(PACKAGES))
import _asset_reader  # noqa: E402

READER = ("import sys\nsys.path.insert(0, sys.argv[1])\nfrom _asset_reader import main\n"
          "sys.exit(main())\n")
STAGES = ROOT / "tests" / "asset_stages.py"
DOCUMENTS = ROOT / "tests" / "asset_mtlx.py"
MX_REFERENCE = ("import sys\nimport MaterialX as mx\nd = mx.createDocument()\n"
                "mx.readFromXmlFile(d, sys.argv[1])\nprint(sum(1 for _ in d.traverseTree()))\n")
REFERENCE = ("import sys\nfrom pxr import Usd\ns = Usd.Stage.Open(sys.argv[1])\n"
             "print(sum(1 for _ in s.Traverse()))\n")


def best(cmd, rounds, request=None):
    times = []
    for _ in range(rounds):
        start = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, input=request)
        times.append(time.perf_counter() - start)
    return min(times)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--prims", type=int, default=10000)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--mtlx", action="store_true")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as d:
        builder, name, reference = ((DOCUMENTS, "many.mtlx", MX_REFERENCE) if a.mtlx
                                    else (STAGES, "many.usda", REFERENCE))
        code = ("import sys; sys.argv = ['', 'many', sys.argv[1]]; import runpy; "
                "g = runpy.run_path(%r); g['many'](sys.argv[2], %d)" % (str(builder), a.prims))
        subprocess.run([sys.executable, "-c", code, d, d], check=True)
        stage = os.path.join(d, name)
        ref = best([sys.executable, "-c", reference, stage], a.rounds)
        # The request `specconv asset --dry-run` sends (protocol.py).
        request = json.dumps(dict(protocol=_asset_reader.PROTOCOL, command="read", stage=stage,
                                  extract=None)).encode()
        ours = best([sys.executable, "-I", "-c", READER, str(PACKAGES)], a.rounds, request)
    print(json.dumps(dict(kind="mtlx" if a.mtlx else "usd", prims=a.prims,
                          reference_s=round(ref, 3), specconv_read_s=round(ours, 3),
                          ratio=round(ours / ref, 2))))


if __name__ == "__main__":
    main()
