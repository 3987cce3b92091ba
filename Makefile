PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
# Compiled again whenever a source changed since (a pull, an edit): numba recompiles what changed
# and loads the rest (about 2 s), where the first command after it would compile alone.
COMPILED := $(VENV)/.compiled
SOURCES := $(shell find src -name '*.py')

.PHONY: install demo test lint bench clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[dev]"
	touch $(STAMP)

$(COMPILED): $(STAMP) $(SOURCES)
	$(BIN)/python -m shipid.precompile  # the numba kernels and Python's bytecode into their caches
	touch $(COMPILED)

install: $(COMPILED)

demo: $(COMPILED)
	$(BIN)/shipid demo --out shipid-demo

test: $(COMPILED)
	$(BIN)/python -m pytest -q -n 2 --dist loadfile --no-loadscope-reorder  # 2 cores; a file's tests on one worker, in order; files in conftest.py's order

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks

bench: $(COMPILED)
	$(BIN)/python benchmarks/bench_lssvm.py
	$(BIN)/python benchmarks/bench_simulate.py
	$(BIN)/python benchmarks/bench_select.py
	$(BIN)/python benchmarks/bench_long_logs.py
	$(BIN)/python benchmarks/bench_plausibility.py
	$(BIN)/python benchmarks/bench_physics.py
	$(BIN)/python benchmarks/bench_residual.py
	$(BIN)/python benchmarks/study_hybrid.py
	$(BIN)/python benchmarks/study_uncertainty.py
	$(BIN)/python benchmarks/study_structure.py
	$(BIN)/python benchmarks/study_stability.py
	$(BIN)/python benchmarks/bench_study.py
	$(BIN)/python benchmarks/bench_figures.py
	$(BIN)/python benchmarks/bench_startup.py
	$(BIN)/python benchmarks/study_esso.py
	$(BIN)/python benchmarks/study_esso_port_turn.py
	$(BIN)/python benchmarks/study_esso_whole_logs.py
	$(BIN)/python benchmarks/study_esso_single_logs.py
	$(BIN)/python benchmarks/study_esso_extrapolation.py
	$(BIN)/python benchmarks/study_kept_terms.py
	$(BIN)/python benchmarks/study_selection_uncertainty.py
	$(BIN)/python benchmarks/study_kvlcc2_average.py
	$(BIN)/python benchmarks/study_kvlcc2_sampling.py
	$(BIN)/python benchmarks/study_kvlcc2_turn.py
	$(BIN)/python benchmarks/study_esso_rudder_normal.py
	$(BIN)/python benchmarks/study_auto_structure.py
	$(BIN)/python benchmarks/study_sampling.py
	$(BIN)/python benchmarks/study_auto_inflow.py
	$(BIN)/python benchmarks/study_tanker.py
	$(BIN)/python benchmarks/study_trim.py
	$(BIN)/python benchmarks/study_gyro_offset.py
	$(BIN)/python benchmarks/study_event_timing.py
	$(BIN)/python benchmarks/study_replica_step.py
	$(BIN)/python benchmarks/study_crossflow.py
	$(BIN)/python benchmarks/study_turn_speed.py
	$(BIN)/python benchmarks/study_replicate_plausibility.py
	$(BIN)/python benchmarks/study_reference_prior.py
	$(BIN)/python benchmarks/study_ahead_forms.py
	$(BIN)/python benchmarks/study_sign_table.py
	$(BIN)/python benchmarks/study_esso_turn_in_training.py
	$(BIN)/python benchmarks/study_esso_rps_range.py
	$(BIN)/python benchmarks/study_astern_thrust.py
	$(BIN)/python benchmarks/bench_blas_threads.py
	$(BIN)/python benchmarks/bench_validate_replicas.py
	$(BIN)/python benchmarks/bench_columns.py
	$(BIN)/python benchmarks/study_cut_logs.py

clean:
	rm -rf $(VENV) shipid-demo build *.egg-info src/*.egg-info
