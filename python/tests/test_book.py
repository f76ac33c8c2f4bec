"""The Python blocks of the book's chapters (docs/book/python.md,
linearised.md) run, in order, in a scratch directory that sees the
repository's data/."""

from __future__ import annotations

import os
import re

import pytest

from conftest import ROOT


def test_the_chapter_runs(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib").use("Agg")
    text = (ROOT / "docs" / "book" / "python.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) >= 5
    (tmp_path / "data").symlink_to(ROOT / "data")
    monkeypatch.chdir(tmp_path)
    scope: dict = {}
    for block in blocks:
        exec(compile(block, "docs/book/python.md", "exec"), scope)
    assert os.path.exists("results/screw_driven.h5")
    assert os.path.exists("half.h5")
    assert os.path.exists("studies/pitch/summary.csv") and os.path.exists("studies/stiffness/summary.csv")
    assert os.path.exists("studies/pitch-dt/summary.csv")


def test_the_linearised_chapter_runs(tmp_path, monkeypatch):
    text = (ROOT / "docs" / "book" / "linearised.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert len(blocks) == 1
    (tmp_path / "data").symlink_to(ROOT / "data")
    monkeypatch.chdir(tmp_path)
    scope: dict = {}
    exec(compile(blocks[0], "docs/book/linearised.md", "exec"), scope)
    assert scope["frame"].critical_points[0][0] == "bifurcation"
    assert abs(scope["modes"].frequencies[0] - 1.8057) < 1e-3
