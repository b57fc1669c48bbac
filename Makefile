# The two set-up commands of the README: `make demo` (main job) and `make test`.
# Both create .venv with Python 3.11 and install the pinned dependencies themselves.
PYTHON ?= python3.11
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
OUT    ?= out

.PHONY: demo test test-unit bench clean

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

bench: $(STAMP)
	$(PY) -m pip install --quiet --disable-pip-version-check -r requirements-bench.txt
	$(PY) bench/run.py $(BENCH)

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache

# The extension package: scipy wheels for every platform (cached in wheels/), one zip per
# platform in $(DIST)/, each validated (scripts/build_extension.py). tests/extension installs
# the linux-x64 zip into a clean Blender user directory on bpy 4.5 and on bpy 5.0
# ($(BPY5_VENV), from requirements-bpy5.txt; the test creates it too when it is missing).
DIST      ?= dist
BPY5_VENV := .venv-bpy5

.PHONY: extension venv-bpy5 test-extension

extension: $(STAMP)
	$(PY) scripts/build_extension.py --output-dir $(DIST)

venv-bpy5: $(BPY5_VENV)/.installed

$(BPY5_VENV)/.installed: requirements-bpy5.txt
	$(PYTHON) -m venv --clear $(BPY5_VENV)
	$(BPY5_VENV)/bin/python -m pip install --quiet --disable-pip-version-check -r requirements-bpy5.txt
	cp requirements-bpy5.txt $@

test-extension: $(STAMP) venv-bpy5
	$(PY) -m pytest tests/extension
