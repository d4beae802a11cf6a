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

# shellcheck source=tools/apt_lib.sh
source "$(dirname "$0")/apt_lib.sh"
apt_prepare install_texlive "install a TeX distribution with pdflatex and booktabs (e.g. TeX Live) with your package manager and put it on PATH"
apt_get update
apt_get install -y --no-install-recommends texlive-latex-base texlive-latex-recommended

if have_tex; then
    echo "install_texlive: installed $(command -v pdflatex)"
    exit 0
fi
echo "install_texlive: the install finished but pdflatex or booktabs.sty is missing" >&2
exit 1
