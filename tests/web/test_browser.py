"""The web app in a real browser: ``arena run --live`` is watched, paused, stepped and given a
goal by clicking; its results list it; its episode replays with the time slider."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time

import pytest

from arena.web.server import free_port, serve_subprocess
from tests.web.browser_kit import browser_page, chromium_path, screenshot, wait_until


@pytest.fixture
def live_run(tmp_path):
    """``arena run --live`` in its own process (episodes at real time); its live URL.

    It has more episodes than a test watches: its web app stops with the run.
    """
    chromium_path()
    port = free_port(8300 + os.getpid() % 500)
    cmd = [sys.executable, "-m", "arena.cli", "run", "-n", "20", "--no-video", "--seed", "4",
           "--live", "--port", str(port), "-o", str(tmp_path / "runs" / "watched")]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            start_new_session=True)
    lines = []
    try:
        url = None
        deadline = time.monotonic() + 90
        while url is None and time.monotonic() < deadline:
            line = proc.stdout.readline()
            if not line:
                break
            lines.append(line)
            if line.startswith("live view:"):
                url = line.split()[-1]
        assert url, "no live view URL: " + "".join(lines)
        yield url, tmp_path / "runs"
    finally:
        proc.send_signal(signal.SIGINT)  # as Ctrl+C: the run stops its web server
        try:
            proc.wait(20)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(10)


def _frame(page):
    return page.evaluate("window.arenaLive && window.arenaLive.lastFrame || null")


def test_watch_pause_step_and_set_a_goal(live_run):
    url, _ = live_run
    with browser_page() as page:
        page.goto(url)
        wait_until(lambda: page.evaluate("window.arenaView ? window.arenaView.drawn : 0") > 5,
              what="frames")
        first = _frame(page)
        assert first["people"]["id"] and first["plan"]
        start = first["poses"][0][:2]  # free for the robot's body: it stood there
        screenshot(page, "live")
        page.click("#arena-pause")
        wait_until(lambda: "paused" in page.inner_text("#arena-status"), what="paused")
        time.sleep(0.3)  # the tick running when the pause came finishes (at most one)
        held = _frame(page)["step"]
        time.sleep(0.6)
        assert _frame(page)["step"] == held
        page.click("#arena-step")
        wait_until(lambda: _frame(page)["step"] == held + 1, what="one step")
        time.sleep(0.4)
        assert _frame(page)["step"] == held + 1
        # set a goal by clicking the canvas where the robot stood earlier (free for its body
        # and a few steps away, so the episode does not end at once)
        x, y = start
        page.get_by_text("set goal").click()
        wait_until(lambda: page.evaluate("window.arenaView.tool") == "goal", what="the goal tool")
        px, py = page.evaluate(
            f"(() => {{ const v = window.arenaView, r = v.canvas.getBoundingClientRect();"
            f" const [sx, sy] = v.toScreen({x}, {y}); const k = r.width / v.canvas.width;"
            f" return [r.left + sx * k, r.top + sy * k]; }})()")
        page.mouse.click(px, py)
        page.click("#arena-resume")
        goal = wait_until(lambda: (g := _frame(page)["goal"])
                          and math.hypot(g[0] - x, g[1] - y) < 0.1 and g, what="the clicked goal")
        assert math.hypot(goal[0] - x, goal[1] - y) < 0.1
        assert "error" not in page.inner_text("#arena-status")
        screenshot(page, "live_goal")


def test_results_and_replay(live_run):
    url, root = live_run
    base = url.split("/live/")[0]
    done = root / "watched" / "episode_000" / "episode.json"
    summary = root / "watched" / "summary.csv"  # written after the episode's own files
    wait_until(summary.is_file, timeout=120, what="the first episode")
    with browser_page() as page:
        page.goto(f"{base}/")
        page.get_by_text("watched").first.click()
        page.get_by_text("replay").first.click()
        try:
            wait_until(lambda: page.evaluate(
                "window.arenaReplay ? window.arenaReplay.frames.length : window.arenaReplayError"
                " ? -1 : 0"), timeout=120, what="the replay")  # simulated again: a loaded machine
        except AssertionError:
            raise AssertionError(f"no replay at {page.url}: {page.inner_text('body')[-400:]}"
                                 ) from None
        assert page.evaluate("window.arenaReplayError || null") is None, page.inner_text("body")
        steps = json.loads(done.read_text())["steps"]
        assert page.evaluate("window.arenaReplay.frames.length") == steps + 1
        page.fill("#arena-slider", str(steps // 2))
        page.dispatch_event("#arena-slider", "input")
        assert page.evaluate("window.arenaView.frame.step") == steps // 2
        assert f"step {steps // 2}" in page.inner_text("#arena-time")
        screenshot(page, "replay")


def test_served_pages_refuse_traversal(tmp_path):
    chromium_path()
    (tmp_path / "runs").mkdir()
    web = serve_subprocess(tmp_path / "runs", port=free_port(8900))
    try:
        with browser_page() as page:
            page.goto(f"{web.url}/replay/x?record=../../etc/passwd")
            assert "no run named 'x'" in page.inner_text("body")
            r = page.request.get(f"{web.url}/api/runs/x/files/%2Fetc%2Fpasswd")
            assert r.status == 404
    finally:
        web.stop()
