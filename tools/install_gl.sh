#!/usr/bin/env bash
# Install headless OpenGL (EGL with Mesa's software and GPU drivers) for MuJoCo's offscreen
# rendering of 3-D worlds (arena.sim.mujoco, MUJOCO_GL=egl). Debian/Ubuntu, apt.
#
# Usage: sudo tools/install_gl.sh        (or as root in a container; .ci/run calls it)
#
# Idempotent: does nothing if libEGL, libOpenGL (GLVND) and Mesa's EGL vendor library are
# already known to the dynamic linker.
set -euo pipefail

have_gl() {
    local libs
    libs="$(ldconfig -p 2>/dev/null || /sbin/ldconfig -p)"
    for lib in libEGL.so.1 libOpenGL.so.0 libEGL_mesa.so.0; do
        grep -q "$lib " <<<"$libs" || return 1
    done
}

if have_gl; then
    echo "install_gl: EGL and OpenGL libraries already installed"
    exit 0
fi

# shellcheck source=tools/apt_lib.sh
source "$(dirname "$0")/apt_lib.sh"
apt_prepare install_gl "install libEGL, libOpenGL and Mesa's EGL driver (Debian: libegl1 libopengl0 libegl-mesa0 libgl1-mesa-dri) with your package manager"
apt_get update
apt_get install -y --no-install-recommends libegl1 libopengl0 libegl-mesa0 libgl1-mesa-dri

if have_gl; then
    echo "install_gl: installed"
    exit 0
fi
echo "install_gl: the install finished but libEGL/libOpenGL/libEGL_mesa are not found" >&2
exit 1
