"""LfLH: learning a local planner from hallucinated obstacles (Wang, Xiao et al., IROS 2021).

:mod:`.motions` samples open-space motions, :mod:`.hallucinate` places the obstacles that
make each motion the only way through, :mod:`.dataset` renders the scans the robot would see,
:mod:`.features` turns scan and target into the policy's input, :mod:`.actor` holds the MLP as
a ``.npz`` file run with numpy, :mod:`.safety` checks commands against a scan and
:mod:`.train` fits the MLP with torch. The planner is :mod:`arena.learn.planners.lflh`.
"""
