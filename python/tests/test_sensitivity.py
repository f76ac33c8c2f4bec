"""Exact sensitivities from Python: a cantilever built in Python asks for
its tip deflection's derivatives by a stiffness, by the load and by its
length, checked against Timoshenko's closed form of the discrete beam."""

from __future__ import annotations

import flexmech

# Length, elements, tip force, EI, GA: |F| L^2 / EI = 2e-3, linear to ~1e-6.
L, N, F, EI, GA = 2.0, 16, -0.5, 1e3, 4e6


def cantilever() -> flexmech.Model:
    model = flexmech.Model("cantilever").section("rod", EA=1e7, GA=[GA, GA], GJ=1e3, EI=[EI, EI])
    model.beam("arm", "rod", start=[0, 0, 0], end=[L, 0, 0], elements=N, e2=[0, 1, 0])
    model.support("arm.start").nodal_load("arm.end", [0, 0, F]).statics(4)
    return model.solver(tolerance=1e-12).track("arm.end")


def test_the_tip_deflection_by_ei_and_by_the_load():
    model = cantilever().sensitivity("section.rod.EI[0]", "load[0].force[2]")
    result = flexmech.run(model)
    assert result.completed
    w = result["/nodes/arm.end/displacement"][-1, 2]
    by_ei = result["/sensitivity/section.rod.EI[0]/nodes/arm.end/displacement"][-1, 2]
    by_f = result["/sensitivity/load[0].force[2]/nodes/arm.end/displacement"][-1, 2]
    # The one-point-quadrature elements bend as the Timoshenko beam with
    # L^3 -> L^3 (1 - 1/(4 N^2)): dw/dEI2 = -F L^3/(3 EI^2)(1 - 1/(4N^2)).
    exact = -F * L**3 / (3 * EI**2) * (1 - 1 / (4 * N * N))
    assert abs(by_ei / exact - 1) < 1e-5, (by_ei, exact)
    assert abs(by_f - w / F) < 1e-5 * abs(w / F), (by_f, w / F)
    # A linear structure's total energy at equilibrium is E = -F w / 2 with
    # w = c F, so dE/dF = -c F = -w.
    by_f_energy = result["/sensitivity/load[0].force[2]/energy/total"][-1]
    assert abs(by_f_energy + w) < 1e-5 * abs(w), (by_f_energy, w)


def test_the_tip_deflection_by_the_beams_length():
    # Moving the beam's end along its axis: dw/dL = F L^2/EI (1 - 1/(4N^2)) + F/GA
    # for the discrete Timoshenko beam (its w = F L^3/(3EI)(1 - 1/(4N^2)) + F L/GA).
    model = cantilever().sensitivity("beam.arm.end[0]")
    result = flexmech.run(model)
    assert result.completed
    by_l = result["/sensitivity/beam.arm.end[0]/nodes/arm.end/displacement"][-1, 2]
    exact = F * L**2 / EI * (1 - 1 / (4 * N * N)) + F / GA
    assert abs(by_l / exact - 1) < 1e-5, (by_l, exact)


def test_a_key_that_names_no_real_value_is_refused():
    model = cantilever().sensitivity("beam[0].elements")
    try:
        flexmech.run(model)
    except flexmech.ModelError as e:
        assert e.key == "output.sensitivity[0]" and "an integer" in str(e)
    else:
        raise AssertionError("a key naming an integer was accepted")
