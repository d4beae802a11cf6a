"""Pedestrian simulation: crowd models behind one registry, social states, semantic layers.

The :class:`~arena.crowd.simulator.CrowdSimulator` is what the simulator backends call; the
motion model inside it comes from :data:`~arena.crowd.base.CROWD_MODELS`. Import from the
modules (``arena.crowd.base``, ``arena.crowd.simulator``, ``arena.crowd.state``): this package
imports nothing, so reading the registry does not compile the simulator's kernels.
"""
