"""ROS 1 from Debian: importing rospy into Arena's Python, and finding the ROS master.

Debian 12 packages ROS 1 (``ros-base``, ``python3-rospy`` and the ``python3-*-msgs``
packages; ``bash tools/install_ros1.sh``) into ``/usr/lib/python3/dist-packages``, which a
virtual environment does not see. :func:`import_rospy` makes it visible with as little reach
as it can:

- where ``rospy`` already imports (Debian's own ``python3``, a sourced ROS 1 setup, a
  ``PYTHONPATH``), nothing changes;
- otherwise that folder is *appended* to ``sys.path``, after the environment's own packages, so
  Debian's numpy, yaml or catkin_pkg never shadow the environment's;
- the ROS 1 message packages there (the folders with a ``msg/`` or ``srv/`` package:
  ``geometry_msgs``, ``std_srvs`` ...) are the exception: the ROS 2 wheels of ``arena[ros2]``
  install packages of the same names into the environment, whose ROS 2 classes rospy cannot
  send, so a finder placed first on ``sys.meta_path`` serves those names (and only those) from
  Debian's folder. One process therefore holds ROS 1's or ROS 2's message packages, not both:
  a process that already imported ROS 2's gets a one-line error instead of a mix.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import os
import socket
import sys
from collections.abc import Sequence
from pathlib import Path
from types import ModuleType
from urllib.parse import urlparse

from arena.core.errors import ConfigError

#: Where Debian installs ROS 1's Python packages.
DEBIAN_DIST = Path("/usr/lib/python3/dist-packages")
#: Debian packages of everything the bridge imports.
DEBIAN_PACKAGES = ("ros-base", "python3-rospy", "python3-tf2-msgs", "python3-nav-msgs",
                   "python3-sensor-msgs", "python3-geometry-msgs", "python3-visualization-msgs",
                   "python3-rosgraph-msgs", "python3-std-msgs", "python3-std-srvs")
INSTALL_HINT = (f"bash tools/install_ros1.sh (Debian: apt-get install "
                f"{' '.join(DEBIAN_PACKAGES)})")
#: The modules the bridge uses, each a ROS 1 (genpy) one once imported.
MESSAGE_MODULES = ("std_msgs.msg", "geometry_msgs.msg", "nav_msgs.msg", "sensor_msgs.msg",
                   "visualization_msgs.msg", "rosgraph_msgs.msg", "tf2_msgs.msg", "std_srvs.srv")
#: s to wait for the master's port to answer.
MASTER_CONNECT_S = 2.0


class _DebianMessageFinder(importlib.abc.MetaPathFinder):
    """Serves the top-level packages ``names`` from ``root`` ahead of every other path entry."""

    def __init__(self, root: Path, names: frozenset[str]) -> None:
        self.root = root
        self.names = names

    def find_spec(self, fullname: str, path: Sequence[str] | None,
                  target: ModuleType | None = None) -> importlib.machinery.ModuleSpec | None:
        if fullname not in self.names:
            return None  # submodules follow their package's __path__ (inside root)
        return importlib.machinery.PathFinder.find_spec(fullname, [str(self.root)])


def debian_message_packages(root: Path) -> frozenset[str]:
    """Top-level packages in ``root`` that hold ROS messages or services (genpy's layout)."""
    if not root.is_dir():
        return frozenset()
    return frozenset(p.name for p in root.iterdir()
                     if any((p / sub / "__init__.py").is_file() for sub in ("msg", "srv")))


def _findable(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


def _use_debian(root: Path) -> None:
    """Make Debian's ROS 1 under ``root`` importable (see the module doc); idempotent."""
    if any(isinstance(f, _DebianMessageFinder) for f in sys.meta_path):
        return
    names = debian_message_packages(root)
    foreign = sorted(n for n in names if n in sys.modules
                     and root not in Path(getattr(sys.modules[n], "__file__", None) or "/").parents)
    if foreign:
        raise ConfigError(
            f"the ROS 1 bridge cannot load Debian's {foreign[0]}: this process already imported "
            "another package of that name (ROS 2's?); run ROS 1 and ROS 2 in separate processes")
    if str(root) not in sys.path:
        sys.path.append(str(root))
    sys.meta_path.insert(0, _DebianMessageFinder(root, names))
    importlib.invalidate_caches()


def import_rospy() -> ModuleType:
    """``rospy`` with the message packages the bridge uses (ROS 1's), or a one-line error.

    Raises:
        ConfigError: ROS 1 is not installed (names the Debian packages), or a message package
            of that name is not ROS 1's (ROS 2's, imported by this process earlier).
    """
    if not _findable("rospy"):
        if not (DEBIAN_DIST / "rospy" / "__init__.py").is_file():
            raise ConfigError(f"the ROS 1 bridge needs rospy (Debian's ROS 1): {INSTALL_HINT}")
        _use_debian(DEBIAN_DIST)
    for module in ("rospy", *MESSAGE_MODULES):
        try:
            mod = importlib.import_module(module)
        except ImportError as e:
            raise ConfigError(f"the ROS 1 bridge needs {module.split('.')[0]} ({e}): "
                              f"{INSTALL_HINT}") from None
        probe = next((v for k, v in vars(mod).items() if isinstance(v, type)
                      and not k.startswith("_")), None)
        if module != "rospy" and not hasattr(probe, "_slot_types"):
            raise ConfigError(
                f"the ROS 1 bridge imported {module} from {getattr(mod, '__file__', '?')}, which "
                "is not a ROS 1 (genpy) package; run ROS 1 and ROS 2 in separate processes")
    return importlib.import_module("rospy")


def master_uri() -> str:
    """The ROS master's URI (``ROS_MASTER_URI``, ROS 1's default ``http://localhost:11311``)."""
    return os.environ.get("ROS_MASTER_URI", "http://localhost:11311")


def check_master(uri: str | None = None, timeout: float = MASTER_CONNECT_S) -> None:
    """Raise a one-line :class:`ConfigError` unless the master's port accepts a connection.

    rospy's ``init_node`` waits for the master forever; this bounds that wait.
    """
    uri = uri or master_uri()
    url = urlparse(uri)
    if url.scheme != "http" or not url.hostname:
        raise ConfigError(f"ROS_MASTER_URI: {uri!r} is not a URI like http://127.0.0.1:11311")
    try:
        with socket.create_connection((url.hostname, url.port or 11311), timeout=timeout):
            pass
    except OSError as e:
        raise ConfigError(f"no ROS master answers at ROS_MASTER_URI={uri} ({e.strerror or e}): "
                          "start roscore, or set ROS_MASTER_URI") from None


def master_has_node(name: str) -> bool:
    """Whether a node called ``name`` (``/arena``) is registered with the master now."""
    import rosgraph

    try:
        rosgraph.Master("/arena_probe").lookupNode(name)
    except rosgraph.MasterError:
        return False
    return True
