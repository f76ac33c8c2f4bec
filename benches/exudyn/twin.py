"""Shared by the Exudyn twins (cantilever.py, slider_crank.py, four_bar.py): the
command line of the mechanism twins and their start (Exudyn imported after the
command line is read: its fast module must be chosen before the import), and the
simulation settings all use — fixed step dt to t_end, every step recorded by the sensors, no
solution file, EigenSparse, one thread, full Newton unless `fast` (then Exudyn's
modified Newton with its reused pattern and constant mass matrix); generalized-α
with spectral radius `rho`, or Newmark's trapezoidal rule with `newmark`."""


import argparse
import sys
import time


def mechanism_args(doc, t_end, dt, counts):
    """the mechanism twins' common options; `counts` names the element counts that
    --elements-scale multiplies"""
    ap = argparse.ArgumentParser(description=doc.split('\n')[0])
    ap.add_argument('--t-end', type=float, default=t_end)
    ap.add_argument('--dt', type=float, default=dt)
    ap.add_argument('--elements-scale', type=int, default=1,
                    help=f'multiplies the element counts {counts}')
    ap.add_argument('--fast', action='store_true', help='modified Newton + exudynCPPfast')
    return ap


def start(ap):
    """parses the command line and imports Exudyn (its exudynCPPfast module with
    --fast: no range checks, AVX2); returns the arguments, the module and the CPU time
    at the start"""
    cpu0 = time.process_time()
    a = ap.parse_args()
    if getattr(a, 'elements_scale', 1) < 1:
        ap.error('--elements-scale must be at least 1')
    if a.fast:
        sys.exudynFast = True          # must precede the import
    import exudyn
    return a, exudyn, cpu0


def dynamic_settings(exu, dt, t_end, fast, newmark, rho):
    s = exu.SimulationSettings()
    s.solution.file.write = False
    s.solution.sensors.writePeriod = 0.999 * dt    # record every step
    s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    s.parallel.numberOfThreads = 1
    s.show.globalTimers = False
    t = s.timeIntegration
    t.endTime = t_end
    t.numberOfSteps = round(t_end / dt)
    t.adaptiveStep = False                          # fixed dt, as flexmech here
    t.verboseMode = 0
    t.generalizedAlpha.computeInitialAccelerations = True
    t.generalizedAlpha.useNewmark = newmark
    t.generalizedAlpha.spectralRadius = rho
    t.newton.useModifiedNewton = fast               # default full Newton
    if fast:
        s.linearSolver.reuseAnalyzedPattern = True
        t.reuseConstantMassMatrix = True
    return s
