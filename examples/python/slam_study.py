"""SLAM with a heterogeneous prior map from Python: the Monte Carlo study, with and without the map.

Run: PYTHONPATH=build/release/python python3 examples/python/slam_study.py
"""

import priormap

study = priormap.slam_study(runs=10, seed=1)
for variant in ("with_prior", "without_prior"):
    s = study[variant]
    print(f"{variant:14s} RMS position {s['rms_position_m']:.2f} m, mean NEES {s['mean_nees']:.2f}")
c = study["constraints"]
print(f"landmark-to-wall relations: {c['correct']} correct, {c['incorrect']} incorrect; "
      f"the prior map cuts the position error {study['rms_position_ratio']:.1f}-fold")
