"""The learned local planners: ``rosnav_rl``, ``rlca``, ``crowdnav``/``sarl``, ``applr``, ``lflh``.

``rosnav_rl`` is a PPO policy, ``rlca`` Long et al.'s, ``crowdnav``/``sarl`` value networks,
``applr`` DWA whose parameters a TD3 policy sets every second and ``lflh`` an MLP trained on
hallucinated obstacles behind a safety check.

They run, with numpy, the policies trained by :mod:`arena.learn` and registered in
:data:`~arena.nav.local_planners.LOCAL_PLANNERS` under those names (imported when a config
first names one). They live here, above ``nav``, so that ``nav`` never imports ``learn``.
"""
