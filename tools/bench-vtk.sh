#!/usr/bin/env bash
# The cost of writing ParaView files: the paper's wing (cases/wing_aoa5.json, 20 s) run with and
# without `--vtk` at the default stride, one formulation at a time, alternating, N times each;
# prints each run's CPU time (user + system of the whole `harness run` process: set-up, time
# loop with the VTK writes, CSV and plots; CPU rather than wall time, so that other work on the
# machine does not enter) and the medians. Release build:
#   cargo build --release -p harness && tools/bench-vtk.sh [N]
set -euo pipefail
cd "$(dirname "$0")/.."
N="${1:-5}"
OUT="$(mktemp -d)"
trap 'rm -rf "$OUT"' EXIT
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
for f in ancf gebf; do
    : >"$OUT/$f-plain" ; : >"$OUT/$f-vtk"
    for i in $(seq "$N"); do
        for mode in plain vtk; do
            flag=(); [ "$mode" = vtk ] && flag=(--vtk)
            TIMEFORMAT='%U %S'
            t=$( { time ./target/release/harness run cases/wing_aoa5.json --formulation "$f" --out "$OUT/r" "${flag[@]}" \
                >/dev/null 2>&1; } 2>&1 )
            ms=$(echo "$t" | awk '{printf "%.0f", 1000 * ($1 + $2)}')
            echo "$f $mode run $i: $ms ms"
            echo "$ms" >>"$OUT/$f-$mode"
        done
    done
    p=$(median <"$OUT/$f-plain"); v=$(median <"$OUT/$f-vtk")
    awk -v f="$f" -v p="$p" -v v="$v" 'BEGIN {printf "%s: median CPU %.0f ms without VTK, %.0f ms with (%+.1f %%)\n", f, p, v, 100*(v-p)/p}'
done
