"""priormap.infer_scan: the MAP scan under a prior, against the truth of a synthetic room."""

import numpy as np
import pytest

import priormap
from conftest import true_normals, true_ranges


def angle_error(a, b):
    return np.abs(np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b)))))


def test_rectangular_prior_shrinks_the_noise_and_finds_the_walls(rng):
    pose = (0.3, -0.2, 0.4)
    angles = np.linspace(-2.0, 2.0, 361)
    truth = true_ranges(pose, angles)
    ranges = truth + rng.normal(0.0, 0.01, truth.shape)
    out = priormap.infer_scan(ranges, angles, prior="rectangular", sigma=0.01)

    assert isinstance(out["rho"], np.ndarray) and out["rho"].shape == (361,)
    assert out["inmodel"].dtype == bool
    inmodel = out["inmodel"]
    assert inmodel.mean() > 0.9
    measured_rms = np.sqrt(np.mean((ranges - truth)[inmodel] ** 2))
    corrected_rms = np.sqrt(np.mean((out["rho"] - truth)[inmodel] ** 2))
    assert corrected_rms < 0.5 * measured_rms
    # Normals: in the sensor frame the map gives alpha; the truth is in the world frame.
    normal_error = angle_error(out["alpha"] + pose[2], true_normals(pose, angles))[inmodel]
    assert np.median(normal_error) < np.radians(1.0)
    # The posterior is narrower than the sensor noise, and there are 4 walls' worth of regions.
    assert np.median(out["posterior_std"][inmodel]) < 0.01
    assert 4 <= len(out["regions"]) <= 12
    assert out["dof"]["extrinsic"] == 3


def test_outliers_are_flagged(rng):
    pose = (0.0, 0.0, 0.0)
    angles = np.linspace(-1.5, 1.5, 301)
    truth = true_ranges(pose, angles)
    ranges = truth + rng.normal(0.0, 0.01, truth.shape)
    spurious = rng.choice(301, 10, replace=False)
    ranges[spurious] *= 0.5
    out = priormap.infer_scan(ranges, angles, prior="polygonal")
    assert not out["inmodel"][spurious].any()


def test_nan_readings_are_invalid_and_bad_shapes_raise(rng):
    angles = np.linspace(-1.0, 1.0, 101)
    ranges = true_ranges((0.0, 0.0, 0.0), angles) + rng.normal(0.0, 0.01, 101)
    ranges[[5, 50]] = np.nan
    out = priormap.infer_scan(ranges, angles, prior="polygonal")
    assert not out["inmodel"][[5, 50]].any()
    with pytest.raises(ValueError, match="angles"):
        priormap.infer_scan(ranges, angles[:-1])
    with pytest.raises(ValueError):
        priormap.infer_scan(ranges, angles, prior="no-such-prior")


def test_infinite_readings_come_back_as_infinite_floats(rng):
    # The JSON behind the dict writes infinities as "inf"; the arrays hold them as floats.
    angles = np.linspace(-1.0, 1.0, 101)
    ranges = true_ranges((0.0, 0.0, 0.0), angles) + rng.normal(0.0, 0.01, 101)
    ranges[[3, 70]] = [np.inf, -np.inf]
    out = priormap.infer_scan(ranges, angles, prior="polygonal")
    assert isinstance(out["rho"], np.ndarray) and out["rho"].dtype == np.float64
    assert out["rho"][3] == np.inf and out["rho"][70] == -np.inf
    assert not out["inmodel"][[3, 70]].any()
    assert isinstance(out["max_violation"], float)


def test_index_members_are_int_arrays_and_an_open_space_scan_gives_nan_arrays():
    pose = (0.3, -0.2, 0.4)
    angles = np.linspace(-2.0, 2.0, 361)
    out = priormap.infer_scan(true_ranges(pose, angles), angles, prior="rectangular")
    assert out["regions"].dtype == np.int64 and out["regions"].shape[1] == 2
    assert out["inmodel_beams"].dtype == np.int64
    lo, hi = out["regions"][0]
    assert len(out["rho"][lo:hi + 1]) == hi - lo + 1
    # Every beam at max range: nothing fits the prior, and the arrays stay arrays.
    empty = priormap.infer_scan(np.full(361, np.inf), angles, max_range=10.0)
    assert isinstance(empty["alpha"], np.ndarray) and np.all(np.isnan(empty["alpha"]))
    assert empty["regions"].shape == (0, 2) and empty["inmodel_beams"].shape == (0,)


def test_out_of_range_arguments_raise_value_errors():
    angles = np.linspace(-1.0, 1.0, 11)
    ranges = np.full(11, 2.0)
    with pytest.raises(ValueError, match="beta"):
        priormap.infer_scan(ranges, angles, beta=1.0)
    with pytest.raises(ValueError, match="eigenvariations"):
        priormap.infer_scan(ranges, angles, eigenvariations=-1)
    with pytest.raises(ValueError, match="empty"):
        priormap.infer_scan(np.zeros(0), np.zeros(0))


def test_one_scan_errors_index_the_scan_as_given():
    angles = np.linspace(-1.0, 1.0, 11)
    ranges = np.full(11, 2.0)
    holes = angles.copy()
    holes[4] = np.nan
    with pytest.raises(ValueError, match=r"^angles\[4\] = nan: angles must be finite"):
        priormap.infer_scan(ranges, holes)
    long = ranges.copy()
    long[3] = 1e300
    with pytest.raises(ValueError, match=r"^ranges\[3\] = 1e\+300: a return"):
        priormap.infer_scan(long, angles)
    with pytest.raises(ValueError, match=r"^angles must increase \(beam 0 to 1\)"):
        priormap.infer_scan(ranges, angles[::-1])
