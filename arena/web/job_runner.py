"""``python -m arena.web.job_runner RUN_DIR``: run a job's command and record how it ended.

The web app starts every job through this wrapper, detached (its own session and process
group), with ``RUN_DIR/job.log`` as its output. It runs ``argv`` from ``RUN_DIR/job.json``, waits
for it and writes the exit status and the time into ``job.json``; so a job's outcome is known
even when the web server was stopped, or restarted, while it ran.

A cancel sends SIGTERM to the whole process group: the command stops on it, and this wrapper
only notes it and keeps waiting, so that it can still write the (negative) exit status.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path
from types import FrameType

from arena.web.job_file import read_job, update_job

#: A name in the wrapper's command line, so that a pid can be checked to be a wrapper.
MODULE = "arena.web.job_runner"


def _wait_on(signum: int, frame: FrameType | None) -> None:
    """A signal for the group: the command handles it; the wrapper waits for the command."""


def main(args: list[str] | None = None) -> int:
    """Run the job of the folder ``args[0]``; 0 once its exit status is written, 2 on bad use."""
    args = sys.argv[1:] if args is None else args
    if len(args) != 1:
        print(f"usage: python -m {MODULE} RUN_DIR", file=sys.stderr)
        return 2
    folder = Path(args[0])
    try:
        record = read_job(folder)
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    # A Python handler (not SIG_IGN, which a child would inherit): the command gets the default.
    for signum in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(signum, _wait_on)
    try:
        child = subprocess.Popen(record.argv, stdin=subprocess.DEVNULL)
    except OSError as e:
        print(f"error: cannot start {record.argv[:1]}: {e.strerror or e}", flush=True)
        code = 127
    else:
        code = child.wait()  # retried after a handled signal (PEP 475)
    update_job(folder, returncode=code, finished=time.time())
    return 0


if __name__ == "__main__":
    sys.exit(main())
