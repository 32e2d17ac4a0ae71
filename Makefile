# Two commands set up and use volumen on a fresh Debian machine with Python >= 3.11:
#   make demo   - create .venv, install with every extra a user command needs, write the phantoms' pictures into out/
#   make test   - create .venv, install with test extras, lint (ruff), run the whole suite
#   make fuzz   - a long seeded fuzz campaign over every reader (table per format), then over the network surfaces
#   make pictures - the README's pictures (docs/*.png) from the README's own commands (docs/pictures.py)
#   make huge   - an 8 GiB OME-Zarr drawn out of core with a 1 GiB cache: peak RSS vs its bound (minutes)
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
# the demo installs every extra a command of the README needs (the application, OpenGL, out of core and batch, the
# notebook viewer, MP4 video), not the test-only tools (VTK, pytest, the CUDA compiler's libraries)
DEMO_EXTRAS := gui,gl,scale,notebook,video,report
DEMO_STAMP := $(VENV)/.installed-demo
# two workers on the two cores, each given one contiguous half of the tests, then stealing from the other's end
# (neighbouring tests share kernel variants: on a cold checkout round-robin made both workers compile the same
# kernels side by side; whole files per worker left one long file running alone); Numba caches them beside the sources
PYTEST_ARGS ?= -n 2 --dist worksteal

.PHONY: demo test pictures fuzz fuzz-net huge install system-data system-libs browser pacs-server web-deps lint-web readme-venv clean

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip

# pip byte-compiles the installed modules one at a time (about half the install's time): it is told not to, and
# compileall does it on every core instead (the suite's many processes then import from .pyc files; some
# packages ship test files that do not parse, so its exit status is ignored)
$(STAMP): pyproject.toml | $(PY)
	$(PY) -m pip install --quiet --no-compile -e ".[test,video]"
	-$(PY) -m compileall -q -j 0 $(VENV)/lib >/dev/null 2>&1
	touch $(STAMP)

install: $(STAMP)

# make demo's install, into the venv $(1): volumen with every user extra, byte-compiled on every core
define demo_install
	$(1)/bin/python -m pip install --quiet --no-compile -e ".[$(DEMO_EXTRAS)]"
	-$(1)/bin/python -m compileall -q -j 0 $(1)/lib >/dev/null 2>&1
endef

$(DEMO_STAMP): pyproject.toml | $(PY)
	$(call demo_install,$(VENV))
	touch $(DEMO_STAMP)

# The README's commands are run by tests/test_readme.py with a venv of their own made by make demo's recipe (every
# user extra, none of the test tools), so a command that needs a package only the test extra brings fails the
# suite as it would fail a new user; where it cannot be made (no registry), the test runs them in the test venv and
# says so
README_VENV := .venv-readme
README_STAMP := $(README_VENV)/.installed-demo
$(README_STAMP): pyproject.toml
	rm -rf $(README_VENV)
	$(PYTHON) -m venv $(README_VENV)
	$(README_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(call demo_install,$(README_VENV))
	touch $(README_STAMP)

readme-venv:
	@$(MAKE) --no-print-directory $(README_STAMP) || \
	  (rm -rf $(README_VENV); echo "the README's venv could not be made: its commands run in the test venv")

# Optional real data: Debian's mricron-data ships MRI brain templates used by
# volumen.data.sample(). Installing it needs root and apt; when that is not
# possible the tests that use it skip with the reason printed.
system-data:
	@if [ -f /usr/share/mricron/templates/ch2better.nii.gz ]; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	  echo "installing Debian package mricron-data (MRI templates)"; \
	  (apt-get install -y -qq mricron-data >/dev/null 2>&1 || \
	   (apt-get update -qq >/dev/null 2>&1 && apt-get install -y -qq mricron-data >/dev/null 2>&1)) || \
	  echo "mricron-data could not be installed; tests using it will skip"; \
	else echo "not root: mricron-data not installed; tests using it will skip"; fi

# Optional libraries: Debian's libfreeimage3 lets imageio read HDR environment maps (.hdr, .exr;
# volumen.io.read_environment); libxcb-cursor0 is what Qt 6.5+ needs to open a window on X11 (`volumen view`;
# without it the command says so in one line, and `volumen view --screenshot` draws offscreen anyway).
# Installing them needs root and apt; without libfreeimage3 the environment-map tests skip with the reason printed.
system-libs:
	@if ls /usr/lib/*/libfreeimage.so.3 >/dev/null 2>&1; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	  echo "installing Debian package libfreeimage3 (HDR environment maps)"; \
	  (apt-get install -y -qq libfreeimage3 >/dev/null 2>&1 || \
	   (apt-get update -qq >/dev/null 2>&1 && apt-get install -y -qq libfreeimage3 >/dev/null 2>&1)) || \
	  echo "libfreeimage3 could not be installed; environment-map tests will skip"; \
	else echo "not root: libfreeimage3 not installed; environment-map tests will skip"; fi
	@if ls /usr/lib/*/libxcb-cursor.so.0 >/dev/null 2>&1; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	  echo "installing Debian package libxcb-cursor0 (Qt's X11 windows)"; \
	  (apt-get install -y -qq libxcb-cursor0 >/dev/null 2>&1 || \
	   (apt-get update -qq >/dev/null 2>&1 && apt-get install -y -qq libxcb-cursor0 >/dev/null 2>&1)) || \
	  echo "libxcb-cursor0 could not be installed; volumen view will say so (--screenshot works offscreen)"; \
	else echo "not root: libxcb-cursor0 not installed; volumen view will say so (--screenshot works offscreen)"; fi

# Optional browser: Debian's chromium opens the notebook viewer's page (tests/notebook/test_browser.py) and the
# browser viewer (tests/web) headless. Installing it needs root and apt; without it those tests skip with the
# reason printed.
browser:
	@if command -v chromium >/dev/null || command -v chromium-browser >/dev/null; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	  echo "installing Debian package chromium (headless browser test of the notebook viewer)"; \
	  (apt-get install -y -qq chromium >/dev/null 2>&1 || \
	   (apt-get update -qq >/dev/null 2>&1 && apt-get install -y -qq chromium >/dev/null 2>&1)) || \
	  echo "chromium could not be installed; the browser test will skip"; \
	else echo "not root: chromium not installed; the browser test will skip"; fi

# Optional archive server: Debian's orthanc and its DICOMweb plugin (orthanc-dicomweb). The tests of volumen.pacs
# (tests/pacs, the application's archive dialog, the README's pacs lines) start it as a plain process on free local
# ports with a temporary storage folder and stop it after. Installing needs root and apt; without them those tests
# skip with the reason printed. The package's own system service is not wanted: it is stopped and disabled.
pacs-server:
	@if command -v Orthanc >/dev/null && ls /usr/share/orthanc/plugins/libOrthancDicomWeb.so* >/dev/null 2>&1; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	  echo "installing Debian packages orthanc and orthanc-dicomweb (the archive tests' server)"; \
	  (apt-get install -y -qq orthanc orthanc-dicomweb >/dev/null 2>&1 || \
	   (apt-get update -qq >/dev/null 2>&1 && apt-get install -y -qq orthanc orthanc-dicomweb >/dev/null 2>&1)) || \
	  echo "orthanc could not be installed; the archive tests will skip"; \
	  (systemctl disable --now orthanc || service orthanc stop) >/dev/null 2>&1 || true; \
	else echo "not root: orthanc not installed; the archive tests will skip"; fi

# The browser viewer's tests (tests/web) emulate a headset with the npm package iwer (the Immersive Web Emulation
# Runtime, MIT); its code (volumen/web/static) is linted by ESLint (with @eslint/js and globals) and type checked
# by TypeScript's tsc over the JSDoc types (with @types/webxr), configured by eslint.config.mjs and jsconfig.json.
# All are installed here, at these exact versions, into the git-ignored .web-deps/ (the page itself needs nothing
# but a browser); .web-deps/.installed lists what is there. Without npm or the registry those tests skip with the
# reason printed.
IWER_VERSION ?= 2.5.0
ESLINT_VERSION ?= 10.15.0
ESLINT_JS_VERSION ?= 10.0.1
GLOBALS_VERSION ?= 17.14.0
TYPESCRIPT_VERSION ?= 5.9.3
WEBXR_TYPES_VERSION ?= 0.5.24
WEB_DEPS := iwer@$(IWER_VERSION) eslint@$(ESLINT_VERSION) @eslint/js@$(ESLINT_JS_VERSION) \
  globals@$(GLOBALS_VERSION) typescript@$(TYPESCRIPT_VERSION) @types/webxr@$(WEBXR_TYPES_VERSION)
web-deps:
	@if [ "$$(cat .web-deps/.installed 2>/dev/null)" = "$(WEB_DEPS)" ]; then :; \
	elif command -v npm >/dev/null; then \
	  echo "installing $(WEB_DEPS) from npm into .web-deps (headset emulator, lint and type check of the browser viewer)"; \
	  (npm install --silent --no-audit --no-fund --save-exact --prefix .web-deps $(WEB_DEPS) >/dev/null 2>&1 && \
	   echo "$(WEB_DEPS)" > .web-deps/.installed) || \
	  echo "the npm packages could not be installed; the WebXR tests and the browser code's lint will skip"; \
	else echo "npm not found: iwer, eslint and typescript not installed; the WebXR tests and the browser code's lint will skip"; fi

# ESLint and the type check of the browser viewer's code (tests/web/test_lint.py runs the same two commands)
lint-web: web-deps
	.web-deps/node_modules/.bin/eslint --max-warnings 0 volumen/web/static
	.web-deps/node_modules/.bin/tsc -p jsconfig.json

demo: $(DEMO_STAMP)
	$(VENV)/bin/volumen demo --out out
	@echo "the other modes' kernels compile on first use (cached once per machine); to compile them all now: $(VENV)/bin/volumen warm"

# the README's pictures, each from the README lines that write it (their outputs side by side; a video's frames);
# tests/test_readme.py compares them with those lines' outputs at a small size
pictures: $(DEMO_STAMP)
	$(PY) docs/pictures.py

# a lint finding fails the build before any test runs (rules in pyproject.toml, [tool.ruff]); the test extra installs
# the CUDA compiler's libraries, so the CUDA kernels' PTX check must run, not skip (VOLUMEN_REQUIRE_PTX)
test: $(STAMP) system-data system-libs browser pacs-server web-deps readme-venv
	$(VENV)/bin/ruff check volumen tests tools
	VOLUMEN_REQUIRE_PTX=1 $(PY) -m pytest $(PYTEST_ARGS)

# A long seeded fuzz campaign over every reader (12,000 mutants, 2 workers, 10 s and 4 GiB per mutant);
# prints a table per family of formats and fails on any untyped error, hang, crash, out-of-memory or
# read outside the header's folder. `make test` runs a 3,000-mutant slice (tests/io/test_fuzz.py).
FUZZ_ARGS ?= --mutants 12000 --seed 1
fuzz: $(STAMP) fuzz-net
	$(PY) -m tools.fuzz.io $(FUZZ_ARGS)

# A long seeded campaign over the network surfaces: 20,000 mutated requests (request lines, headers, bodies, query
# values) to `volumen serve` in a process of its own and 5,000 mutated DICOMweb answers from a hostile archive to
# `volumen pacs`; a table per surface, failing on any 5xx, hang, crash, memory over budget, token or patient in the
# server's log, or control character in a table. `make test` runs a slice (tests/web/test_net_fuzz.py).
FUZZ_NET_ARGS ?= --requests 20000 --replies 5000 --seed 1
fuzz-net: $(STAMP)
	$(PY) -m tools.fuzz.net $(FUZZ_NET_ARGS)

# The 2048x2048x1024 int16 synthetic volume (8 GiB of disk, written to a temporary folder and deleted)
# drawn out of core in a fresh process; prints its peak RSS, the cache, the bound and the time.
huge: $(STAMP)
	$(VENV)/bin/volumen bench scale --huge

clean:
	rm -rf $(VENV) $(README_VENV) out test-output .web-deps
