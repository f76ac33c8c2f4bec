# Shared by compare.sh and compare_slider_crank.sh (sourced first): the binary,
# one thread for every library, a scratch directory, the CPU time of one command
# and the median ratios of paired rounds.

bin="${FLEXMECH:-$here/../../target/release/flexmech}"
export RAYON_NUM_THREADS=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
out="$(mktemp -d)"; trap 'rm -rf "$out"' EXIT

TIMEFORMAT='%U %S'

# cpu LOGFILE CMD... : runs CMD with its output to LOGFILE, prints user+sys seconds
cpu() {
    local log="$1"; shift; local t
    t=$( { time "$@" > "$log" 2>&1; } 2>&1 ) || { cat "$log" >&2; exit 1; }
    awk '{printf "%.3f", $1 + $2}' <<<"$t"
}

# solve LOGFILE : the solve-only CPU seconds an Exudyn twin printed
solve() { awk '/^cpu_solve_s/ {print $2}' "$1"; }

# scaled_models SOURCE SCALE T_END NAME : writes $out/NAME.toml, SOURCE with its
# element counts times SCALE, t_end = T_END and every step stored, and
# $out/modified.toml, the same with newton = "modified"
scaled_models() {
    awk -v k="$2" -v te="$3" '
        /^elements = / { $3 = $3 * k }
        /^t_end = /    { $3 = te }
        /^every = /    { next }
        { print }
        /^\[output\]/  { print "every = 1" }' "$1" > "$out/$4.toml"
    sed -e 's/^\[solver\]/[solver]\nnewton = "modified"/' "$out/$4.toml" > "$out/modified.toml"
}

# medians < ROWS : rows "A B_solve B_process C_solve C_process M" of the rounds
# (A, M flexmech full and modified Newton; B, C Exudyn full and fastest);
# prints the median of each per-round ratio
medians() {
    awk '
    function med(x, n,   i, j, t) { for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++)
        if (x[j] < x[i]) { t = x[i]; x[i] = x[j]; x[j] = t } return x[int((n + 1) / 2)] }
    { n++; r1[n] = $1 / $2; r2[n] = $1 / $3; r3[n] = $1 / $4; r4[n] = $1 / $5
      r5[n] = $6 / $2; r6[n] = $6 / $3; r7[n] = $6 / $4; r8[n] = $6 / $5 }
    END { printf "median ratio A flexmech-full/Exudyn-full        : %.3f (solve only)  %.3f (whole process)\n", med(r1, n), med(r2, n)
          printf "median ratio A flexmech-full/Exudyn-fastest     : %.3f (solve only)  %.3f (whole process)\n", med(r3, n), med(r4, n)
          printf "median ratio M flexmech-modified/Exudyn-full    : %.3f (solve only)  %.3f (whole process)\n", med(r5, n), med(r6, n)
          printf "median ratio M flexmech-modified/Exudyn-fastest : %.3f (solve only)  %.3f (whole process)\n", med(r7, n), med(r8, n) }'
}

# paired_rounds ROUNDS FULL_TOML MODIFIED_TOML TWIN ARGS... : ROUNDS paired rounds of
# A (flexmech FULL_TOML), M (flexmech MODIFIED_TOML), B (python3 TWIN ARGS, full
# Newton) and C (the same with --fast), with $bin the flexmech binary and the logs,
# results (fm, fmm) and twin CSVs (full.csv, fast.csv) in $out; prints each round
# and the median ratios
paired_rounds() {
    local rounds="$1" full="$2" modified="$3"; shift 3
    local rows=() r a m b c bs cs
    printf '%-6s %10s %10s | %10s %10s | %10s %10s\n' round "A flexmech" "M modified" "B solve" "B process" "C solve" "C process"
    for r in $(seq 1 "$rounds"); do
        a=$(cpu "$out/a.log" "$bin" run "$full" --out "$out/fm")
        m=$(cpu "$out/m.log" "$bin" run "$modified" --out "$out/fmm")
        b=$(cpu "$out/b.log" python3 "$@" --csv "$out/full.csv")
        c=$(cpu "$out/c.log" python3 "$@" --fast --csv "$out/fast.csv")
        bs=$(solve "$out/b.log"); cs=$(solve "$out/c.log")
        printf '%-6s %10s %10s | %10s %10s | %10s %10s\n' "$r" "$a" "$m" "$bs" "$b" "$cs" "$c"
        rows+=("$a $bs $b $cs $c $m")
    done
    printf '%s\n' "${rows[@]}" | medians
}
