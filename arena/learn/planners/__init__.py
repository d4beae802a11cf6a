"""The learned local planners: ``rosnav_rl`` (PPO), ``rlca`` (Long et al.), ``crowdnav``/``sarl``.

They run, with numpy, the policies trained by :mod:`arena.learn` and registered in
:data:`~arena.nav.local_planners.LOCAL_PLANNERS` under those names (imported when a config
first names one). They live here, above ``nav``, so that ``nav`` never imports ``learn``.
"""
