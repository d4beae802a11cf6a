"""Full-page screenshots of an HTML report with headless Chromium, split into readable sections.

Usage::

    tools/install_chromium.sh                      # once (root, apt): chromium + a font
    .venv/bin/arena report RUN                     # writes RUN/report/report.html
    .venv/bin/python tools/screenshot_report.py RUN/report/report.html -o docs/images/report

writes ``OUTDIR/report_1.png``, ``report_2.png``, ... (each at most ``--width`` × ``--max-height``
pixels, cut at blank rows where possible so figures are not split) and removes older
``report_*.png`` there. The page is rendered at ``--width`` × a tall window, the blank bottom
is trimmed with Pillow (the window grows until the page fits, up to ``--limit`` pixels), and
the sections are saved as optimised palette PNGs (``--colors``; 0 = full colour).

The browser is the first of ``$CHROME``, chromium, chromium-browser, google-chrome and
google-chrome-stable found. Options: ``--sections N`` keeps only the first N sections.
"""

from __future__ import annotations

import argparse
import itertools
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image

BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


def find_browser() -> str:
    """Path of a Chromium-family browser, or exit with a hint to run install_chromium.sh."""
    env = os.environ.get("CHROME")
    if env and shutil.which(env):
        return str(shutil.which(env))
    for name in BROWSERS:
        path = shutil.which(name)
        if path:
            return path
    sys.exit("screenshot_report: no chromium/google-chrome on PATH; run tools/install_chromium.sh")


def shoot(browser: str, html: Path, png: Path, width: int, height: int) -> Image.Image:
    """One headless screenshot of ``html`` at ``width`` × ``height`` CSS pixels."""
    with tempfile.TemporaryDirectory(prefix="arena-chrome-") as profile:
        cmd = [
            browser, "--headless=new", "--disable-gpu", "--no-sandbox", "--hide-scrollbars",
            "--no-first-run", "--no-default-browser-check", "--mute-audio",
            "--force-device-scale-factor=1", f"--user-data-dir={profile}",
            f"--window-size={width},{height}", "--virtual-time-budget=5000",
            f"--screenshot={png}", html.resolve().as_uri(),
        ]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=180, check=False)
    if proc.returncode != 0 or not png.is_file():
        sys.exit(f"screenshot_report: chromium failed ({proc.returncode}):\n{proc.stderr[-2000:]}")
    return Image.open(png).convert("RGB")


def blank_rows(img: Image.Image, tol: float = 1.0) -> np.ndarray:
    """Per row: whether it is a single colour (the page background between elements)."""
    a = np.asarray(img.convert("L"), np.float32)
    return np.ptp(a, axis=1) <= tol


def content_height(img: Image.Image) -> int:
    """Rows down to the last non-blank row, plus a small margin."""
    blank = blank_rows(img)
    filled = np.flatnonzero(~blank)
    return int(min(img.height, (filled[-1] + 24) if filled.size else 1))


def full_page(browser: str, html: Path, width: int, start: int, limit: int) -> Image.Image:
    """Screenshot tall enough for the whole page (the window doubles until a blank bottom)."""
    height = start
    with tempfile.TemporaryDirectory(prefix="arena-shot-") as tmp:
        while True:
            img = shoot(browser, html, Path(tmp) / "page.png", width, height)
            h = content_height(img)
            if h < img.height - 8 or height >= limit:
                return img.crop((0, 0, img.width, h))
            height = min(limit, height * 2)


def split_points(img: Image.Image, max_height: int, min_height: int) -> list[int]:
    """Row indices to cut at, each section at most ``max_height`` rows.

    A cut goes at the lowest blank row at least ``min_height`` below the previous cut.
    """
    blank = blank_rows(img)
    cuts, top = [0], 0
    while img.height - top > max_height:
        window = np.flatnonzero(blank[top + min_height: top + max_height]) + top + min_height
        cut = int(window[-1]) if window.size else top + max_height
        cuts.append(cut)
        top = cut
    cuts.append(img.height)
    return cuts


def save_png(img: Image.Image, path: Path, colors: int) -> None:
    """Save optimised: a palette of ``colors`` (Floyd–Steinberg off, crisp text), or RGB."""
    if colors > 0:
        img = img.quantize(colors=colors, method=Image.Quantize.FASTOCTREE,
                           dither=Image.Dither.NONE)
    img.save(path, format="PNG", optimize=True)


def main(argv: list[str] | None = None) -> int:
    """Command line; see the module docstring."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("html", type=Path, help="the report HTML file")
    p.add_argument("-o", "--out", type=Path, required=True, help="output folder")
    p.add_argument("--width", type=int, default=1400, help="window width in px (1400)")
    p.add_argument("--max-height", type=int, default=1800, help="section height cap (1800)")
    p.add_argument("--start-height", type=int, default=8000, help="first window height")
    p.add_argument("--limit", type=int, default=64000, help="largest window height tried")
    p.add_argument("--sections", type=int, default=0, help="keep only the first N (0 = all)")
    p.add_argument("--colors", type=int, default=256, help="PNG palette size (0 = RGB)")
    p.add_argument("--prefix", default="report", help="file name prefix (report)")
    args = p.parse_args(argv)
    if not args.html.is_file():
        p.error(f"{args.html}: no such file")
    browser = find_browser()
    t0 = time.perf_counter()
    page = full_page(browser, args.html, args.width, args.start_height, args.limit)
    t_shot = time.perf_counter() - t0
    cuts = split_points(page, args.max_height, args.max_height // 2)
    args.out.mkdir(parents=True, exist_ok=True)
    for old in args.out.glob(f"{args.prefix}_*.png"):
        old.unlink()
    pairs = list(itertools.pairwise(cuts))
    if args.sections > 0:
        pairs = pairs[:args.sections]
    for i, (a, b) in enumerate(pairs, start=1):
        path = args.out / f"{args.prefix}_{i}.png"
        save_png(page.crop((0, a, page.width, b)), path, args.colors)
        print(f"{path}  {page.width}x{b - a}  {path.stat().st_size / 1024:.0f} KiB")
    print(f"page {page.width}x{page.height} px, screenshot {t_shot:.1f} s, "
          f"total {time.perf_counter() - t0:.1f} s ({Path(browser).name})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
