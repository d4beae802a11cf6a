# Two commands set up a fresh machine: `make run` and `make test`.
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test
ARGS   ?=

.PHONY: run demo test lint bench screenshots clean

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip

$(STAMP): pyproject.toml | $(PY)
	$(PY) -m pip install --quiet -e .
	touch $@

$(TEST_STAMP): pyproject.toml | $(PY)
	$(PY) -m pip install --quiet torch==2.13.0  # first: the CPU build, before SB3 asks for torch
	$(PY) -m pip install --quiet -e ".[test]"
	$(VENV)/bin/arena ros2 setup  # tf2_msgs for the ROS 2 bridge tests (~5 s, cmake + g++)
	touch $@ $(STAMP)

## run: create .venv, install Arena and run the main job: the packaged quick benchmark
## (4 planners x 31 episodes: 10 in each of 3 worlds with people + a corridor scenario) and its report
RUN_DIR ?= runs/quick_$(shell date +%Y%m%d-%H%M%S)
run: $(STAMP)
	$(VENV)/bin/arena bench quick --contest quick --workers 2 -o $(RUN_DIR) --report $(ARGS)

## test: install the test extras and run the test suite
test: $(TEST_STAMP)
	$(PY) -m pytest -n 2 -q

## demo: one episode of the default experiment with a video (arena run)
demo: $(STAMP)
	$(VENV)/bin/arena run $(ARGS)

lint: $(TEST_STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/mypy

bench: $(STAMP)
	$(PY) benchmarks/sim_step.py

## screenshots: install Chromium (apt) and screenshot a report: make screenshots REPORT=runs/x/report/report.html
screenshots:
	bash tools/install_chromium.sh
	$(PY) tools/screenshot_report.py $(REPORT) -o docs/images/report

clean:
	rm -rf $(VENV) runs .pytest_cache .ruff_cache
