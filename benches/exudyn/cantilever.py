#!/usr/bin/env python3
"""Exudyn twin of benches/cantilever512.toml (flexmech's 2-node yardstick).

A 2 m cantilever along x, clamped at x = 0, a dead tip force (0, 0, 50) from t = 0,
EA = GA2 = GA3 = 1e6, GJ = EI2 = EI3 = 1e3, rhoA = 1, rhoJ = diag(1e-3, 5e-4, 5e-4),
Newmark trapezoidal rule (beta = 1/4, gamma = 1/2), dt = 1e-3. Element:
ObjectBeamGeometricallyExact (2 nodes, SE(3) interpolation) with NodeRigidBodyRxyz
nodes (see README.md for why not NodeRigidBodyRotVecLG).

    python3 cantilever.py [--elements 512] [--t-end 0.1] [--fast] [--csv tip.csv]

Default: full Newton. --fast: Exudyn's fastest setting (modified Newton, the
exudynCPPfast module, reused sparse pattern). One thread in both cases.
Prints the CPU time of the solve alone (time.process_time) and of the model build.
"""
import argparse
import sys
import time

from twin import dynamic_settings, start

ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
ap.add_argument('--elements', type=int, default=512)
ap.add_argument('--t-end', type=float, default=0.1)
ap.add_argument('--dt', type=float, default=1e-3)
ap.add_argument('--fast', action='store_true', help='modified Newton + exudynCPPfast')
ap.add_argument('--node', choices=['Rxyz', 'EP', 'RotVecLG'], default='Rxyz')
ap.add_argument('--static', action='store_true', help='static solution only (check)')
ap.add_argument('--csv', default='', help='write t,ux,uy,uz of the tip here')
a, exu, cpu0 = start(ap)
import numpy as np
from exudyn.itemInterface import (NodeRigidBodyRxyz, NodeRigidBodyEP, NodeRigidBodyRotVecLG,
    NodePointGround, ObjectGround, ObjectBeamGeometricallyExact, MarkerNodeCoordinate,
    MarkerNodeRigid, MarkerBodyRigid, CoordinateConstraint, GenericJoint, Force, SensorNode)

L, ne = 2.0, a.elements
sec = exu.BeamSection()
# generalized strains (axial, shear y, shear z | torsion, bending y, bending z);
# local y = flexmech's e2 = global y, so GA2/EI2 are the y entries (all equal here)
sec.stiffnessMatrix = np.diag([1e6, 1e6, 1e6, 1e3, 1e3, 1e3])   # EA GA2 GA3 GJ EI2 EI3
sec.inertia = np.diag([1e-3, 5e-4, 5e-4])  # rho*(I2+I3), rho*I2, rho*I3 (flexmech's rhoJ)
sec.massPerLength = 1.0                    # rhoA

SC = exu.SystemContainer()
mbs = SC.AddSystem()
Node, rot0 = {'Rxyz': (NodeRigidBodyRxyz, [0, 0, 0]), 'EP': (NodeRigidBodyEP, [1, 0, 0, 0]),
              'RotVecLG': (NodeRigidBodyRotVecLG, [0, 0, 0])}[a.node]
le = L / ne
nodes = [mbs.AddNode(Node(referenceCoordinates=[i * le, 0, 0] + rot0)) for i in range(ne + 1)]
for i in range(ne):
    mbs.AddObject(ObjectBeamGeometricallyExact(nodeNumbers=[nodes[i], nodes[i + 1]],
                                               length=le, sectionData=sec))
if a.node == 'EP':   # clamp by a joint (Euler parameters are not zero at rest)
    mG = mbs.AddMarker(MarkerBodyRigid(bodyNumber=mbs.AddObject(ObjectGround())))
    mbs.AddObject(GenericJoint(markerNumbers=[mG, mbs.AddMarker(MarkerNodeRigid(nodeNumber=nodes[0]))]))
else:                # clamp: 3 displacements + 3 rotation parameters held at 0
    mG = mbs.AddMarker(MarkerNodeCoordinate(
        nodeNumber=mbs.AddNode(NodePointGround(referenceCoordinates=[0, 0, 0])), coordinate=0))
    for c in range(6):
        mbs.AddObject(CoordinateConstraint(markerNumbers=[
            mG, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=c))]))
# dead load: global direction, constant from t = 0 (bodyFixed=False is the default)
mbs.AddLoad(Force(markerNumber=mbs.AddMarker(MarkerNodeRigid(nodeNumber=nodes[-1])),
                  loadVector=[0, 0, 50], bodyFixed=False))
sTip = mbs.AddSensor(SensorNode(nodeNumber=nodes[-1], storeInternal=True, writeToFile=False,
                                outputVariableType=exu.OutputVariableType.Displacement))
mbs.Assemble()

s = dynamic_settings(exu, a.dt, a.t_end, a.fast, newmark=True, rho=1.0)
t = s.timeIntegration
t.generalizedAlpha.newmarkBeta = 0.25
t.generalizedAlpha.newmarkGamma = 0.5
cpu1 = time.process_time()

if a.static:
    s.staticSolver.numberOfLoadSteps = 10
    s.staticSolver.verboseMode = 0
    mbs.SolveStatic(s)
    u = mbs.GetNodeOutput(nodes[-1], exu.OutputVariableType.Displacement)
    print(f'static tip displacement {u}; linear PL^3/(3EI) + PL/GA = {50*8/3000 + 50*2/1e6:.6f}')
    sys.exit(0)

mbs.SolveDynamic(s)
cpu2 = time.process_time()
d = mbs.GetSensorStoredData(sTip)                   # columns t, ux, uy, uz
assert len(d) == t.numberOfSteps + 1, f'{len(d)} sensor rows for {t.numberOfSteps} steps'
if a.csv:
    np.savetxt(a.csv, d, delimiter=',', header='t,ux,uy,uz', comments='', fmt='%.17g')
it = mbs.sys['dynamicSolver'].it
print(f'exudyn {exu.__version__} {"fast/modified" if a.fast else "full"} Newton, node {a.node}, '
      f'{ne} elements, {int(t.numberOfSteps)} steps: {it.newtonStepsCount} Newton iterations, '
      f'{it.newtonJacobiCount} Jacobians')
print(f'tip uz final {d[-1, 3]:.9f} max {d[:, 3].max():.9f} at t = {d[d[:, 3].argmax(), 0]:.4f}')
print(f'cpu_build_s {cpu1 - cpu0:.4f}')
print(f'cpu_solve_s {cpu2 - cpu1:.4f}')
