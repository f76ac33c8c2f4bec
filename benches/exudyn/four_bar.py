#!/usr/bin/env python3
"""Exudyn twin of data/benchmarks/four_bar_tacs.toml (flexmech's flexible four-bar).

Bar 1 from A = (0, 0, 0) to B = (0, 0.12, 0), bar 2 from B to C = (0.24, 0.12, 0),
bar 3 from C to D = (0.24, 0, 0); revolutes about z at A and D (to the ground) and B,
the revolute at C about n_C = (sin 5 deg, 0, cos 5 deg). Steel square sections (E =
207 GPa, nu = 0.3, rho = 7800, shear factor 5/6, torsion constant Iy + Iz): bars 1 and
2 of 16 mm, bar 3 of 8 mm. The crank angle at A is driven from rest by
theta = -0.3 (t - sin(pi t)/pi) for t <= 1 and -0.3 - 0.6 (t - 1) after. 8/16/8
2-node ObjectBeamGeometricallyExact elements, generalized-alpha rho_inf = 0.5,
dt = 1e-2, t_end = 12, fixed step, no gravity.

    python3 four_bar.py [--t-end 12] [--elements-scale 1] [--fast] [--csv out.csv]

--elements-scale K multiplies the element counts 8/16/8. Default: full Newton,
NodeRigidBodyRotVecLG nodes, Newton converged on the increment (1e-7). --fast:
Exudyn's fastest setting (modified Newton, the exudynCPPfast module, reused sparse
pattern). One thread in both cases. The CSV has one row per step: t, the position of
C (x, y, z), the axial force of bar 1's element at index n1/2 (its mid-span) and the
bending moments (local y, z) of bar 3's element at index n3/2.
Prints the CPU time of the solve alone (time.process_time) and of the model build.
"""
import time

from twin import dynamic_settings, mechanism_args, start

ap = mechanism_args(__doc__, t_end=12.0, dt=1e-2, counts='8/16/8 of bars 1/2/3')
ap.add_argument('--tol', type=float, default=1e-7,
                help='Newton tolerance on the increment (at 1e-8 it stalls at ~4e-8 in the first step)')
ap.add_argument('--csv', default='', help='write the histories (see above) here')
a, exu, cpu0 = start(ap)
import numpy as np
from exudyn.itemInterface import (NodeRigidBodyRotVecLG, ObjectGround,
    ObjectBeamGeometricallyExact, MarkerNodeRigid, MarkerBodyRigid, GenericJoint,
    SensorNode, SensorBody)

E, nu, rho, kappa = 207e9, 0.3, 7800.0, 5.0 / 6.0
G = E / (2 * (1 + nu))


def section(w):
    """square section of side w: (axial, shear y, shear z | torsion, bending y, z)"""
    s = exu.BeamSection()
    A, I = w * w, w**4 / 12
    s.stiffnessMatrix = np.diag([E * A, kappa * G * A, kappa * G * A, G * 2 * I, E * I, E * I])
    s.inertia = np.diag([rho * 2 * I, rho * I, rho * I])
    s.massPerLength = rho * A
    return s


def rz(phi):
    c, s = np.cos(phi), np.sin(phi)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


SC = exu.SystemContainer()
mbs = SC.AddSystem()


def bar(p0, p1, ne, sec):
    """nodes and elements of a straight bar; the nodes' x axis along the bar (the
    element's axis), z = global z: reference rotation vector (0, 0, phi)"""
    p0, p1 = np.array(p0), np.array(p1)
    d = p1 - p0
    phi = np.arctan2(d[1], d[0])
    nodes = [mbs.AddNode(NodeRigidBodyRotVecLG(
        referenceCoordinates=list(p0 + d * i / ne) + [0, 0, phi])) for i in range(ne + 1)]
    elems = [mbs.AddObject(ObjectBeamGeometricallyExact(nodeNumbers=[nodes[i], nodes[i + 1]],
             length=np.linalg.norm(d) / ne, sectionData=sec)) for i in range(ne)]
    return nodes, elems, rz(phi)


K = a.elements_scale
n1, n2, n3 = 8 * K, 16 * K, 8 * K
b1, e1, R1 = bar([0, 0, 0], [0, 0.12, 0], n1, section(0.016))
b2, e2, R2 = bar([0, 0.12, 0], [0.24, 0.12, 0], n2, section(0.016))
b3, e3, R3 = bar([0.24, 0.12, 0], [0.24, 0, 0], n3, section(0.008))

ground = mbs.AddObject(ObjectGround())
def rigid(node, R):
    """a marker on a beam node whose frame is the joint frame: R maps the joint frame
    into the node's"""
    return mbs.AddMarker(MarkerNodeRigid(nodeNumber=node, localHT=exu.HT(rotation=R, translation=[0, 0, 0])))
def fixed(x, y):
    return mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[x, y, 0]))


free_z = [1, 1, 1, 1, 1, 0]
a5 = np.radians(5.0)
RC = np.array([[np.cos(a5), 0, np.sin(a5)], [0, 1, 0], [-np.sin(a5), 0, np.cos(a5)]])  # z -> n_C


def theta(t):
    return -0.3 * (t - np.sin(np.pi * t) / np.pi) if t <= 1 else -0.3 - 0.6 * (t - 1)


def theta_t(t):
    return -0.3 * (1 - np.cos(np.pi * t)) if t <= 1 else -0.6


# every joint frame is the global frame at t = 0 (C's: z along n_C); each node
# marker's frame is that joint frame (R_node^T R_joint in the node's frame)
# A: all six held, the z-rotation offset by theta(t) = the driven revolute
mbs.AddObject(GenericJoint(markerNumbers=[fixed(0, 0), rigid(b1[0], R1.T)], constrainedAxes=[1] * 6,
                           offsetUserFunction=lambda mbs, t, i, p: [0, 0, 0, 0, 0, theta(t)],
                           offsetUserFunction_t=lambda mbs, t, i, p: [0, 0, 0, 0, 0, theta_t(t)]))
mbs.AddObject(GenericJoint(markerNumbers=[rigid(b1[-1], R1.T), rigid(b2[0], R2.T)],
                           constrainedAxes=free_z))
mbs.AddObject(GenericJoint(markerNumbers=[rigid(b2[-1], R2.T @ RC), rigid(b3[0], R3.T @ RC)],
                           constrainedAxes=free_z))
mbs.AddObject(GenericJoint(markerNumbers=[fixed(0.24, 0), rigid(b3[-1], R3.T)],
                           constrainedAxes=free_z))

sensors = [mbs.AddSensor(SensorNode(nodeNumber=b2[-1], storeInternal=True, writeToFile=False,
                                    outputVariableType=exu.OutputVariableType.Position)),
           mbs.AddSensor(SensorBody(bodyNumber=e1[n1 // 2], storeInternal=True, writeToFile=False,
                                    localPosition=[0, 0, 0],
                                    outputVariableType=exu.OutputVariableType.ForceLocal)),
           mbs.AddSensor(SensorBody(bodyNumber=e3[n3 // 2], storeInternal=True, writeToFile=False,
                                    localPosition=[0, 0, 0],
                                    outputVariableType=exu.OutputVariableType.TorqueLocal))]
mbs.Assemble()

s = dynamic_settings(exu, a.dt, a.t_end, a.fast, newmark=False, rho=0.5)
t = s.timeIntegration
t.newton.residualMode = 1          # converge on the increment
t.newton.relativeTolerance = t.newton.absoluteTolerance = a.tol
cpu1 = time.process_time()

mbs.SolveDynamic(s)
cpu2 = time.process_time()
pc, fa, mb = (mbs.GetSensorStoredData(x) for x in sensors)   # columns t, then values
assert len(pc) == t.numberOfSteps + 1, f'{len(pc)} sensor rows for {t.numberOfSteps} steps'
if a.csv:
    np.savetxt(a.csv, np.column_stack([pc[:, :4], fa[:, 1], mb[:, 2:4]]), delimiter=',',
               header='t,x_C,y_C,z_C,N_bar1,M2_bar3,M3_bar3', comments='', fmt='%.17g')
it = mbs.sys['dynamicSolver'].it
print(f'exudyn {exu.__version__} {"fast/modified" if a.fast else "full"} Newton (increment {a.tol:g}), '
      f'{n1}/{n2}/{n3} elements, {int(t.numberOfSteps)} steps: '
      f'{it.newtonStepsCount} Newton iterations, {it.newtonJacobiCount} Jacobians')
print(f'C final {pc[-1, 1:4]}; max |z_C| {np.abs(pc[:, 3]).max():.6e}; '
      f'max |N bar1| {np.abs(fa[:, 1]).max():.6e}; max |M bar3| {np.abs(mb[:, 2:4]).max(0)}')
print(f'cpu_build_s {cpu1 - cpu0:.4f}')
print(f'cpu_solve_s {cpu2 - cpu1:.4f}')
