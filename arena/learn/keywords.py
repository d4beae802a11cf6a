"""Config keys as keyword arguments of the environments (``gym.make(id, robot="burger")``).

Gymnasium passes ``gym.make`` keywords to the env's constructor; the envs accept every
top-level key of :class:`~arena.config.schema.ExperimentConfig` that way. Each keyword becomes
the override ``key=<value as YAML>`` applied after the env's ``overrides``, so it merges into
the config exactly as ``arena run key=value`` would (a block with a new ``type`` replaces the
old block, other blocks merge). Errors name the keyword: ``SocialNavEnv(robot='burgr'): robot:
unknown robot 'burgr'; did you mean 'burger'? …``.
"""

from __future__ import annotations

import difflib
import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from arena.config.loader import load_config
from arena.config.schema import ExperimentConfig
from arena.core.errors import ConfigError


def check_config_keywords(owner: str, keywords: Mapping[str, Any]) -> None:
    """Raise a one-line :class:`ConfigError` for a keyword that is not a config key."""
    known = sorted(ExperimentConfig.model_fields)
    for key in keywords:
        if key not in known:
            close = difflib.get_close_matches(key, known, n=1, cutoff=0.6)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ConfigError(
                f"{owner}: unknown keyword argument {key!r}{hint} (expected 'config', "
                f"'overrides', the env's own arguments or a config key: {', '.join(known)})"
            )


def load_with_keywords(
    path: str | Path | None,
    overrides: Sequence[str],
    keywords: Mapping[str, Any],
    owner: str,
) -> ExperimentConfig:
    """:func:`~arena.config.loader.load_config` with ``keywords`` appended as overrides.

    Raises:
        ConfigError: the loader's error, located at the keyword that caused it.
    """
    texts = {f"{key}={_yaml_value(owner, key, value)}": key for key, value in keywords.items()}
    try:
        return load_config(path, [*overrides, *texts])
    except ConfigError as e:
        src = (e.source or "").removeprefix("override ")
        for text, key in texts.items():
            if src == repr(text):
                raise ConfigError(
                    e.message, source=f"{owner}({key}={keywords[key]!r})", path=e.path
                ) from None
        raise


def _yaml_value(owner: str, key: str, value: Any) -> str:
    """``value`` as a YAML flow text for an override (paths as strings, numpy as Python)."""

    def plain(v: Any) -> Any:
        if isinstance(v, Mapping):
            return {str(k): plain(x) for k, x in v.items()}
        if isinstance(v, list | tuple):
            return [plain(x) for x in v]
        if isinstance(v, Path):
            return str(v)
        if isinstance(v, np.generic | np.ndarray):
            return plain(v.tolist())
        if v is None or isinstance(v, bool | int | float | str):
            return v
        raise ConfigError(
            f"{owner}({key}=...): a value of type {type(v).__name__} is not config data "
            "(expected strings, numbers, booleans, lists and dicts)"
        )

    return json.dumps(plain(value))  # JSON is YAML flow syntax


ConfigLike = ExperimentConfig | str | Path | None


def resolve_config(
    config: ConfigLike,
    overrides: Sequence[str] = (),
    keywords: Mapping[str, Any] | None = None,
    *,
    owner: str = "SocialNavEnv",
) -> ExperimentConfig:
    """An :class:`ExperimentConfig` from a config, a YAML path (+ overrides) or ``None``.

    Args:
        config: a built config, a YAML path or ``None`` (the packaged default).
        overrides: ``key.path=value`` strings, applied to the YAML.
        keywords: top-level config keys given as keyword arguments, applied after
            ``overrides`` (see :func:`~arena.learn.keywords.load_with_keywords`).
        owner: the class named in error messages.

    Raises:
        ConfigError: an invalid config, override or keyword, in one line.
    """
    if isinstance(config, ExperimentConfig):
        if overrides or keywords:
            raise ConfigError(
                f"{owner}: overrides and config keywords apply to a YAML path or None, "
                "not to a built ExperimentConfig (use cfg.model_copy(update=...))"
            )
        return config
    return load_with_keywords(config, overrides, keywords or {}, owner)
