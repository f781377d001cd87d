"""Shared fixtures: synthetic scans of a rectangular room with known truth, made in numpy."""

import numpy as np
import pytest

ROOM = (-2.0, -1.5, 3.0, 2.5)  # xmin, ymin, xmax, ymax of a rectangular room, m


def true_ranges(pose, angles, room=ROOM):
    """Distance from the sensor pose (x, y, theta) along each beam to the room's walls."""
    x, y, theta = pose
    xmin, ymin, xmax, ymax = room
    directions = theta + np.asarray(angles)
    dx, dy = np.cos(directions), np.sin(directions)
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = np.where(dx > 0, (xmax - x) / dx, np.where(dx < 0, (xmin - x) / dx, np.inf))
        ty = np.where(dy > 0, (ymax - y) / dy, np.where(dy < 0, (ymin - y) / dy, np.inf))
    return np.minimum(tx, ty)


def true_normals(pose, angles, room=ROOM):
    """World angle of the inward normal of the wall each beam hits."""
    x, y, theta = pose
    xmin, ymin, xmax, ymax = room
    r = true_ranges(pose, angles, room)
    px = x + r * np.cos(theta + angles)
    py = y + r * np.sin(theta + angles)
    normals = np.empty_like(r)
    tol = 1e-9
    normals[np.abs(px - xmax) < tol] = np.pi
    normals[np.abs(px - xmin) < tol] = 0.0
    normals[np.abs(py - ymax) < tol] = -np.pi / 2
    normals[np.abs(py - ymin) < tol] = np.pi / 2
    return normals


@pytest.fixture
def rng():
    return np.random.default_rng(7)


@pytest.fixture
def room_scans(rng):
    """Eight localized scans of 181 beams over 180 degrees (sigma 1 cm) and their truth."""
    angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    poses = np.array([[-1.0 + 0.5 * k, 0.2 * np.sin(k), 0.8 * k] for k in range(8)])
    truth = np.array([true_ranges(p, angles) for p in poses])
    ranges = truth + rng.normal(0.0, 0.01, truth.shape)
    return poses, ranges, angles, truth
