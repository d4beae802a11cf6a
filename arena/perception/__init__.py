"""Perception: people as a robot's own sensors see them (issue 20).

:mod:`.tracker` tracks detected people (constant-velocity Kalman filters, optimal assignment);
:mod:`.mot` scores tracks against the ground truth (MOTA, MOTP, IDF1, id switches);
:mod:`.segments` cuts lidar scans into segments with the features a people detector classifies.
"""
