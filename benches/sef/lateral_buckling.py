"""Twin of data/benchmarks/lateral_buckling.toml in an independent code: the
SE(3) beam and joint library of one of the 2016 benchmark paper's authors
(public repository vspsonn/mb_sef_py, commit ed991431c877693fd35ee64621e6f9e25ce334f6).

The same mechanism, sections, mesh (20 two-node elements on the strip, 10 on
the link, 5 on the crank), driver, integrator (generalized-alpha, rho_inf =
0.9, h = 1e-3, 0.5 s) and imperfection (a dead lateral force of 1e-3 N on the
strip's mid-span node) as the model file. Writes the mid-span node's
displacement every 2e-3 s as CSV (t, ux, uy, uz).

    python3.11 -m venv sef && sef/bin/pip install "numpy<1.24" "scipy<1.12" h5py   # Python <= 3.11
    git clone https://github.com/vspsonn/mb_sef_py && git -C mb_sef_py checkout ed99143
    PYTHONPATH=mb_sef_py sef/bin/python benches/sef/lateral_buckling.py \
        [--strip-elements 20] [--csv out.csv]

--strip-elements must be even (half on each side of the mid-span node). About
a minute per run (20 elements) on one core. The CSV has the columns of
data/benchmarks/reference/lateral_buckling_twin.csv, without its comment
lines (which say where it came from); compare the two with any CSV tool.

The library's default Newton tolerance (1e-6 of the force norm, about 0.3 N
here) would seed the buckling with residual forces larger than the
imperfection; the twin solves to 1e-12 (--tol). The library stores its logs in
single precision (about 7 digits).
"""
import argparse
import os
import tempfile

import h5py
import numpy as np
from mb_sef_py.core import Model, NodalFrame
from mb_sef_py.elements import (BeamProperties_EIGJ, ClampedFrameProperties, ExternalForceProperties,
                                GroundJointElement, KinematicJointElement, ServoConstraintProperties,
                                discretize_beam)
from mb_sef_py.elements.KinematicJointProperties import HingeJointProperties, SphericalJointProperties
from mb_sef_py.math import Frame, UnitQuaternion
from mb_sef_py.solvers import GeneralizedAlpha, TimeIntegrationParameters
from mb_sef_py.utils import LogNodalFields, Logger, SensorNode


def section(EA, GA, GJ, EI, rhoA, rhoJ):
    return BeamProperties_EIGJ(EA=EA, GA_1=GA[0], GA_2=GA[1], GJ=GJ, EI_1=EI[0], EI_2=EI[1],
                               m=rhoA, m_11=rhoJ[0], m_22=rhoJ[1], m_33=rhoJ[2])


STRIP = section(73e6, (5.025e6, 23.40e6), 877.2, (60830, 608.3), 2.68, (2.25533e-3, 2.233e-3, 22.33e-6))
LINK = section(33.02e6, (10.81e6, 10.81e6), 914.5, (1189, 1189), 1.212, (87.3e-6, 43.65e-6, 43.65e-6))
CRANK = section(132.1e6, (43.22e6, 43.22e6), 14630, (19020, 19020), 4.85,
                (1396.6e-6, 698.3e-6, 698.3e-6))


def hub_angle(t):
    return -0.5 * np.pi * (1.0 - np.cos(np.pi * t / 0.4)) if t < 0.4 else -np.pi


def build(strip_elements, log_name):
    model = Model()
    def node(x, q=None):
        frame = Frame(x=np.array(x, dtype=float)) if q is None else Frame(x=np.array(x, dtype=float), q=q)
        return model.add_node(NodalFrame, frame)

    # The library's beams take their axial direction from the nodal frames'
    # first axis: the link's nodes get a frame with that axis along the link.
    vertical = UnitQuaternion()
    vertical.set_from_triad(np.array([0.0, 0.0, 1.0]), np.array([-1.0, 0.0, 0.0]))
    root, mid, tip = node([0, 0, 0]), node([0.5, 0, 0]), node([1, 0, 0])
    top, elbow_link = node([1, 0, 0], vertical), node([1, 0, -0.25], vertical)
    elbow_crank, hub = node([1, 0, -0.25]), node([0.95, 0, -0.25])
    model.add_element(ClampedFrameProperties(), root)
    discretize_beam(model, root, mid, strip_elements // 2, STRIP)
    discretize_beam(model, mid, tip, strip_elements // 2, STRIP)
    model.add_element(SphericalJointProperties(), tip, top, element_type=KinematicJointElement)
    discretize_beam(model, top, elbow_link, 10, LINK)
    y_hinge = HingeJointProperties(axis=np.array([0.0, 1.0, 0.0]))
    model.add_element(y_hinge, elbow_link, elbow_crank, element_type=KinematicJointElement)
    discretize_beam(model, hub, elbow_crank, 5, CRANK)
    ground = model.add_element(y_hinge, hub, element_type=GroundJointElement)
    model.add_element(ServoConstraintProperties(hub_angle), ground)
    push = ExternalForceProperties()
    push.forces = np.array([0.0, 1e-3, 0.0, 0.0, 0.0, 0.0])
    model.add_element(push, mid)
    logger = Logger(log_name, periodicity=2)
    logger.add_sensor(SensorNode(mid, LogNodalFields.MOTION))
    return model, logger


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--strip-elements", type=int, default=20)
    parser.add_argument("--csv", default="lateral_buckling_twin.csv")
    parser.add_argument("--tol", type=float, default=1e-12,
                        help="relative Newton tolerance (the library's default 1e-6 leaves residual forces\n"
                             "of about 0.3 N, far above the 1 mN imperfection)")
    args = parser.parse_args()
    csv = os.path.abspath(args.csv)
    work = tempfile.mkdtemp()
    os.chdir(work)
    model, logger = build(args.strip_elements, "twin")
    params = TimeIntegrationParameters()
    params.rho, params.T, params.h = 0.9, 0.5, 1e-3
    params.tol_res_forces = params.tol_res_constraints = args.tol
    GeneralizedAlpha(model, params, logger).solve()
    with h5py.File(os.path.join(work, "twin.h5")) as f:
        t = np.array(f["time"], dtype=float).ravel()
        x = np.array(f["node_1/MOTION"], dtype=float)[:3]
    u = (x.T - x[:3, 0])
    np.savetxt(csv, np.column_stack([t, u]), delimiter=",", header="t,ux,uy,uz", comments="",
               fmt="%.7e")


if __name__ == "__main__":
    main()
