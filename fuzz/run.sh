#!/usr/bin/env bash
# Fuzzes the CSV and model readers for a bounded time each, on the stable toolchain: builds the
# targets with libFuzzer's coverage instrumentation (the flags `cargo fuzz build -s none` uses;
# no sanitizer, which needs nightly), seeds each corpus from the repository's own valid files,
# and fails on any crash. With cargo-fuzz and a nightly toolchain, `cargo fuzz run csv` works too.
#
#   fuzz/run.sh [SECONDS_PER_TARGET]     (default 30; $CARGO_TARGET_DIR is honoured)
set -euo pipefail
cd "$(dirname "$0")"
seconds="${1:-30}"
triple="$(rustc -vV | sed -n 's/^host: //p')"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
export RUSTFLAGS="-Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4 \
 -Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-pc-table \
 -Cllvm-args=-sanitizer-coverage-trace-compares --cfg fuzzing -Cdebug-assertions -Coverflow-checks"
# --target keeps the flags off build scripts and proc macros, as cargo-fuzz does.
cargo build --locked --release --target "$triple" --bins

# Seeds: the built-in models, the repository's own tables and two small hand-written CSVs
# (quoting, CRLF, exponents, blank lines, uneven steps); never the measured spectra.
work="$CARGO_TARGET_DIR/fuzz-work"
rm -rf "$work" && mkdir -p "$work/csv" "$work/model" "$work/artifacts"
cp ../crates/spectral/models/*.json "$work/model/"
cp seeds/*.csv ../crates/spectral/data/smits1999_basis.csv \
  ../crates/colour/data/cie_illuminant_f2_380-780_5nm.csv "$work/csv/"

status=0
for target in csv model; do
  log="$work/$target.log"
  # -timeout: a single input taking longer is a hang, reported as a crash.
  if ! "$CARGO_TARGET_DIR/$triple/release/$target" "$work/$target" \
      -dict="$target.dict" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$work/artifacts/$target-" -print_final_stats=1 >"$log" 2>&1; then
    echo "fuzz/$target: CRASH; input in $work/artifacts, log $log:" >&2
    tail -40 "$log" >&2
    status=1
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
  echo "fuzz/$target: ${runs:-?} runs in ${seconds} s (${rate:-?}/s), corpus $(ls "$work/$target" | wc -l) inputs"
done
exit $status
