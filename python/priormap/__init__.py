"""priormap: 2D robotic mapping with structural prior knowledge.

Python bindings of the priormap C++ library (see docs/python.md):

- ``infer_scan``: MAP scan under an environment prior (priorlets), numpy in, dict of numpy out
- ``load_prior``, ``compile_prior``, ``list_priors``, ``Prior``: the prior language
- ``slam_study``: EKF-SLAM with and without a heterogeneous prior map (Monte Carlo study)
- ``occupancy_grid``, ``prf_map``: occupancy grid and polygonal random field mapping
"""

from ._priormap import (  # noqa: F401  (re-exported)
    Prior,
    compile_prior,
    infer_scan,
    list_priors,
    load_prior,
    occupancy_grid,
    prf_map,
    slam_study,
)

__all__ = [
    "Prior",
    "compile_prior",
    "infer_scan",
    "list_priors",
    "load_prior",
    "occupancy_grid",
    "prf_map",
    "slam_study",
]
