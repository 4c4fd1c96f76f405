# robotale — the two commands a newcomer needs are `make demo` and `make test`.
# Everything else here is what those two build on.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

# Debian packages the test suite drives for real: Chromium for the browser tests,
# docker-compose to validate docker-compose.yml (no Docker engine is needed for that),
# Graphviz to draw discovered process models as SVG.
SYSTEM_PACKAGES ?= chromium chromium-driver docker-compose graphviz

.PHONY: install system-deps test typecheck test-neo4j-next demo bench lint format constraints clean fuzz bpmn-engine verify-findings

install: $(STAMP)

$(STAMP): pyproject.toml constraints.txt Makefile
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -c constraints.txt -e '.[dev,dds,dask,server]'
	touch $(STAMP)

# Installs the missing Debian packages when we are allowed to (root or passwordless sudo);
# otherwise says which ones to install and stops.
system-deps:
	@missing=""; for p in $(SYSTEM_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" = 0 ]; then sudo=""; elif sudo -n true 2>/dev/null; then sudo="sudo -n"; \
	  else echo "Please install these Debian packages first:$$missing"; exit 1; fi; \
	  echo "Installing Debian packages:$$missing"; \
	  $$sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$sudo apt-get install -y -qq $$missing >/dev/null; \
	fi

test: install system-deps bpmn-engine
	$(BIN)/ruff check .
	$(BIN)/mypy --strict $(TYPED_PACKAGES)
	$(BIN)/pytest

# bpmn-engine (FAME's own engine), pinned in the harness's package-lock.json, for the
# differential semantics suite (tests/fame_runtime/test_differential.py). Without node and npm
# the suite says so and leaves that engine out.
HARNESS := tests/fame_runtime/bpmn_engine
bpmn-engine: $(HARNESS)/node_modules/.package-lock.json

$(HARNESS)/node_modules/.package-lock.json: $(HARNESS)/package.json $(HARNESS)/package-lock.json
	@if command -v npm >/dev/null 2>&1; then \
	  npm ci --prefix $(HARNESS) --no-audit --no-fund --silent; \
	else \
	  echo "node and npm are not installed: the differential suite will leave bpmn-engine out"; \
	fi

# The Neo4j tests again on the newest Neo4j release robotale runs (`make test` runs them on
# 5.26 LTS, and starts the newest release with the real `robotale neo4j start --version`):
# every file of cypher/ planned without a deprecation, logs built, appended, listed and
# deleted, object-centric logs. Its jars are downloaded once, like 5.26's.
NEO4J_NEXT ?= 2026.08
NEO4J_NEXT_TESTS ?= tests/ekg/test_cypher_files.py tests/ekg/test_build.py \
  tests/ekg/test_append.py tests/ekg/test_batches.py tests/ekg/test_logs.py \
  tests/ekg/test_objects.py tests/ekg/test_releases.py
test-neo4j-next: install
	ROBOTALE_TEST_NEO4J_VERSION=$(NEO4J_NEXT) $(BIN)/pytest -m "not slow" $(NEO4J_NEXT_TESTS)

# The fuzz suite with many more examples than `make test` runs (FUZZ_EXAMPLES per test):
# nothing but robotale's own errors may come out of the log readers, the bag reader and the
# BPMN parser, and the console's JSON encoder writes strict JSON for any value (its round
# trip through Neo4j needs a server: NEO4J_URI, or a local one the tests start).
FUZZ_EXAMPLES ?= 20000
fuzz: install
	ROBOTALE_FUZZ_EXAMPLES=$(FUZZ_EXAMPLES) $(BIN)/pytest -p no:timeout tests/test_fuzz*.py tests/eventlog/test_fuzz*.py \
	  tests/webapp/test_web_console_fuzz.py

# robotale's answers against the simulation's truth on SEEDS generated missions (one run
# each): a table of every disagreement, then the count per subject and the time per mission.
SEEDS ?= 50
verify-findings: install
	$(BIN)/python scripts/verify_findings.py --seeds $(SEEDS)

# DEMO_ARGS passes options on (`make demo DEMO_ARGS="--port 5001"`); ROBOTALE_DEMO_RUNS
# shortens the simulation (20 runs by default).
DEMO_ARGS ?=
demo: install
	$(BIN)/robotale demo $(DEMO_ARGS)

bench: install
	@for b in benchmarks/*.py; do echo "== $$b"; $(BIN)/python $$b || exit 1; done

# The packages whose types mypy checks strictly (settings in pyproject.toml's [tool.mypy]);
# `make test` checks them too.
TYPED_PACKAGES := robotale/fame_runtime robotale/eventlog robotale/neo4j_server robotale/ekg robotale/results \
	robotale/queries.py \
	robotale/files.py robotale/errors.py robotale/config.py robotale/executors.py robotale/storage.py \
	robotale/extras.py
typecheck: install
	$(BIN)/mypy --strict $(TYPED_PACKAGES)

lint: install
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

format: install
	$(BIN)/ruff check --fix .
	$(BIN)/ruff format .

constraints: install
	( sed -n '1,2p' constraints.txt; $(BIN)/pip freeze --exclude-editable | grep -v -i '^robotale' ) > constraints.txt.new
	mv constraints.txt.new constraints.txt

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .ruff_cache .mypy_cache
