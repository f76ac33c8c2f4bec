"""Shared by the Exudyn twins (cantilever.py, slider_crank.py): the simulation
settings both use — fixed step dt to t_end, every step recorded by the sensors, no
solution file, EigenSparse, one thread, full Newton unless `fast` (then Exudyn's
modified Newton with its reused pattern and constant mass matrix); generalized-α
with spectral radius `rho`, or Newmark's trapezoidal rule with `newmark`."""


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
