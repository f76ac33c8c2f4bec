#!/usr/bin/env python3
"""Reads the ParaView series of one mode (`flexmech export RESULT.h5 --vtk DIR
--mode K`) with the VTK library itself and checks it against the mode stored
in the HDF5 result file.

    python3 scripts/check_vtk_mode.py RESULT.h5 SERIES.pvd K

Exit status 0 when every check holds; 1 with the first failure; 3 when the
Python modules `vtk` or `h5py` are missing (`pip install vtk h5py`).
Checks: the collection's times run from 0 to 1 (one cycle); the first and
last frames are the stored state (the last row of /configuration/position);
every frame's nodes (the mean of a node's two ribbon points) are displaced
from it by `a sin(2 pi s)` times the mode's /modes/displacement (or
/buckling/displacement) row K, with one amplitude `a` for the whole series.
"""
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

try:
    import h5py
    import numpy as np
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
except ImportError as e:  # pragma: no cover
    print(f"check_vtk_mode: missing Python module ({e}); pip install vtk h5py", file=sys.stderr)
    sys.exit(3)

TOL = 1e-9  # relative to the largest displacement drawn


def fail(msg):
    print(f"check_vtk_mode: FAILED: {msg}", file=sys.stderr)
    sys.exit(1)


def node_positions(path, nodes):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    g = r.GetOutput()
    if g is None or g.GetNumberOfPoints() == 0:
        fail(f"{path}: VTK read no points")
    pts = vtk_to_numpy(g.GetPoints().GetData())
    node = vtk_to_numpy(g.GetPointData().GetArray("node")).astype(int)
    out = np.full((nodes, 3), np.nan)
    for n in np.unique(node):
        out[n] = pts[node == n].mean(axis=0)
    return out


def main():
    h5, pvd, k = sys.argv[1], Path(sys.argv[2]), int(sys.argv[3])
    with h5py.File(h5, "r") as f:
        group = "/modes" if "/modes/displacement" in f else "/buckling"
        u = f[f"{group}/displacement"][k - 1]
        base = f["/configuration/position"][-1]
    series = [(float(d.get("timestep")), pvd.parent / d.get("file"))
              for d in ET.parse(pvd).getroot().iter("DataSet") if d.get("part") == "0"]
    times = [t for t, _ in series]
    if abs(times[0]) > 0 or abs(times[-1] - 1.0) > 1e-15:
        fail(f"times run from {times[0]} to {times[-1]}, not one cycle 0 to 1")
    beam = ~np.isnan(node_positions(series[0][1], len(base))[:, 0])
    amplitude = None
    for s, path in series:
        x = node_positions(path, len(base))
        d = (x - base)[beam]
        w = math.sin(2 * math.pi * s)
        if abs(w) < 1e-12:
            if np.abs(d).max() > TOL * max(1.0, np.abs(base).max()):
                fail(f"phase {s}: the frame is not the stored state")
            continue
        a = float(np.sum(d * u[beam]) / np.sum(u[beam] * u[beam])) / w
        amplitude = a if amplitude is None else amplitude
        err = np.abs(d - a * w * u[beam]).max()
        if abs(a - amplitude) > TOL * abs(amplitude) or err > TOL * abs(a) * np.abs(u).max():
            fail(f"phase {s}: not the mode (amplitude {a} vs {amplitude}, misfit {err:.2e})")
    print(f"check_vtk_mode: {len(series)} frames of mode {k} agree (amplitude {amplitude:.6g})")


if __name__ == "__main__":
    main()
