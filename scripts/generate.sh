#!/usr/bin/env bash
# Rewrites what is made from the options' definitions and the command line: the option table of
# docs/guide.md, `convert`'s keywords in the Python stub, the man pages, and the numbers the C
# header shares with the library. CI fails when one is stale (`cargo test -p specconv-cli --lib`,
# `cargo test -p specconv-spectral --test spectral header_constants`).
set -euo pipefail
cd "$(dirname "$0")/.."
SPECCONV_UPDATE_GENERATED=1 SPECCONV_UPDATE_MAN=1 cargo test -p specconv-cli --lib -- \
  generated_references_are_current man_pages_match_the_cli
SPECCONV_UPDATE_GENERATED=1 cargo test -p specconv-spectral --test spectral -- header_constants
