# bcfem: the README's commands. Every target bootstraps .venv first.
VENV  ?= .venv
BIN   := $(VENV)/bin
NP    ?= 2

.PHONY: venv demo test test-serial test-mpi bench report clean

venv:
	@./tools/bootstrap.sh

demo: venv
	$(BIN)/bcfem run blister-rigid --material gent --Jm 100 --out results/blister-rigid

test: venv
	$(BIN)/python -m pytest -q tests
	PATH=$(abspath $(BIN)):$$PATH $(BIN)/mpirun -n $(NP) ./tools/pytest-mpi.sh -q -m mpi tests

bench: venv
	$(BIN)/python benchmarks/blister_rigid.py

report: venv
	$(BIN)/python demos/blister_theories.py
	$(BIN)/python demos/blister_surface_tension.py

clean:
	rm -rf results .pytest_cache
