#!/usr/bin/env python3
"""Reads a ParaView series written by `flexmech export` with the VTK library
itself and checks it against the HDF5 result file it came from, step by step.

    python3 scripts/check_vtk.py RESULT.h5 SERIES.pvd [WIDTH]

Exit status 0 when every check holds; 1 with the first failure; 3 when the
Python modules `vtk` or `h5py` are missing (`pip install vtk h5py`).
Checks, for every stored step: the collection's times equal /time; the
ribbon has two points per beam node and one cell per element (quads for
2-node, quadratic-linear quads (VTK type 26) for 3-node elements); the mean
of a node's two points is its /configuration/position; they are WIDTH apart
along R e2 (R from /configuration/quaternion, e2 from /mesh/node_directors);
displacement, rotation_vector, velocity and angular_velocity equal the
file's; the joints sit at their slave nodes with the file's angle, released
translation and constraint error.
"""
import math
import os
import sys
import xml.etree.ElementTree as ET

try:
    import h5py
    import numpy as np
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
except ImportError as e:  # pragma: no cover
    print(f"check_vtk: missing Python module ({e}); pip install vtk h5py", file=sys.stderr)
    sys.exit(3)

TOL = 1e-12  # the .vtu holds the same float64 values: only round-off of the arithmetic


def fail(msg):
    print(f"check_vtk: FAILED: {msg}", file=sys.stderr)
    sys.exit(1)


def close(a, b, what, scale=1.0):
    a, b = np.asarray(a, float), np.asarray(b, float)
    if a.shape != b.shape:
        fail(f"{what}: shape {a.shape} != {b.shape}")
    both_nan = np.isnan(a) & np.isnan(b)
    err = np.where(both_nan, 0.0, np.abs(a - b))
    if np.any(np.isnan(err)) or err.max(initial=0.0) > TOL * max(scale, 1.0):
        fail(f"{what}: differs by {np.nanmax(err) if err.size else 0:.3e}")


def read(path):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    g = r.GetOutput()
    if g is None or g.GetNumberOfPoints() == 0:
        fail(f"{path}: VTK read no points")
    return g


def arr(data, name):
    a = data.GetArray(name)
    if a is None:
        fail(f"array {name} missing")
    return vtk_to_numpy(a)


def rotation(q):
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def rotation_vector(q):
    q = q / np.linalg.norm(q)
    if q[0] < 0:
        q = -q
    s = np.linalg.norm(q[1:])
    if s == 0:
        return np.zeros(3)
    return 2 * math.atan2(s, q[0]) * q[1:] / s


def main():
    h5_path, pvd_path = sys.argv[1], sys.argv[2]
    width = float(sys.argv[3]) if len(sys.argv) > 3 else None
    f = h5py.File(h5_path, "r")
    time = f["/time"][()]
    pos = f["/configuration/position"][()]
    quat = f["/configuration/quaternion"][()]
    init = f["/mesh/initial_position"][()]
    directors = f["/mesh/node_directors"][()]
    en, eo = f["/mesh/element_nodes"][()], f["/mesh/element_offsets"][()]
    elements = [en[eo[i]:eo[i + 1]] for i in range(len(eo) - 1)]
    bn, bo = f["/mesh/beam_nodes"][()], f["/mesh/beam_offsets"][()]
    beam_nodes = sorted({int(n) for n in bn})
    vel = f["/configuration/velocity"][()] if "/configuration/velocity" in f else None
    avel = f["/configuration/angular_velocity"][()] if "/configuration/angular_velocity" in f else None
    joints = []
    for name, g in f["/joints"].items() if "/joints" in f else []:
        if "slave_node" in g.attrs:
            joints.append((int(g.attrs["joint_index"]), int(g.attrs["slave_node"]), g))
    joints.sort()

    base = os.path.dirname(pvd_path)
    sets = ET.parse(pvd_path).getroot().find("Collection").findall("DataSet")
    parts = {0: [], 1: []}
    for d in sets:
        parts[int(d.get("part"))].append((float(d.get("timestep")), os.path.join(base, d.get("file"))))
    if len(parts[0]) != len(time):
        fail(f"{len(parts[0])} beam data sets for {len(time)} stored steps")
    close([t for t, _ in parts[0]], time, "timesteps vs /time")
    if joints and len(parts[1]) != len(time):
        fail(f"{len(parts[1])} joint data sets for {len(time)} stored steps")

    checked_points = 0
    for k, (_, path) in enumerate(parts[0]):
        g = read(path)
        if g.GetNumberOfPoints() != 2 * len(beam_nodes):
            fail(f"step {k}: {g.GetNumberOfPoints()} points for {len(beam_nodes)} beam nodes")
        if g.GetNumberOfCells() != len(elements):
            fail(f"step {k}: {g.GetNumberOfCells()} cells for {len(elements)} elements")
        pd, cd = g.GetPointData(), g.GetCellData()
        node = arr(pd, "node")
        pts = vtk_to_numpy(g.GetPoints().GetData())
        cell_elem = arr(cd, "element")
        for c in range(g.GetNumberOfCells()):
            e = elements[int(cell_elem[c])]
            want = 9 if len(e) == 2 else 26
            if g.GetCellType(c) != want:
                fail(f"step {k}: cell {c} has VTK type {g.GetCellType(c)}, expected {want}")
            ids = [g.GetCell(c).GetPointId(i) for i in range(g.GetCell(c).GetNumberOfPoints())]
            if [int(node[i]) for i in ids[:2]] != [int(e[0]), int(e[-1])]:
                fail(f"step {k}: cell {c} does not run from node {e[0]} to {e[-1]}")
        n = node[0::2].astype(int)
        if not np.array_equal(n, node[1::2]) or sorted(n) != beam_nodes:
            fail(f"step {k}: the point pairs do not cover the beam nodes once each")
        scale = np.abs(pos[k]).max()
        close((pts[0::2] + pts[1::2]) / 2, pos[k][n], f"step {k}: ribbon centre vs position", scale)
        side = pts[1::2] - pts[0::2]
        e2 = np.array([rotation(quat[k][i]) @ directors[i][1] for i in n])
        w = width if width is not None else np.linalg.norm(side[0])
        close(side, w * e2, f"step {k}: ribbon cross-section vs width * R e2", scale)
        close(arr(pd, "displacement")[0::2], pos[k][n] - init[n], f"step {k}: displacement", scale)
        close(arr(pd, "rotation_vector")[0::2], [rotation_vector(quat[k][i]) for i in n],
              f"step {k}: rotation_vector", math.pi)
        if vel is not None:
            close(arr(pd, "velocity")[1::2], vel[k][n], f"step {k}: velocity", np.abs(vel[k]).max())
            close(arr(pd, "angular_velocity")[0::2], avel[k][n], f"step {k}: angular_velocity",
                  np.abs(avel[k]).max())
        checked_points += g.GetNumberOfPoints()

    for k, (_, path) in enumerate(parts[1]):
        g = read(path)
        if g.GetNumberOfPoints() != len(joints):
            fail(f"step {k}: {g.GetNumberOfPoints()} joint points for {len(joints)} joints")
        pd = g.GetPointData()
        pts = vtk_to_numpy(g.GetPoints().GetData())
        for i, (index, slave, grp) in enumerate(joints):
            if int(arr(pd, "joint")[i]) != index:
                fail(f"step {k}: joint point {i} is joint {arr(pd, 'joint')[i]}, expected {index}")
            close(pts[i], pos[k][slave], f"step {k}: joint {index} position", np.abs(pos[k]).max())
            angle = grp["angle"][k] if "angle" in grp else float("nan")
            close([arr(pd, "angle")[i]], [angle], f"step {k}: joint {index} angle", math.pi)
            close(arr(pd, "released_translation")[i], grp["released_translation"][k],
                  f"step {k}: joint {index} released_translation")
            close([arr(pd, "constraint_error")[i]], [grp["constraint_error"][k]],
                  f"step {k}: joint {index} constraint_error")

    print(f"check_vtk: ok: {len(time)} steps, {checked_points} ribbon points, "
          f"{len(joints)} joints per step, VTK {vtk.vtkVersion.GetVTKVersion()}")


if __name__ == "__main__":
    main()
