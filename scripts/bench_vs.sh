#!/usr/bin/env bash
# CPU time of two flexmech executables on the same model, as ratios of paired
# runs (A B A B ...: pairing keeps the ratio meaningful on a shared machine).
#
#   scripts/bench_vs.sh A_BINARY B_BINARY [MODEL] [PAIRS]
#   (defaults: benches/cantilever512.toml, 3 pairs; one thread each)
#
# Prints each pair's CPU seconds (user + system) and the median ratio A/B.
set -euo pipefail
a="$1"; b="$2"
model="${3:-benches/cantilever512.toml}"
pairs="${4:-3}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
cpu() {
    # user + system seconds of one run of "$1".
    local t
    t=$( { TIMEFORMAT='%U %S'; time RAYON_NUM_THREADS=1 "$1" run "$model" --out "$out/$2" >/dev/null 2>&1; } 2>&1 )
    awk '{print $1 + $2}' <<<"$t"
}
ratios=()
for i in $(seq 1 "$pairs"); do
    ta=$(cpu "$a" a); tb=$(cpu "$b" b)
    r=$(awk -v x="$ta" -v y="$tb" 'BEGIN {printf "%.4f", x / y}')
    echo "pair $i: A $ta s, B $tb s, A/B $r"
    ratios+=("$r")
done
printf '%s\n' "${ratios[@]}" | sort -g | awk '{v[NR] = $1} END {print "median A/B cpu:", v[int((NR + 1) / 2)]}'
