# krsview — the README's two commands: `make demo` and `make test`.
# Both work as root on a fresh Debian 12 machine: system packages, .venv, package, then run.

PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
# Headless OpenGL through EGL on Mesa (llvmpipe when there is no GPU); Xvfb for the tests
# that open the real viewer and editor windows, xdotool for real pointer and key events there;
# chromium (headless WebGL2 on SwiftShader) and glslang-tools test the web export.
APT_PACKAGES := libegl1 libegl-mesa0 libgl1 libgl1-mesa-dri libglx-mesa0 xvfb xauth xdotool \
                chromium glslang-tools
STAMP  := $(VENV)/.installed

.PHONY: demo test deps venv clean

# The viewer where there is a display, else a headless render to a PNG.
demo: $(STAMP)
	@if [ -n "$$DISPLAY$$WAYLAND_DISPLAY" ]; then $(BIN)/krsview view tree; \
	else $(BIN)/krsview render tree -o out/demo.png --size 640x360; fi

test: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/python -m pytest -q -n 2 --dist loadgroup

# System packages: installed only when one is missing (needs root or sudo).
deps:
	@missing=$$(for p in $(APT_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || echo $$p; done); \
	if [ -n "$$missing" ]; then \
		echo "installing system packages: $$missing"; \
		SUDO=$$([ "$$(id -u)" = 0 ] || echo sudo); \
		$$SUDO apt-get update -qq && \
		DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing; \
	fi

$(STAMP): pyproject.toml | deps
	@[ -x $(BIN)/python ] || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[test]'
	@touch $(STAMP)

venv: $(STAMP)

clean:
	rm -rf $(VENV) out test-output .pytest_cache .hypothesis *.egg-info
