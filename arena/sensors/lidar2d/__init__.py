"""The planar lidar: :class:`Lidar2D`, :class:`LidarBank` and their numba kernels.

:mod:`.model` holds :class:`Lidar2D`, the wall faces of a map and the documentation of what a
beam hits; :mod:`.bank` the :class:`LidarBank` (every lidar of every world of a batched core,
one kernel call; its rows kernels in :mod:`.bank_kernels`); :mod:`.kernels` the one scan
function both use (faces, circles, segments, noise) and :mod:`.grid_kernels` the grid walk.
:data:`FACES_PER_BEAM` is read by :mod:`.model`: set it there.

The underscored names re-exported here (``_x as _x``) are the kernels ``arena.sim.batch``
imports; that engine is to be deleted (issue 18 §1), and those lines with it.
"""

from arena.sensors.lidar2d.bank import DynamicGeometry, LidarBank
from arena.sensors.lidar2d.grid_kernels import CORNER_EPS
from arena.sensors.lidar2d.grid_kernels import _cast_grid_many as _cast_grid_many
from arena.sensors.lidar2d.grid_kernels import _origin_touches_wall as _origin_touches_wall
from arena.sensors.lidar2d.kernels import _AXIS_SNAP as _AXIS_SNAP
from arena.sensors.lidar2d.kernels import ATAN_ERR
from arena.sensors.lidar2d.kernels import _add_noise as _add_noise
from arena.sensors.lidar2d.kernels import _beam_window as _beam_window
from arena.sensors.lidar2d.kernels import _cast_faces as _cast_faces
from arena.sensors.lidar2d.kernels import _circle_hit as _circle_hit
from arena.sensors.lidar2d.kernels import _fast_atan2 as _fast_atan2
from arena.sensors.lidar2d.kernels import _segments_into as _segments_into
from arena.sensors.lidar2d.model import FACES_PER_BEAM, Lidar2D, use_wall_faces, wall_faces

__all__ = [
    "ATAN_ERR",
    "CORNER_EPS",
    "FACES_PER_BEAM",
    "DynamicGeometry",
    "Lidar2D",
    "LidarBank",
    "use_wall_faces",
    "wall_faces",
]
