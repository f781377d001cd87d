"""Priorlets from Python: one noisy scan of a rectangular room + the rectangular prior.

Run: PYTHONPATH=build/release/python python3 examples/python/priorlets_scan.py
"""

import numpy as np

import priormap
from room import room_ranges


rng = np.random.default_rng(1)
angles = np.linspace(-2.0, 2.0, 361)
truth = room_ranges((0.3, -0.2, 0.4), angles)
ranges = truth + rng.normal(0.0, 0.01, angles.size)  # 1 cm noise
ranges[::40] *= 0.6                                    # a few spurious short readings

out = priormap.infer_scan(ranges, angles, prior="rectangular", sigma=0.01)
inmodel = out["inmodel"]
print(f"{inmodel.sum()} of {inmodel.size} readings fit the prior, {(~inmodel).sum()} outliers")
print(f"{len(out['regions'])} regions, {len(out['surfaces'])} surfaces, "
      f"degrees of freedom: {out['dof']['free']} free, {out['dof']['extrinsic']} extrinsic")
rms = lambda e: 1000 * np.sqrt(np.mean(e[inmodel] ** 2))  # noqa: E731
print(f"range error: {rms(ranges - truth):.1f} mm measured, {rms(out['rho'] - truth):.1f} mm "
      f"after the prior; posterior std {1000 * np.median(out['posterior_std'][inmodel]):.1f} mm")
