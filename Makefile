# The two set-up commands of the README: `make demo` (main job) and `make test`.
# Both create .venv with Python 3.11 and install the pinned dependencies themselves.
PYTHON ?= python3.11
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
OUT    ?= out

.PHONY: demo test test-unit bench bench-all clean

$(STAMP): requirements.txt requirements-test.txt scripts/system-deps.sh
	bash scripts/system-deps.sh
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -r requirements.txt -r requirements-test.txt
	touch $(STAMP)

demo: $(STAMP)
	$(PY) scripts/demo.py --out $(OUT)

test: $(STAMP)
	$(PY) -m pytest tests

test-unit: $(STAMP)
	$(PY) -m pytest tests/unit

# bench: the product's figures as one markdown table (bench/summary.py calls each bench
# module's figures()); bench-all: every bench module's detailed printout (bench/run.py).
bench: $(STAMP)
	$(PY) -m pip install --quiet --disable-pip-version-check -r requirements-bench.txt
	$(PY) bench/summary.py $(BENCH)

bench-all: $(STAMP)
	$(PY) -m pip install --quiet --disable-pip-version-check -r requirements-bench.txt
	$(PY) bench/run.py $(BENCH)

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache

# The extension package: scipy wheels for every platform and both Blender Pythons (cp311,
# cp313; cached in wheels/), one zip per platform in $(DIST)/, each validated
# (scripts/build_extension.py). tests/extension installs the linux-x64 zip into a clean
# Blender user directory on bpy 4.5 LTS (.venv), bpy 5.0 ($(BPY5_VENV), Python 3.11) and
# bpy 5.2 LTS ($(BPY52_VENV), Python 3.13); the test creates the two extra venvs too when
# they are missing, the same way as these targets.
DIST       ?= dist
BPY5_VENV  := .venv-bpy5
BPY52_VENV := .venv-bpy52
# Blender 5.1+ runs Python 3.13: the first python3.13 that runs (PATH, then pyenv's).
PYTHON313  ?= $(shell for p in python3.13 $$HOME/.pyenv/versions/3.13*/bin/python3.13; do \
                "$$p" -c '' 2>/dev/null && { echo "$$p"; break; }; done)

.PHONY: extension venv-bpy5 venv-bpy52 test-extension

extension: $(STAMP)
	$(PY) scripts/build_extension.py --output-dir $(DIST)

venv-bpy5: $(BPY5_VENV)/.installed

$(BPY5_VENV)/.installed: requirements-bpy5.txt
	$(PYTHON) -m venv --clear $(BPY5_VENV)
	$(BPY5_VENV)/bin/python -m pip install --quiet --disable-pip-version-check -r requirements-bpy5.txt
	cp requirements-bpy5.txt $@

venv-bpy52: $(BPY52_VENV)/.installed

$(BPY52_VENV)/.installed: requirements-bpy52.txt
	@test -n "$(PYTHON313)" || { echo "Python 3.13 not found (set PYTHON313=...)" >&2; exit 1; }
	$(PYTHON313) -m venv --clear $(BPY52_VENV)
	$(BPY52_VENV)/bin/python -m pip install --quiet --disable-pip-version-check -r requirements-bpy52.txt
	cp requirements-bpy52.txt $@

test-extension: $(STAMP) venv-bpy5 venv-bpy52
	$(PY) -m pytest tests/extension
