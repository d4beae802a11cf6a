"""An RGB-D camera over a compiled MuJoCo world: colour, metric depth and per-pixel person ids.

One :class:`RgbdCamera` per camera keeps its own GL context, ``MjrContext`` and ``MjvScene``
(creating them takes tens of milliseconds; a frame takes a few). A frame is two render passes
of the same scene:

1. colour and depth together: ``mjr_render`` then one ``mjr_readPixels(rgb, depth)``;
2. segmentation (optional): the same scene with ``mjRND_SEGMENT | mjRND_IDCOLOR``, every geom
   drawn flat in a colour encoding its index in the scene, read back and mapped to person ids
   (:func:`~arena.sim.mujoco.mjcf.person_ids_by_geom`). Colour and segmentation cannot share a
   pass: a pixel holds one colour.

The camera is a free ``mjvCamera`` placed from the robot's base pose and the spec's mount (the
model needs no camera elements); after ``mjv_updateScene`` the scene's GL camera gets the
spec's exact pose and frustum (intrinsics, near and far planes), so each camera has its own
field of view and principal point. OpenGL's rows run bottom-up; frames are flipped to image
order (row 0 at the top). The z-buffer is MuJoCo's reversed one (1 at ``near``, 0 at ``far``);
depth is linearised from it with the spec's ``near``/``far`` (not ``model.vis.map``, whose
``znear``/``zfar`` are fractions of ``model.stat.extent`` and apply to MuJoCo's own cameras).
Frames carry no noise; :func:`add_depth_noise` adds the spec's from a given generator.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from arena.sensors.spec3d import RgbdFrame, RgbdSpec, camera_pose
from arena.sim.mujoco.gl import gl_error, open_context
from arena.sim.mujoco.mjcf import import_mujoco, person_ids_by_geom


class RgbdCamera:
    """Renders :class:`RgbdFrame` s of ``spec`` from a world ``model`` (see the module docstring).

    Args:
        model: the compiled world (:func:`~arena.sim.mujoco.mjcf.compile_model`), left
            unchanged: this camera's offscreen buffer is the model's ``visual/global offwidth,
            offheight``, enlarged to the spec's image if that is larger, without multisampling.
        spec: the camera.
        segmentation: render the person-id pass (``False``: ``RgbdFrame.person`` is ``None``).

    Raises:
        ConfigError: no working OpenGL (what to install, see :mod:`.gl`).
    """

    def __init__(self, model: Any, spec: RgbdSpec, *, segmentation: bool = True) -> None:
        mj = import_mujoco()
        self._mj = mj
        self.model = model
        self.spec = spec
        self.segmentation = segmentation
        w, h = spec.width, spec.height
        self._ctx: Any = None
        glob, quality = model.vis.global_, model.vis.quality
        saved = (glob.offwidth, glob.offheight, quality.offsamples)
        # the MjrContext reads these once, when it is made: set them for it, then restore the
        # model. No multisampling: it would blend the id colours of the segmentation pass at
        # edges (and costs 4x the fragment work of a software renderer).
        glob.offwidth, glob.offheight = max(saved[0], w), max(saved[1], h)
        quality.offsamples = 0
        try:
            self._gl = open_context(mj, glob.offwidth, glob.offheight)
            try:  # GLFW without a display "opens" a context and fails here
                self._ctx = mj.MjrContext(model, mj.mjtFontScale.mjFONTSCALE_100)
            except Exception as e:
                raise gl_error(e) from None
        finally:
            glob.offwidth, glob.offheight, quality.offsamples = saved
        self._scene = mj.MjvScene(model, maxgeom=max(1000, 2 * model.ngeom))
        self._option = mj.MjvOption()
        mj.mjr_setBuffer(mj.mjtFramebuffer.mjFB_OFFSCREEN, self._ctx)
        self._ctx.readDepthMap = mj.mjtDepthMap.mjDEPTH_ZEROFAR
        self._rect = mj.MjrRect(0, 0, w, h)
        self._cam = mj.MjvCamera()
        self._cam.type = mj.mjtCamera.mjCAMERA_FREE
        self._person_of_geom = person_ids_by_geom(model).astype(np.int32)
        fx, fy, cx, cy = spec.intrinsics()
        # the frustum at the near plane through the outer pixel edges (u = -0.5 .. w - 0.5)
        near, far = np.float32(spec.near), np.float32(spec.far)
        self._near, self._far = float(near), float(far)
        self._frustum = (
            self._near * ((w - 1) / 2 - cx) / fx,  # horizontal centre
            -self._near * (h - 0.5 - cy) / fy,  # bottom
            self._near * (cy + 0.5) / fy,  # top
        )
        self._rgb = np.empty((h, w, 3), dtype=np.uint8)
        self._zbuf = np.empty((h, w), dtype=np.float32)
        self._seg = np.empty((h, w, 3), dtype=np.uint8)

    def close(self) -> None:
        """Free the GL resources (the camera cannot render afterwards); idempotent.

        The ``MjrContext`` is freed with this camera's own GL context current: freed under
        another camera's context it would delete that camera's buffers (GL object ids are per
        context and repeat).
        """
        ctx = getattr(self, "_ctx", None)
        if ctx is not None:
            with self._gl.as_current():
                ctx.free()
            self._ctx = None
            self._gl.free()

    def __del__(self) -> None:
        self.close()

    def remount(self, mount: tuple[float, float, float, float, float]) -> None:
        """Move the camera on its base to ``mount`` ``(x, y, z m, yaw, pitch rad)``.

        The image size and intrinsics stay (a video camera that follows a robot at a varying
        distance and pitch).
        """
        self.spec = self.spec.model_copy(update={"mount": tuple(float(v) for v in mount)})

    def _place(self, data: Any, pose: ArrayLike) -> None:
        """Update the scene from ``data`` and set its GL camera to the spec's pose and frustum."""
        mj = self._mj
        pos, forward, up = camera_pose(self.spec, pose)
        cam = self._cam
        cam.lookat[:] = pos + forward
        cam.distance = 1.0
        cam.azimuth = math.degrees(math.atan2(forward[1], forward[0]))
        cam.elevation = -math.degrees(self.spec.mount[4])
        mj.mjv_updateScene(self.model, data, self._option, None, cam, mj.mjtCatBit.mjCAT_ALL,
                           self._scene)
        centre, bottom, top = self._frustum
        for glcam in self._scene.camera:  # left and right eye: the same (no stereo)
            glcam.pos[:] = pos
            glcam.forward[:] = forward
            glcam.up[:] = up
            glcam.frustum_center = centre
            glcam.frustum_bottom = bottom
            glcam.frustum_top = top
            glcam.frustum_near = self._near
            glcam.frustum_far = self._far
            glcam.orthographic = 0

    def render(self, data: Any, pose: ArrayLike) -> RgbdFrame:
        """The frame seen from robot base pose ``pose`` ``(x, y, yaw)`` in world ``data``.

        ``data`` must be current (``mj_forward`` or ``mj_step`` after moving bodies). Returns
        new arrays; the same state renders the same bytes.
        """
        mj = self._mj
        if self._ctx is None:
            raise RuntimeError("render() after close()")
        self._gl.make_current()
        self._place(data, pose)
        mj.mjr_render(self._rect, self._scene, self._ctx)
        mj.mjr_readPixels(self._rgb, self._zbuf, self._rect, self._ctx)
        rgb = self._rgb[::-1].copy()
        depth = self.linear_depth(self._zbuf[::-1])
        person = self._person_pass()[::-1].copy() if self.segmentation else None
        return RgbdFrame(rgb, depth, person)

    def linear_depth(self, zbuf: NDArray[np.float32]) -> NDArray[np.float32]:
        """Metric depth ``(H, W)`` float32 (m) of reversed z-buffer values (1: near, 0: far).

        Inverts OpenGL's perspective projection: ``z = n (f - d) / (d (f - n))``, so
        ``d = f n / (n + z (f - n))``; ``z = 0`` (nothing drawn, or beyond ``far``) gives 0.
        """
        n, f = self._near, self._far
        z = zbuf.astype(np.float64)
        d = (f * n) / (n + z * (f - n))
        return np.where(z > 0.0, d, 0.0).astype(np.float32)

    def _person_pass(self) -> NDArray[np.int32]:
        """Person id per pixel (GL row order) from the segmentation render of the same scene."""
        mj = self._mj
        scene = self._scene
        flags = scene.flags
        seg, idc = mj.mjtRndFlag.mjRND_SEGMENT, mj.mjtRndFlag.mjRND_IDCOLOR
        flags[seg], flags[idc] = 1, 1
        try:
            mj.mjr_render(self._rect, scene, self._ctx)
        finally:
            flags[seg], flags[idc] = 0, 0
        mj.mjr_readPixels(self._seg, None, self._rect, self._ctx)
        s = self._seg.astype(np.int32)
        code = s[..., 0] | (s[..., 1] << 8) | (s[..., 2] << 16)  # segid + 1; 0: background
        geom = int(mj.mjtObj.mjOBJ_GEOM)
        pairs = [(g.segid + 1, self._person_of_geom[g.objid])
                 for g in (scene.geoms[k] for k in range(scene.ngeom))
                 if g.objtype == geom and g.segid >= 0]
        top = max((c for c, _ in pairs), default=0) + 1
        lut = np.full(top + 1, -1, dtype=np.int32)  # lut[top]: any code out of range
        for c, pid in pairs:
            lut[c] = pid
        out: NDArray[np.int32] = lut[np.minimum(code, top)]
        return out


def add_depth_noise(
    depth: NDArray[np.float32], spec: RgbdSpec, rng: np.random.Generator
) -> NDArray[np.float32]:
    """A copy of ``depth`` ``(H, W)`` (m) with the spec's Gaussian depth noise.

    One ``(H, W)`` standard normal draw when ``depth_noise_std > 0`` (none otherwise), added to
    the valid pixels only (``0``, no return, stays ``0``), clipped to ``[near, far]``.
    """
    out = np.array(depth, dtype=np.float32)
    if spec.depth_noise_std > 0.0:
        z = rng.standard_normal(out.shape)
        valid = out > 0
        noisy = np.clip(out + spec.depth_noise_std * z, spec.near, spec.far)
        out[valid] = noisy[valid]
    return out
