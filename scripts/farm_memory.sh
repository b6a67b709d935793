#!/bin/sh
# Peak resident memory of one conversion (-j 1, default settings) against the input's pixel
# count, with /usr/bin/time -v, for the farm's memory request (crates/farm: MEMORY_BASE_MIB,
# MEMORY_BYTES_PER_PIXEL). Prints each size, then the least-squares line through them.
#   SPECCONV=target/release/specconv scripts/farm_memory.sh [SIZES…]
set -eu
bin=${SPECCONV:-target/release/specconv}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
[ $# -gt 0 ] || set -- 256 1024 2048 4096
for s in "$@"; do
    oiiotool --pattern noise:min=0:max=1 "${s}x$s" 3 -d uint8 -o "$dir/in.png"
    kib=$(/usr/bin/time -v "$bin" -q -j 1 --force "$dir/in.png" "$dir/out.exr" 2>&1 |
        sed -n 's/.*Maximum resident set size (kbytes): //p')
    echo "$((s * s)) $kib"
done >"$dir/points"
awk '{printf "%dx%d px: %.0f MiB peak\n", sqrt($1), sqrt($1), $2 / 1024}' "$dir/points"
awk '{n++; x += $1; y += $2 * 1024; xx += $1 * $1; xy += $1 * $2 * 1024}
     END {b = (n * xy - x * y) / (n * xx - x * x); a = (y - b * x) / n;
          printf "peak ≈ %.0f MiB + %.1f bytes per pixel of the input\n", a / 1048576, b}' "$dir/points"
