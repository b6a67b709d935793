"""The CPU cost of `convert --layout compact` against `convert` (the spectral layout) of the same
texture, measured in one run (docs/compact.md, "Cost"):

  python python/bench/compact_cost.py SPECCONV [SPECCONV ...] --textures T.tx [T.tx ...] [--repeats 3]

For each texture, each binary converts it both ways `--repeats` times, interleaved (binary,
layout, repeat), each run timed by its own CPU time (user + system, from wait4's rusage) and
wall time. Prints, per texture and binary, the range of each and the ratio compact / spectral
of the medians, as JSON lines; with two or more binaries, also each binary's compact CPU time
against the first's. Asserts nothing.
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile
import time


def timed(cmd):
    """(cpu seconds, wall seconds) of one run of `cmd`."""
    start = time.monotonic()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.monotonic() - start
    err = p.stderr.read().decode()
    p.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(cmd)} failed: {err}")
    return usage.ru_utime + usage.ru_stime, wall


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binaries", nargs="+")
    ap.add_argument("--textures", nargs="+", required=True)
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args()
    layouts = {"spectral": [], "compact": ["--layout", "compact"]}
    with tempfile.TemporaryDirectory() as work:
        for texture in a.textures:
            times = {(b, l): [] for b in a.binaries for l in layouts}
            for _ in range(a.repeats):
                for b in a.binaries:
                    for layout, args in layouts.items():
                        out = f"{work}/out.exr"
                        cmd = [b, "convert", "--progress", "never", texture, out, *args]
                        times[(b, layout)].append(timed(cmd))
                        os.remove(out)
            first = statistics.median(c for c, _ in times[(a.binaries[0], "compact")])
            for b in a.binaries:
                row = {"texture": os.path.basename(texture), "binary": b}
                for layout in layouts:
                    t = times[(b, layout)]
                    row[f"{layout}_cpu_s"] = [round(min(c for c, _ in t), 2), round(max(c for c, _ in t), 2)]
                    row[f"{layout}_wall_s"] = [round(min(w for _, w in t), 2), round(max(w for _, w in t), 2)]
                cpu = {l: statistics.median(c for c, _ in times[(b, l)]) for l in layouts}
                row["compact_over_spectral_cpu"] = round(cpu["compact"] / cpu["spectral"], 2)
                row["compact_cpu_over_first_binary"] = round(cpu["compact"] / first, 2)
                row["load"] = round(os.getloadavg()[0], 1)
                print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
