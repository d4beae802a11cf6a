"""Perception: people as a robot's own sensors see them (issue 20; docs/perception.md).

:mod:`.lidar_detector` finds people in planar scans (:mod:`.segments` cuts a scan into
segments with their features, :mod:`.lidar_data` draws labelled scans to train on);
:mod:`.rgbd_detector` finds them in RGB-D frames (:mod:`.convnet` is its pixel network,
:mod:`.rgbd_data` draws auto-labelled MuJoCo frames); both score candidates with
:mod:`.classifier` and are measured by :mod:`.scoring` (average precision).
:mod:`.tracker` tracks detected people (constant-velocity Kalman filters, optimal assignment);
:mod:`.mot` scores tracks against the ground truth (MOTA, MOTP, IDF1, id switches);
:mod:`.stage` is ``navigation.perception``: where the planners' people come from.
"""
