#!/usr/bin/env bash
# Runs every test suite of the project: formatting and lints, the Rust unit and integration
# tests, and (when present) the Python/fmpy and C suites. Installs what it needs itself.
set -euo pipefail
cd "$(dirname "$0")"

echo "== cargo fmt --check"
cargo fmt --all -- --check

echo "== cargo clippy -D warnings"
cargo clippy --workspace --all-targets -- -D warnings

echo "== cargo test"
cargo test --workspace

if [ -d tests/python ] && ls tests/python/test_*.py >/dev/null 2>&1; then
  echo "== python tests (fmpy + pytest in .venv)"
  if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
  fi
  .venv/bin/python -m pip install --quiet --disable-pip-version-check -r tests/python/requirements.txt
  .venv/bin/python -m pytest -q tests/python
fi
