"""People from an RGB-D frame: a learned per-pixel person mask, back-projected and clustered.

:class:`RgbdPeopleDetector`:

1. shrinks the frame to every :data:`~arena.perception.rgbd_data.STRIDE`-th pixel (320 × 240 ->
   80 × 60; :func:`~arena.perception.rgbd_data.shrink_depth`) and builds the network's input
   (:func:`net_input`): depth, a valid-depth flag and each pixel's height above the floor (from
   the depth and the camera's mount). Colour is left out (see :data:`COLOUR`);
2. scores each pixel with the small fully convolutional network of
   :mod:`arena.perception.convnet` (numpy; weights trained on auto-labelled frames of the
   MuJoCo backend by ``tools/train_rgbd_detector.py``, shipped in ``arena/perception/data/``);
3. back-projects the pixels scoring at least ``pixel_score`` to 3-D points in the robot base
   frame (:func:`base_points`) and clusters them on the floor plane: points in touching
   0.1 m cells are one blob, blobs whose centres lie within ``merge_radius`` are one person
   (two legs, a body cut by an arm). A person is at their blob's mean floor position moved
   ``offset`` metres further along the line of sight (the camera sees the near surface of a
   body, not its centre; the offset is fitted on the training frames). Their score is the blob's
   mean pixel score.

Positions are in the robot base frame (x forward, y left; m), as the lidar detector's are in
its sensor frame.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from arena.core.errors import ConfigError
from arena.perception.classifier import Classifier
from arena.perception.convnet import PixelNet
from arena.perception.rgbd_data import STRIDE, shrink, shrink_depth
from arena.sensors.spec3d import RgbdFrame, RgbdSpec, camera_pose

F32 = NDArray[np.float32]
F64 = NDArray[np.float64]

WEIGHTS = Path(__file__).parent / "data" / "rgbd_people.npz"
"""The shipped detector (``python tools/train_rgbd_detector.py`` makes it)."""

CHANNELS = ("depth", "valid", "height")
"""The network's input channels (:func:`net_input`): geometry only."""

COLOUR = ("red", "green", "blue")
"""Colour channels a weights file may add after :data:`CHANNELS` (``channels`` in the file).
The shipped detector leaves them out: on held-out maps colour cost 9 points of AP (the
simulated people wear few colours, and blue office chairs then look like blue shirts)."""

DEPTH_SCALE = 0.1
"""1/m: depth enters the network as metres × 0.1."""

HEIGHT_SCALE = 0.5
"""1/m: height above the floor enters as metres × 0.5."""

CELL = 0.1
"""m, floor-plane cell of the clustering."""

BLOB_FEATURES = ("pixels", "mean_score", "max_score", "area", "bottom", "top", "range",
                 "spread")
"""Features of a candidate person (a group of person pixels): its shrunk pixels, their mean
and best scores, the surface they cover (m²), the lowest and highest point above the floor
(m), the range from the camera (m) and the points' spread on the floor (m, rms distance to
the centre)."""

CLASSIFIER = "blob_"
"""Prefix of the candidate classifier's arrays in the weights file."""


@lru_cache(maxsize=16)
def _rays(spec: RgbdSpec, stride: int) -> tuple[F64, F64]:
    """``(rays (h, w, 3), camera position (3,))`` in the robot base frame.

    The rays of the shrunk grid's pixels have unit optical z (a depth times a ray is a point).
    """
    pos, forward, up = camera_pose(spec, (0.0, 0.0, 0.0))
    right = np.cross(forward, up)
    rays = spec.rays()[stride // 2 :: stride, stride // 2 :: stride]
    h, w = spec.height // stride, spec.width // stride
    rays = rays[:h, :w]
    d = rays[..., :1] * right + rays[..., 1:2] * (-up) + rays[..., 2:3] * forward
    return np.ascontiguousarray(d), pos


def base_points(depth: F32, spec: RgbdSpec, stride: int = STRIDE) -> F64:
    """``(h, w, 3)`` 3-D points (m) in the robot base frame of a shrunk depth image.

    Depth is along the optical axis, so a pixel's point is its ray (optical z = 1) times its
    depth; pixels without a return give the camera's position.
    """
    rays, pos = _rays(spec, stride)
    return pos + rays * np.asarray(depth, dtype=np.float64)[..., None]


def net_input(depth: F32, spec: RgbdSpec, rgb: F32 | None = None, stride: int = STRIDE) -> F32:
    """``(C, h, w)`` float32 input of a shrunk frame.

    The channels are :data:`CHANNELS`, then :data:`COLOUR` when ``rgb`` ``(h, w, 3)`` is given.
    """
    valid = depth > 0
    height = base_points(depth, spec, stride)[..., 2]
    x = np.empty((len(CHANNELS) + (0 if rgb is None else 3), *depth.shape), dtype=np.float32)
    x[0] = depth * DEPTH_SCALE
    x[1] = valid
    x[2] = np.where(valid, height * HEIGHT_SCALE, 0.0)
    if rgb is not None:
        x[3:] = rgb.transpose(2, 0, 1)
    return x


class RgbdPeopleDetector:
    """Detects people in RGB-D frames (see the module docstring).

    Args:
        weights: an ``.npz`` with the network's ``w1`` … ``b6`` and ``offset`` (default: the
            shipped one).
        pixel_score: pixels scoring less are not a person's.
        merge_radius: m, blobs whose centres are closer are one person.
        min_pixels: blobs of fewer shrunk pixels are dropped.
    """

    def __init__(
        self, weights: str | Path | None = None, *, pixel_score: float = 0.5,
        merge_radius: float = 0.4, min_pixels: int = 3,
    ) -> None:
        path = Path(weights) if weights is not None else WEIGHTS
        try:
            with np.load(path) as data:
                arrays = {k: data[k] for k in data.files}
            self.net = PixelNet(arrays)
            self.offset = float(arrays["offset"])
        except (OSError, KeyError, ValueError) as e:
            raise ConfigError(f"not an RGB-D people detector ({e})", source=str(path)) from None
        self.classifier = (Classifier.from_arrays(arrays, CLASSIFIER)
                           if CLASSIFIER + "w1" in arrays else None)
        self.colour = self.net.in_channels == len(CHANNELS) + len(COLOUR)
        self.pixel_score = float(pixel_score)
        self.merge_radius = float(merge_radius)
        self.min_pixels = int(min_pixels)

    def pixel_scores(self, depth: F32, spec: RgbdSpec, rgb: F32 | None = None) -> F32:
        """``(h, w)`` probability that each shrunk pixel shows a person.

        ``rgb`` ``(h, w, 3)`` is read only by a detector trained with colour.
        """
        z = self.net.logits(net_input(depth, spec, rgb if self.colour else None))
        return (1.0 / (1.0 + np.exp(-z))).astype(np.float32)

    def detect(self, frame: RgbdFrame, spec: RgbdSpec) -> tuple[F64, F64]:
        """People in one frame of camera ``spec``.

        Returns:
            ``(k, 2)`` positions in the robot base frame (m) and ``(k,)`` scores.
        """
        if self.colour:
            depth, rgb = shrink(frame)
            return self.people(depth, self.pixel_scores(depth, spec, rgb), spec)
        depth = shrink_depth(frame)
        return self.people(depth, self.pixel_scores(depth, spec), spec)

    def people(self, depth: F32, scores: F32, spec: RgbdSpec) -> tuple[F64, F64]:
        """The people among the scored pixels of a shrunk depth image (module docstring)."""
        xy, features = self.candidates(depth, scores, spec)
        if not len(xy):
            return xy, np.zeros(0)
        score = (self.classifier.scores(features) if self.classifier is not None
                 else features[:, BLOB_FEATURES.index("mean_score")])
        # from the near surface to the body's centre, along the line of sight
        cam = _rays(spec, STRIDE)[1][:2]
        sight = xy - cam
        sight /= np.maximum(np.hypot(*sight.T), 1e-9)[:, None]
        return xy + self.offset * sight, score

    def candidates(self, depth: F32, scores: F32, spec: RgbdSpec) -> tuple[F64, F64]:
        """Candidate people: groups of person pixels (module docstring, step 3).

        Returns:
            near-surface floor positions ``(k, 2)`` (m, base frame) and features ``(k, F)``
            (:data:`BLOB_FEATURES`).
        """
        sel = (scores >= self.pixel_score) & (depth > 0)
        if np.count_nonzero(sel) < self.min_pixels:
            return np.zeros((0, 2)), np.zeros((0, len(BLOB_FEATURES)))
        pts = base_points(depth, spec)[sel]
        s = scores[sel].astype(np.float64)
        fx = spec.intrinsics()[0] / STRIDE
        area = (depth[sel].astype(np.float64) / fx) ** 2  # m² a shrunk pixel covers there
        cells = np.floor(pts[:, :2] / CELL).astype(np.int64)
        cells -= cells.min(axis=0)
        occ = np.zeros(cells.max(axis=0) + 1, dtype=bool)
        occ[cells[:, 0], cells[:, 1]] = True
        labels, n = ndimage.label(occ, structure=np.ones((3, 3), dtype=bool))
        blob = labels[cells[:, 0], cells[:, 1]] - 1
        count = np.bincount(blob, minlength=n).astype(np.float64)
        centre = np.stack([np.bincount(blob, weights=pts[:, k], minlength=n) for k in (0, 1)],
                          axis=1) / count[:, None]
        g = _group(centre, count, self.merge_radius)[blob]  # person index of each point
        m = int(g.max()) + 1
        cnt = np.bincount(g, minlength=m).astype(np.float64)
        xy = np.stack([np.bincount(g, weights=pts[:, k], minlength=m) for k in (0, 1)],
                      axis=1) / cnt[:, None]
        top = np.full(m, -np.inf)
        bottom = np.full(m, np.inf)
        best = np.zeros(m)
        np.maximum.at(top, g, pts[:, 2])
        np.minimum.at(bottom, g, pts[:, 2])
        np.maximum.at(best, g, s)
        spread = np.sqrt(np.bincount(g, weights=((pts[:, :2] - xy[g]) ** 2).sum(axis=1),
                                     minlength=m) / cnt)
        cam = _rays(spec, STRIDE)[1][:2]
        features = np.stack([
            cnt, np.bincount(g, weights=s, minlength=m) / cnt, best,
            np.bincount(g, weights=area, minlength=m), bottom, top,
            np.hypot(*(xy - cam).T), spread,
        ], axis=1)
        keep = cnt >= self.min_pixels
        return xy[keep], features[keep]


def _group(xy: F64, weight: F64, radius: float) -> NDArray[np.int64]:
    """Greedy grouping, largest first: blobs within ``radius`` of an ungrouped one join it.

    Returns each blob's group index (two legs, a body cut by an arm: one person).
    """
    order = np.argsort(-weight, kind="stable")
    group = np.full(len(xy), -1, dtype=np.int64)
    k = 0
    for i in order:
        if group[i] >= 0:
            continue
        near = (group < 0) & (np.hypot(*(xy - xy[i]).T) <= radius)
        group[near] = k
        k += 1
    return group
