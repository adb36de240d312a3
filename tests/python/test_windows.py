"""The Windows binaries of the FMUs (``binaries/win64``), cross-compiled by ``fmu-build`` for
``x86_64-pc-windows-gnu`` with the MinGW-w64 linker and run here under wine:

* every FMU in ``target/fmu`` carries ``binaries/win64/<modelIdentifier>.dll``, an x86-64 PE
  file exporting every fmi2 function of its interfaces (read from the PE export table);
* ``tests/c/test_capi.c`` is compiled with ``x86_64-w64-mingw32-gcc -Wall -Wextra -Werror``
  against ``include/`` and linked against the FMU's DLL, and passes under wine;
* ``tests/c/win/fmu_loader.c`` loads each FMU's DLL with LoadLibrary/GetProcAddress as a
  Windows importer does and runs one co-simulation step; for HelicalGearMesh the torques
  equal those of the linux64 binary driven through fmpy.

Wine 8 (Debian 12) lacks ``bcryptprimitives.dll``, which Rust's standard library imports, so
the stand-in ``tests/c/win/bcryptprimitives.c`` is built and placed beside the programs (never
in an FMU). Skipped with a message when MinGW-w64, wine or the FMU's win64 binary is missing.
"""

import os
import shutil
import struct
import subprocess
import time
import zipfile
from pathlib import Path
from urllib.parse import quote

import fmpy
import pytest
from fmpy import read_model_description

from conftest import ROOT, Instance

FMU_DIR = ROOT / "target" / "fmu"
WIN_SRC = ROOT / "tests" / "c" / "win"
MINGW_GCC = "x86_64-w64-mingw32-gcc"
RUST_TARGET = "x86_64-pc-windows-gnu"
FMI2_HEADERS = Path(os.path.dirname(fmpy.__file__)) / "c-code"

# FMI 2.0 standard, section 2.1 (common), 4.2 (Co-Simulation) and 3.2 (Model Exchange).
FMI2_COMMON = """GetTypesPlatform GetVersion SetDebugLogging Instantiate FreeInstance
SetupExperiment EnterInitializationMode ExitInitializationMode Terminate Reset GetReal GetInteger
GetBoolean GetString SetReal SetInteger SetBoolean SetString GetFMUstate SetFMUstate
FreeFMUstate SerializedFMUstateSize SerializeFMUstate DeSerializeFMUstate
GetDirectionalDerivative""".split()
FMI2_CS = """SetRealInputDerivatives GetRealOutputDerivatives DoStep CancelStep GetStatus
GetRealStatus GetIntegerStatus GetBooleanStatus GetStringStatus""".split()
FMI2_ME = """EnterEventMode NewDiscreteStates EnterContinuousTimeMode CompletedIntegratorStep
SetTime SetContinuousStates GetDerivatives GetEventIndicators GetContinuousStates
GetNominalsOfContinuousStates""".split()


def pe_exports(data):
    """Machine type and exported names of a PE32+ image (the bytes of a DLL)."""
    (pe,) = struct.unpack_from("<I", data, 0x3C)
    assert data[pe:pe + 4] == b"PE\0\0", "not a PE image"
    machine, n_sections, _, _, _, opt_size = struct.unpack_from("<HHIIIH", data, pe + 4)
    opt = pe + 24
    assert struct.unpack_from("<H", data, opt)[0] == 0x20B, "not PE32+"
    export_rva, _ = struct.unpack_from("<II", data, opt + 112)  # data directory 0
    sections = [struct.unpack_from("<IIII", data, opt + opt_size + 40 * i + 8)
                for i in range(n_sections)]  # VirtualSize, VirtualAddress, RawSize, RawPointer

    def offset(rva):
        for vsize, va, rsize, raw in sections:
            if va <= rva < va + max(vsize, rsize):
                return rva - va + raw
        raise ValueError(f"RVA {rva:#x} is in no section")

    exp = offset(export_rva)
    (n_names,) = struct.unpack_from("<I", data, exp + 24)
    (names_rva,) = struct.unpack_from("<I", data, exp + 32)
    names = []
    for i in range(n_names):
        (name_rva,) = struct.unpack_from("<I", data, offset(names_rva) + 4 * i)
        start = offset(name_rva)
        names.append(data[start:data.index(b"\0", start)].decode())
    return machine, names


def fmus():
    return sorted(FMU_DIR.glob("*.fmu"))


def win64_toolchain_missing():
    """Why fmu-build cannot cross-compile win64 here, or None."""
    if shutil.which(MINGW_GCC) is None:
        return f"{MINGW_GCC} is not on PATH"
    r = subprocess.run(["rustc", "--print", "target-libdir", "--target", RUST_TARGET],
                       capture_output=True, text=True)
    if r.returncode != 0 or not Path(r.stdout.strip()).is_dir():
        return f"the Rust target {RUST_TARGET} is not installed"
    return None


def model_identifiers(md):
    return sorted({i.modelIdentifier for i in (md.coSimulation, md.modelExchange) if i})


def win64_members(fmu):
    """(model identifier, DLL bytes) of each win64 binary an FMU must carry; skips the test
    when fmu-build could not build win64 here."""
    md = read_model_description(str(fmu))
    with zipfile.ZipFile(fmu) as z:
        names = set(z.namelist())
        out = []
        for mid in model_identifiers(md):
            member = f"binaries/win64/{mid}.dll"
            if member not in names:
                why = win64_toolchain_missing()
                if why:
                    pytest.skip(f"{fmu.name} has no win64 binary: {why}")
                pytest.fail(f"{fmu.name} lacks {member} although the toolchain is installed")
            assert f"binaries/linux64/{mid}.so" in names
            out.append((mid, z.read(member)))
    return md, out


def test_every_fmu_carries_a_win64_dll_exporting_every_fmi2_function():
    assert fmus(), f"no FMU in {FMU_DIR}: build them with `cargo run --release -p fmu-build`"
    for fmu in fmus():
        md, dlls = win64_members(fmu)
        wanted = FMI2_COMMON + (FMI2_CS if md.coSimulation else []) + \
            (FMI2_ME if md.modelExchange else [])
        for mid, data in dlls:
            machine, names = pe_exports(data)
            assert machine == 0x8664, f"{fmu.name}: {mid}.dll machine {machine:#x}, not x86-64"
            missing = [f"fmi2{f}" for f in wanted if f"fmi2{f}" not in names]
            assert not missing, f"{fmu.name}: {mid}.dll does not export {missing}"


@pytest.fixture(scope="session")
def wine(tmp_path_factory):
    """Runs a Windows program under wine in a fresh prefix and returns the completed process;
    the first start creates the prefix (timed and printed)."""
    exe = shutil.which("wine64") or shutil.which("wine") or \
        next((p for p in ["/usr/lib/wine/wine64"] if os.access(p, os.X_OK)), None)
    if exe is None:
        pytest.skip("wine is not installed: the Windows binaries are not run")
    if shutil.which(MINGW_GCC) is None:
        pytest.skip(f"{MINGW_GCC} is not installed: the Windows test programs are not built")
    env = dict(os.environ, WINEDEBUG="-all", WINEPREFIX=str(tmp_path_factory.mktemp("wine")),
               # No Mono or Gecko installation prompt while the prefix is created.
               WINEDLLOVERRIDES="mscoree,mshtml=")
    t0 = time.perf_counter()
    boot = subprocess.run([exe, "wineboot", "--init"], env=env, capture_output=True, text=True,
                          timeout=300)
    assert boot.returncode == 0, boot.stderr[-4000:]
    print(f"wine prefix created in {time.perf_counter() - t0:.1f} s")

    def run(args, cwd):
        return subprocess.run([exe, *map(str, args)], env=env, cwd=cwd, capture_output=True,
                              text=True, timeout=300)

    return run


def mingw(args):
    r = subprocess.run([MINGW_GCC, "-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic",
                        *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


@pytest.fixture(scope="session")
def windir(tmp_path_factory):
    """A directory with the wine stand-in bcryptprimitives.dll and HelicalGearMesh's DLL."""
    fmu = FMU_DIR / "HelicalGearMesh.fmu"
    if not fmu.exists():
        pytest.fail(f"{fmu} is missing: build it with `cargo run --release -p fmu-build`")
    _, dlls = win64_members(fmu)
    d = tmp_path_factory.mktemp("win")
    mingw(["-shared", "-O2", "-o", d / "bcryptprimitives.dll",
           WIN_SRC / "bcryptprimitives.c", "-ladvapi32"])
    for mid, data in dlls:
        (d / f"{mid}.dll").write_bytes(data)
    return d


def test_c_program_under_wine(md, wine, windir):
    exe = windir / "test_capi.exe"
    # GNU ld links against the FMU's DLL itself (no import library needed). The import is
    # recorded under the name in the DLL's export directory, the crate's
    # `helical_gear_mesh.dll` (as with cargo's import library), so the program finds the FMU's
    # DLL under that name.
    dll = windir / "helical_gear_mesh.dll"
    shutil.copyfile(windir / "HelicalGearMesh.dll", dll)
    mingw([f"-I{ROOT / 'include'}", f"-I{FMI2_HEADERS}", ROOT / "tests" / "c" / "test_capi.c",
           dll, "-o", exe])
    run = wine([exe, md.guid, "100"], cwd=windir)
    print(run.stdout)
    assert run.returncode == 0, f"exit status {run.returncode} (53: a DLL was not found)\n" + \
        run.stdout[-4000:] + run.stderr[-4000:]
    assert "all C checks passed" in run.stdout


def resource_uri(unzipdir):
    """file:// URI of an unpacked FMU's resources as a Windows program under wine sees it
    (drive Z: is the root of the host file system)."""
    return "file:///Z:" + quote(Path(unzipdir, "resources").as_posix())


def test_each_fmu_dll_loads_and_steps_like_a_windows_importer(wine, windir, tmp_path):
    loader = windir / "fmu_loader.exe"
    mingw([f"-I{FMI2_HEADERS}", WIN_SRC / "fmu_loader.c", "-o", loader])
    for fmu in fmus():
        md, dlls = win64_members(fmu)
        unzipdir = tmp_path / fmu.stem
        fmpy.extract(str(fmu), unzipdir=str(unzipdir))
        dll = unzipdir / "binaries" / "win64" / f"{md.coSimulation.modelIdentifier}.dll"
        run = wine([loader, dll, md.guid, resource_uri(unzipdir), "1e-4"], cwd=windir)
        assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-4000:]
        assert "fmi2GetVersion = 2.0" in run.stdout and "fmu_loader: done" in run.stdout
        # The Windows path of the resources reached the model intact.
        assert f"resources directory: Z:{unzipdir.as_posix()}/resources" in run.stdout, \
            run.stdout


def test_mesh_torques_on_windows_equal_those_on_linux(md, unzipdir, wine, windir):
    """One state (TE = 20 um at 100 rad/s, slightly approaching teeth) through the win64 DLL
    under wine and through the linux64 binary under fmpy: the same numbers up to the last
    bits (the two C runtimes' maths libraries may round differently)."""
    g_p, g_g = 0.042860629350090065, 0.06714831931514112
    inputs = {"phi_p": 0.01, "phi_g": (20e-6 - 0.01 * g_p) / g_g, "w_p": 100.0,
              "w_g": -100.0 * g_p / g_g + 0.01}
    outputs = ["M_F_p", "M_F_g", "M_D_p", "TE", "F_n"]
    vr = {v.name: v.valueReference for v in md.modelVariables}

    lin = Instance(md, unzipdir, "linux-vs-windows")
    try:
        lin.init()
        lin.set(**inputs)
        lin.slave.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-4)
        linux = dict(zip(outputs, lin.get(*outputs)))
    finally:
        lin.free()

    loader = windir / "fmu_loader.exe"
    if not loader.exists():
        mingw([f"-I{FMI2_HEADERS}", WIN_SRC / "fmu_loader.c", "-o", loader])
    args = [f"{vr[n]}={x!r}" for n, x in inputs.items()] + [f"?{vr[n]}" for n in outputs]
    run = wine([loader, windir / "HelicalGearMesh.dll", md.guid, resource_uri(unzipdir), "1e-4",
                *args], cwd=windir)
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-4000:]
    values = dict(line.split(" = ") for line in run.stdout.splitlines() if " = " in line)
    windows = {n: float(values[str(vr[n])]) for n in outputs}
    print("linux64:", linux, "\nwin64:  ", windows)
    assert linux["M_F_p"] > 10.0, "the state is loaded"
    for n in outputs:
        assert windows[n] == pytest.approx(linux[n], rel=1e-12, abs=1e-18), n
