#!/usr/bin/env bash
# The whole test suite, set up from a fresh checkout: needs only Rust (cargo) and Python
# >= 3.9 (with its venv module). This is the README's test command, and what .ci/run runs.
#
#   1. cargo test: every crate, optimized-tests profile (the statistical suites need
#      optimized code; see the README).
#   2. The Python package built as a wheel (maturin, fetched by pip) from the same target
#      directory and profile, so the Rust crates compile once; into target/wheels/.
#   3. A virtual environment (target/test-venv, kept between runs) with that wheel and its
#      `test` extra (pytest, Ray, matplotlib; numpy): the wheel installs as a user would
#      install it, without Rust.
#   4. pytest on crates/python/tests with that environment's Python.
#
# FACETTE_TEST_VENV overrides the environment's folder.
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
venv="${FACETTE_TEST_VENV:-$CARGO_TARGET_DIR/test-venv}"

cargo test --workspace --profile optimized-tests

[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
py="$venv/bin/python"
wheels="$CARGO_TARGET_DIR/wheels"
mkdir -p "$wheels"
rm -f "$wheels"/facette-*.whl
MATURIN_PEP517_ARGS="--profile optimized-tests" \
    "$py" -m pip wheel --quiet --no-deps ./crates/python -w "$wheels"
wheel=$(echo "$wheels"/facette-*.whl)
# The version does not change between builds: --force-reinstall replaces the package
# (and only it: --no-deps), then the extra's dependencies are installed when missing.
"$py" -m pip install --quiet --force-reinstall --no-deps "$wheel"
"$py" -m pip install --quiet "$wheel[test]"

"$py" -m pytest -q crates/python/tests
