#!/usr/bin/env bash
# Runs the same set of conversions with two specconv binaries and compares what they write:
# every output byte for byte (cmp), every --json record and every report line on standard
# error (times left out). For refactors that must not change a conversion:
#   scripts/same_outputs.sh OLD_BINARY NEW_BINARY
# Exit status 0 when everything is the same.
set -euo pipefail
old=$(realpath "$1"); new=$(realpath "$2")
images="$(cd "$(dirname "$0")/../testdata/images" && pwd)"
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT

# name | arguments (INPUT OUTPUT or -o DIR forms; OUT stands for the side's folder)
cases=(
  "default|$images/srgb8.png OUT/a.exr"
  "mip-levels|$images/float_alpha.tx OUT/a.exr"
  "emissive|$images/srgba8.tx OUT/a.exr --emissive"
  "float|$images/half_tiled_alpha.exr OUT/a.exr -d float"
  "bands-smits|$images/rgb16.tif OUT/a.exr --bands 400:700:5 --method smits1999"
  "piz-scanline|$images/photo.jpg OUT/a.exr --compression piz --scanline"
  "photometric|$images/sky.hdr OUT/a.exr --emissive --emission-units photometric -d float"
  "photometric-half|$images/sky.hdr OUT/a.exr --emissive --emission-units photometric"
  "colour-rounding|$images/float_scanline.exr OUT/a.exr --half-rounding colour --unbounded"
  "tile-level|$images/srgb8.png OUT/a.exr --mip 0 --tile 32 16 --zip-level 6 -j 1"
  "jakob|$images/rgba16.png OUT/a.exr --method jakob2019 --alpha straight"
  "shard-0|$images/srgb8.png $images/rgb16.png $images/photo.jpg -o OUT --json --shard 0/2"
  "shard-1|$images/srgb8.png $images/rgb16.png $images/photo.jpg -o OUT --json --shard 1/2"
  "batch-update|$images/srgb8.png $images/rgb16.png $images/srgba8.tx -o OUT --json -u"
  "batch-exists|$images/srgb8.png $images/rgb16.png -o OUT --json"
  "scanline-mip|$images/float_alpha.tx OUT/b.exr --scanline --json"
  "raw|$images/srgb8.png OUT/a.exr --colorspace Raw"
  "zip-level|$images/srgb8.png OUT/a.exr --compression piz --zip-level 4"
  "threads|$images/srgb8.png OUT/a.exr -j 0"
  "spectral-alpha|$images/srgba8.tx OUT/s.exr"
  "spectral-emissive|$images/sky.hdr OUT/e.exr --emissive"
  "to-rgb|to-rgb OUT/s.exr OUT/r1.exr"
  "to-rgb-a|to-rgb OUT/s.exr OUT/r2.exr --illuminant A --colorspace ACEScg"
  "to-rgb-emissive|to-rgb OUT/e.exr OUT/r3.exr"
  "to-rgb-exists|to-rgb OUT/s.exr OUT/r1.exr"
  "to-rgb-own-light|to-rgb OUT/e.exr OUT/r4.exr --illuminant D50"
  "preview|preview OUT/s.exr -o OUT/p1.png --bounces 2"
  "preview-diff|preview OUT/s.exr -o OUT/p2.png --bounces 3 --diff-rgb --illuminant A --json"
  "preview-emissive|preview OUT/e.exr -o OUT/p3.png"
)
status=0
for side in old new; do mkdir -p "$work/$side"; done
for c in "${cases[@]}"; do
  name=${c%%|*}; args=${c#*|}
  for side in old new; do
    bin=${!side}
    # shellcheck disable=SC2086
    progress="--progress never"; case $args in to-rgb*|preview*) progress="" ;; esac
    # shellcheck disable=SC2086
    (cd "$work/$side" && SPECCONV_CACHE_DIR="$work/cache-$side" "$bin" ${args//OUT/$work/$side} $progress \
      > "$work/$side/$name.json" 2> "$work/$side/$name.err"; echo $? > "$work/$side/$name.rc") || true
    sed -i -E 's/"seconds":[0-9.e-]+/"seconds":_/g' "$work/$side/$name.json"
    sed -i -E 's/[0-9]+\.[0-9]+ s\b/_ s/g; s/in [0-9.]+ (s|ms|min)/in _/g' "$work/$side/$name.err"
    sed -i "s|$work/$side|OUT|g" "$work/$side/$name.json" "$work/$side/$name.err"
  done
  for f in json err rc; do
    if ! cmp -s "$work/old/$name.$f" "$work/new/$name.$f"; then
      echo "DIFFERENT $name.$f"; diff "$work/old/$name.$f" "$work/new/$name.$f" | head -5 || true; status=1
    fi
  done
  for out in "$work"/old/*.exr "$work"/old/*.png; do
    [ -e "$out" ] || continue
    o=$(basename "$out")
    if ! cmp -s "$out" "$work/new/$o"; then echo "DIFFERENT $name: $o"; status=1; fi
  done
  # Single outputs are re-made per case; batches keep theirs for the next (-u) case.
  rm -f "$work"/old/a.exr "$work"/new/a.exr
  echo "compared $name (exit $(cat "$work/new/$name.rc"))"
  # Two binaries that both fail alike (one without libspecconv_oiio.so beside it, say) would
  # compare as the same: the first case must convert on both sides.
  if [ "$name" = default ]; then
    for side in old new; do
      if [ "$(cat "$work/$side/default.rc")" != 0 ]; then
        echo "the $side binary did not convert the first case:" >&2
        cat "$work/$side/default.err" >&2
        exit 2
      fi
    done
  fi
done
exit $status
