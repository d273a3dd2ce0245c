"""The t-conorm catalogue and operator parsing."""

import re
from pathlib import Path

import numpy as np
import pytest

import fuzzyvox
from conftest import wall_points


def test_catalogue_lists_every_family_once_and_each_parses_back():
    names = fuzzyvox.operators()
    assert len(names) == len(set(names)) >= 12
    assert "product" in names and "dombi:2" in names and "minimum" in names
    for name in names:
        op = fuzzyvox.parse_operator(name)
        assert str(op) == name
        # Every t-conorm has 0 as identity and 1 as absorbing element.
        assert op.apply(0.0, 0.3) == pytest.approx(0.3, abs=1e-6)
        assert op.apply(1.0, 0.3) == pytest.approx(1.0, abs=1e-6)
        assert op.apply(0.2, 0.7) == pytest.approx(op.apply(0.7, 0.2), abs=1e-6)


def test_parse_operator():
    dombi = fuzzyvox.parse_operator(" Dombi:2 ")
    assert dombi.name == "dombi"
    assert dombi.parameter == 2.0
    assert dombi.parameter_name is not None
    assert fuzzyvox.parse_operator("product").parameter is None
    maximum = fuzzyvox.parse_operator("max")
    assert maximum.apply(0.2, 0.5) == pytest.approx(0.5)
    assert fuzzyvox.parse_operator("product").apply(0.5, 0.5) == pytest.approx(0.75)
    for bad in ["nope", "dombi:-1", "dombi:x", "product:2", ""]:
        with pytest.raises(fuzzyvox.InvalidInputError):
            fuzzyvox.parse_operator(bad)
    with pytest.raises(ValueError):
        maximum.apply(1.5, 0.0)


def test_every_operator_builds_a_map_that_sees_the_wall():
    q = np.array([[3.0, 0.02, 0.5], [1.5, 0.02, 0.25]])
    for name in fuzzyvox.operators():
        m = fuzzyvox.FuzzyMap(0.1, op=name)
        assert m.operator == name
        m.integrate_cloud(wall_points(), confidence=np.full(50, 0.8))
        mu = m.memberships(q)
        assert mu[0, 0] > mu[0, 1], name  # the wall: more occupied than free
        assert mu[1, 1] > mu[1, 0], name  # the way to it: more free than occupied


def test_the_package_readme_example_runs(capsys):
    readme = (Path(__file__).resolve().parent.parent / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", readme, flags=re.S)
    assert blocks
    for block in blocks:
        exec(compile(block, "python/README.md", "exec"), {})
    assert "occupied" in capsys.readouterr().out


def test_operators_pickle_and_compare():
    import pickle

    op = fuzzyvox.Operator("Dombi:2")
    assert op == fuzzyvox.parse_operator("dombi:2") != fuzzyvox.Operator("dombi:3")
    again = pickle.loads(pickle.dumps(op))
    assert again == op and str(again) == "dombi:2"
    assert len({op, again, fuzzyvox.Operator("max")}) == 2
