# Two entry points: `make run` (the station on the bundled SITL) and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: run test lint bench clean

$(STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -c constraints.txt -e '.[dev]'
	touch $(STAMP)

run: $(STAMP)
	$(BIN)/quadgcs teleop

# One BLAS thread: on two cores numpy's threaded linear algebra fights the test processes.
# Two test processes, a file each at a time (a file's flights share module fixtures): most e2e
# flights wait on real time, so two of them fit on two cores (26 min in one process, 12 in two).
# Then the `solo` tests, alone: five stations at 2x want 1.4 cores, and starved of them by a
# neighbour their loops tick 0.1-0.2 s late and the vehicles fall out of the air; lockstep
# campaigns on two Ray workers would starve a wall-clock flight on the other test process.
test: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/mypy
	OPENBLAS_NUM_THREADS=1 $(BIN)/python -m pytest -q -n 2 --dist loadfile --durations=25 \
		-m "not solo"
	OPENBLAS_NUM_THREADS=1 $(BIN)/python -m pytest -q -m solo

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/mypy

bench: $(STAMP)
	$(BIN)/quadgcs bench --all

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
