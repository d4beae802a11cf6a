#!/usr/bin/env bash
# Install a headless-capable Chromium for tools/screenshot_report.py (Debian/Ubuntu, apt).
#
# Usage: sudo tools/install_chromium.sh        (or as root in a container)
#
# Idempotent: does nothing if chromium, chromium-browser, google-chrome or
# google-chrome-stable is already on PATH. Debian names the package "chromium";
# Ubuntu's "chromium-browser" is a snap shim, so on Ubuntu "chromium" is tried first as well.
set -euo pipefail

for b in chromium chromium-browser google-chrome google-chrome-stable; do
    if command -v "$b" >/dev/null 2>&1; then
        echo "install_chromium: $b already installed: $(command -v "$b")"
        "$b" --version 2>/dev/null || true
        exit 0
    fi
done

# shellcheck source=tools/apt_lib.sh
source "$(dirname "$0")/apt_lib.sh"
apt_prepare install_chromium "install Chromium or Google Chrome with your package manager and put it on PATH"
apt_get update
# fonts-dejavu-core: a sans font so the report's text renders in the screenshots.
if ! apt_get install -y --no-install-recommends chromium fonts-dejavu-core; then
    apt_get install -y --no-install-recommends chromium-browser fonts-dejavu-core
fi

for b in chromium chromium-browser; do
    if command -v "$b" >/dev/null 2>&1; then
        echo "install_chromium: installed $(command -v "$b")"
        "$b" --version 2>/dev/null || true
        exit 0
    fi
done
echo "install_chromium: the install finished but no chromium binary is on PATH" >&2
exit 1
