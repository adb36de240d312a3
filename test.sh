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

# Each section starts with the time since the start (minutes:seconds), so a log shows where the
# time goes.
section() { printf '== [%d:%02d] %s\n' $((SECONDS / 60)) $((SECONDS % 60)) "$*"; }

section "what a fresh machine needs: cargo with rustfmt and clippy, Python >= 3.11 with venv"
missing=()
command -v cargo >/dev/null || missing+=("cargo (the Rust toolchain: https://rustup.rs)")
cargo fmt --version >/dev/null 2>&1 || missing+=("rustfmt (rustup component add rustfmt)")
cargo clippy --version >/dev/null 2>&1 || missing+=("clippy (rustup component add clippy)")
if ! python3 -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)' 2>/dev/null; then
  missing+=("Python >= 3.11 as python3")
elif ! python3 -c 'import venv, ensurepip' 2>/dev/null; then
  missing+=("Python's venv module with ensurepip (Debian/Ubuntu: apt-get install python3-venv)")
fi
if [ "${#missing[@]}" -gt 0 ]; then
  printf 'test.sh: missing: %s\n' "${missing[@]}" >&2
  exit 1
fi

# Offline cargo tools must not depend on what an earlier build happened to download: a cargo
# home that holds only the host's crates (what a fresh Linux build downloads) is handed to the
# tests that run cargo offline (tests/dependencies.rs reads HGM_HOST_ONLY_CARGO_HOME).
section "a cargo home with only the host's crates, for the offline tools"
host=$(rustc -vV | sed -n 's/^host: //p')
host_only_home=$(mktemp -d)
trap 'rm -rf "$host_only_home"' EXIT
# The user's cargo configuration (a registry mirror, say) applies there too.
for f in config.toml config; do
  [ -f "${CARGO_HOME:-$HOME/.cargo}/$f" ] && cp "${CARGO_HOME:-$HOME/.cargo}/$f" "$host_only_home/"
done
CARGO_HOME="$host_only_home" cargo fetch --locked --target "$host" --quiet
export HGM_HOST_ONLY_CARGO_HOME="$host_only_home"

# The declared minimum Rust version (rust-version in Cargo.toml) builds the workspace.
msrv=$(sed -n 's/^rust-version = "\(.*\)"/\1/p' Cargo.toml)
section "minimum Rust version $msrv: cargo +$msrv check"
if command -v rustup >/dev/null &&
  rustup toolchain install "$msrv" --profile minimal >/dev/null 2>&1; then
  CARGO_TARGET_DIR=target/msrv cargo "+$msrv" check --workspace --all-targets --quiet
else
  echo "test.sh: the Rust $msrv toolchain cannot be installed here: the minimum version is not checked"
fi

section "cargo fmt --check"
cargo fmt --all -- --check

section "cargo clippy -D warnings"
cargo clippy --workspace --all-targets -- -D warnings

section "cargo doc -D warnings (the workspace's crates, no dependencies)"
RUSTDOCFLAGS="-D warnings" cargo doc --workspace --no-deps

section "cargo test"
cargo test --workspace

if [ -d tests/python ] && ls tests/python/test_*.py >/dev/null 2>&1; then
  section "Windows tools: Rust target x86_64-pc-windows-gnu, MinGW-w64, wine"
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

  section "python environment: fmpy and pytest in .venv"
  if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
  fi
  .venv/bin/python -m pip install --quiet --disable-pip-version-check -r tests/python/requirements.txt

  # Release builds in this order: the Python package, then the FMUs, then the CLI. The library
  # is a cdylib, so its files carry no hash of the build's dependency set, and each build whose
  # set differs from the last compiles it again: the package's (PyO3's macros add to it) once,
  # the FMUs' and the CLI's after it, and the README's `cargo run --release` in pytest reuses
  # the CLI's.
  section "python package helical_gear (python/: PyO3 + maturin, release build into .venv)"
  .venv/bin/python -m pip install --quiet --disable-pip-version-check -r python/requirements-test.txt
  .venv/bin/python -m pip install --quiet --disable-pip-version-check ./python

  section "release build: FMU (target/fmu/HelicalGearMesh.fmu, linux64 and win64) and CLI"
  cargo run --release -p fmu-build -- "${win64[@]}"
  cargo build --release -p helical-gear-app --bin helical-gear

  section "python tests (pytest in .venv; includes the C test of tests/c)"
  # pytest exits 5 when it collects no test: say so instead of failing on a bare status.
  pytest_status=0
  .venv/bin/python -m pytest -q --durations=10 tests/python || pytest_status=$?
  if [ "$pytest_status" -eq 5 ]; then
    echo "pytest collected no test in tests/python"
  elif [ "$pytest_status" -ne 0 ]; then
    exit "$pytest_status"
  fi
fi
section "every suite passed"
