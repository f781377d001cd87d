"""priormap.slam_study: the prior map makes the filter more accurate; runs are reproducible."""

import pytest

import priormap


def test_prior_map_reduces_the_position_error_and_seeds_reproduce():
    a = priormap.slam_study(runs=4, seed=2)
    assert a["runs"] == 4
    assert a["with_prior"]["rms_position_m"] < a["without_prior"]["rms_position_m"]
    assert a["constraints"]["correct"] > 10 * a["constraints"]["incorrect"]
    b = priormap.slam_study(runs=4, seed=2)
    assert a["with_prior"]["rms_position_m"] == b["with_prior"]["rms_position_m"]


def test_out_of_range_arguments_raise_value_errors_naming_them():
    # The bounds of `priormap slam simulate --runs` and `--prior-std`.
    for runs in (0, 100001):
        with pytest.raises(ValueError, match=r"runs must be in \[1, 100000\]"):
            priormap.slam_study(runs=runs)
    for std in (0.0, -1.0, float("nan"), 2e9):
        with pytest.raises(ValueError, match=r"prior_std must be in \(0, 1e\+09\] m"):
            priormap.slam_study(runs=1, prior_std=std)
