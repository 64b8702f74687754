#!/usr/bin/env bash
# The whole test suite, set up from a fresh checkout: needs only Rust (cargo) and Python
# >= 3.9 (with its venv module). This is the README's test command, and what .ci/run runs.
#
#   1. cargo test: every crate, optimized-tests profile (the statistical suites need
#      optimized code; see the README).
#   2. The Python package built as a wheel (maturin, fetched by pip) from the same target
#      directory and profile, with its `test-build` feature (the strict finite guard and the
#      features the Rust tests unify on shared crates), so the Rust crates compile once;
#      into target/wheels/.
#   3. A virtual environment (target/test-venv, kept between runs) with that wheel and its
#      `test` extra (pytest, Ray, matplotlib; numpy): the wheel installs as a user would
#      install it, without Rust.
#   4. pytest on crates/python/tests with that environment's Python.
#   5. The explorer's browser tests (crates/explore/tests/browser): Debian's chromium and
#      chromium-driver, installed with apt-get when missing (as root, or through sudo),
#      in the background while the crates compile; selenium from PyPI into the same
#      environment. Screenshots and latency figures go to target/explore-artefacts/.
#
# FACETTE_TEST_VENV overrides the environment's folder.
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
venv="${FACETTE_TEST_VENV:-$CARGO_TARGET_DIR/test-venv}"

# The browser, installed while the crates compile (its log in target/browser-install.log).
mkdir -p "$CARGO_TARGET_DIR"
browser_log="$CARGO_TARGET_DIR/browser-install.log"
install_browser() {
    if command -v chromium >/dev/null && command -v chromedriver >/dev/null; then
        return 0
    fi
    local sudo=""
    if [ "$(id -u)" != 0 ]; then
        command -v sudo >/dev/null || { echo "chromium and chromium-driver are missing, and installing them needs root or sudo"; return 1; }
        sudo="sudo -n"
    fi
    $sudo apt-get update -qq && DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq chromium chromium-driver
}
install_browser >"$browser_log" 2>&1 &
browser_install=$!
# Each phase's wall time, printed at the end (what CI's total is made of). A failing step
# ends the script: the browser install in the background ends with it.
phases=()
phase() { phases+=("$(printf '%5d s  %s' "$SECONDS" "$1")"); SECONDS=0; }
trap 'kill "$browser_install" 2>/dev/null || true; [ ${#phases[@]} -eq 0 ] || printf "%s\n" "phase times:" "${phases[@]}"' EXIT
SECONDS=0

cargo test --workspace --profile optimized-tests
phase "cargo test (build and run)"

[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
py="$venv/bin/python"
wheels="$CARGO_TARGET_DIR/wheels"
mkdir -p "$wheels"
rm -f "$wheels"/facette-*.whl
MATURIN_PEP517_ARGS="--profile optimized-tests --features test-build" \
    "$py" -m pip wheel --quiet --no-deps ./crates/python -w "$wheels"
phase "wheel"
wheel=$(echo "$wheels"/facette-*.whl)
# The version does not change between builds: --force-reinstall replaces the package
# (and only it: --no-deps), then the extra's dependencies are installed when missing.
"$py" -m pip install --quiet --force-reinstall --no-deps "$wheel"
"$py" -m pip install --quiet "$wheel[test]"
phase "environment"

"$py" -m pytest -q crates/python/tests
phase "Python tests"

if ! wait "$browser_install"; then
    echo "error: installing chromium and chromium-driver failed (see $browser_log):" >&2
    tail -n 20 "$browser_log" >&2
    exit 1
fi
"$py" -m pip install --quiet selenium
FACETTE_BIN="$CARGO_TARGET_DIR/optimized-tests/facette" \
    FACETTE_ARTEFACTS="$CARGO_TARGET_DIR/explore-artefacts" \
    "$py" -m pytest -q crates/explore/tests/browser
phase "browser tests (with the browser's install wait)"
