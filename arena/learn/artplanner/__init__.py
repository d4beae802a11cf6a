"""ArtPlanner's learned motion cost (Wellhausen & Hutter 2023), trained on a stepping model.

:mod:`.stepping` labels an edge on a height map (feasible, time per metre) with a kinematic
model of a Go1-sized quadruped, :mod:`.features` samples the height patch along an edge that the
network sees, :mod:`.dataset` draws random terrain patches and edges, :mod:`.model` holds the
MLP as a ``.npz`` file run with numpy and :mod:`.train` fits it with torch. The planner is
:mod:`arena.learn.planners.artplanner`.
"""
