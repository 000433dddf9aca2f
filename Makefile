# Two entry points (see README): `make study` and `make test`.
# Each creates .venv with the pinned dependencies of requirements.txt, no conda needed.
PYTHON ?= python3
VENV   ?= .venv
CORES  ?= 2
BIN     = $(VENV)/bin
STAMP   = $(VENV)/.installed

.PHONY: study test test-slow emps detection benchmark dag clean-results

# uv installs the pinned wheels in parallel: 19 s against pip's 75 s from a cold cache, .pyc
# compiled (docs/measurements.md). It is only the installer; nothing imports it. Where it
# cannot be had or cannot reach the index, pip installs the same pins.
UV_PIN  = uv==0.13.9
PIP     = $(BIN)/python -m pip install -q --disable-pip-version-check

$(STAMP): requirements.txt pyproject.toml
	$(PYTHON) -m venv $(VENV)
	($(PIP) $(UV_PIN) && $(BIN)/uv pip install -q --python $(BIN)/python --compile-bytecode \
		-r requirements.txt) || (echo "uv failed: installing with pip" && $(PIP) -r requirements.txt)
	$(PIP) --no-deps --no-build-isolation -e .
	touch $@

# The longest chains (the paper's tanh posterior, then the electrical half and the power; its
# linear posterior, then that model's diagnosis) are scheduled first, so that the last minute
# does not run one job on two cores.
CRITICAL = results/electrical/weights.json results/groups/paper/diagnosis/linear/summary.html

study: $(STAMP)
	$(BIN)/snakemake --cores $(CORES) all emps_all --prioritize $(CRITICAL)
	$(BIN)/snakemake --cores $(CORES) all emps_all --report results/report.html

emps: $(STAMP)
	$(BIN)/snakemake --cores $(CORES) emps_all

# One worker per core; a file's tests stay on one worker (they share module fixtures); files
# in the order of tests/conftest.py (the longest first), not by their number of tests.
test: $(STAMP)
	$(BIN)/python -m pytest -n $(CORES) --dist loadfile --no-loadscope-reorder

test-slow: $(STAMP)
	$(BIN)/python -m pytest -m slow -n $(CORES) --dist loadfile --no-loadscope-reorder

benchmark: $(STAMP)
	$(BIN)/python benchmarks/bench_simulator.py
	$(BIN)/python benchmarks/bench_tmcmc.py
	$(BIN)/python benchmarks/bench_evidence_spread.py
	$(BIN)/python benchmarks/bench_resampling.py
	$(BIN)/python benchmarks/bench_evidence.py
	$(BIN)/python benchmarks/bench_reference.py
	$(BIN)/python benchmarks/bench_diagnosis.py
	$(BIN)/python benchmarks/bench_calibration.py --fast

detection: $(STAMP)
	$(BIN)/snakemake --cores $(CORES) detection_all

dag: $(STAMP)
	$(BIN)/snakemake -n all

clean-results:
	rm -rf results logs
