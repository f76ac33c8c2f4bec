#!/usr/bin/env bash
# flexmech vs Exudyn on the flexible four-bar of data/benchmarks/four_bar_tacs.toml:
# CPU time (one thread each, paired rounds A M B C, A M B C, ...) and the agreement
# of C's position, bar 1's axial force and bar 3's bending moments.
#
#   benches/exudyn/compare_four_bar.sh [SCALE] [T_END] [ROUNDS]     (defaults 1 12 3)
#   FLEXMECH=path/to/flexmech overrides the binary (default: this repository's
#   target/release/flexmech; build it with `cargo build --release`)
#
# SCALE multiplies the element counts 8/16/8 of bars 1/2/3 (the joints stay four).
# A = flexmech (generalized-alpha, full Newton), whole-process CPU;
# M = flexmech (generalized-alpha, newton = "modified"), whole-process CPU;
# B = Exudyn, full Newton; C = Exudyn, fastest setting (modified Newton, exudynCPPfast).
# For B and C both the solve alone and the whole process are reported.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
scale="${1:-1}"; tend="${2:-12}"; rounds="${3:-3}"
. "$here/paired.sh"

scaled_models "$here/../../data/benchmarks/four_bar_tacs.toml" "$scale" "$tend" four_bar

echo "four-bar: element scale $scale ($((8 * scale))/$((16 * scale))/$((8 * scale)) elements), t_end $tend, dt 1e-2, $rounds rounds, one thread each"
paired_rounds "$rounds" "$out/four_bar.toml" "$out/modified.toml" "$here/four_bar.py" --elements-scale "$scale" --t-end "$tend"
echo "flexmech: $(head -1 "$out/a.log")"
echo "flexmech modified: $(head -1 "$out/m.log")"
grep -h '^exudyn' "$out/b.log" "$out/c.log"

python3 - "$out/fm/four-bar.h5" "$out/fmm/four-bar.h5" "$out/full.csv" "$out/fast.csv" "$scale" <<'PY'
import sys, h5py, numpy as np
k = int(sys.argv[5]); n1, n2, n3 = 8 * k, 16 * k, 8 * k
def flexmech(path):
    with h5py.File(path) as f:
        F, M = f['/resultants/force'][:], f['/resultants/moment'][:]
        return f['/time'][:], np.column_stack([f['/nodes/bar2.end/position'][:],
            F[:, n1 // 2, 0], M[:, n1 + n2 + n3 // 2, 1:3]])
t, a = flexmech(sys.argv[1])
tm, m = flexmech(sys.argv[2])
# A run that halved a step stores the extra times too: compare on A's grid.
m = m[[int(np.argmin(np.abs(tm - ti))) for ti in t]]
names = ['x_C', 'y_C', 'z_C', 'N bar 1', 'M2 bar 3', 'M3 bar 3']
def row(label, b):
    # in-plane positions against the bar length 0.12, the rest against their amplitude
    scale = [0.12, 0.12] + [np.abs(b[:, q]).max() for q in range(2, 6)]
    print(f'{label:34s}' + ' '.join(f'{np.abs(a[:, q] - b[:, q]).max() / scale[q]:9.2e}' for q in range(6)))
print(f'{"max |flexmech - other| / scale":34s}' + ' '.join(f'{n:>9s}' for n in names))
row('flexmech modified Newton', m)
for name, path in (('Exudyn full Newton', sys.argv[3]), ('Exudyn fastest', sys.argv[4])):
    e = np.loadtxt(path, delimiter=',', skiprows=1)
    assert len(e) == len(t) and np.allclose(e[:, 0], t, atol=1e-9), 'time grids differ'
    row(name, e[:, 1:])
print('(scale: the bar length 0.12 for x_C, y_C; each quantity\'s amplitude otherwise)')
PY
