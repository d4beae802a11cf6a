"""Pedestrian simulation: crowd models behind one registry (:data:`CROWD_MODELS`)."""

from arena.crowd import walker as _walker  # noqa: F401  (registers the built-in models)
from arena.crowd.base import CROWD_MODELS

__all__ = ["CROWD_MODELS"]
