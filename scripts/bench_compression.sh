#!/bin/sh
# Size and time of every compression the exr crate writes (and our ZIP at several levels), on
# the textures of scripts/bench_textures.sh: each converted at level 0 (2048², 36-band half,
# the default stack) with the release binary, best of $RUNS runs (default 2), times as ratios to
# `--compression none` of the same texture in the same run. Prints a Markdown table.
#   scripts/bench_compression.sh [THREADS] [TEXTURES…]
set -eu
cd "$(dirname "$0")/.."
threads=${1:-2}
runs=${RUNS:-2}
[ $# -gt 0 ] && shift
textures=${*:-photo flower painted mask noise}
data=target/bench-data
scripts/bench_textures.sh "$data"
bin=${SPECCONV_BIN:-target/release/specconv}
[ -n "${SPECCONV_BIN:-}" ] || cargo build --release --locked --bin specconv -q
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
methods=${METHODS:-none zip:1 zip zip:6 zip:9 zips rle piz pxr24 b44 b44a dwaa dwab}

seconds() { # best of $runs conversions of $1 with $2 (a method, or zip:LEVEL)
    method=${2%%:*}
    level=""
    [ "$method" != "$2" ] && level="--zip-level ${2#*:}"
    best=""
    for _ in $(seq "$runs"); do
        s=$(date +%s.%N)
        # shellcheck disable=SC2086
        "$bin" convert "$data/$1.tx" "$out/o.exr" --mip 0 -j "$threads" --force -q \
            --compression "$method" $level
        t=$(echo "$(date +%s.%N) - $s" | bc -l)
        if [ -z "$best" ] || [ "$(echo "$t < $best" | bc -l)" = 1 ]; then best=$t; fi
    done
    echo "$best"
}

printf '| texture |'
for m in $methods; do printf ' %s |' "$m"; done
printf '\n|---|'
for _ in $methods; do printf -- '---|'; done
printf '\n'
for tex in $textures; do
    printf '| %s |' "$tex"
    base=""
    for m in $methods; do
        t=$(seconds "$tex" "$m")
        mib=$(echo "$(stat -c %s "$out/o.exr") / 1048576" | bc -l)
        if [ -z "$base" ]; then
            base=$t
            printf ' %.1f MiB, %.2f s |' "$mib" "$t"
        else
            printf ' %.1f MiB, %.2f× |' "$mib" "$(echo "$t / $base" | bc -l)"
        fi
    done
    printf '\n'
done
echo "(times: best of $runs, as ratios to none; $threads threads; load: $(cut -d' ' -f1-3 /proc/loadavg))"
