#!/usr/bin/env bash
# Runs every test suite of the project: formatting, lints and the API docs (cargo doc), the Rust
# unit and integration tests, then the FMU suite: the release FMU and CLI are built, and pytest
# (with fmpy, in a .venv this script creates) validates and drives the FMU, compares a Python RK4
# master with the CLI's RK4 reference, and compiles and runs the C test of tests/c with gcc
# (skipped when gcc is missing), and once more under valgrind for memory errors and leaks (skipped
# with a message when valgrind is missing). The FMU also carries a Windows DLL cross-compiled with
# MinGW-w64, which pytest runs under wine (skipped with a message when the Rust target, MinGW-w64
# or wine cannot be installed). Installs what it needs itself; needs Rust and Python 3.
set -euo pipefail
cd "$(dirname "$0")"

echo "== cargo fmt --check"
cargo fmt --all -- --check

echo "== cargo clippy -D warnings"
cargo clippy --workspace --all-targets -- -D warnings

echo "== cargo doc -D warnings (the workspace's crates, no dependencies)"
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps

echo "== cargo test"
cargo test --workspace

if [ -d tests/python ] && ls tests/python/test_*.py >/dev/null 2>&1; then
  echo "== Windows tools: Rust target x86_64-pc-windows-gnu, MinGW-w64, wine"
  win_start=$SECONDS
  if command -v rustup >/dev/null; then
    rustup target add x86_64-pc-windows-gnu >/dev/null 2>&1 ||
      echo "test.sh: rustup could not add x86_64-pc-windows-gnu: the FMUs get no win64 binary"
  fi
  if ! command -v x86_64-w64-mingw32-gcc >/dev/null || ! command -v wine >/dev/null; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
      { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
        gcc-mingw-w64-x86-64 wine64; } >/dev/null 2>&1 ||
        echo "test.sh: apt-get could not install gcc-mingw-w64-x86-64 and wine64: the Windows part is skipped"
    else
      echo "test.sh: gcc-mingw-w64-x86-64 or wine64 is missing and cannot be installed" \
        "(not root, or no apt-get): the Windows part is skipped"
    fi
  fi
  # With the target and the linker present a failing win64 build is an error, not a skip.
  win64=()
  if [ -d "$(rustc --print target-libdir --target x86_64-pc-windows-gnu 2>/dev/null)" ] &&
    command -v x86_64-w64-mingw32-gcc >/dev/null; then
    win64=(--require-win64)
  fi
  echo "Windows tools ready in $((SECONDS - win_start)) s"

  echo "== release build: FMU (target/fmu/HelicalGearMesh.fmu, linux64 and win64) and CLI"
  cargo run --release -p fmu-build -- "${win64[@]}"
  cargo build --release -p helical-gear-app --bin helical-gear

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
