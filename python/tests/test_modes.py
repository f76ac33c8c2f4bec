"""Linearised analyses and critical points from Python: a cantilever's
natural frequencies against Euler–Bernoulli's, a column's buckling load
against Euler's, and the located limit points of an arc-length path against
the exact curve of the two-bar truss — the same runs as the command line's
(`flexmech/tests/modes.rs`, `arc_length.rs`)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import flexmech

L, EI, RHO_A = 2.0, 50.0, 0.3


def cantilever(elements: int = 24) -> flexmech.Model:
    model = flexmech.Model("cantilever").section(
        "rod", EA=1e7, GA=[1e7, 1e7], GJ=1e3, EI=[EI, EI], rhoA=RHO_A, rhoJ=[1e-8, 1e-8, 1e-8]
    )
    model.beam("arm", "rod", start=[0, 0, 0], end=[L, 0, 0], elements=elements, e2=[0, 1, 0], nodes_per_element=3)
    return model.support("arm.start")


def test_cantilever_frequencies_are_euler_bernoullis():
    # f_k = (β_k L)² / (2π L²) √(EI/ρA), each bending mode twice (two
    # planes, equal stiffness). Slender (EI/GA L² ~ 1e-6) with negligible
    # rotary inertia (ρJ/ρA L² ~ 1e-8), so Euler–Bernoulli holds; the
    # 3-node elements' discretisation error is below 1e-4.
    result = flexmech.run(cantilever().modal(6))
    assert result.completed, result.status
    f = result.frequencies
    assert f.shape == (6,)
    beta = [1.8751040687, 4.6940911330]
    expected = [b * b / (2 * math.pi * L * L) * math.sqrt(EI / RHO_A) for b in beta]
    bending = sorted(f)[:4]
    for k, fk in enumerate(bending):
        assert abs(fk / expected[k // 2] - 1) < 1e-4, (k, fk, expected[k // 2])
    # Mode 1 as nodal arrays in /configuration order, unit mass norm: the
    # clamped node does not move, the tip does.
    u, theta = result.mode(1)
    assert u.shape == theta.shape == (len(result.node_labels), 3)
    assert np.all(u[0] == 0.0) and np.linalg.norm(u[-1]) > 0.0
    with pytest.raises(IndexError, match="modes 1..6"):
        result.mode(7)


def test_column_buckling_load_is_eulers():
    p = 1.0
    model = cantilever(20).nodal_load("arm.end", [-p, 0, 0]).buckling(2)
    result = flexmech.run(model)
    p_cr = math.pi**2 * EI / (4 * L * L)
    # Both planes buckle at once (equal stiffness), within the element's
    # discretisation error.
    for lam in result.load_factors:
        assert abs(lam * p / p_cr - 1) < 1e-3, lam


def test_an_arc_length_path_locates_the_truss_limit_points(in_root):
    # data/statics/snap_through_truss.toml: reference load 2 P_max, so the
    # limit points are at load factors ±1/2 of the exact curve (the file's
    # comment); a stop at |u| = 0.3 ends the path earlier, completed, past
    # the first.
    model = flexmech.Model.load("data/statics/snap_through_truss.toml")
    result = flexmech.run(model)
    assert result.completed
    points = result.critical_points
    assert [k for k, _ in points] == ["limit", "limit"]
    a, h, ea = 1.0, 0.2, 1e4
    l0 = math.hypot(a, h)
    w = np.linspace(0.0, h, 200_001)
    exact = 2 * ea * (l0 - np.hypot(a, h - w)) / l0 * (h - w) / np.hypot(a, h - w)
    p_ref = 59.210352
    assert abs(points[0][1] * p_ref - exact.max()) < 1e-6 * exact.max()
    assert abs(points[1][1] * p_ref + exact.max()) < 1e-6 * exact.max()
    assert result.end_reason.startswith("reached load factor 1")
    model.solver(stop={"displacement": {"node": "left.end", "max": 0.3}})
    stopped = flexmech.run(model)
    assert stopped.completed
    assert "solver.stop.displacement" in stopped.end_reason
    assert stopped.critical_points[0] == points[0]


def test_a_ball_on_an_arm_passes_its_force_at_the_arm_s_end():
    # A cantilever whose tip carries a spherical joint on an arm a = 0.1
    # (the `arm` key); a post pinned at its foot hangs from the ball and is
    # pulled down by F. The cantilever twists by -a F L / GJ (linear
    # theory, to 1e-3) — the same model as flexmech/tests/joint_models.rs.
    a, f, gj = 0.1, 1.0, 100.0
    model = flexmech.Model("ball-on-arm").section("s", EA=1e8, GA=[1e8, 1e8], GJ=gj, EI=[1e4, 1e4])
    model.beam("cantilever", "s", start=[0, 0, 0], end=[1, 0, 0], elements=4, e2=[0, 1, 0], nodes_per_element=3)
    model.beam("post", "s", start=[1, a, 0], end=[1, a, -0.5], elements=2, e2=[1, 0, 0])
    model.support("cantilever.start").support("post.end", ["ux", "uy", "rz"])
    model.joint("ball", "spherical", "cantilever.end", "post.start", arm=[0.0, a, 0.0])
    model.nodal_load("post.end", [0, 0, -f]).statics(1).track("cantilever.end")
    result = flexmech.run(model)
    assert result.completed, result.status
    twist = result["/nodes/cantilever.end/rotation"][-1, 0]
    assert abs(twist / (-a * f / gj) - 1) < 1e-3, twist
    # The slave must start at the master plus the arm.
    model.set("joint[0].arm", [0.0, 2 * a, 0.0])
    with pytest.raises(Exception, match="joint\\[0\\].slave"):
        flexmech.run(model)
