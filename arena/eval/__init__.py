"""Evaluation: recorded episodes, metrics, results store, plots and reports."""

from arena.eval.record import EpisodeMeta, EpisodeRecord

__all__ = ["EpisodeMeta", "EpisodeRecord"]
