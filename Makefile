# Entry points: `make run`, `make test` (everything, as CI) and `make test-fast` (the inner loop).
# Everything else is plumbing.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
HOST   ?= 127.0.0.1
PORT   ?= 8080
CHROMIUM ?= /usr/bin/chromium
SUDO   := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
# Python caches what it compiles (and pytest its rewritten tests) even where the environment
# says not to: each of the suite's workers and child processes would compile the project
# again (about 12 core-seconds of the suite on a 2-core machine).
unexport PYTHONDONTWRITEBYTECODE

.PHONY: run test test-busy test-fast test-times install install-test chromium bench bench-compare load lint docs pictures clean

$(VENV)/bin/activate:
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --upgrade pip

# `make run` installs what the README's commands need too: matplotlib (poinsot report, fit --plot)
# and playwright (poinsot screenshot; Chromium itself comes from `make chromium`).
$(VENV)/.installed: pyproject.toml | $(VENV)/bin/activate
	$(PY) -m pip install -e '.[lecture]'
	touch $@

$(VENV)/.installed-test: pyproject.toml | $(VENV)/bin/activate
	$(PY) -m pip install -e '.[test,report]'
	touch $@ $(VENV)/.installed

$(VENV)/.installed-dev: pyproject.toml | $(VENV)/bin/activate
	$(PY) -m pip install -e '.[dev]'
	touch $@ $(VENV)/.installed-test $(VENV)/.installed

$(VENV)/.installed-docs: pyproject.toml | $(VENV)/bin/activate
	$(PY) -m pip install -e '.[docs]'
	touch $@

install: $(VENV)/.installed
install-test: $(VENV)/.installed-test

# Debian's Chromium drives the real-browser tests (playwright uses it via executable_path).
# strace lets a test prove that the browser reaches nothing past loopback; nginx runs the
# README's load-balancer set-up on loopback (tests/app/test_nginx.py); redis-server links the
# hosts of a classroom (tests/app/test_redis.py).
chromium:
	@if [ -x "$(CHROMIUM)" ] && command -v strace >/dev/null && [ -x /usr/sbin/nginx ] \
		&& command -v redis-server >/dev/null; then \
		echo "chromium: $(CHROMIUM)"; else \
		echo "installing Debian's chromium, strace, nginx-light and redis-server"; \
		$(SUDO) apt-get update && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y \
			chromium strace nginx-light redis-server; fi

run: install
	$(VENV)/bin/poinsot serve --host $(HOST) --port $(PORT)

# The suite on JOBS pytest-xdist workers. tests/conftest.py groups the tests (--dist loadgroup,
# xdist_group): the real-browser tests in two groups (a worker each with its own Chromium,
# started first, as they are the longest; the second holds the tests that neither type into a
# slider nor point at the scene), but for the files whose tests start a Chromium of their own
# (a group each, run once a worker is free);
# tests/report/ in one; every other module in its own. Most of a test's time is waiting (on a
# browser, a server, a child process), so there are more workers than cores. Then the
# `serial` tests, if any, alone (they would measure what the machine gives them), collected
# from the files that hold one only (collecting the whole suite costs seconds); none today:
# every test counts frames and events. The second stage runs even when the first failed.
JOBS ?= 4
PARALLEL = -n $(JOBS) --dist loadgroup --no-loadscope-reorder -m "not serial"
SERIAL_FILES = $(shell grep -rl --include='test_*.py' 'mark.serial' tests)
test: install-test chromium
	status=0; \
	$(PY) -m pytest $(PARALLEL) || status=1; \
	if [ -n "$(SERIAL_FILES)" ]; then $(PY) -m pytest -m serial $(SERIAL_FILES) || status=1; fi; \
	exit $$status

# The suite as `make test` runs it, beside two busy loops (tests/busy.py starts them and stops
# them however the suite ends, Ctrl-C included): a student's laptop or a shared CI runner is
# busy too. Its status is the suite's.
BUSY_LOOPS ?= 2
test-busy: install-test chromium
	$(PY) tests/busy.py --loops $(BUSY_LOOPS) -- $(MAKE) --no-print-directory test

# Where the suite's time goes: the parallel stage with a JUnit report (its own status is not
# this target's), then each group's seconds and the slowest tests (tests/durations.py).
test-times: install-test chromium
	-$(PY) -m pytest $(PARALLEL) -q --junitxml=build/junit.xml
	$(PY) tests/durations.py build/junit.xml

# The inner loop: no browser, no live server, nothing slow (physics, report, the app's logic).
# These tests compute rather than wait: a worker more than the cores, no more (each worker
# imports and collects the whole suite before its first test).
FAST_JOBS ?= 3
test-fast: install-test
	$(PY) -m pytest -n $(FAST_JOBS) --dist loadgroup --no-loadscope-reorder -m "not browser and not server and not slow"

bench: install
	$(PY) -m poinsot.physics.tools.benchmark

# Both benchmarks of this working tree against another revision, alternating, as ratios new/old
# (exits 1 when a figure regressed), e.g. make bench-compare AGAINST=8b3cd8c ARGS="--rounds 5".
bench-compare: install
	$(PY) -m poinsot.app.devtools.compare --against $(AGAINST) $(ARGS)

# Load test of the live server on loopback (about 8 minutes; exits 1 when a goal is missed).
# Options go in ARGS, e.g. make load ARGS="--phase soak storm --clients 10 --seconds 60".
load: install
	$(PY) -m poinsot.app.devtools.load $(ARGS)

# mypy checks the folders under their installed names: poinsot.physics, poinsot.app.
TYPECHECK := $(VENV)/typecheck
lint: $(VENV)/.installed-dev
	$(VENV)/bin/ruff check physics app tests
	$(VENV)/bin/ruff format --check physics app tests
	mkdir -p $(TYPECHECK)/poinsot
	ln -sfn "$(CURDIR)/physics" $(TYPECHECK)/poinsot/physics
	ln -sfn "$(CURDIR)/app" $(TYPECHECK)/poinsot/app
	MYPYPATH=$(TYPECHECK) $(VENV)/bin/mypy -p poinsot.physics -p poinsot.app
	$(VENV)/bin/lint-imports

# The user guide (mkdocs.yml, docs/) into site/, which `poinsot serve` serves at /docs/. --strict:
# a broken link, a missing page or a docstring the API reference cannot read fails the build.
docs: $(VENV)/.installed-docs
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict

# The pictures of the README and the guide, made again by Poinsot's own commands (headless
# Chromium: `make chromium`), the page's at every size and theme among them (assets/page/).
# Minutes of software rendering; not part of CI. The guide is built first: the pages link to it.
pictures: install-test chromium docs
	PATH="$(CURDIR)/$(VENV)/bin:$$PATH" sh docs/pictures.sh

clean:
	rm -rf $(VENV) .pytest_cache build site *.egg-info
