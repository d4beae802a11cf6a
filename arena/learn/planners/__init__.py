"""The learned local planners (eight, trained by :mod:`arena.learn`, run with numpy).

``rosnav_rl`` is a PPO policy, ``rlca`` Long et al.'s, ``crowdnav``/``sarl`` value networks,
``applr`` DWA whose parameters a TD3 policy sets every second, ``lflh`` an MLP trained on
hallucinated obstacles behind a safety check, ``trail`` DRL-VO's CNN policy with turning in
place and ``iplanner`` a depth-image network whose waypoints pure pursuit tracks.

They run, with numpy, the policies trained by :mod:`arena.learn` and registered in
:data:`~arena.nav.local_planners.LOCAL_PLANNERS` under those names (imported when a config
first names one). They live here, above ``nav``, so that ``nav`` never imports ``learn``.
"""
