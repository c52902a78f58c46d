# Two entry points: `make run` (the station on the bundled SITL) and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
# The compiled SITL (sitl/native.py): rebuilt when a SITL source changes; with no C compiler
# the build says so and the SITL runs interpreted.
NATIVE := sitl/_native.json
SITL_SOURCES := $(shell find sitl -name '*.py')

.PHONY: run test lint bench clean

$(STAMP): pyproject.toml constraints.txt
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -c constraints.txt -e '.[dev]'
	touch $(STAMP)

$(NATIVE): $(STAMP) $(SITL_SOURCES)
	$(BIN)/python -m sitl.native_build build

run: $(STAMP) $(NATIVE)
	$(BIN)/quadgcs teleop

# One BLAS thread: on two cores numpy's threaded linear algebra fights the test processes.
# Three passes:
# - The rest, two test processes, a file each at a time (a file's flights share module
#   fixtures): most e2e flights wait on real time, so two of them fit on two cores.
# - The `wallclock` flights, three processes: each holds a wall-clock flight that a CPU-bound
#   neighbour (a lockstep run, a planner's property test) would starve of its ticks, while
#   together they use about a core (the real-time fault matrix, the TCP and serial steps, the
#   carpet hold, the 1x TCP flights compared with lockstep).
# - The `solo` tests, alone: five stations at 2x want 1.4 cores, and starved of them by a
#   neighbour their loops tick 0.1-0.2 s late and the vehicles fall out of the air; the
#   starved-SITL test's stalls are its own; lockstep campaigns on two Ray workers take both
#   cores.
test: $(STAMP) $(NATIVE)
	$(BIN)/ruff check .
	$(BIN)/mypy
	OPENBLAS_NUM_THREADS=1 $(BIN)/python -m pytest -q -n 2 --dist loadfile --durations=25 \
		-m "not solo and not wallclock"
	OPENBLAS_NUM_THREADS=1 $(BIN)/python -m pytest -q -n 3 --dist loadfile --durations=10 \
		-m wallclock
	OPENBLAS_NUM_THREADS=1 $(BIN)/python -m pytest -q -m solo

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/mypy

bench: $(STAMP) $(NATIVE)
	$(BIN)/quadgcs bench --all

clean:
	-test -x $(BIN)/python && $(BIN)/python -m sitl.native_build clean
	rm -rf $(VENV) build *.egg-info .pytest_cache
