# bcfem: the README's commands. Every target bootstraps .venv first.
VENV  ?= .venv
BIN   := $(VENV)/bin
NP    ?= 2

.PHONY: venv demo test test-all study bench profile report docs docs-check clean

venv:
	@./tools/bootstrap.sh

demo: venv
	$(BIN)/bcfem run blister-rigid --material gent --Jm 100 --out results/blister-rigid

PYTEST := $(BIN)/python -m pytest -q -p no:cacheprovider
MPI_PYTEST := OMP_NUM_THREADS=1 PATH=$(abspath $(BIN)):$$PATH $(BIN)/mpirun -n $(NP) ./tools/pytest-mpi.sh -q

# the fast tier: term battery, toys, every scene on a tiny mesh, CLI contracts, MPI on small cases;
# each test runs once: one marked mpi on NP ranks only (its physics asserted there), unless serial
FAST := not slow and not convergence and not demo and not study
test: venv
	$(BIN)/ruff check .
	$(BIN)/mypy
	./tools/test-halves.sh -m "$(FAST) and (serial or not mpi)"
	$(MPI_PYTEST) -m "mpi and $(FAST)" tests

# everything: adds full crater cycles, convergence studies and the demos on NP ranks
test-all: venv
	$(BIN)/ruff check .
	$(BIN)/mypy
	BCFEM_FULL_DRAW=1 WEIGHTS=tools/test-durations-all.txt ./tools/test-halves.sh -m "not study" --durations=20
	$(MPI_PYTEST) -m "mpi and not study" tests
	$(MAKE) docs-check

# the site, docs/_build/html (warnings are errors): the docs, a page per scene, demo and tutorial,
# the API reference; docs-check opens every page in headless Chromium (tools/check_site.py)
docs: venv
	$(BIN)/python -m sphinx -b html -W --keep-going -q docs docs/_build/html

docs-check: docs
	$(BIN)/python tools/check_site.py docs/_build/html

# checks of a minute or more each (contact cycles, plate contact in a cell, the demos in serial): not in CI
study: venv
	$(PYTEST) -m study --durations=0 tests
	$(MPI_PYTEST) -m "mpi and study" tests

DEMOS := $(filter-out _%,$(basename $(notdir $(wildcard demos/*.py))))

# where one run's time goes (one core): make profile ARGS="blister-rigid --v-max 2"
PROFILE_ARGS ?= crater --preload 0.3
profile: venv
	$$(command -v taskset >/dev/null && echo taskset -c 0) $(BIN)/bcfem run $(or $(ARGS),$(PROFILE_ARGS)) \
		--out results/profile --quiet --no-plots --profile

# error against run time: docs/benchmarks/<scene>.{csv,md,png}; the speed of this checkout against
# another commit: python benchmarks/speed.py --before COMMIT
bench: venv
	$(BIN)/python benchmarks/blister_rigid.py
	$(BIN)/python benchmarks/blister_3d.py
	$(BIN)/python benchmarks/blister_shooting.py
	$(BIN)/python benchmarks/blister_edges.py
	OMP_NUM_THREADS=1 $(BIN)/python benchmarks/newtonal_vs_bordered.py
	$(BIN)/python benchmarks/crater_air.py
	$(BIN)/python benchmarks/crater_design.py
	$(BIN)/python benchmarks/crater_closure.py
	$(BIN)/python benchmarks/crater_regulariser.py
	$(BIN)/python benchmarks/crater_double.py
	$(BIN)/python benchmarks/crater_double_exchange.py
	$(BIN)/python benchmarks/crater_cell.py
	$(BIN)/python benchmarks/assembly_limit.py
	$(BIN)/python benchmarks/blister_soft.py
	$(BIN)/python benchmarks/blister_soft_delamination.py
	$(BIN)/python benchmarks/blister_soft_dgamma_step.py
	$(BIN)/python benchmarks/droplet_soft.py
	$(BIN)/python benchmarks/droplet_soft_cusp.py

# the dissertation's figures, reproduced by the demos on $(NP) ranks: docs/figures/<demo>/
# (--full: the published grids; demos without such a grid ignore it); the crater demos again on
# the dissertation's FE model: docs/figures/<demo>_dissertation/
DISSERTATION_MODEL_DEMOS := crater_air crater_design
report: venv
	@for d in $(DEMOS); do echo "== $$d"; PATH=$(abspath $(BIN)):$$PATH $(BIN)/mpirun -n $(NP) $(BIN)/python demos/$$d.py --quiet --full --out docs/figures/$$d || exit 1; done
	@for d in $(DISSERTATION_MODEL_DEMOS); do echo "== $$d --dissertation-model"; PATH=$(abspath $(BIN)):$$PATH $(BIN)/mpirun -n $(NP) $(BIN)/python demos/$$d.py --quiet --full --dissertation-model --out docs/figures/$${d}_dissertation || exit 1; done

clean:
	rm -rf results .pytest_cache docs/_build docs/_generated
