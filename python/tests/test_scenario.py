"""The simulated scenarios, their ground truth and an operator study from Python."""

import numpy as np
import pytest

import fuzzyvox


@pytest.fixture(scope="module")
def wall():
    return fuzzyvox.Scenario.wall()


def test_scenarios(wall):
    assert wall.name == "wall"
    assert wall.pairs == 12
    assert [p[0] for p in wall.phases] == ["strafe", "recede"]
    r = fuzzyvox.Scenario.random(pairs=5, seed=3)
    assert r.name == "random" and r.pairs == 5
    with pytest.raises(ValueError):
        fuzzyvox.Scenario.random(pairs=0)


def test_ground_truth_scores_itself_perfectly(wall):
    truth = wall.ground_truth(0.2)
    assert truth.resolution == 0.2
    assert 0 < truth.occupied_count < truth.observed_count
    occ = truth.occupied_centres()
    assert occ.shape == (truth.occupied_count, 3)
    empty = fuzzyvox.FuzzyMap(0.2)
    metrics = truth.evaluate(empty)
    assert metrics["occupied_recall"] == 0.0
    assert metrics["occupied"] == 0
    with pytest.raises(ValueError, match="resolution"):
        truth.evaluate(fuzzyvox.FuzzyMap(0.1))


def test_operator_study_on_the_wall(wall):
    exp = fuzzyvox.run_experiment(wall, res=0.2, operators=["max", "dombi:2"], seed=1)
    maps = exp.maps
    assert set(maps) == {"logodds", "alpha", "fuzzy", "fuzzy:maximum", "fuzzy:dombi:2"}
    assert isinstance(maps["fuzzy"], fuzzyvox.FuzzyMap)
    assert isinstance(maps["logodds"], fuzzyvox.LogOddsMap)
    report = exp.report
    assert report["scenario"] == "wall" and report["pairs"] == 12
    truth = wall.ground_truth(0.2)
    assert report["truth_occupied"] == truth.occupied_count
    for name, m in maps.items():
        metrics = report["maps"][name]
        assert 0.0 < metrics["occupied_f1"] <= 1.0
        assert metrics["holes"] >= 0 and metrics["spurious_unknown"] >= 0
        # The report's metrics are those of the returned map against the same truth.
        again = truth.evaluate(m)
        assert again["holes"] == metrics["holes"]
        assert again["occupied_f1"] == pytest.approx(metrics["occupied_f1"])
    assert maps["fuzzy:dombi:2"].operator == "dombi:2"
    with pytest.raises(ValueError, match="nope"):
        fuzzyvox.run_experiment(wall, operators=["nope"])
