#!/usr/bin/env bash
# Install pdflatex (Debian's texlive) for the test that compiles the report's summary.tex.
#
# Usage: sudo tools/install_texlive.sh        (or as root in a container; .ci/run calls it)
#
# Idempotent: does nothing if pdflatex is on PATH and booktabs.sty is found. The report's tables
# need booktabs (texlive-latex-recommended) on top of texlive-latex-base; the larger
# texlive-latex-extra is not needed.
set -euo pipefail

have_tex() {
    command -v pdflatex >/dev/null 2>&1 && command -v kpsewhich >/dev/null 2>&1 \
        && [ -n "$(kpsewhich booktabs.sty 2>/dev/null)" ]
}

if have_tex; then
    echo "install_texlive: pdflatex already installed: $(command -v pdflatex)"
    exit 0
fi

if ! command -v apt-get >/dev/null 2>&1; then
    echo "install_texlive: no apt-get here; install a TeX distribution with pdflatex and" \
         "booktabs (e.g. TeX Live) with your package manager and put it on PATH" >&2
    exit 1
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
        SUDO="sudo"
    else
        echo "install_texlive: needs root (run as root or with sudo)" >&2
        exit 1
    fi
fi

export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
$SUDO apt-get install -y --no-install-recommends texlive-latex-base texlive-latex-recommended

if have_tex; then
    echo "install_texlive: installed $(command -v pdflatex)"
    exit 0
fi
echo "install_texlive: the install finished but pdflatex or booktabs.sty is missing" >&2
exit 1
