"""What reading a stage costs `specconv asset`, against usd-core's own open and traversal.

    python python/bench/asset_read.py [--prims 10000] [--rounds 3]

One run, one machine, with the interpreter that has usd-core: a stage of --prims meshes bound to
one material that reads one texture (tests/asset_stages.py `many`), then the best of --rounds of
(a) usd-core opening the stage and traversing it (the reference), and (b) the reader script of
`specconv asset` (crates/asset/src/read_stage.py: open, bindings, material networks, uses), each
in a process of its own. Prints both times and their ratio (b / a), never a bare timing.
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
READER = ROOT / "crates" / "asset" / "src" / "read_stage.py"
STAGES = ROOT / "tests" / "asset_stages.py"
REFERENCE = ("import sys\nfrom pxr import Usd\ns = Usd.Stage.Open(sys.argv[1])\n"
             "print(sum(1 for _ in s.Traverse()))\n")


def best(cmd, rounds):
    times = []
    for _ in range(rounds):
        start = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        times.append(time.perf_counter() - start)
    return min(times)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--prims", type=int, default=10000)
    ap.add_argument("--rounds", type=int, default=3)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as d:
        code = ("import sys; sys.argv = ['', 'many', sys.argv[1]]; import runpy; "
                "g = runpy.run_path(%r); g['many'](sys.argv[2], %d)" % (str(STAGES), a.prims))
        subprocess.run([sys.executable, "-c", code, d, d], check=True)
        stage = os.path.join(d, "many.usda")
        inputs = json.dumps(["diffuseColor"])
        ref = best([sys.executable, "-c", REFERENCE, stage], a.rounds)
        ours = best([sys.executable, str(READER), "read", stage, inputs], a.rounds)
    print(json.dumps(dict(prims=a.prims, usd_open_traverse_s=round(ref, 3),
                          specconv_read_s=round(ours, 3), ratio=round(ours / ref, 2))))


if __name__ == "__main__":
    main()
