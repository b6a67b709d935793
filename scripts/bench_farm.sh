#!/bin/sh
# The farm path's overhead: 64 textures converted through a Slurm job array of TASKS tasks of
# one CPU each (`specconv farm submit --wait`) against one local batch with as many threads
# (`specconv convert -j TASKS`), alternating, median of 3 each; prints both and their ratio.
# Needs a cluster (scripts/slurm-cluster.sh start) whose nodes see this directory.
#   SPECCONV=target/release/specconv scripts/bench_farm.sh [TASKS [SIZE [COUNT]]]
set -eu
bin=$(realpath "${SPECCONV:-target/release/specconv}")
tasks=${1:-2}
size=${2:-512}
count=${3:-64}
dir=$(mktemp -d "${BENCH_DIR:-$PWD/target}/bench-farm.XXXXXX")
trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/in" "$dir/local" "$dir/farm"
# Textures of uneven sizes (SIZE², SIZE×SIZE/2, SIZE/2 × SIZE/2 in turn), smooth colour with
# noise, as painted textures are.
i=0
while [ "$i" -lt "$count" ]; do
    case $((i % 3)) in
        0) res="${size}x$size" ;;
        1) res="${size}x$((size / 2))" ;;
        *) res="$((size / 2))x$((size / 2))" ;;
    esac
    oiiotool --pattern "fill:topleft=0.$((i % 9 + 1)),0.3,0.2:topright=0.2,0.6,0.$((i % 7 + 1)):bottomleft=0.1,0.2,0.7:bottomright=0.8,0.8,0.6" \
        "$res" 3 --pattern noise:min=-0.05:max=0.05 "$res" 3 --add -d uint8 \
        -o "$dir/in/tex$i.png"
    i=$((i + 1))
done
pixels=$(for f in "$dir"/in/*.png; do oiiotool --info "$f"; done | sed -n 's/.* \([0-9]*\) x \([0-9]*\),.*/\1 \2/p' | awk '{s += $1 * $2} END {print s}')
now() { date +%s.%N; }
: >"$dir/l"
: >"$dir/f"
for _ in 1 2 3; do
    rm -f "$dir"/local/*.exr
    t0=$(now)
    "$bin" convert -q -j "$tasks" "$dir"/in/*.png -o "$dir/local"
    t1=$(now)
    echo "$t1 - $t0" | bc -l >>"$dir/l"
    rm -rf "$dir"/farm/*
    t0=$(now)
    "$bin" farm submit "$dir"/in/*.png -o "$dir/farm" --tasks "$tasks" --cpus-per-task 1 --wait >/dev/null
    t1=$(now)
    echo "$t1 - $t0" | bc -l >>"$dir/f"
done
median() { sort -g "$1" | sed -n 2p; }
l=$(median "$dir/l")
f=$(median "$dir/f")
printf '%s textures (%s Mpixel), %s tasks × 1 CPU against one batch with -j %s: local %.2f s, farm %.2f s, ratio %.3f\n' \
    "$count" "$(echo "$pixels / 1000000" | bc -l | cut -c1-5)" "$tasks" "$tasks" "$l" "$f" "$(echo "$f / $l" | bc -l)"
