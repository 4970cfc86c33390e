# Two entry points for a fresh clone (see README): `make lab` and `make test`.
# Both create .venv with the package installed editable and its test extras.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
ROOT_FLAG := $(if $(filter 0,$(shell id -u)),--allow-root,)

.PHONY: lab test bench notebooks clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

lab: $(STAMP)
	$(VENV)/bin/jupyter lab --notebook-dir=notebooks $(ROOT_FLAG) $(ARGS)

test: $(STAMP)
	$(PY) -m pytest tests labkit --nbval --nbval-current-env --nbval-sanitize-with tests/nbval_sanitize.cfg notebooks

notebooks: $(STAMP)
	$(VENV)/bin/labkit execute notebooks

bench: $(STAMP)
	$(PY) benchmarks/bench_core.py
	$(PY) benchmarks/bench_2d.py
	$(PY) benchmarks/bench_sliders.py

clean:
	rm -rf $(VENV) build .pytest_cache .hypothesis
