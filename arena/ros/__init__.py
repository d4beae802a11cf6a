"""ROS interoperability: the topic and frame table, messages as plain values, bags.

- :mod:`arena.ros.topics`: topic names, types and frames after REP 105 and Nav2's defaults
  (:func:`~arena.ros.topics.topic_table`), shared by bags and live bridges;
- :mod:`arena.ros.messages`: an episode's scene and frames as message field values (nested
  dicts, no ROS library needed), :class:`~arena.ros.messages.RosMessages`;
- :mod:`arena.ros.bag`: ROS 1 bags and ROS 2 MCAP bags with ``rosbags``
  (``pip install 'arena[rosbag]'``), :class:`~arena.ros.bag.RosbagSink`.
"""
