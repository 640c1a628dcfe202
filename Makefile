# roastlab: `make reproduce` runs the main job, `make test` the test suite.
# Both create .venv on a fresh machine (Python >= 3.11 and the package registries only).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: test test-fast reproduce bench lint clean distclean wheel-check real-roaster app-screens

# --no-compile: pip byte-compiles every module of every package as it installs (SymPy's alone are
# thousands); Python compiles those a run imports when it first imports them. On 2026-11-30's 2-core VM
# the install took 44 s against 96 s, back to back with a warm pip cache.
$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet --no-compile -e '.[test]'
	touch $(STAMP)

# The suite runs on every core (pytest-xdist). On 2 cores, back to back on 2026-11-27, the fast suite took
# 159 s against 221 s in one process (1.4 times faster); the clean-clone CI run's whole suite 452 s, where
# one process had taken 779 s an hour before on the same busy machine. `make test TEST_WORKERS=0` runs it
# in one process. Each worker runs numba's parallel loops on its share of the cores (tests/conftest.py):
# with a thread per core in each of 2 workers the suite took 703 s in a warm clone on 2026-11-28, with one
# thread per worker 569 s, back to back.
# Each kernel is compiled first, once, in a pool of processes (roastlab compile): started together, the
# workers compiled the same kernels at the same time (128 s of a clean clone's 445 s of compiling,
# 2026-11-29); with a warm cache the step takes a few seconds. The lanes for the paper's laws and both
# examples' (the Skywalker's with its held swelling), which most tests call, and the wetted-arc contact's
# (contact=wall), which the band and comparison tests fit on synthetic batches: left to the suite, both
# workers compiled it at once (222 worker-seconds in tests/test_bands.py's fixture on 2026-11-30's VM;
# ahead it adds about 60 s to this step). The lanes tests' other laws still compile in the suite.
# --durations=20: the slowest tests in every run's log, where CI's 20 minutes go.
TEST_WORKERS ?= auto
test: $(STAMP)
	$(VENV)/bin/roastlab compile examples/bullet/fit.toml examples/skywalker/fit.toml --bed contact=wall
	$(PY) -m pytest -n $(TEST_WORKERS) --durations=20

# The inner loop: every test but those marked slow (make test, which CI runs, has them all).
test-fast: $(STAMP)
	$(PY) -m pytest -n $(TEST_WORKERS) -m "not slow"

reproduce: $(STAMP)
	$(VENV)/bin/roastlab reproduce --out out/reproduce

bench: $(STAMP)
	$(VENV)/bin/roastlab bench

lint: $(STAMP)
	$(VENV)/bin/ruff check src tests
	$(VENV)/bin/ruff format --check src tests

# Outputs and caches; the venv stays (distclean removes it too). Compiled kernels need no
# cleaning: their cache is keyed on a hash of the sources (roastlab.sim.cache).
clean:
	rm -rf out .pytest_cache .hypothesis
	find src tests -name __pycache__ -type d -exec rm -rf {} +

distclean: clean
	rm -rf $(VENV)

# The wheel (not an editable install) in a fresh venv runs the main job from outside the repository.
wheel-check:
	rm -rf /tmp/roastlab-wheel && $(PYTHON) -m venv /tmp/roastlab-wheel/venv
	/tmp/roastlab-wheel/venv/bin/python -m pip install --quiet --no-compile .
	cd /tmp/roastlab-wheel && venv/bin/roastlab reproduce --out X && test -s X/model.json && test -s X/fig2_profiles.png

# The measured figures of docs/real-roaster.md, from the real logs in ../shared/data/real.
# Then every bed-law variant, the probe depth scale's profile and the two surface-scaled heat paths
# cross-validated by batch size on the Bullet (15 variants x 9 fits; the swelling beans since session
# 36), then by roaster (3 variants x 6 fits). Then the band's calibration: the example leave-one-log-out on the 17 nominal logs (18 fits)
# and on 16 splits of them into 9 fit and 8 held out, and the Skywalker's held-out FIT on 16 halves of
# its logs, with and without the fan (docs/band_splits.py, 4 + 4 min). Last, the Skywalker's 16
# logs one by one: the example's bed laws, the same with the probe's depth at the Skywalker's, the paper's
# probe (3 x 17 fits). All of it: 21 min on 2 cores at ab8774a (2026-11-29); every rerun, its time and
# what it changed are in CHANGELOG.md.
real-roaster: $(STAMP)
	$(PY) docs/real_roaster.py
	$(VENV)/bin/roastlab compare-models --plant examples/bullet/plant.toml --map examples/bullet/map.toml \
	  --spec examples/bullet/fit.toml $(BULLET_WEIGHED) \
	  --variant $(BED_EXAMPLE) \
	  $(foreach v,$(BED_VARIANTS),--variant $(v),h_probe_m=free,$(PAPER_EXOTHERM)) \
	  $(foreach h,$(H_PROBE_PROFILE_M),--variant $(BED_EXAMPLE),h_probe_m=$(h),$(PAPER_EXOTHERM)) \
	  --variant $(BED_BEFORE),h_probe_m=0.2,$(PAPER_EXOTHERM) \
	  $(foreach x,$(SURFACE_HEAT),--variant $(BED_EXAMPLE),$(x)) \
	  --variant $(BED_EXAMPLE),bean_swell=$(SKYWALKER_SWELL) \
	  --json docs/real-roaster-compare.json --plot docs/real-roaster-compare.png
	$(VENV)/bin/roastlab compare-models --plant examples/bullet/plant.toml --map examples/bullet/map.toml \
	  --spec examples/bullet/fit.toml $(BULLET_WEIGHED) --group-by unit \
	  --variant $(BED_EXAMPLE) --variant $(BED_EXAMPLE),$(PAPER_EXOTHERM) --variant paper,h_probe_m=free,$(PAPER_EXOTHERM) \
	  --json docs/real-roaster-roasters.json --plot docs/real-roaster-roasters.png
	$(VENV)/bin/roastlab compare-models --plant examples/bullet/plant.toml --map examples/bullet/map.toml \
	  --spec examples/bullet/fit.toml $(BULLET_NOMINAL) --group-by log \
	  --variant $(BED_EXAMPLE) --json docs/real-roaster-logs.json --plot docs/real-roaster-logs.png
	$(PY) docs/band_splits.py
	$(VENV)/bin/roastlab compare-models --plant examples/skywalker/plant.toml --map examples/skywalker/map.toml \
	  --spec examples/skywalker/fit.toml $(SKYWALKER_LOGS) --group-by log \
	  --variant $(BED_EXAMPLE) --variant $(BED_EXAMPLE),h_probe_m=$(SKYWALKER_DEPTH_M) --variant paper,h_probe_m=0 \
	  --json docs/real-roaster-skywalker.json --plot docs/real-roaster-skywalker.png
# the beans' swelling the Skywalker example holds, tried on the Bullet's sizes (docs/real-roaster.md, "Skywalker: the beans swell")
SKYWALKER_SWELL = $(shell $(PY) -c "from roastlab.io.fitspec import load_fit_spec as f; print(f('examples/skywalker/fit.toml').fixed['bean_swell'])")
# the two heat paths that grow with the bed's surface, as the code holds them (roastlab.model.bed.SURFACE_HEAT)
SURFACE_HEAT = $(shell $(PY) -c "from roastlab.model.bed import SURFACE_HEAT as s; print(' '.join(s))")
# each bed law with the probe's depth scale fitted, then that scale's profile under the example's laws
BED_VARIANTS = paper probe=tumbling contact=wall probe=tumbling,probe_gas=mean contact=wall,probe=tumbling,probe_gas=mean
# the laws cross-validation chose, as the code holds them (roastlab.model.bed.CROSS_VALIDATED)
BED_EXAMPLE = $(shell $(PY) -c "from roastlab.model.bed import CROSS_VALIDATED as b; print(b.name)")
# the Bullet's logs that record their green weight (docs/real_roaster.py's bullet_logs, as init reads a batch)
BULLET_WEIGHED = $(shell cd docs && ../$(PY) -c "from real_roaster import bullet_logs; print(*bullet_logs())")
# the Skywalker's logs the example's files can drive (docs/real_roaster.py's skywalker_logs)
SKYWALKER_LOGS = $(shell cd docs && ../$(PY) -c "from real_roaster import skywalker_logs; print(*skywalker_logs())")
# the Bullet's logs of the fit's batch size (docs/real_roaster.py's NOMINAL_G)
BULLET_NOMINAL = $(shell cd docs && ../$(PY) -c "from real_roaster import nominal_logs; print(*nominal_logs())")
# the paper's exothermic rate law (Schwartzberg's A and Ha/R, the quantity table's defaults), held in the
# rows that compare bed laws; the example fits it (examples/bullet/fit.toml)
PAPER_EXOTHERM = $(shell $(PY) -c "from roastlab.model.quantities import QUANTITIES as q; print(f'A={q[\"A\"].default:g},Ha_R={q[\"Ha_R\"].default:g}')")
# the example's laws until 2026-11-25, held at its depth scale, for comparison
BED_BEFORE = contact=wall,probe=tumbling,probe_gas=mean
H_PROBE_PROFILE_M = 0.03 0.1 0.2 0.5 1
# the Skywalker's probe depth scale held where init holds it (the drum's diameter), the example's until
# 2026-11-27; the example fits it (examples/skywalker/fit.toml)
SKYWALKER_DEPTH_M = $(shell $(PY) -c "from roastlab import load_plant; from roastlab.model.bed import PROBE_DEPTH_OVER_DIAMETER as k; print(f'{k * load_plant(\"examples/skywalker/plant.toml\").Dch_m:g}')")

# The page's screenshots for docs/app.md and its measured speed (needs Debian's chromium).
app-screens: $(STAMP)
	$(PY) docs/app_screens.py
