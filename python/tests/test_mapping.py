"""Occupancy grid and PRF mapping on numpy scans of a known rectangular room."""

import json

import numpy as np
import pytest

import priormap
from conftest import ROOM


def cell_of(raster, x, y):
    ox, oy = raster["origin"]
    w, h = raster.get("cell_size", (raster["resolution"], raster["resolution"]))
    return int((y - oy) // h), int((x - ox) // w)  # row (from the bottom), column


def test_grid_sees_the_walls_and_the_free_room(room_scans):
    poses, ranges, angles, _ = room_scans
    grid = priormap.occupancy_grid(poses, ranges, angles, max_range=8.0, resolution=0.05)
    p = grid["probability"]
    assert p.ndim == 2
    xmin, ymin, xmax, ymax = ROOM
    assert p[cell_of(grid, 0.5, 0.5)] < 0.2       # inside: free
    assert p[cell_of(grid, xmax + 0.01, 0.5)] > 0.8  # on the east wall: occupied
    assert np.isnan(p[cell_of(grid, xmax + 0.8, 0.5)])  # behind it: unknown


def test_prf_posterior_is_white_inside_black_outside_and_reproducible(room_scans):
    poses, ranges, angles, _ = room_scans
    args = dict(max_range=8.0, samples=100000, burn_in=100000, chains=2, seed=5, beam_step=4)
    a = priormap.prf_map(poses, ranges, angles, anneal=True, **args)
    black = a["black_fraction"]
    xmin, ymin, xmax, ymax = ROOM
    assert black[cell_of(a, 0.5, 0.5)] < 0.1
    assert black[cell_of(a, xmax + 0.1, 0.5)] > 0.8  # just behind the wall: occupied
    assert a["beams"] == 8 * 46
    assert len(a["log_posterior"]) == 2
    # Two chains: each chain's P(black) is the pooled one plus or minus half the spread.
    spread = a["chain_spread"]
    assert spread.shape == black.shape
    assert np.all(spread >= 0.0)
    assert np.all(spread <= 2.0 * np.minimum(black, 1.0 - black) + 1e-12)
    geojson = json.loads(a["map_geojson"])
    assert geojson["type"] == "FeatureCollection"
    b = priormap.prf_map(poses, ranges, angles, anneal=True, **args)
    np.testing.assert_array_equal(a["black_fraction"], b["black_fraction"])


def test_bad_shapes_raise_value_errors(room_scans):
    poses, ranges, angles, _ = room_scans
    with pytest.raises(ValueError, match="poses"):
        priormap.occupancy_grid(poses[:, :2], ranges, angles, max_range=8.0)
    with pytest.raises(ValueError, match="ranges"):
        priormap.prf_map(poses, ranges[:3], angles, max_range=8.0)


def test_prf_cells_span_the_window_and_bad_arguments_raise_value_errors(room_scans):
    poses, ranges, angles, _ = room_scans
    args = dict(max_range=8.0, samples=1000, burn_in=1000, chains=1, beam_step=8)
    out = priormap.prf_map(poses, ranges, angles, resolution=0.7, **args)
    x0, y0, x1, y1 = out["window"]
    rows, columns = out["black_fraction"].shape
    width, height = out["cell_size"]
    assert width * columns == pytest.approx(x1 - x0)
    assert height * rows == pytest.approx(y1 - y0)
    for bad in (0.0, -0.1, float("nan")):
        with pytest.raises(ValueError, match="resolution"):
            priormap.prf_map(poses, ranges, angles, resolution=bad, **args)
    with pytest.raises(ValueError, match="samples"):
        priormap.prf_map(poses, ranges, angles, **{**args, "samples": 0})
    # Rasters the CLI refuses too (each chain keeps several of the window).
    with pytest.raises(ValueError, match="more than 1e\\+08"):
        priormap.prf_map(poses, ranges, angles, resolution=1e-4, **args)


def test_a_grid_too_large_for_memory_is_a_value_error(room_scans):
    poses, ranges, angles, _ = room_scans
    far = poses.copy()
    far[-1, 0] = 1e6  # a pose in millimetres among poses in metres
    with pytest.raises(ValueError, match="cells"):
        priormap.occupancy_grid(far, ranges, angles, max_range=8.0)


def test_out_of_range_run_options_raise_value_errors_as_the_cli_refuses_them(room_scans):
    # The bounds of `priormap prf`: --chains 1..256 (100000 chains would not finish), --beam-step
    # 1..100000, --p positive and finite, --samples 1..2^40, --burn-in 0..2^40.
    poses, ranges, angles, _ = room_scans
    args = dict(max_range=8.0, samples=1000, burn_in=1000, chains=1, beam_step=8)
    for key, bad, match in [("chains", 257, "chains must be in \\[1, 256\\], got 257"),
                            ("beam_step", 100001, "beam_step must be in \\[1, 100000\\]"),
                            ("p", float("inf"), "p must be positive and finite"),
                            ("samples", 2**40 + 1, "samples must be in \\[1, 2\\^40\\]"),
                            ("burn_in", 2**40 + 1, "burn_in must be in \\[0, 2\\^40\\]")]:
        with pytest.raises(ValueError, match=match):
            priormap.prf_map(poses, ranges, angles, **{**args, key: bad})


@pytest.mark.parametrize("mapper", ["occupancy_grid", "prf_map"])
def test_what_the_file_readers_refuse_is_a_value_error_naming_the_element(room_scans, mapper):
    poses, ranges, angles, _ = room_scans
    run = getattr(priormap, mapper)
    args = dict(max_range=8.0)
    if mapper == "prf_map":
        args.update(samples=1000, burn_in=0, chains=1, beam_step=8)
    far = poses.copy()
    far[2, 1] = 1e300  # beyond the world's 1e9 m: such a pose once made a grid one cell wide
    with pytest.raises(ValueError, match=r"poses\[2, 1\] = 1e\+300: x and y .* 1e\+09"):
        run(far, ranges, angles, **args)
    turned = poses.copy()
    turned[0, 2] = np.inf
    with pytest.raises(ValueError, match=r"poses\[0, 2\] = inf: theta must be finite"):
        run(turned, ranges, angles, **args)
    holes = angles.copy()
    holes[7] = np.nan  # was: "angles must increase (beam 6 to 7)"
    with pytest.raises(ValueError, match=r"angles\[7\] = nan: angles must be finite"):
        run(poses, ranges, holes, **args)
    long = ranges.copy()
    long[1, 3] = 1e300  # a return, as max_range is inf
    with pytest.raises(ValueError, match=r"ranges\[1, 3\] = 1e\+300: a return"):
        run(poses, long, angles, **{**args, "max_range": np.inf})
    # Beyond max_range the same value is a no-return reading, kept whatever its value.
    run(poses, long, angles, **args)
