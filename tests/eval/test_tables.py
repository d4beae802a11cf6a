import csv
import os
import re
import shutil
import subprocess

import numpy as np
import pytest

from arena.eval import tables
from arena.eval.metrics import MetricParams
from arena.eval.stats import bootstrap_mean
from tests.eval._table import CONTESTANTS, STAGES, build_columns, build_table, values


def test_summary_means_n_and_bootstrap_intervals():
    rows = tables.summary_table(build_table())
    assert len(rows) == 2 * 2 * 7  # collisions (an integer column) included
    by = {(r.contestant, r.stage, r.metric): r for r in rows}
    for c, cn in enumerate(CONTESTANTS):
        for s, sn in enumerate(STAGES):
            for m, v in values(c, s).items():
                r = by[(cn, sn, m)]
                e = bootstrap_mean(v)
                assert r.n == 5 and not r.low_n
                assert r.mean == pytest.approx(np.mean(v))
                assert (r.lower, r.upper) == (e.lower, e.upper)
                assert v.min() <= r.lower <= r.mean <= r.upper <= v.max()
    r = by[("alpha", "easy", "time_to_goal")]  # 10..14
    assert (r.mean, r.unit) == (12.0, "s")


def test_overall_rows_pool_the_stages():
    rows = tables.summary_table(build_table(), ["time_to_goal"], overall=True)
    (alpha,) = [r for r in rows if r.contestant == "alpha" and r.stage == tables.ALL_STAGES]
    assert alpha.n == 10 and alpha.mean == pytest.approx((12.0 + 15.0) / 2)
    assert [r.stage for r in rows if r.contestant == "alpha"] == [*STAGES, tables.ALL_STAGES]


def test_csv_keeps_integer_metrics_and_flags_low_n(tmp_path):
    cols = build_columns()
    keep = ~((cols["contestant"] == "beta") & (cols["stage"] == "hard") & (cols["episode"] > 1))
    csv_path, _ = tables.write_tables({k: v[keep] for k, v in cols.items()}, tmp_path)
    rows = list(csv.DictReader(csv_path.open()))
    assert list(rows[0]) == ["contestant", "stage", "metric", "unit", "n", "mean", "lower",
                             "upper", "low_n"]
    coll = {(r["contestant"], r["stage"]): r for r in rows if r["metric"] == "collisions"}
    assert coll[("alpha", "easy")]["unit"] == "-"
    assert float(coll[("alpha", "easy")]["mean"]) == pytest.approx(0.4)  # 0 1 0 1 0
    low = coll[("beta", "hard")]  # 2 episodes left
    assert (low["n"], low["lower"], low["upper"], low["low_n"]) == ("2", "", "", "1")
    assert coll[("beta", tables.ALL_STAGES)]["n"] == "7"
    assert coll[("alpha", "easy")]["low_n"] == "0" and coll[("alpha", "easy")]["lower"] != ""


def test_latex_tables_headline_metrics_intervals_and_captions(tmp_path):
    cols = build_columns()
    keep = ~((cols["contestant"] == "beta") & (cols["stage"] == "hard") & (cols["episode"] > 1))
    _, tex_path = tables.write_tables({k: v[keep] for k, v in cols.items()}, tmp_path,
                                      MetricParams(personal_space_radius=0.5))
    tex = tex_path.read_text()
    assert tex.count(r"\begin{table*}") == 2 and tex.count(r"\toprule") == 2
    assert r"\label{tab:arena-overall}" in tex and r"\label{tab:arena-stages}" in tex
    assert "Collisions" in tex and "goal [s]" in tex
    assert "personal-space radius 0.5\\,m" in tex and "fewer than 5 values" in tex
    # alpha, all stages: time to goal 10..14 and 13..17 -> mean 13.5 with an interval
    e = bootstrap_mean(np.r_[10:15, 13:18].astype(float))
    cell = f"$13.5^{{+{e.upper - 13.5:.1f}}}_{{-{13.5 - e.lower:.1f}}}$"
    assert re.search(r"^alpha & 10 & .*" + re.escape(cell), tex, re.M)
    # beta on the hard stage has 2 episodes: flagged, no interval
    assert re.search(r"^beta & 2 & \$0\.50\^\{\\dagger\}\$ & \$1\.50\^\{\\dagger\}\$", tex, re.M)
    assert "m/s^" not in tex


def _pdflatex_or_skip() -> str:
    exe = shutil.which("pdflatex")
    if exe is None:
        if os.environ.get("ARENA_REQUIRE_PDFLATEX") == "1":
            pytest.fail("pdflatex is missing but ARENA_REQUIRE_PDFLATEX=1 (CI): run "
                        "tools/install_texlive.sh")
        pytest.skip("pdflatex not installed: run tools/install_texlive.sh (root, apt: "
                    "texlive-latex-base, texlive-latex-recommended)")
    return exe


def test_summary_tex_compiles_with_pdflatex(tmp_path):
    exe = _pdflatex_or_skip()
    cols = build_columns()
    cols["contestant"] = np.where(cols["contestant"] == "alpha", "social_force & co", "b#2")
    tables.write_tables(cols, tmp_path)
    (tmp_path / "doc.tex").write_text(
        "\\documentclass{article}\n\\setlength{\\textwidth}{17cm}\n"
        "\\setlength{\\oddsidemargin}{-0.5cm}\n\\usepackage{booktabs}\n"
        "\\begin{document}\n\\input{summary.tex}\n\\end{document}\n")
    run = subprocess.run([exe, "-interaction=nonstopmode", "-halt-on-error", "doc.tex"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=120,
                         check=False)
    log = (tmp_path / "doc.log").read_text(errors="replace")
    assert run.returncode == 0, log[-3000:]
    assert (tmp_path / "doc.pdf").read_bytes().startswith(b"%PDF")
    assert "Overfull \\hbox" not in log  # the tables fit a 17 cm text width
    assert "Undefined control sequence" not in log


def test_decimals_per_column():
    assert tables.decimals([0.963, 0.975]) == 3
    assert tables.decimals([12.4, 3.0]) == 1
    assert tables.decimals([123.0, np.nan]) == 0
    assert tables.decimals([0.0]) == 2
    assert tables.tex_escape("a_b&c%^~") == r"a\_b\&c\%\textasciicircum{}\textasciitilde{}"
