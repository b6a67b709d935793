"""The package's costs, each against a reference measured in the same run (never a timed test):

- `uplift` of 10^6 colours from numpy (float32, the default model, bounded) against the Rust
  kernel on the same colours in Rust's memory, its output already written once
  (`specconv._specconv._kernel_seconds`: the kernel alone, no allocation or page faults);
- per colour against colour-science's `XYZ_to_sd_Otsu2018` (its own Otsu 2018 implementation
  and basis, on a sample of the same colours): with the defaults, and in the paper's setting
  that colour-science implements (hard switch, unbounded), from float32 and float64;
- `import specconv`: time and resident memory in a fresh interpreter, against `import numpy`.

Usage: python bench/uplift.py [--colours N] [--repeat R]. Prints one JSON object.
"""
import argparse
import json
import subprocess
import sys
import time
import warnings

import numpy as np


def best(f, repeat):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return min(times)


def import_cost(statement):
    """Seconds `statement` takes in a fresh interpreter, and the interpreter's peak resident
    memory after it (VmHWM, KiB: reset by exec, unlike getrusage's maxrss)."""
    code = (
        "import time; t = time.perf_counter(); {s}; t = time.perf_counter() - t; "
        "hwm = [l.split()[1] for l in open('/proc/self/status') if l.startswith('VmHWM')][0]; "
        "print(t, hwm)"
    ).format(s=statement)
    runs = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
            .stdout.split() for _ in range(5)]
    return min(float(r[0]) for r in runs), min(int(r[1]) for r in runs)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--colours", type=int, default=1_000_000)
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--colour-science", type=int, default=200, dest="cs")
    a = p.parse_args()

    import specconv
    from specconv import _specconv

    rng = np.random.default_rng(0)
    # Colours of real textures: sRGB in [0, 1] through OCIO, so every one is a reflectance.
    xyz = specconv.rgb_to_xyz(rng.uniform(0, 1, (a.colours, 3)).astype(np.float32),
                              "sRGB - Texture")
    specconv.uplift(xyz[:1000])  # build and cache the stack
    kernel = min(_specconv._kernel_seconds(xyz) for _ in range(a.repeat))
    python = best(lambda: specconv.uplift(xyz), a.repeat)
    # The paper's own setting (hard switch, unbounded), as colour-science implements it.
    paper = best(lambda: specconv.uplift(xyz, bounded=False, blend=0.0), a.repeat)
    # colour-science computes in float64: the same setting from float64 colours.
    xyz64 = xyz.astype(np.float64)
    paper64 = best(lambda: specconv.uplift(xyz64, bounded=False, blend=0.0), a.repeat)

    warnings.simplefilter("ignore")
    import colour

    sample = xyz[: a.cs].astype(np.float64)
    start = time.perf_counter()
    for c in sample:
        colour.XYZ_to_sd(c, method="Otsu 2018")
    cs_per = (time.perf_counter() - start) / len(sample)
    ours_per = python / a.colours

    bare_t, bare_kb = import_cost("pass")
    spec_t, spec_kb = import_cost("import specconv")
    np_t, np_kb = import_cost("import numpy")
    # The first call imports numpy (the extension's arrays) and builds the model's stack.
    first_t, first_kb = import_cost("import specconv; specconv.uplift([[0.2, 0.2, 0.2]])")
    print(json.dumps({
        "colours": a.colours,
        "kernel_s": kernel,
        "uplift_from_numpy_s": python,
        "throughput_ratio_numpy_vs_kernel": kernel / python,
        "colour_science_per_colour_s": cs_per,
        "specconv_per_colour_s": ours_per,
        "speedup_vs_colour_science": cs_per / ours_per,
        "paper_setting_per_colour_s": paper / a.colours,
        "paper_setting_speedup_vs_colour_science": cs_per / (paper / a.colours),
        "paper_setting_f64_per_colour_s": paper64 / a.colours,
        "paper_setting_f64_speedup_vs_colour_science": cs_per / (paper64 / a.colours),
        "import_specconv_s": spec_t,
        "import_numpy_s": np_t,
        "import_and_first_uplift_s": first_t,
        "interpreter_peak_mib": bare_kb / 1024,
        "import_specconv_peak_mib": spec_kb / 1024,
        "import_numpy_peak_mib": np_kb / 1024,
        "import_and_first_uplift_peak_mib": first_kb / 1024,
    }, indent=1))


if __name__ == "__main__":
    main()
