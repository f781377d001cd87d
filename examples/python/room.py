"""A rectangular room with exact ranges: the simulated data of the examples."""

import numpy as np

ROOM = (-2.0, -1.5, 3.0, 2.5)  # xmin, ymin, xmax, ymax, m


def room_ranges(pose, angles, room=ROOM):
    """Exact distances from the sensor pose (x, y, theta) along each beam to the room's walls."""
    x, y, theta = pose
    xmin, ymin, xmax, ymax = room
    dx, dy = np.cos(theta + angles), np.sin(theta + angles)
    with np.errstate(divide="ignore"):
        tx = np.where(dx > 0, (xmax - x) / dx, (xmin - x) / dx)
        ty = np.where(dy > 0, (ymax - y) / dy, (ymin - y) / dy)
    return np.minimum(tx, ty)
