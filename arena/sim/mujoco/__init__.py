"""3-D worlds for MuJoCo (and Gazebo export), built from Arena's 2-D scene.

:mod:`.world` turns an occupancy grid, placed obstacles, robots and pedestrians into a
:class:`~.scene.Scene3D`: a plain description of bodies and primitive geoms that needs no
simulator. :mod:`.mjcf` writes it as MJCF (and compiles it with the optional ``mujoco``
package, extra ``arena[3d]``); :mod:`.sdf` writes a Gazebo SDF world. The ``mujoco`` simulator
backend (:mod:`.backend`) compiles that world per episode (:mod:`.sim`), takes its contacts as
the collision truth (:mod:`.contacts`) and measures sensors in it (:mod:`.sensors`,
:mod:`.lidar2d`).
"""
