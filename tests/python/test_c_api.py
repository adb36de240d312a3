"""Compiles tests/c/test_capi.c with gcc -Wall -Wextra -Werror against the generated headers and
the FMI 2.0 standard headers shipped with fmpy (so every exported fmi2 signature is checked
against the standard), links the release library and runs it."""

import os
import shutil
import subprocess
from pathlib import Path

import fmpy
import pytest

from conftest import RELEASE, ROOT


def test_c_program_against_the_generated_headers(md, tmp_path):
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
