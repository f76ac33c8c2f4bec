"""Result.plot draws with matplotlib (skipped where it is not installed)."""

from __future__ import annotations

import numpy as np
import pytest

import flexmech

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")


def test_plot_draws_a_curve_per_column(in_root, tmp_path):
    result = flexmech.run(flexmech.Model.load("data/paper/screw_driven.toml"))
    ax = result.plot("/nodes/arm.end/position", "/energy/total")
    lines = ax.get_lines()
    assert len(lines) == 4
    assert [l.get_label() for l in lines] == [
        "/nodes/arm.end/position[x]",
        "/nodes/arm.end/position[y]",
        "/nodes/arm.end/position[z]",
        "/energy/total",
    ]
    assert np.array_equal(lines[2].get_ydata(), result["/nodes/arm.end/position"][:, 2])
    assert np.array_equal(lines[0].get_xdata(), result.time)
    assert ax.get_xlabel() == "time"
    ax = result.plot("/nodes/arm.end/position[z]", x="/nodes/arm.end/position[x]")
    assert np.array_equal(ax.get_lines()[0].get_xdata(), result["/nodes/arm.end/position"][:, 0])
    ax.figure.savefig(tmp_path / "plot.png")
    assert (tmp_path / "plot.png").stat().st_size > 1000
