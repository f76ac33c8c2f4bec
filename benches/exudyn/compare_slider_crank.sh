#!/usr/bin/env bash
# flexmech vs Exudyn on the slider-crank of data/benchmarks/slider_crank.toml:
# CPU time (one thread each, paired rounds A M B C, A M B C, ...) and the agreement of
# the slider position x_C with each other and with the rigid-body formula.
#
#   benches/exudyn/compare_slider_crank.sh [SCALE] [T_END] [ROUNDS]     (defaults 1 1.0 3)
#   FLEXMECH=path/to/flexmech overrides the binary (default: this repository's
#   target/release/flexmech; build it with `cargo build --release`)
#
# SCALE multiplies the element counts 2/4/1 of crank/rod/block (the joints stay four).
# A = flexmech (generalized-alpha, full Newton), whole-process CPU;
# M = flexmech (generalized-alpha, newton = "modified"), whole-process CPU;
# B = Exudyn, full Newton; C = Exudyn, fastest setting (modified Newton, exudynCPPfast).
# For B and C both the solve alone (time.process_time inside Python) and the whole
# process (Python start-up, import and model build included) are reported.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
scale="${1:-1}"; tend="${2:-1.0}"; rounds="${3:-3}"
. "$here/paired.sh"

scaled_models "$here/../../data/benchmarks/slider_crank.toml" "$scale" "$tend" slider_crank

echo "slider-crank: element scale $scale ($((2 * scale))/$((4 * scale))/$scale elements), t_end $tend, dt 1e-3, $rounds rounds, one thread each"
paired_rounds "$rounds" "$out/slider_crank.toml" "$out/modified.toml" "$here/slider_crank.py" --elements-scale "$scale" --t-end "$tend"
echo "flexmech: $(head -1 "$out/a.log")"
echo "flexmech modified: $(head -1 "$out/m.log")"
grep -h '^exudyn' "$out/b.log" "$out/c.log"

python3 - "$out/fm/slider-crank.h5" "$out/fmm/slider-crank.h5" "$out/full.csv" "$out/fast.csv" <<'PY'
import sys, h5py, numpy as np
r, l, omega = 0.15, 0.30, 2 * np.pi
with h5py.File(sys.argv[1]) as f:
    t, x = f['/time'][:], f['/nodes/block.start/position'][:, 0]
with h5py.File(sys.argv[2]) as f:
    xm = f['/nodes/block.start/position'][:, 0]
    fac, its = f['/solver/factorizations'][:].sum(), f['/solver/iterations'][:].sum()
th = omega * t
xr = r * np.cos(th) + np.sqrt(l**2 - (r * np.sin(th))**2)   # rigid-body reference
late = t >= 0.05                                              # after the start-up transient
def dev(y):
    d = np.abs(y - xr)
    return f'{d.max():.3e} (after t = 0.05 s: {d[late].max():.3e})'
print(f'x_C = /nodes/block.start/position[:, 0]; rigid: r cos(theta) + sqrt(l^2 - r^2 sin^2(theta))')
print(f'flexmech full Newton     : max |x_C - rigid| = {dev(x)}')
print(f'flexmech modified Newton : max |x_C - rigid| = {dev(xm)}; max |x_C - x_C full| = '
      f'{np.abs(xm - x).max():.2e}; {fac} factorisations, {its} iterations')
for name, path in (('full Newton', sys.argv[3]), ('fastest', sys.argv[4])):
    e = np.loadtxt(path, delimiter=',', skiprows=1)
    assert len(e) == len(t) and np.allclose(e[:, 0], t, atol=1e-12), 'time grids differ'
    print(f'Exudyn {name:11s}       : max |x_C - rigid| = {dev(e[:, 1])}; '
          f'max |x_C flexmech - x_C Exudyn| = {np.abs(e[:, 1] - x).max():.2e}')
PY
