"""Twin of data/benchmarks/rotating_shaft.toml in an independent code: the SE(3)
beam and joint library of one of the 2016 benchmark paper's authors (public
repository vspsonn/mb_sef_py, commit ed991431c877693fd35ee64621e6f9e25ce334f6).

The same shaft (16 two-node elements), disc (a rigid body 0.05 off the axis
at mid-span, on a rigid link), joints (a driven revolute about x at x = 0, a
cylindrical joint along x at x = 6), speed profile, gravity, integrator
(generalized-alpha, rho_inf = 0, h = 1e-4, 2.5 s) as the model file. Writes
the mid-span node's displacement every 1e-3 s as CSV (t, ux, uy, uz).

    python3.11 -m venv sef && sef/bin/pip install "numpy<1.24" "scipy<1.12" h5py   # Python <= 3.11
    git clone https://github.com/vspsonn/mb_sef_py && git -C mb_sef_py checkout ed99143
    PYTHONPATH=mb_sef_py sef/bin/python benches/sef/rotating_shaft.py [--t-end 2.5] [--csv out.csv]

The library stores its logs in single precision (about 7 digits). Takes
about 35 minutes on one core (25 000 steps). The CSV has the columns of
data/benchmarks/reference/rotating_shaft_twin.csv (which keeps every second
row), without its comment lines.
"""
import argparse
import os
import tempfile

import h5py
import numpy as np
from mb_sef_py.core import Model, NodalFrame
from mb_sef_py.elements import (BeamProperties_EIGJ, CylindricalJointProperties, ExternalForceProperties,
                                GroundJointElement, HingeJointProperties, RigidBodyProperties,
                                RigidLinkProperties, ServoConstraintProperties, discretize_beam)
from mb_sef_py.math import Frame
from mb_sef_py.solvers import GeneralizedAlpha, TimeIntegrationParameters
from mb_sef_py.utils import LogNodalFields, Logger, SensorNode

A1, A2, T1, T2, T3, OMEGA = 0.8, 1.2, 0.5, 1.0, 1.25, 60.0
G = 9.81
DISC_MASS = 70.573


def angle(t):
    """The driven angle: the integral of the speed profile, in closed form."""
    def ramp(s, duration):
        return 0.5 * (s - duration / np.pi * np.sin(np.pi * s / duration))
    if t < T1:
        return A1 * OMEGA * ramp(t, T1)
    theta1 = A1 * OMEGA * 0.5 * T1
    if t < T2:
        return theta1 + A1 * OMEGA * (t - T1)
    theta2 = theta1 + A1 * OMEGA * (T2 - T1)
    if t < T3:
        return theta2 + A1 * OMEGA * (t - T2) + (A2 - A1) * OMEGA * ramp(t - T2, T3 - T2)
    theta3 = theta2 + A1 * OMEGA * (T3 - T2) + (A2 - A1) * OMEGA * 0.5 * (T3 - T2)
    return theta3 + A2 * OMEGA * (t - T3)


def build(log_name):
    model = Model()
    node = lambda x, name=None: model.add_node(NodalFrame, Frame(x=np.array(x, dtype=float)), name) \
        if name else model.add_node(NodalFrame, Frame(x=np.array(x, dtype=float)))
    left, mid, disc, right = node([0, 0, 0]), node([3, 0, 0], "node_mid"), node([3, 0, 0.05]), node([6, 0, 0])
    shaft = BeamProperties_EIGJ(EA=313.4e6, GA_1=60.5e6, GA_2=60.5e6, GJ=272.7e3, EI_1=354.5e3,
                                EI_2=354.5e3, m=11.64, m_11=2 * 13.17e-3, m_22=13.17e-3, m_33=13.17e-3)
    shaft.gravity = np.array([0.0, 0.0, -G])
    hub = model.add_element(HingeJointProperties(axis=np.array([1.0, 0.0, 0.0])), left,
                            element_type=GroundJointElement)
    model.add_element(ServoConstraintProperties(angle), hub)
    discretize_beam(model, left, mid, 8, shaft)
    discretize_beam(model, mid, right, 8, shaft)
    model.add_element(RigidBodyProperties(m=DISC_MASS, J=np.diag([2.0325, 1.0163, 1.0163])), disc)
    weight = ExternalForceProperties()
    weight.forces[2] = -G * DISC_MASS
    model.add_element(weight, disc)
    model.add_element(RigidLinkProperties(), mid, disc)
    model.add_element(CylindricalJointProperties(axis=np.array([1.0, 0.0, 0.0])), right,
                      element_type=GroundJointElement)
    logger = Logger(log_name, periodicity=10)
    logger.add_sensor(SensorNode(mid, LogNodalFields.MOTION))
    return model, logger


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=2.5)
    parser.add_argument("--csv", default="rotating_shaft_twin.csv")
    parser.add_argument("--tol", type=float, default=1e-9,
                        help="relative Newton tolerance (the authors' script: 1e-6, one iteration a step)")
    args = parser.parse_args()
    csv = os.path.abspath(args.csv)
    work = tempfile.mkdtemp()
    os.chdir(work)
    model, logger = build("twin")
    params = TimeIntegrationParameters()
    params.rho, params.T, params.h = 0.0, args.t_end, 1e-4
    params.tol_res_forces = params.tol_res_constraints = args.tol
    GeneralizedAlpha(model, params, logger).solve()
    with h5py.File(os.path.join(work, "twin.h5")) as f:
        t = np.array(f["time"], dtype=float).ravel()
        x = np.array(f["node_mid/MOTION"], dtype=float)[:3]
    u = x.T - x[:3, 0]
    np.savetxt(csv, np.column_stack([t, u]), delimiter=",", header="t,ux,uy,uz", comments="", fmt="%.7e")


if __name__ == "__main__":
    main()
