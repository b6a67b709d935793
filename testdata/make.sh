#!/bin/sh
# Makes the small test images under testdata/ with oiiotool and maketx
# (Debian: openimageio-tools). Deterministic: noise is seeded. Rerun after changing it
# and commit the results; tests compare the reader against `oiiotool --dumpdata`, so the
# exact pixel values here are not baked into any test.
set -eu
cd "$(dirname "$0")"
rm -rf images broken layout && mkdir images broken layout
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

# File structure: data and display windows, layers, parts (tests/it/layout.rs).
cd ../layout
PIXELS="--pattern fill:topleft=0.1,0.2,0.3:topright=0.9,0.2,0.1:bottomleft=0.2,0.8,0.3:bottomright=0.3,0.3,0.9 64x48 3"
oiiotool $PIXELS --origin +10+5 --fullsize 80x60+0+0 -d half -o window.exr
oiiotool $PIXELS --origin -7-3 --fullsize 100x70-20-10 -d float --tile 16 16 -o window_negative.exr
# Two layers, neither named R, G, B at the top: diffuse.R/G/B and rough.Y.
oiiotool $PIXELS --pattern constant:color=0.5 64x48 1 --chappend \
    --chnames diffuse.R,diffuse.G,diffuse.B,rough.Y -d half -o layers.exr
# Two RGB layers: no channel choice without --channels.
oiiotool $PIXELS --pattern constant:color=0.2,0.4,0.6 64x48 3 --chappend \
    --chnames diffuse.R,diffuse.G,diffuse.B,specular.R,specular.G,specular.B -d half -o two_layers.exr
# Two parts, 'beauty' then 'albedo'.
oiiotool --pattern constant:color=0.1,0.2,0.3 64x48 3 --attrib oiio:subimagename beauty \
    $PIXELS --attrib oiio:subimagename albedo --siappend -d half -o parts.exr

# Broken inputs for error tests.
cd ../broken
head -c 600 ../images/float_tiled_alpha.exr > truncated.exr
head -c 300 ../images/srgb8.png > truncated.png
printf 'this is not an image\n' > not_an_image.png
printf 'plain text with an extension no reader knows\n' > unknown.format
# Headers that lie and pixels that are missing (damage_exr.py says how). DWAB packs 256 rows a
# chunk, so the lying header still has an offset table that fits, and OpenImageIO opens it.
CHECKER="--pattern checker:width=4:height=4:color1=0.5,0.4,0.3:color2=0.1,0.2,0.3 32x32 3 -d half"
oiiotool $CHECKER --compression dwab -o small.exr
python3 ../damage_exr.py window small.exr lying_window.exr 0 0 262660 15104
oiiotool $CHECKER --tile 16 16 -o small.exr
python3 ../damage_exr.py window small.exr lying_tiles.exr 0 0 262660 15104
python3 ../damage_exr.py garble ../images/half_scanline.exr garbled_first_block.exr
python3 ../damage_exr.py cut ../images/half_scanline.exr truncated_pixels.exr 0.5
rm small.exr
