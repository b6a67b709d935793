#!/bin/sh
# Peak memory and wall time of converting each damaged input of testdata/broken (headers that
# promise 262661×15105 pixels in 2.2 KB (DWAB scanlines) and 1.2 KB (ZIP tiles), a file cut in
# its pixels, a first block that cannot be decoded, a file cut in its header), against
# converting a valid 64×48 file in the same run:
# each must fail at once, with memory near that of the valid conversion, leaving no file.
#   SPECCONV=target/debug/specconv scripts/damaged_inputs.sh
set -eu
cd "$(dirname "$0")/.."
bin=${SPECCONV:-target/debug/specconv}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
measure() { # $1 = input; prints exit code, seconds, peak RSS in MB and what is left
    /usr/bin/time -v "$bin" --force "$1" "$dir/out.exr" >"$dir/stdout" 2>"$dir/stderr" || true
    code=$(sed -n 's/.*Exit status: //p' "$dir/stderr")
    wall=$(sed -n 's/.*Elapsed (wall clock) time (h:mm:ss or m:ss): //p' "$dir/stderr")
    kb=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$dir/stderr")
    left=$(ls -A "$dir" | grep -v -e '^stdout$' -e '^stderr$' | tr '\n' ' ')
    printf '%-28s exit %s  %8s  %6.1f MB  left: %s\n' "$(basename "$1")" "$code" "$wall" \
        "$(echo "$kb / 1024" | bc -l)" "${left:-nothing}"
    grep 'specconv: error' "$dir/stderr" | cut -c1-160 || true
    rm -f "$dir/out.exr"
}
measure testdata/layout/window.exr
for f in lying_window.exr lying_tiles.exr truncated_pixels.exr garbled_first_block.exr truncated.exr; do
    measure "testdata/broken/$f"
done
