"""APPLR: DWA whose parameters a TD3 policy sets every second (Xu et al., ICRA 2021).

"APPLR: Adaptive Planner Parameter Learning from Reinforcement" (Xu et al.): instead of driving the
robot, a reinforcement-learned policy chooses the parameters of a classical planner (DWA) once per
period from the laser scan, the goal and the parameters in use; the planner keeps driving, so its
safety checks stay in force whatever the policy says.

- :mod:`arena.learn.applr.space`: the tuned parameters, their documented ranges, the action ↔
  parameter mapping and the policy's observation (numpy only);
- :mod:`arena.learn.applr.tuned_dwa`: the DWA planner with parameters set from the outside;
- :mod:`arena.learn.applr.actor`: the exported actor (``.npz``) run with numpy;
- :mod:`arena.learn.applr.env`: the Gymnasium training environment (one step = one period);
- :mod:`arena.learn.applr.train`: TD3 training with Stable-Baselines3 and the export.

The registered local planner is :class:`arena.learn.planners.applr.ApplrPlanner` (``applr``).
"""
