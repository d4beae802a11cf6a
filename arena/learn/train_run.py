"""A training run's folder and settings: the manifest (``run.json``), resume checks, configs.

Part of :mod:`arena.learn.train` (see there for the run folder's layout).
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from arena.config.schema import ExperimentConfig
from arena.core.errors import ArenaError, ConfigError
from arena.learn.train_config import TrainSettings

MANIFEST = "run.json"
CHECKPOINTS = "checkpoints"
BEST = "best"  # eval.keep_best: the best evaluated checkpoint
INSTALL_HINT = "pip install torch==2.13.0, then pip install 'arena[train]'"


def require_sb3() -> None:
    """Raise a one-line :class:`ArenaError` when torch or Stable-Baselines3 is missing."""
    for mod in ("torch", "stable_baselines3", "gymnasium"):
        try:
            __import__(mod)
        except ImportError:
            raise ArenaError(
                f"training needs {mod}, which is not installed: {INSTALL_HINT}"
            ) from None


# -- settings -----------------------------------------------------------------------------------
def settings_of(cfg: ExperimentConfig) -> TrainSettings:
    """The training settings (``learning.ppo`` and ``learning.train``) of a loaded experiment."""
    return TrainSettings(ppo=cfg.learning.ppo, train=cfg.learning.train)


def load_training(
    path: str | Path | None, overrides: Sequence[str] = ()
) -> tuple[ExperimentConfig, TrainSettings]:
    """Load an experiment and its ``learning.ppo`` / ``learning.train`` settings.

    Raises:
        ConfigError: a bad experiment or training block, naming file/override and key path.
    """
    from arena.config.loader import load_config

    cfg = load_config(resolve_training_config(path), overrides)
    return cfg, settings_of(cfg)


#: The packaged training configs (``arena train rosnav_rl``).
TRAIN_CONFIGS_DIR = Path(__file__).resolve().parent / "data" / "train"


def packaged_training_configs() -> list[str]:
    """Names of the packaged training configs (``rlca``, ``rosnav_rl``, ``value_policy``)."""
    return sorted(p.stem for p in TRAIN_CONFIGS_DIR.glob("*.yaml"))


def resolve_training_config(path: str | Path | None) -> str | Path | None:
    """A YAML path as given, or a packaged config's name turned into its file.

    ``rosnav_rl`` (no such file here, no ``.yaml`` suffix, no folder) names
    ``arena/learn/data/train/rosnav_rl.yaml``, so the command works from any folder.

    Raises:
        ConfigError: a bare name that is neither a file nor a packaged config (with a close
            match and the packaged names).
    """
    if path is None or Path(path).exists():
        return path
    text = str(path)
    if Path(text).suffix or "/" in text or os.sep in text:
        return path  # a file path: load_config reports it missing
    packaged = TRAIN_CONFIGS_DIR / f"{text}.yaml"
    if packaged.is_file():
        return packaged
    import difflib

    known = packaged_training_configs()
    close = difflib.get_close_matches(text, known, n=1, cutoff=0.5)
    hint = f"did you mean {close[0]!r}? " if close else ""
    raise ConfigError(
        f"no such file or packaged training config {text!r}; {hint}packaged: {', '.join(known)}"
    )


# -- run folder ---------------------------------------------------------------------------------
def write_json(path: Path, data: Any) -> None:
    """Write ``data`` as JSON to ``path`` atomically (a temporary file renamed)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w") as f:
        json.dump(data, f, indent=1)
    os.replace(tmp, path)


def read_run(run_dir: str | Path) -> dict[str, Any]:
    """Read ``RUN/run.json``.

    Raises:
        ArenaError: not a training run folder, or an unreadable manifest.
    """
    path = Path(run_dir) / MANIFEST
    if not path.is_file():
        raise ArenaError(f"{path}: no run manifest; {run_dir} is not a training run folder")
    try:
        data = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise ArenaError(f"{path}: unreadable run manifest ({e})") from None
    if not isinstance(data, dict) or data.get("kind") != "train":
        raise ArenaError(f"{path}: not a training run manifest")
    return data


def _first_difference(a: Any, b: Any, prefix: str = "") -> str | None:
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b), key=str):
            d = _first_difference(a.get(k), b.get(k), f"{prefix}.{k}" if prefix else str(k))
            if d is not None:
                return d
        return None
    return None if a == b else prefix


def _current(schema: Any, stored: Any) -> Any:
    """A stored config re-read through today's ``schema``, or as stored if it no longer validates.

    Fields added since get their defaults, so a run made before a new option existed still
    resumes; an invalid one is compared as stored (the comparison names the first difference).
    """
    try:
        return json.loads(json.dumps(schema.model_validate(stored).model_dump(mode="json")))
    except ValueError:
        return json.loads(json.dumps(stored))


def check_resume(run_dir: Path, cfg: ExperimentConfig, settings: TrainSettings) -> dict[str, Any]:
    """The run's manifest, if ``cfg``/``settings`` match it (``total_steps`` may differ).

    Raises:
        ArenaError: naming the manifest and the first key that differs.
    """
    data = read_run(run_dir)
    want_settings = settings.model_dump(mode="json")
    have_settings = _current(TrainSettings, data["settings"])
    want_settings["train"].pop("total_steps")
    have_settings["train"].pop("total_steps", None)
    for what, have, want in (
        ("config", _current(ExperimentConfig, data["config"]), cfg.model_dump(mode="json")),
        ("settings", have_settings, want_settings),
    ):
        diff = _first_difference(have, json.loads(json.dumps(want)))
        if diff is not None:
            raise ArenaError(
                f"{run_dir / MANIFEST}: cannot resume: {what} key {diff!r} differs from the run's"
            )
    return data
