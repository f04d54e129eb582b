# Quick start: `make demo` (main job on the bundled recording) and `make test` (whole suite).
# Each target creates or updates .venv on first use; only Python >= 3.11 and PyPI are needed.
PYTHON ?= python3.11
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
OUT    ?= out/demo
DATA   := data/psins_lasergyro_rlg/psins_lasergyro_rlg.csv.gz

.PHONY: demo test bench venv clean

$(STAMP): pyproject.toml
	@command -v $(PYTHON) >/dev/null 2>&1 || { echo "need $(PYTHON) (set PYTHON=...)"; exit 1; }
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

venv: $(STAMP)

demo: $(STAMP)
	mkdir -p $(dir $(OUT))
	$(BIN)/fogdrift analyze $(DATA) --unit deg/h --out $(OUT)

test: $(STAMP)
	$(BIN)/python -m pytest -n 2 -q

bench: $(STAMP)
	$(BIN)/python bench/run_all.py

clean:
	rm -rf $(VENV) out
