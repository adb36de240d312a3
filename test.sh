#!/usr/bin/env bash
# Runs every test suite of the project: formatting and lints, the Rust unit and integration
# tests, then the FMU suite: the release FMU and CLI are built, and pytest (with fmpy, in a
# .venv this script creates) validates and drives the FMU, compares a Python RK4 master with
# the CLI's RK4 reference, and compiles and runs the C test of tests/c with gcc (skipped when
# gcc is missing), and once more under valgrind for memory errors and leaks (skipped with a
# message when valgrind is missing). Installs what it needs itself; needs Rust and Python 3.
set -euo pipefail
cd "$(dirname "$0")"

echo "== cargo fmt --check"
cargo fmt --all -- --check

echo "== cargo clippy -D warnings"
cargo clippy --workspace --all-targets -- -D warnings

echo "== cargo test"
cargo test --workspace

if [ -d tests/python ] && ls tests/python/test_*.py >/dev/null 2>&1; then
  echo "== release build: FMU (target/fmu/HelicalGearMesh.fmu) and CLI"
  cargo run --release -p fmu-build
  cargo build --release --bin helical-gear

  echo "== python tests (fmpy + pytest in .venv; includes the C test of tests/c)"
  if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
  fi
  .venv/bin/python -m pip install --quiet --disable-pip-version-check -r tests/python/requirements.txt

  echo "== python package helical_gear (python/: PyO3 + maturin, release build into .venv)"
  .venv/bin/python -m pip install --quiet --disable-pip-version-check -r python/requirements-test.txt
  .venv/bin/python -m pip install --quiet --disable-pip-version-check ./python

  # pytest exits 5 when it collects no test: say so instead of failing on a bare status.
  pytest_status=0
  .venv/bin/python -m pytest -q tests/python || pytest_status=$?
  if [ "$pytest_status" -eq 5 ]; then
    echo "pytest collected no test in tests/python"
  elif [ "$pytest_status" -ne 0 ]; then
    exit "$pytest_status"
  fi
fi
