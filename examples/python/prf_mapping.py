"""Polygonal random field vs occupancy grid from Python, on localized scans of a simulated room.

Run: PYTHONPATH=build/release/python python3 examples/python/prf_mapping.py
"""

import json

import numpy as np

import priormap
from room import room_ranges


rng = np.random.default_rng(1)
angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
poses = np.array([[-1.0 + 0.5 * k, 0.2 * np.sin(k), 0.8 * k] for k in range(8)])
ranges = np.array([room_ranges(p, angles) for p in poses]) + rng.normal(0.0, 0.01, (8, 181))

grid = priormap.occupancy_grid(poses, ranges, angles, max_range=8.0, resolution=0.05)
prf = priormap.prf_map(poses, ranges, angles, max_range=8.0, beam_step=4, samples=200000,
                       burn_in=200000, seed=1, anneal=True)
known = ~np.isnan(grid["probability"])
print(f"grid: {grid['probability'].shape} cells of {grid['resolution']} m, "
      f"{known.mean():.0%} of them observed")
print(f"PRF: {prf['beams']} beams, {prf['proposals_per_second'] / 1e3:.0f} k proposals/s, "
      f"R-hat {prf['rhat_log_posterior']:.3f}")
walls = json.loads(prf["map_geojson"])["features"]
print(f"MAP polygon map: {prf['map_edges']} edges, {prf['map_compact_bytes']} bytes, "
      f"{len(walls)} faces in GeoJSON")
