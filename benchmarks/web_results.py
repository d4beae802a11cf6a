"""How fast the web app's results page of a 160-episode benchmark opens.

    python benchmarks/web_results.py [--run DIR] [--workers 2] [--opens 5]

Without ``--run`` it first runs the benchmark it measures: ``arena bench quick --contest quick
--scale 1.3`` (4 contestants x 40 episodes = 160; a few minutes) into a cache folder
(``$TMPDIR/arena-bench160``, reused next time). The run is copied into a fresh run store, served
by ``arena web`` and opened in Chromium (Playwright; Debian's ``/usr/bin/chromium``) until the
page has drawn its charts and its episode table. Prints the first open (the server computes
the tables: cold), the median of the next ``--opens`` (cached) and the summary API's cold time.

Goal (issue 21): the results page of a 160-episode benchmark opens in < 2 s.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

from arena.web.server import free_port, serve_subprocess
from tests.web.browser_kit import browser_page

#: The page is open when this holds: the charts are drawn and the episodes listed.
READY = ("document.querySelectorAll('.nicegui-echart canvas').length >= 9"
         " && document.getElementById('results-episodes') !== null")


def _bench(out: Path, workers: int) -> None:
    cmd = [sys.executable, "-m", "arena.cli", "bench", "quick", "--contest", "quick",
           "--scale", "1.3", "-j", str(workers), "--no-progress", "-o", str(out)]
    print("running the benchmark:", " ".join(cmd[2:]), flush=True)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", type=Path, help="a finished bench run folder")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--opens", type=int, default=5)
    args = ap.parse_args()
    run = args.run or Path(tempfile.gettempdir()) / "arena-bench160"
    if args.run is None and len(list(run.glob("episodes/*/*/*.json"))) < 160:
        shutil.rmtree(run, ignore_errors=True)  # none yet, or an unfinished one
        _bench(run, args.workers)
    episodes = len(list(run.glob("episodes/*/*/*.json")))
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp) / "runs"
        shutil.copytree(run, root / "bench")
        shutil.copytree(run, root / "bench2")  # a second copy: the API's time uncached
        web = serve_subprocess(root, port=free_port(8780))
        try:
            times = []
            with browser_page() as page:
                page.set_viewport_size({"width": 1280, "height": 900})
                for _ in range(args.opens + 1):
                    t0 = time.perf_counter()
                    page.goto(f"{web.url}/runs/bench")
                    page.wait_for_function(READY, timeout=60_000)
                    times.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            with urllib.request.urlopen(f"{web.url}/api/runs/bench2/summary") as r:
                size = len(r.read())
            api = time.perf_counter() - t0
        finally:
            web.stop()
    print(json.dumps({"episodes": episodes, "summary_api_cold_s": round(api, 3),
                      "summary_kB": round(size / 1e3, 1)}))
    print(f"results page, {episodes} episodes: first open {times[0]:.2f} s (the server "
          f"computes the tables), then median {statistics.median(times[1:]):.2f} s "
          f"(max {max(times[1:]):.2f} s) over {args.opens} opens; goal < 2 s")


if __name__ == "__main__":
    main()
