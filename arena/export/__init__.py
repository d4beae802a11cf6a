"""Exporters: Arena worlds and recordings written in other tools' formats (Gazebo SDF, MJCF)."""
