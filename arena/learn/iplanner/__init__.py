"""iPlanner: imperative (self-supervised) learning of a depth-image path planner.

After Yang, Wang, Cadena, Hutter, "iPlanner: Imperative Path Planning" (RSS 2023). A network
maps a depth image and a goal in the robot frame to ``K`` waypoints and a collision probability;
it is trained without labels by differentiating a trajectory cost (obstacle cost read from the
map's signed distance field along the spline through the waypoints, goal distance, motion
length) through the spline into the network.

- :mod:`.geometry`: the camera, the network input, the spline, the obstacle cost (numpy);
- :mod:`.network`: the network's numpy forward and its ``.npz`` file;
- :mod:`.data`: training poses on generated maps, their depth images (MuJoCo) and distance maps;
- :mod:`.loss`, :mod:`.torch_net`, :mod:`.train`: training (torch).

The planner that runs it is :mod:`arena.learn.planners.iplanner`.
"""
