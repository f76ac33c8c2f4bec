#!/usr/bin/env bash
# flexmech vs Exudyn on the dynamic cantilever of benches/cantilever512.toml:
# CPU time (one thread each, paired rounds A B C, A B C, ...) and tip agreement.
#
#   benches/exudyn/compare.sh [ELEMENTS] [T_END] [ROUNDS]     (defaults 512 0.1 3)
#   FLEXMECH=path/to/flexmech overrides the binary (default: this repository's
#   target/release/flexmech; build it with `cargo build --release`)
#
# A = flexmech (Newmark, full Newton), whole-process CPU (its setup is negligible);
# M = flexmech (Newmark, newton = "modified"), whole-process CPU;
# B = Exudyn, full Newton; C = Exudyn, fastest setting (modified Newton, exudynCPPfast).
# For B and C both the solve alone (time.process_time inside Python) and the whole
# process (Python start-up, import and model build included) are reported.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ne="${1:-512}"; tend="${2:-0.1}"; rounds="${3:-3}"
. "$here/paired.sh"

# the flexmech model: the yardstick with ELEMENTS, T_END and every step stored
sed -e "0,/^name = .*/s//name = \"cantilever\"/" -e "s/^elements = .*/elements = $ne/" \
    -e "s/^t_end = .*/t_end = $tend/" -e "s/^every = .*/every = 1/" \
    "$here/../cantilever512.toml" > "$out/cantilever.toml"
sed -e 's/^\[solver\]/[solver]\nnewton = "modified"/' "$out/cantilever.toml" > "$out/modified.toml"


echo "cantilever: $ne elements, t_end $tend, dt 1e-3, $rounds rounds, one thread each"
paired_rounds "$rounds" "$out/cantilever.toml" "$out/modified.toml" "$here/cantilever.py" --elements "$ne" --t-end "$tend"
echo "flexmech: $(head -1 "$out/a.log")"
grep -h '^exudyn' "$out/b.log" "$out/c.log"

python3 - "$out/fm/cantilever.h5" "$out/full.csv" "$out/fast.csv" "$out/fmm/cantilever.h5" <<'PY'
import sys, h5py, numpy as np
with h5py.File(sys.argv[1]) as f:
    t, uz = f['/time'][:], f['/nodes/b.end/displacement'][:, 2]
umax = np.abs(uz).max()
print(f'flexmech tip uz: final {uz[-1]:.9f}, max {umax:.9f}')
with h5py.File(sys.argv[4]) as f:
    uzm = f['/nodes/b.end/displacement'][:, 2]
    fac, its = f['/solver/factorizations'][:].sum(), f['/solver/iterations'][:].sum()
print(f'flexmech modified Newton: max |uz_modified - uz_full| / max|uz| = {np.abs(uzm - uz).max() / umax:.2e}; '
      f'{fac} factorisations, {its} iterations')
for name, path in (('full Newton', sys.argv[2]), ('fastest', sys.argv[3])):
    e = np.loadtxt(path, delimiter=',', skiprows=1)
    assert len(e) == len(t) and np.allclose(e[:, 0], t, atol=1e-12), 'time grids differ'
    dev = np.abs(e[:, 3] - uz).max()
    print(f'Exudyn {name:11s}: final {e[-1, 3]:.9f}, max |uz_flexmech - uz_Exudyn| / max|uz_flexmech| = {dev / umax:.2e}')
PY
