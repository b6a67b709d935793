#!/bin/sh
# Makes the small test images under testdata/ with oiiotool and maketx
# (Debian: openimageio-tools). Deterministic: noise is seeded. Rerun after changing it
# and commit the results; tests compare the reader against `oiiotool --dumpdata`, so the
# exact pixel values here are not baked into any test.
set -eu
cd "$(dirname "$0")"
rm -rf images broken && mkdir images broken
cd images

# 61x47: odd sizes give partial edge tiles and non-power-of-two MIP chains.
SIZE=61x47
ramp() { # $1 = channels (3 or 4), then more oiiotool arguments
    nch=$1; shift
    oiiotool --pattern fill:topleft=0,0,0,1:topright=1,0,0,1:bottomleft=0,1,0,0.5:bottomright=0,0,1,0 $SIZE 4 \
        --pattern noise:type=uniform:min=-0.1:max=0.1:seed=7 $SIZE 4 --add \
        --ch "R,G,B$( [ "$nch" = 4 ] && echo ,A )" "$@"
}

# Display-referred integer files.
ramp 3 --clamp:min=0:max=1 -d uint8 -o srgb8.png
ramp 4 --clamp:min=0:max=1 -d uint8 -o srgba8.png
ramp 3 --clamp:min=0:max=1 -d uint16 -o rgb16.png
ramp 4 --clamp:min=0:max=1 -d uint16 -o rgba16.png
ramp 3 --clamp:min=0:max=1 -d uint8 --attrib Compression jpeg:95 -o photo.jpg
ramp 3 --clamp:min=0:max=1 -d uint16 --scanline -o rgb16.tif

# Scene-linear float files, with values above 1 and slightly below 0.
ramp 3 --mulc 4 -d half --scanline -o half_scanline.exr
ramp 4 --mulc 4 -d half --tile 16 16 -o half_tiled_alpha.exr
ramp 4 --mulc 4 -d float --tile 16 16 -o float_tiled_alpha.exr
ramp 3 --mulc 4 -d float --scanline -o float_scanline.exr
ramp 3 --mulc 4 --clamp:min=0 -o sky.hdr

# MIP-mapped textures, from an 8-bit and from a float source.
maketx srgba8.png --tile 16 16 -o srgba8.tx
maketx float_tiled_alpha.exr -d float --tile 16 16 -o float_alpha.tx

# Broken inputs for error tests.
cd ../broken
head -c 600 ../images/float_tiled_alpha.exr > truncated.exr
head -c 300 ../images/srgb8.png > truncated.png
printf 'this is not an image\n' > not_an_image.png
printf 'plain text with an extension no reader knows\n' > unknown.format
