"""The runs manager in a real browser: ``/jobs`` starts a one-episode run, shows it reach
done, and links to its results. ``ARENA_SCREENSHOTS=DIR`` keeps screenshots of each step."""

from __future__ import annotations

from tests.web.browser_kit import browser_page, screenshot

#: Longest wait for the run to finish, in ms (a loaded two-core machine).
DONE_MS = 240_000


def test_start_a_run_watch_it_finish_and_open_its_results(web_app):
    web, root = web_app
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
