# Quick start: `make demo` (main job on the bundled recording) and `make test` (whole suite).
# Each target creates or updates .venv on first use; only Python >= 3.11 and PyPI are needed.
PYTHON ?= python3.11
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
OUT    ?= out/demo
DATA   := data/psins_lasergyro_rlg/psins_lasergyro_rlg.csv.gz

.PHONY: demo test bench venv clean mutation docs

$(STAMP): pyproject.toml
	@command -v $(PYTHON) >/dev/null 2>&1 || { echo "need $(PYTHON) (set PYTHON=...)"; exit 1; }
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

venv: $(STAMP)

# The bundled record is 30.8 min: models are fitted on the first half (40 % training, 10 % validation) and judged
# on the held-out second half in heading error, with the calibration and horizons scaled to that length
# (150-s calibrations every 30 s, 30- and 60-s horizons: 25 and 12 non-overlapping origins per axis).
DEMO_ARGS := --unit deg/h --train-fraction 0.4 --val-fraction 0.1 --calibration 150 --origin-step 30 --horizons 30,60

demo: $(STAMP)
	@mkdir -p $(dir $(OUT))
	$(BIN)/fogdrift analyze $(DATA) $(DEMO_ARGS) --out $(OUT)

test: $(STAMP)
	$(BIN)/python -m pytest -n 2 -q

# Mutation testing (mutmut, config in pyproject.toml [tool.mutmut]; docs/testing-rounds.md). Not part of `make test`.
# One module: make mutation MUTANTS='fogdrift.metrics.*'   (names as `mutmut results` prints them)
# NUMBA_THREADING_LAYER=workqueue: numba's OpenMP pool SIGTERMs a child forked after the parent ran a parallel kernel
# (mutmut forks its workers from the process that ran the clean tests); those mutants ended 'exit -15', undecided.
MUTANTS ?=
mutation: $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[test,mutation]'
	NUMBA_THREADING_LAYER=workqueue $(BIN)/mutmut run --max-children 2 $(MUTANTS)
	$(BIN)/mutmut results

# The documentation site (mkdocs-material + mkdocstrings; mkdocs.yml): the CLI reference is generated from the
# commands first; --strict turns every warning (a broken link, a docstring it cannot read) into an error.
docs: $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[test,docs]'
	$(BIN)/python scripts/gen_cli_reference.py
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --quiet

bench: $(STAMP)
	$(BIN)/python bench/run_all.py

clean:
	rm -rf $(VENV) out
