PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin

# make demo installs what the demo needs (extra: tool); make test what the suite needs: every
# extra but render3d (VTK; matplotlib is the fallback). cad-step (OpenCASCADE) is a 67 MB wheel,
# 380 MB installed, about 5 s to install from PyPI.
DEMO_EXTRAS := tool
TEST_EXTRAS := tool,video,cad,cad-step,sculpt,test

.PHONY: demo test bench clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(VENV)/.installed-demo: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[$(DEMO_EXTRAS)]'
	touch $@

$(VENV)/.installed: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[$(TEST_EXTRAS)]'
	touch $@

demo: $(VENV)/.installed-demo
	$(BIN)/splinedeform demo -o out/demo

test: $(VENV)/.installed
	$(BIN)/python -m pytest -q

bench: $(VENV)/.installed
	$(BIN)/python benchmarks/run.py

clean:
	rm -rf $(VENV) out .pytest_cache
