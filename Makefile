# locust: `make demo` and `make test` do all the set-up on a fresh machine.
VENV   ?= .venv
PY     := $(VENV)/bin/python
PYTHON ?= python3
# the modules whose >>> examples run in `make test`, from this folder (they read calibration/recordings)
DOCTESTS := host/locust/api host/locust/bundled.py
export MUJOCO_GL ?= osmesa
export PYOPENGL_PLATFORM ?= osmesa

.PHONY: demo test test-all bench install sysdeps clean

$(VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	@# the load-testing tool "locust" shares our package and command name: refuse to mix them
	@# (an old install of this toolkit under that name is replaced)
	@$(PY) scripts/check_shadowing.py $(VENV)
	$(PY) -m pip install -q -e '.[test]'
	touch $@

install: $(VENV)/.installed

sysdeps:
	@bash scripts/sysdeps.sh

demo: install sysdeps
	$(VENV)/bin/locust demo --out demo-out

# Lint everything from the root (firmware/ too: ruff does not follow the host/locust/firmware link),
# then the fast tests (the default, well under 15 minutes) on every core, each test file on one
# worker (its module fixtures made once). pytest exits 5 when it collects nothing.
test: install sysdeps
	$(VENV)/bin/ruff check .
	$(PY) -m pytest -q -n auto --dist loadfile; rc=$$?; [ $$rc -eq 5 ] && { echo "no tests collected"; exit 0; }; exit $$rc
	$(PY) -m pytest -q --doctest-modules $(DOCTESTS); rc=$$?; [ $$rc -eq 5 ] && { echo "no doctests collected"; exit 0; }; exit $$rc

# Everything, including the slow system tests.
test-all: install sysdeps
	$(PY) -m pytest -q -m "slow or not slow"

bench: install
	$(PY) bench/sim_speed.py
	$(PY) bench/robust_speed.py
	$(PY) bench/track_speed.py
	$(PY) bench/track_hard.py
	$(PY) bench/sweep_speed.py --skip-grid

clean:
	rm -rf $(VENV) demo-out .pytest_cache
