#!/usr/bin/env bash
# Whether two flexmech executables give the same results, bit for bit: runs
# every model of data/paper and data/benchmarks (and any MODEL given) with
# each, one thread, and compares the result files dataset by dataset.
#
#   scripts/same_results.sh A_BINARY B_BINARY [MODEL ...]
#
# For builds that should not change the arithmetic: the build with HDF5
# linked in, or one for a newer processor (`FLEXMECH_TARGET_CPU` of
# scripts/build_static.sh), against the usual one. Prints each model's
# differing datasets (the largest difference and the largest value) and
# exits non-zero if any differ. Needs Python with h5py and numpy.
#
# With WITHIN set (e.g. WITHIN=1e-7: a thousand times the default Newton
# tolerance), for builds whose arithmetic differs: only the nodes' positions
# (/configuration/position) are compared, as the largest difference over the
# largest displacement from the first stored state, and a model fails where
# that exceeds WITHIN (or where the runs stored different times: the load
# factors of an arc-length path, solved for, within WITHIN of the largest).
set -euo pipefail
[ $# -ge 2 ] || { sed -n '2,19p' "$0"; exit 2; }
a="$1"; b="$2"; shift 2
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
status=0
for model in "$root"/data/paper/*.toml "$root"/data/benchmarks/*.toml "$@"; do
    name="$(basename "$model" .toml)"
    for side in a b; do
        bin="$a"; [ "$side" = b ] && bin="$b"
        RAYON_NUM_THREADS=1 "$bin" run "$model" --out "$out/$side/$name" >/dev/null 2>&1 || true
    done
    python3 - "$out/a/$name" "$out/b/$name" "$name" "${WITHIN:-}" <<'PY' || status=1
import pathlib, sys
import h5py, numpy as np

a_dir, b_dir, name, within = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2]), sys.argv[3], sys.argv[4]
files = sorted(p.name for p in a_dir.glob("*.h5"))
if files != sorted(p.name for p in b_dir.glob("*.h5")) or not files:
    print(f"{name}: the result files differ or are missing: {files}")
    sys.exit(1)
if within:
    worst = 0.0
    for f in files:
        with h5py.File(a_dir / f) as x, h5py.File(b_dir / f) as y:
            u, v = x["/configuration/position"][()], y["/configuration/position"][()]
            # Load factors of arc-length paths are solved for, so compared too.
            s, t = x["/time"][()], y["/time"][()]
            if u.shape != v.shape or s.shape != t.shape or np.abs(s - t).max() > float(within) * np.abs(s).max():
                print(f"{name}: {f} stored different times")
                sys.exit(1)
            scale = max(np.nanmax(np.abs(u - u[:1])), np.finfo(float).tiny)
            worst = max(worst, np.nanmax(np.abs(u - v)) / scale)
    print(f"{name}: positions within {worst:.2e} of the largest displacement")
    sys.exit(0 if worst <= float(within) else 1)
differ = []
for f in files:
    with h5py.File(a_dir / f) as x, h5py.File(b_dir / f) as y:
        def visit(path, obj):
            if not isinstance(obj, h5py.Dataset):
                return
            if path not in y:
                differ.append(f"{f}:{path} (missing)")
                return
            u, v = obj[()], y[path][()]
            same = u.shape == v.shape and (
                np.array_equal(u, v, equal_nan=True) if u.dtype.kind in "fc" else np.array_equal(u, v))
            if not same:
                if u.shape == v.shape and u.dtype.kind in "fc" and u.size:
                    detail = f"largest difference {np.nanmax(np.abs(u - v)):.3e} of {np.nanmax(np.abs(u)):.3e}"
                else:
                    detail = "not comparable"
                differ.append(f"{f}:{path} ({detail})")
        x.visititems(visit)
print(f"{name}: " + ("bitwise the same" if not differ else "differs: " + "; ".join(differ)))
sys.exit(1 if differ else 0)
PY
done
exit "$status"
