#!/usr/bin/env python3
"""Exudyn twin of data/benchmarks/slider_crank.toml (flexmech's slider-crank).

Crank AB (r = 0.15) on a revolute to the ground at A = origin about z, driven at
theta = 2 pi t; connecting rod BC (l = 0.30); slider block (0.02 long) whose start
node C carries a point mass M = 2 and slides on a prismatic joint to the ground
along x; revolutes about z at B (crank/rod) and C (block/rod). Every link is a
chain of 2-node ObjectBeamGeometricallyExact elements with the section EA = GA2 =
GA3 = 1e8, GJ = EI2 = EI3 = 1e5, rhoA = 1e-3, rhoJ = (2e-9, 1e-9, 1e-9). Started at
the top dead centre with the rigid motion's velocities (crank at omega about A,
rod at -omega r/l about C, slider at rest). Generalized-alpha, rho_inf = 0.5,
dt = 1e-3, fixed step. Reference: x_C = r cos(theta) + sqrt(l^2 - r^2 sin^2(theta)).

    python3 slider_crank.py [--t-end 1.0] [--elements-scale 1] [--fast] [--csv xc.csv]

--elements-scale K multiplies the element counts 2/4/1 of crank/rod/block.
Default: full Newton, NodeRigidBodyRotVecLG nodes (Lie group nodes of Exudyn's implicit
generalized-alpha), Newton converged on the increment (1e-8). --fast: Exudyn's fastest setting (modified Newton, the
exudynCPPfast module, reused sparse pattern). One thread in both cases.
Prints the CPU time of the solve alone (time.process_time) and of the model build.
"""
import time

from twin import dynamic_settings, mechanism_args, start

ap = mechanism_args(__doc__, t_end=1.0, dt=1e-3, counts='2/4/1 of crank/rod/block')
ap.add_argument('--node', choices=['RotVecLG', 'Rxyz', 'EP'], default='RotVecLG')
ap.add_argument('--newton-error', choices=['increment', 'residual'], default='increment',
                help="Newton's error measure: the increment (newton.residualMode = 1, relative = "
                     "absolute tolerance = --tol) or the residual (Exudyn's default, relativeTolerance "
                     "= --tol); see README.md")
ap.add_argument('--tol', type=float, default=1e-8, help='Newton tolerance (default 1e-8)')
ap.add_argument('--csv', default='', help='write t,x_C (the slider position) here')
a, exu, cpu0 = start(ap)
import numpy as np
from exudyn.itemInterface import (NodeRigidBodyRotVecLG, NodeRigidBodyRxyz, NodeRigidBodyEP,
    ObjectGround, ObjectBeamGeometricallyExact, ObjectMassPoint, MarkerNodeRigid,
    MarkerBodyRigid, GenericJoint, SensorNode)
from exudyn.rigidBodyUtilities import AngularVelocity2EulerParameters_t

r, l, M, omega = 0.15, 0.30, 2.0, 2 * np.pi
sec = exu.BeamSection()
# generalized strains (axial, shear y, shear z | torsion, bending y, bending z);
# local y = flexmech's e2 = global y
sec.stiffnessMatrix = np.diag([1e8, 1e8, 1e8, 1e5, 1e5, 1e5])   # EA GA2 GA3 GJ EI2 EI3
sec.inertia = np.diag([2e-9, 1e-9, 1e-9])  # rho*(I2+I3), rho*I2, rho*I3 (flexmech's rhoJ)
sec.massPerLength = 1e-3                   # rhoA

SC = exu.SystemContainer()
mbs = SC.AddSystem()
Node, rot0 = {'RotVecLG': (NodeRigidBodyRotVecLG, [0, 0, 0]), 'Rxyz': (NodeRigidBodyRxyz, [0, 0, 0]),
              'EP': (NodeRigidBodyEP, [1, 0, 0, 0])}[a.node]


def rot_rate(wz):
    """node velocity coordinates of an angular velocity (0, 0, wz) at the identity:
    Tait-Bryan rates (Rxyz), angular velocity (RotVecLG), Euler parameter rates (EP)"""
    if a.node == 'EP':
        return list(AngularVelocity2EulerParameters_t([0, 0, wz], [1, 0, 0, 0]))
    return [0, 0, wz]


def beam(x0, x1, ne, wz, xc):
    """nodes and elements of a straight link along x from x0 to x1, moving rigidly at
    angular velocity (0, 0, wz) about the point (xc, 0, 0)"""
    le = (x1 - x0) / ne
    nodes = []
    for i in range(ne + 1):
        x = x0 + i * le
        v = [0, wz * (x - xc), 0]          # (0, 0, wz) x (x - xc, 0, 0)
        nodes.append(mbs.AddNode(Node(referenceCoordinates=[x, 0, 0] + rot0,
                                      initialVelocities=v + rot_rate(wz))))
    for i in range(ne):
        mbs.AddObject(ObjectBeamGeometricallyExact(nodeNumbers=[nodes[i], nodes[i + 1]],
                                                   length=le, sectionData=sec))
    return nodes


K = a.elements_scale
crank = beam(0.0, r, 2 * K, omega, 0.0)
rod = beam(r, r + l, 4 * K, -omega * r / l, r + l)
block = beam(r + l, r + l + 0.02, 1 * K, 0.0, 0.0)
mbs.AddObject(ObjectMassPoint(nodeNumber=block[0], mass=M))     # the slider's mass at C

ground = mbs.AddObject(ObjectGround())
def rigid(node):
    return mbs.AddMarker(MarkerNodeRigid(nodeNumber=node))
def fixed(x):
    return mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[x, 0, 0]))


# A: crank.start to the ground at the origin; the revolute's released angle about z
# driven at theta = omega t (all six relative coordinates held, the z-rotation offset
# by theta: Tait-Bryan angles (0, 0, theta) of the joint frame)
def drive(mbs, t, itemNumber, p):
    return [0, 0, 0, 0, 0, omega * t]
def drive_t(mbs, t, itemNumber, p):
    return [0, 0, 0, 0, 0, omega]
mbs.AddObject(GenericJoint(markerNumbers=[fixed(0.0), rigid(crank[0])], constrainedAxes=[1] * 6,
                           offsetUserFunction=drive, offsetUserFunction_t=drive_t))
# B and C: revolutes about z (joint frames = global axes at t = 0, the nodes' frames)
mbs.AddObject(GenericJoint(markerNumbers=[rigid(crank[-1]), rigid(rod[0])],
                           constrainedAxes=[1, 1, 1, 1, 1, 0]))
mbs.AddObject(GenericJoint(markerNumbers=[rigid(block[0]), rigid(rod[-1])],
                           constrainedAxes=[1, 1, 1, 1, 1, 0]))
# slide: block.start on the ground, free along x only
mbs.AddObject(GenericJoint(markerNumbers=[fixed(r + l), rigid(block[0])],
                           constrainedAxes=[0, 1, 1, 1, 1, 1]))

sC = mbs.AddSensor(SensorNode(nodeNumber=block[0], storeInternal=True, writeToFile=False,
                              outputVariableType=exu.OutputVariableType.Position))
mbs.Assemble()

s = dynamic_settings(exu, a.dt, a.t_end, a.fast, newmark=False, rho=0.5)
t = s.timeIntegration
if a.newton_error == 'increment':   # robust at every element count, see README.md
    t.newton.residualMode = 1
    t.newton.relativeTolerance = t.newton.absoluteTolerance = a.tol
else:
    t.newton.relativeTolerance = a.tol
cpu1 = time.process_time()

mbs.SolveDynamic(s)
cpu2 = time.process_time()
d = mbs.GetSensorStoredData(sC)                     # columns t, x, y, z
assert len(d) == t.numberOfSteps + 1, f'{len(d)} sensor rows for {t.numberOfSteps} steps'
if a.csv:
    np.savetxt(a.csv, d[:, :2], delimiter=',', header='t,x_C', comments='', fmt='%.17g')
th = omega * d[:, 0]
xr = r * np.cos(th) + np.sqrt(l**2 - (r * np.sin(th))**2)
late = d[:, 0] >= 0.05
it = mbs.sys['dynamicSolver'].it
print(f'exudyn {exu.__version__} {"fast/modified" if a.fast else "full"} Newton ({a.newton_error} {a.tol:g}), '
      f'node {a.node}, '
      f'{len(crank) - 1}/{len(rod) - 1}/{len(block) - 1} elements, {int(t.numberOfSteps)} steps: '
      f'{it.newtonStepsCount} Newton iterations, {it.newtonJacobiCount} Jacobians')
print(f'x_C final {d[-1, 1]:.9f}; max |x_C - rigid| {np.abs(d[:, 1] - xr).max():.3e}, '
      f'after t = 0.05: {np.abs(d[late, 1] - xr[late]).max():.3e}; max |y_C| {np.abs(d[:, 2]).max():.3e}')
print(f'cpu_build_s {cpu1 - cpu0:.4f}')
print(f'cpu_solve_s {cpu2 - cpu1:.4f}')
