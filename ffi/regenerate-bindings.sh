#!/bin/sh
# Regenerates the committed bindgen output of the sys crates from their shim headers.
# Needs libclang (Debian: libclang-dev). The same code checks for staleness in CI.
set -eu
cd "$(dirname "$0")/.."
for crate in oiio-sys ocio-sys; do
    SPECCONV_REGENERATE_BINDINGS=1 cargo test -q -p "$crate" --test bindings
done
