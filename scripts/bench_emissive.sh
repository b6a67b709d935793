#!/bin/sh
# Conversion time of an HDR texture with --emissive against reflectance mode, measured in the
# same run (alternating, median of 3 each): prints both and their ratio.
#   SPECCONV=target/release/specconv scripts/bench_emissive.sh [SIZE [CONVERT OPTIONS…]]
# Options (e.g. --unbounded, -d float) apply to both modes.
set -eu
bin=${SPECCONV:-target/release/specconv}
size=${1:-2048}
[ $# -gt 0 ] && shift
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
# A smooth HDR gradient: linear Rec.709 colours from black to 16 (values above 1 in 90 %).
oiiotool --pattern fill:topleft=0,0,0:topright=8,2,1:bottomleft=0.5,4,8:bottomright=16,16,16 \
    "${size}x$size" 3 -d half -o "$dir/hdr.exr"
seconds() {
    "$bin" --ocio aces --colorspace 'Linear Rec.709 (sRGB)' --force --json "$@" \
        "$dir/hdr.exr" "$dir/out.exr" | sed 's/.*"seconds":\([0-9.e-]*\).*/\1/'
}
: >"$dir/r"
: >"$dir/e"
for _ in 1 2 3; do
    seconds "$@" >>"$dir/r"
    seconds --emissive "$@" >>"$dir/e"
done
median() { sort -g "$1" | sed -n 2p; }
r=$(median "$dir/r")
e=$(median "$dir/e")
echo "${size}x$size HDR, $(nproc) threads, options '$*': reflectance ${r} s, --emissive ${e} s, ratio $(echo "$e / $r" | bc -l | cut -c1-4)"
