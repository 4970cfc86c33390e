# Two entry points for a fresh clone (see README): `make lab` and `make test`.
# Both create .venv with the package installed editable with every extra (lab, grade, test).
# `make lab` is the students' JupyterLab: the student copies in $(WORK)/, nbgrader's panels off;
# `make lab-instructor` opens notebooks/ (every solution and hidden test) with nbgrader's panels.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
ROOT_FLAG := $(if $(filter 0,$(shell id -u)),--allow-root,)
# The student's working folder: written once from the packaged release, then only ever the student's.
# Set on the command line (make lab WORK=DIR); a WORK in the environment (some clusters set one) is ignored.
WORK := work
# Jupyter config of the student session: nbgrader's lab extension and server extensions disabled.
# JUPYTER_CONFIG_PATH outranks every other config folder; JUPYTER_CONFIG_DIR would not, because in a
# venv jupyter prefers the venv's etc/jupyter, where nbgrader enables itself.
STUDENT_CONFIG := $(CURDIR)/jupyter/student

.PHONY: lab lab-prepare lab-instructor test test-fast golden bench notebooks chromium bwrap clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[lab,grade,test]'
	@# an editable install leaves out the config file a wheel brings, which enables labkit's server extension
	mkdir -p $(VENV)/etc/jupyter/jupyter_server_config.d
	cp jupyter/jupyter_server_config.d/labkit.json $(VENV)/etc/jupyter/jupyter_server_config.d/labkit.json
	touch $(STAMP)

# The student copies (labkit notebooks) into $(WORK)/ on the first run only: an existing folder is never written to.
lab-prepare: $(STAMP)
	@if [ -e "$(WORK)" ]; then echo "$(WORK)/ exists: your work is left as it is"; \
	else $(PY) -m labkit.cli notebooks "$(WORK)"; fi

lab: lab-prepare
	JUPYTER_CONFIG_PATH="$(STUDENT_CONFIG)$${JUPYTER_CONFIG_PATH:+:$$JUPYTER_CONFIG_PATH}" \
	  $(VENV)/bin/jupyter lab --notebook-dir="$(WORK)" $(ROOT_FLAG) $(ARGS)

# The instructor notebooks, solutions and hidden tests included, with nbgrader's panels.
lab-instructor: $(STAMP)
	$(VENV)/bin/jupyter lab --notebook-dir=notebooks $(ROOT_FLAG) $(ARGS)

test: $(STAMP) chromium bwrap
	$(PY) -m ruff check .
	$(PY) -m ruff format --check .
	$(PY) -m mypy
	$(PY) -m pytest tests labkit --nbval --nbval-current-env --nbval-sanitize-with tests/nbval_sanitize.cfg notebooks

# The quick loop while changing code (under 3 minutes): lint, types, and every test that starts no sandbox, browser,
# server or whole notebook (tests/conftest.py marks the others slow), on both cores (pytest-xdist: its summary leaves
# out the figures tests print). `make test` runs everything, in one process, before a commit.
test-fast: $(STAMP)
	$(PY) -m ruff check .
	$(PY) -m ruff format --check .
	$(PY) -m mypy
	$(PY) -m pytest -q -n 2 -m "not slow" tests labkit

# Regrade the catalog class (tests/catalog.py) with the golden seed and write its grades.csv over the golden file
# test_catalog compares with; `git diff tests/data/` then shows every row a change moved (keep only intended ones).
golden: $(STAMP) bwrap
	cd tests && ../$(PY) catalog.py --golden

# The browser test drives Debian's Chromium (never a Playwright download).
chromium:
	@test -x /usr/bin/chromium || { [ "$$(id -u)" = 0 ] \
	  && (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null) \
	  || echo "!! /usr/bin/chromium is missing and could not be installed: the browser test will be SKIPPED"; }

# Grading runs every submission in a bubblewrap sandbox; the grading tests need it.
bwrap:
	@command -v bwrap >/dev/null || { [ "$$(id -u)" = 0 ] \
	  && (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq bubblewrap >/dev/null) \
	  || echo "!! bwrap is missing and could not be installed: install bubblewrap, or the grading tests fail"; }

# Re-execute the instructor notebooks, then regenerate the student copies shipped in the package.
notebooks: $(STAMP)
	$(VENV)/bin/labkit execute notebooks
	$(VENV)/bin/labkit release notebooks --out labkit/student_notebooks

# Speed limits live here, never in `make test`: bench_browser_latency fails when a slider is above its limits
# (median 50 ms and 90th percentile 100 ms quiet, median 100 ms with two CPU-bound processes running).
bench: $(STAMP) chromium
	$(PY) benchmarks/bench_core.py
	$(PY) benchmarks/bench_2d.py
	$(PY) benchmarks/bench_sliders.py
	$(PY) benchmarks/bench_grading.py
	$(PY) benchmarks/bench_grading_styles.py  # grading of one submission against its notebooks, two styles (limit 1.5x)
	$(PY) benchmarks/bench_similarity.py
	$(PY) benchmarks/bench_websocket.py
	$(PY) benchmarks/bench_browser_latency.py
	$(PY) benchmarks/bench_report.py
	$(PY) benchmarks/bench_class.py $(CLASS_ARGS)  # a class of 300 three ways (CLASS_ARGS="--count 12" for a quick run)

clean:
	rm -rf $(VENV) build .pytest_cache .hypothesis
