"""Scene types: what a world holds, below every layer that builds, simulates or samples one.

``state`` has the placed obstacles, the static world and the per-step snapshots
(:class:`~arena.scene.state.SimState`); ``episode`` has the episode description a task generator
produces and a backend consumes. Both are plain values that import nothing above
:mod:`arena.core` (the grid and the robot model they hold are typed, not imported), so maps,
robots, crowd, sim and tasks can all use them without importing one another.
"""
