"""The planar lidar: :class:`Lidar2D` and its numba kernels.

:mod:`.model` holds :class:`Lidar2D`, the wall faces of a map and the documentation of what a
beam hits; :mod:`.kernels` the scan kernel (faces, circles, segments, noise) and
:mod:`.grid_kernels` the grid walk; :mod:`.bank` every lidar of every engine world.
:data:`FACES_PER_BEAM` is read by :mod:`.model`: set it there.
"""

from arena.sensors.lidar2d.grid_kernels import CORNER_EPS
from arena.sensors.lidar2d.kernels import ATAN_ERR
from arena.sensors.lidar2d.model import FACES_PER_BEAM, Lidar2D, use_wall_faces, wall_faces

__all__ = ["ATAN_ERR", "CORNER_EPS", "FACES_PER_BEAM", "Lidar2D", "use_wall_faces", "wall_faces"]
