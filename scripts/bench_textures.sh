#!/bin/sh
# Makes the 2048×2048 8-bit MIP-mapped .tx textures the benchmarks convert, under
# target/bench-data (or $1), with oiiotool and maketx (Debian: openimageio-tools):
#   photo.tx    a real photograph: a 2048² crop of the 4032×3024 phone photo of a harbour
#               building site that ships with the `image` crate (examples/scaledown/test.jpg)
#   flower.tx   a real photograph: a hibiscus close-up, the `jpeg-decoder` crate's
#               benches/large_image.jpg (2268×1512), its central 1512² square scaled to 2048²
#   painted.tx  a stand-in for painted albedo: photo.tx median-filtered (9×9) and posterised
#               to 24 levels per channel (flat brushed areas, sharp edges)
#   mask.tx     a flat-colour mask: photo.tx median-filtered (25×25) and thresholded at 0.45
#               per channel (at most 8 colours)
#   noise.tx    uniform noise (incompressible)
# Both photographs come from crates in Cargo.lock, found through `cargo metadata`.
set -eu
cd "$(dirname "$0")/.."
out=${1:-target/bench-data}
mkdir -p "$out"
crate_dir() { # the source directory of the locked crate $1-$2
    cargo metadata --format-version 1 2>/dev/null |
        grep -o "\"manifest_path\":\"[^\"]*/$1-$2/Cargo.toml\"" | head -1 |
        sed 's/"manifest_path":"\(.*\)\/Cargo.toml"/\1/'
}
tx() { # $1 = name; the .tif made beforehand becomes $1.tx
    maketx "$out/$1.tif" --colorconvert sRGB sRGB -o "$out/$1.tx"
    rm "$out/$1.tif"
}
if [ ! -f "$out/photo.tx" ] || [ ! -f "$out/flower.tx" ]; then
    image=$(crate_dir image 0.24.9)
    jpeg=$(crate_dir jpeg-decoder 0.3.2)
    if [ -z "$image" ] || [ -z "$jpeg" ]; then
        echo "bench_textures.sh: the image and jpeg-decoder crates' sources are missing; run cargo fetch" >&2
        exit 1
    fi
    oiiotool "$image/examples/scaledown/test.jpg" --cut 2048x2048+992+488 -d uint8 -o "$out/photo.tif"
    oiiotool "$out/photo.tif" -o "$out/photo_src.tif"
    tx photo
    oiiotool "$jpeg/benches/large_image.jpg" --cut 1512x1512+378+0 --resize 2048x2048 -d uint8 -o "$out/flower.tif"
    tx flower
    oiiotool "$out/photo_src.tif" --median 9x9 --mulc 0.0902 -d uint8 -o "$out/painted_q.tif"
    oiiotool "$out/painted_q.tif" --mulc 11.087 -d uint8 -o "$out/painted.tif"
    rm "$out/painted_q.tif"
    tx painted
    oiiotool "$out/photo_src.tif" --median 25x25 --subc 0.45 --mulc 1000 --clamp:min=0:max=1 \
        --mulc 0.8 --addc 0.1 -d uint8 -o "$out/mask.tif"
    tx mask
    rm "$out/photo_src.tif"
fi
if [ ! -f "$out/noise.tx" ]; then
    oiiotool --pattern noise:type=uniform:min=0:max=1:seed=1 2048x2048 3 -d uint8 -o "$out/noise.tif"
    tx noise
fi
