#!/bin/sh
# Planning at scale: N input paths on standard input, half of them small PNGs in one folder and
# half missing, checked as a batch and as a farm job, against a reference measured in the same
# run (one `stat` of every input and every output name, from Python: the floor of any check).
#
#   plan      `specconv - -o OUT`, OUT holding the last input's output already (not made by
#             specconv): the whole plan is checked, then refused (exit 2) before anything is
#             read or written
#   missing   `specconv - -o OUT2` with every input missing, as issue 31 timed it (`seq N | sed
#             's/$/.png/'`): the plan, then each input failing on its own (exit 1)
#   farm      `specconv farm submit - -o OUT3 --tasks 8 --dry-run`: the plan, every input weighed
#             (its image header read), the tasks printed (exit 0)
#
# Prints, per command, the median wall time of RUNS runs (outputs to /dev/null), the ratio to
# the reference, and the stat-family system calls of one more run under `strace -f -c`.
# STRACE=0 leaves the count out (a quadratic binary makes N² calls, which strace slows ~5×).
#   SPECCONV=target/debug/specconv RUNS=3 scripts/bench_plan.sh [N]
set -eu
bin=$(realpath "${SPECCONV:-target/debug/specconv}")
n=${1:-100000}
runs=${RUNS:-3}
dir=$(mktemp -d "${BENCH_DIR:-$PWD/target}/bench-plan.XXXXXX")
trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/in" "$dir/out" "$dir/out2" "$dir/out3"
oiiotool --pattern constant:color=0.5,0.4,0.3 4x4 3 -d uint8 -o "$dir/tiny.png"
# The list (absolute paths: in/e0.png, in/m1.png, …), the existing half written, and a
# list of N missing names alone.
python3 - "$dir" "$n" <<'EOF'
import os, sys
d, n = sys.argv[1], int(sys.argv[2])
tiny = open(os.path.join(d, "tiny.png"), "rb").read()
with open(os.path.join(d, "list"), "w") as f, open(os.path.join(d, "missing"), "w") as g:
    for i in range(n):
        kind = "e" if i % 2 == 0 else "m"
        p = os.path.join(d, "in", f"{kind}{i}.png")
        if kind == "e":
            with open(p, "wb") as t:
                t.write(tiny)
        f.write(p + "\n")
        g.write(os.path.join(d, "gone", f"{i + 1}.png") + "\n")
EOF
last=$(tail -n 1 "$dir/list")
last=$(basename "$last" .png)
: >"$dir/out/${last}_spectral.exr"
reference() {
    python3 - "$dir" <<'EOF'
import os, sys
d = sys.argv[1]
for line in open(os.path.join(d, "list")):
    p = line.rstrip("\n")
    for q in (p, os.path.join(d, "out", os.path.basename(p)[:-4] + "_spectral.exr")):
        try:
            os.stat(q)
        except FileNotFoundError:
            pass
EOF
}
plan() { "$bin" - -o "$dir/out" <"$dir/list"; }
missing() { "$bin" - -o "$dir/out2" <"$dir/missing"; }
farm() { "$bin" farm submit - -o "$dir/out3" --tasks 8 --dry-run <"$dir/list"; }
now() { date +%s.%N; }
# One timed run of $1, its exit status checked against $2.
timed() {
    t0=$(now)
    set +e
    "$1" >/dev/null 2>"$dir/err"
    rc=$?
    set -e
    t1=$(now)
    if [ "$rc" -ne "$2" ]; then
        echo "$1: exit $rc, expected $2:" >&2
        tail -n 3 "$dir/err" >&2
        exit 1
    fi
    echo "$t1 - $t0" | bc -l
}
median() { sort -g | awk '{v[NR] = $1} END {print v[int((NR + 1) / 2)]}'; }
# The stat-family system calls of one run of $1 (plan, missing or farm) under strace.
stats() {
    if [ "${STRACE:-1}" = 0 ]; then
        echo "-"
        return
    fi
    case $1 in
        plan) set -- "$dir/list" - -o "$dir/out" ;;
        missing) set -- "$dir/missing" - -o "$dir/out2" ;;
        farm) set -- "$dir/list" farm submit - -o "$dir/out3" --tasks 8 --dry-run ;;
    esac
    list=$1
    shift
    set +e
    strace -f -c -o "$dir/strace" "$bin" "$@" <"$list" >/dev/null 2>&1
    set -e
    awk '$NF ~ /^(statx|newfstatat|stat|lstat|fstat|fstatat64)$/ {s += $4} END {print s + 0}' "$dir/strace"
}
: >"$dir/times"
for k in $(seq "$runs"); do
    echo "reference $(timed reference 0)" >>"$dir/times"
    echo "plan $(timed plan 2)" >>"$dir/times"
    echo "missing $(timed missing 1)" >>"$dir/times"
    echo "farm $(timed farm 0)" >>"$dir/times"
done
ref=$(awk '$1 == "reference" {print $2}' "$dir/times" | median)
load=$(cut -d' ' -f1 /proc/loadavg)
printf '%s inputs (%s existing), %s runs each, load %s; reference (2 stat a file, Python) %.3f s\n' \
    "$n" "$(((n + 1) / 2))" "$runs" "$load" "$ref"
for c in plan missing farm; do
    t=$(awk -v c="$c" '$1 == c {print $2}' "$dir/times" | median)
    printf '%-8s %7.3f s  %5.2f× reference  %9s stat-family calls\n' \
        "$c" "$t" "$(echo "$t / $ref" | bc -l)" "$(stats "$c")"
done
