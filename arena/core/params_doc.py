"""Describe a plugin's parameters from its pydantic ``Params`` model (``arena plugins KIND NAME``).

By the project's convention a field's ``description`` starts with its SI unit when it has one
(``Field(0.6, gt=0, description="m, lookahead distance")``); :func:`describe_params` splits that
unit off so that tools can show it in its own column.
"""

from __future__ import annotations

import re
import types
import typing
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel
from pydantic_core import PydanticUndefined

#: Symbols a leading unit is built from (``m/s²``, ``rad/s``, ``1/s``, ``m``, ``kg·m``).
_UNIT_SYMBOLS = frozenset({"1", "m", "s", "rad", "deg", "Hz", "N", "kg", "px", "cells", "%"})
_CONSTRAINTS = (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<="),
                ("multiple_of", "multiple of"), ("min_length", "min length"),
                ("max_length", "max length"))


@dataclass(frozen=True)
class ParamInfo:
    """One parameter of a plugin.

    Attributes:
        name: the YAML key.
        type: the annotation as text (``float``, ``float | None``, ``Literal['a', 'b']``).
        default: the default as text (``required`` when there is none).
        unit: the SI unit taken from the start of the description (``""`` if none).
        description: the rest of the description.
        constraints: bounds and limits, e.g. ``("> 0", "<= 1")``.
    """

    name: str
    type: str
    default: str
    unit: str
    description: str
    constraints: tuple[str, ...]

    def as_dict(self) -> dict[str, Any]:
        """Plain data (``constraints`` as a list), e.g. for JSON."""
        return {
            "name": self.name, "type": self.type, "default": self.default, "unit": self.unit,
            "description": self.description, "constraints": list(self.constraints),
        }


def split_unit(description: str) -> tuple[str, str]:
    """``"m/s, cruise speed"`` -> ``("m/s", "cruise speed")``; no leading unit -> ``("", text)``."""
    text = description.strip()
    match = re.match(r"([^\s,;]+)(?:[,;]\s*|\s+|$)", text)
    if match is None:
        return "", text
    head = match.group(1)
    parts = re.split(r"[/·]", re.sub(r"[²³]|\^-?\d+", "", head))
    if all(p in _UNIT_SYMBOLS for p in parts) and not (head == "1" and match.end() < len(text)):
        return head, text[match.end():].strip()
    return "", text


def _type_text(annotation: Any) -> str:
    if annotation is type(None):
        return "None"
    if isinstance(annotation, type) and not typing.get_args(annotation):
        return annotation.__name__
    if isinstance(annotation, types.UnionType) or typing.get_origin(annotation) is typing.Union:
        return " | ".join(_type_text(a) for a in typing.get_args(annotation))
    text = str(annotation)
    return re.sub(r"\b(typing|collections\.abc|builtins)\.", "", text).replace("NoneType", "None")


def _default_text(field: Any) -> str:
    if field.default is PydanticUndefined:
        if field.default_factory is not None:
            try:
                return repr(field.default_factory())
            except TypeError:  # a factory that wants the validated data
                return "(computed)"
        return "required"
    if isinstance(field.default, BaseModel):
        return repr(field.default.model_dump(mode="json"))
    return repr(field.default)


def describe_params(model: type[BaseModel] | None) -> list[ParamInfo]:
    """Every field of a ``Params`` model, in declaration order (``[]`` for ``None``)."""
    if model is None:
        return []
    out = []
    for name, field in model.model_fields.items():
        constraints = []
        for meta in field.metadata:
            for attr, symbol in _CONSTRAINTS:
                value = getattr(meta, attr, None)
                if value is not None:
                    text = f"{value:.6g}" if isinstance(value, float) else str(value)
                    constraints.append(f"{symbol} {text}")
        unit, text = split_unit(field.description or "")
        out.append(ParamInfo(
            name=field.alias or name, type=_type_text(field.annotation),
            default=_default_text(field), unit=unit, description=text,
            constraints=tuple(constraints),
        ))
    return out
