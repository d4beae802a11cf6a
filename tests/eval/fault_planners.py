"""A local planner that fails on purpose, for the runner's fault tests.

Benchmark workers are fresh interpreters, so a planner registered inside a test is unknown to
them; this module is importable in a worker and reaches the registry as a third-party plugin
through an entry point (see ``fault_plugin`` in ``test_runner_faults.py``). Once the simulated
time reaches ``at`` it pure-pursues no more but fails as ``fault`` says.
"""

from __future__ import annotations

import ctypes
import os
import time
from pathlib import Path
from typing import Literal

from pydantic import Field

from arena.nav.local_planners.pure_pursuit import PurePursuitPlanner

#: ``os._exit`` status of the ``exit`` fault.
EXIT_CODE = 3


class FaultPlanner(PurePursuitPlanner):
    """Pure pursuit until ``at`` seconds, then exits, segfaults, hangs or raises."""

    class Params(PurePursuitPlanner.Params):
        """Parameters of :class:`FaultPlanner`."""

        fault: Literal["exit", "segfault", "hang", "raise"] = "raise"
        at: float = Field(0.0, ge=0, description="s, simulated time of the fault")
        touch: str | None = Field(
            None, description="folder where the fault leaves a file named after this process's "
            "pid as it starts (tests wait for it)",
        )

    def compute(self, obs):  # type: ignore[no-untyped-def]
        """Fail as configured once ``obs.time >= at``; pure pursuit before."""
        p = self.params
        if obs.time >= p.at:
            if p.touch is not None:
                (Path(p.touch) / str(os.getpid())).touch()
            if p.fault == "exit":
                os._exit(EXIT_CODE)
            elif p.fault == "segfault":
                ctypes.string_at(0)  # reads address 0: SIGSEGV
            elif p.fault == "hang":
                while True:
                    time.sleep(60)
            raise RuntimeError("fault planner raised on purpose")
        return super().compute(obs)
