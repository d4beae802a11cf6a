"""ROS 2 from the package index: import checks and the one package it lacks (``tf2_msgs``).

``pip install 'arena[ros2]'`` installs rclpy and the message packages Arena uses from PyPI
(the ``ros-kilted-*`` wheels), with no ROS install. Those wheels have no ``tf2_msgs``, whose
``TFMessage`` carries ``/tf`` and ``/tf_static``; :func:`build_tf2_msgs` builds it (TFMessage
only, upstream's definition, so the same type hash as a full ROS 2's) into the Python
environment with the wheels' own ``ament_cmake`` and ``rosidl`` generators, cmake and a C/C++
compiler: ``arena ros2 setup`` runs it once (about 5 s). Where a sourced ROS 2 install already
provides ``tf2_msgs``, nothing is built.
"""

from __future__ import annotations

import importlib
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path
from types import ModuleType

from arena.core.errors import ConfigError

#: The package sources (package.xml, CMakeLists.txt, msg/TFMessage.msg) shipped with Arena.
TF2_MSGS_SOURCE = Path(__file__).parent / "data" / "tf2_msgs"
INSTALL_HINT = "pip install 'arena[ros2]'"


def import_rclpy() -> ModuleType:
    """``rclpy`` with every message package the bridge uses, or a one-line error.

    Raises:
        ConfigError: what to install (the ``arena[ros2]`` extra, or ``arena ros2 setup`` for
            ``tf2_msgs``).
    """
    for module in ("rclpy", "geometry_msgs.msg", "nav_msgs.msg", "sensor_msgs.msg",
                   "visualization_msgs.msg", "rosgraph_msgs.msg", "std_srvs.srv"):
        try:
            mod = importlib.import_module(module)
        except ImportError as e:
            raise ConfigError(
                f"the ROS 2 bridge needs {module.split('.')[0]} ({e}): {INSTALL_HINT}, "
                "or source a ROS 2 install") from None
        probe = next((v for k, v in vars(mod).items() if isinstance(v, type)
                      and not k.startswith("_")), None)
        if module.endswith(".msg") and not hasattr(probe, "get_fields_and_field_types"):
            # ROS 1's genpy package of the same name, loaded earlier by the ROS 1 bridge
            raise ConfigError(
                f"the ROS 2 bridge imported {module} from {getattr(mod, '__file__', '?')}, which "
                "is not a ROS 2 (rosidl) package; run ROS 1 and ROS 2 in separate processes")
    try:
        importlib.import_module("tf2_msgs.msg")
    except ImportError:
        raise ConfigError(
            "the ROS 2 bridge needs tf2_msgs, which the PyPI ROS 2 wheels lack: run "
            "'arena ros2 setup' once (builds it; needs cmake and a C++ compiler), or source a "
            "ROS 2 install") from None
    return importlib.import_module("rclpy")


def tf2_msgs_available() -> bool:
    """``tf2_msgs.msg.TFMessage`` imports."""
    try:
        importlib.import_module("tf2_msgs.msg")
    except ImportError:
        return False
    return True


def build_tf2_msgs(prefix: Path | None = None, *, jobs: int = 2) -> Path:
    """Build ``tf2_msgs`` (TFMessage) and install it into ``prefix`` (default: ``sys.prefix``).

    The Python package lands in the environment's site-packages, its libraries in
    ``prefix/lib`` (where the wheels' loader looks) and its CMake files in ``prefix/share``.

    Returns:
        The installed Python package's folder.

    Raises:
        ConfigError: no ROS 2 wheels, no cmake or no compiler, or a failed build (its last
            output line in the message).
    """
    prefix = Path(prefix or sys.prefix)
    share = prefix / "share"
    if not (share / "rosidl_default_generators").is_dir() or not (share / "ament_cmake").is_dir():
        raise ConfigError(f"building tf2_msgs needs the ROS 2 build wheels in {prefix}: "
                          f"{INSTALL_HINT}")
    cmake = shutil.which("cmake")
    if cmake is None:
        raise ConfigError("building tf2_msgs needs cmake (Debian: apt-get install cmake; or "
                          "pip install cmake)")
    if shutil.which("c++") is None and shutil.which("g++") is None:
        raise ConfigError("building tf2_msgs needs a C++ compiler (Debian: apt-get install g++)")
    env = dict(os.environ)
    path_var = os.pathsep.join(p for p in (str(prefix), env.get("AMENT_PREFIX_PATH", "")) if p)
    env.update(AMENT_PREFIX_PATH=path_var, CMAKE_PREFIX_PATH=path_var,
               PATH=os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")]),
               LD_LIBRARY_PATH=os.pathsep.join(
                   p for p in (str(prefix / "lib"), env.get("LD_LIBRARY_PATH", "")) if p))
    with tempfile.TemporaryDirectory(prefix="arena-tf2-msgs-") as tmp:
        build = Path(tmp)
        steps = [
            [cmake, "-S", str(TF2_MSGS_SOURCE), "-B", str(build),
             f"-DCMAKE_INSTALL_PREFIX={prefix}", f"-DPython3_EXECUTABLE={sys.executable}",
             "-DBUILD_TESTING=OFF", "-DCMAKE_BUILD_TYPE=Release"],
            [cmake, "--build", str(build), "-j", str(jobs)],
            [cmake, "--install", str(build)],
        ]
        for cmd in steps:
            done = subprocess.run(cmd, env=env, capture_output=True, text=True, check=False)
            if done.returncode != 0:
                lines = [ln for ln in (done.stderr + done.stdout).splitlines() if ln.strip()]
                raise ConfigError(f"building tf2_msgs failed at '{Path(cmd[0]).name} "
                                  f"{cmd[1]}': {lines[-1] if lines else done.returncode}")
    site = Path(sysconfig.get_path("purelib", vars={"base": str(prefix)}))
    importlib.invalidate_caches()
    return site / "tf2_msgs"
