"""Compiles tests/c/test_capi.c with gcc -Wall -Wextra -Werror against the generated headers and
the FMI 2.0 standard headers shipped with fmpy (so every exported fmi2 signature is checked
against the standard), links the release library and runs it; then, when valgrind is
installed, runs it again under `valgrind --error-exitcode=1 --leak-check=full` (100
create/free and instantiate/free cycles instead of 1000; about 10 s)."""

import os
import shutil
import subprocess
from pathlib import Path

import fmpy
import pytest

from conftest import RELEASE, ROOT


def _build_and_run(md, tmp_path):
    """Builds the C test, runs it once and returns the executable."""
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc is not installed: the C test is not run")
    lib = RELEASE / "libhelical_gear_mesh.so"
    if not lib.exists():
        pytest.fail(f"{lib} is missing: build it with `cargo run --release -p fmu-build`")
    fmi2_headers = Path(os.path.dirname(fmpy.__file__)) / "c-code"
    exe = tmp_path / "test_capi"
    cmd = [
        gcc, "-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic",
        f"-I{ROOT / 'include'}", f"-I{fmi2_headers}",
        str(ROOT / "tests" / "c" / "test_capi.c"),
        f"-L{RELEASE}", "-lhelical_gear_mesh", f"-Wl,-rpath,{RELEASE}", "-lm",
        "-o", str(exe),
    ]
    build = subprocess.run(cmd, capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    run = subprocess.run([str(exe), md.guid], capture_output=True, text=True)
    print(run.stdout)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "all C checks passed" in run.stdout
    return exe


def test_c_program_against_the_generated_headers(md, tmp_path):
    _build_and_run(md, tmp_path)


def test_c_program_under_valgrind(md, tmp_path):
    valgrind = shutil.which("valgrind")
    if valgrind is None:
        pytest.skip("valgrind is not installed: the memory check of the C test is not run")
    exe = _build_and_run(md, tmp_path)
    cmd = [valgrind, "--error-exitcode=1", "--leak-check=full", "-q", str(exe), md.guid, "100"]
    # The stateful units' part builds a mesh table, minutes under valgrind: it runs natively in
    # test_c_program_against_the_generated_headers and is skipped here.
    env = dict(os.environ, HGM_TEST_SKIP_UNITS="1")
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=env)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-8000:]
    assert "all C checks passed" in run.stdout
