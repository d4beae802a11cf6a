"""The runs manager in a real browser: ``/jobs`` starts a one-episode run, shows it reach
done, and links to its results. ``ARENA_SCREENSHOTS=DIR`` keeps screenshots of each step."""

from __future__ import annotations

import os

import pytest

from arena.web.server import free_port, serve_subprocess
from tests.web.browser_kit import browser_page, chromium_path, screenshot
from tests.web.test_jobs import kill_jobs

#: Longest wait for the run to finish, in ms (a loaded two-core machine).
DONE_MS = 240_000



@pytest.fixture
def server(tmp_path):
    """``arena web`` on an empty store; stopped, with every job it started, afterwards."""
    chromium_path()
    root = tmp_path / "runs"
    root.mkdir()
    web = serve_subprocess(root, port=free_port(8600 + os.getpid() % 300),
                           log=tmp_path / "web.log")
    try:
        yield web, root
    finally:
        web.stop()
        kill_jobs(root)


def test_start_a_run_watch_it_finish_and_open_its_results(server):
    web, root = server
    with browser_page() as page:
        page.goto(f"{web.url}/jobs")
        page.locator("input#jobs-name").fill("from_the_page")
        episodes = page.locator("input#jobs-episodes")
        episodes.fill("1")
        screenshot(page, "jobs_form", full_page=True)
        page.locator("#jobs-start").click()
        state = page.locator('[id="jobs-state-from_the_page"]')
        state.wait_for()
        page.wait_for_function(
            "document.getElementById('jobs-state-from_the_page')?.textContent.trim() === 'done'",
            timeout=DONE_MS)
        assert page.locator("#jobs-error").inner_text().strip() == ""
        assert "1 / 1 episodes" in page.locator('[id="jobs-row-from_the_page"]').inner_text()
        screenshot(page, "jobs_done", full_page=True)
        page.locator('[id="jobs-results-from_the_page"]').click()
        page.wait_for_url(f"{web.url}/runs/from_the_page")
        page.get_by_text("replay").first.wait_for()
        screenshot(page, "jobs_results", full_page=True)
    assert (root / "from_the_page" / "summary.csv").is_file()
