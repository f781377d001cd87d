"""priormap.slam_study: the prior map makes the filter more accurate; runs are reproducible."""

import priormap


def test_prior_map_reduces_the_position_error_and_seeds_reproduce():
    a = priormap.slam_study(runs=4, seed=2)
    assert a["runs"] == 4
    assert a["with_prior"]["rms_position_m"] < a["without_prior"]["rms_position_m"]
    assert a["constraints"]["correct"] > 10 * a["constraints"]["incorrect"]
    b = priormap.slam_study(runs=4, seed=2)
    assert a["with_prior"]["rms_position_m"] == b["with_prior"]["rms_position_m"]
