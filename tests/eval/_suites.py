"""Small suite files for the benchmark-runner tests (one text, not a copy per test module)."""

from __future__ import annotations


def stage(name: str, episodes: int, robot: str, *, timeout: float = 6,
          static: tuple[int, int] = (0, 0), dynamic: tuple[int, int] = (1, 1)) -> str:
    """One stage of a suite file on the packaged ``empty_room``, random robots and obstacles."""
    return f"""\
  - name: {name}
    episodes: {episodes}
    robot: {robot}
    map: empty_room
    tm_robots: random
    tm_obstacles: random
    timeout: {timeout:g}
    config:
      RANDOM:
        static: {{min: {static[0]}, max: {static[1]}}}
        dynamic: {{min: {dynamic[0]}, max: {dynamic[1]}}}
"""


#: Two stages of two episodes: ``open`` (jackal, a few boxes and people), ``crowd`` (burger, two
#: people).
TWO_STAGES = "stages:\n" + stage("open", 2, "jackal", static=(1, 2), dynamic=(1, 2)) + stage(
    "crowd", 2, "burger", dynamic=(2, 2)
)
