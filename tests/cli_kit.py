"""Running the ``arena`` command line in-process, as a user's shell would."""

from __future__ import annotations

import sys

import pytest

from arena import cli


def run_cli(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str],
            *args: str) -> tuple[int, str, str]:
    """``arena ARGS...`` through :func:`arena.cli.main`: ``(exit code, stdout, stderr)``."""
    monkeypatch.setattr(sys, "argv", ["arena", *args])
    code = 0
    try:
        cli.main()
    except SystemExit as e:
        code = e.code or 0
    out = capsys.readouterr()
    return code, out.out, out.err
