#!/bin/sh
# Trains the same models with two `specconv` binaries and compares their JSON byte for byte:
# for a change to training that must not change any model (issue 15's faster split search).
# The option sets cover what `specconv train --help` offers: clusters, minimum cluster size,
# condition bound, grid, observer, illuminant, several files.
#   scripts/train_identical.sh BEFORE AFTER      (two specconv binaries)
# Exits 1, naming the option sets, when any model differs.
set -eu
cd "$(dirname "$0")/.."
[ $# -eq 2 ] || { echo "usage: $0 BEFORE AFTER (two specconv binaries)" >&2; exit 2; }
before=$1
after=$2
spectra=${SPECCONV_SHARED:-../shared}/spectra
munsell=$spectra/munsell1269_matte_380-800_1nm.csv
checker=$spectra/colorchecker_n_ohta_380-780_5nm.csv
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# One option set per line: a name, then the flags after --spectra MUNSELL.
sets="default
k1 --clusters 1
k2 --clusters 2
k16_min4 --clusters 16 --min-cluster-size 4
k32_min4 --clusters 32 --min-cluster-size 4
k64_min4 --clusters 64 --min-cluster-size 4
k12_min10_cond20 --clusters 12 --min-cluster-size 10 --max-condition 20
paper_5nm_E_wyman --bands 380:780:5 --illuminant E --observer wyman2013
paper_5nm_E_wyman_k16_min4 --bands 380:780:5 --illuminant E --observer wyman2013 --clusters 16 --min-cluster-size 4
cie1964_A_20nm --bands 400:700:20 --illuminant A --observer cie1964 --clusters 10
d50_1nm_k6 --bands 400:720:1 --illuminant D50 --clusters 6
fl11_k20_min8 --illuminant FL11 --clusters 20 --min-cluster-size 8
blackbody_k8 --illuminant blackbody:3000 --observer cie1964
with_checker_k12 --spectra $checker --clusters 12
with_checker_k24_min4_5nm --spectra $checker --clusters 24 --min-cluster-size 4 --bands 380:780:5"

echo "$sets" | while read -r name flags; do
    for which in before after; do
        eval bin=\$$which
        # shellcheck disable=SC2086
        "$bin" train --spectra "$munsell" $flags -o "$out/$name.$which.json" 2>"$out/$name.$which.log" ||
            echo "$name: $which failed: $(cat "$out/$name.$which.log")" >&2
    done
    if cmp -s "$out/$name.before.json" "$out/$name.after.json"; then
        echo "same  $name ($(wc -c <"$out/$name.after.json") bytes)"
    else
        echo "DIFF  $name"
        echo "$name" >>"$out/failed"
    fi
done
if [ -s "$out/failed" ]; then
    echo "models differ: $(tr '\n' ' ' <"$out/failed")" >&2
    exit 1
fi
echo "every model identical"
