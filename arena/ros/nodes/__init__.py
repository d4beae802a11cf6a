"""Small ROS nodes of Arena's own: examples and test partners of the ROS bridges."""
