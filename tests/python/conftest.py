"""Shared fixtures of the FMU tests: the packed FMU, its model description, and FMU2Slave
instances whose log messages are captured.

The FMU is built by ``cargo run --release -p fmu-build`` (``test.sh`` does it first).
"""

import shutil
from ctypes import byref
from pathlib import Path

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy import calloc, free
from fmpy.logging import addLoggerProxy

ROOT = Path(__file__).resolve().parents[2]
FMU = ROOT / "target" / "fmu" / "HelicalGearMesh.fmu"
RELEASE = ROOT / "target" / "release"

FMUS = ROOT / "target" / "fmu"
MODELS = [
    "HelicalGearMesh", "HelicalGearPair", "HelicalGearStage", "HelicalGearDrive", "HelicalGearbox",
]
EXE = RELEASE / "helical-gear"

__all__ = ["EXE", "FMICallException", "FMUS", "Instance", "MODELS", "ROOT", "RELEASE", "fmu_file"]


def fmu_file(model):
    """Path of the packed FMU of `model` (fails the test with the build command if missing)."""
    p = FMUS / f"{model}.fmu"
    if not p.exists():
        pytest.fail(f"{p} is missing: build it with `cargo run --release -p fmu-build`")
    return str(p)


@pytest.fixture(scope="session")
def fmu_path():
    if not FMU.exists():
        pytest.fail(f"{FMU} is missing: build it with `cargo run --release -p fmu-build`")
    return str(FMU)


@pytest.fixture(scope="session")
def md(fmu_path):
    return read_model_description(fmu_path)


@pytest.fixture(scope="session")
def unzipdir(fmu_path, tmp_path_factory):
    d = tmp_path_factory.mktemp("fmu with space")
    extract(fmu_path, unzipdir=str(d))
    yield str(d)
    shutil.rmtree(d, ignore_errors=True)


@pytest.fixture(scope="session")
def vr(md):
    return {v.name: v.valueReference for v in md.modelVariables}


# fmpy's native logger proxy (which formats the printf-style messages) forwards to one Python
# logger per process, so all instances log into one list, tagged with the instance name.
LOG = []


def _log(env, instance, status, category, message):
    LOG.append((instance.decode(), status, category.decode(), message.decode()))


CALLBACKS = fmi2CallbackFunctions()
CALLBACKS.logger = fmi2CallbackLoggerTYPE(_log)
CALLBACKS.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
CALLBACKS.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
addLoggerProxy(byref(CALLBACKS))


class Instance:
    """An FMU2Slave with name-based get/set and its log messages (instance names must be
    unique within a test session)."""

    def __init__(self, md, unzipdir, name, logging_on=False):
        self.name = name
        self.callbacks = CALLBACKS
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.slave = FMU2Slave(
            guid=md.guid,
            unzipDirectory=unzipdir,
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        self.slave.instantiate(callbacks=self.callbacks, loggingOn=logging_on)

    @property
    def messages(self):
        return [(s, c, m) for n, s, c, m in LOG if n == self.name]

    def init(self, start=0.0):
        self.slave.setupExperiment(startTime=start)
        self.slave.enterInitializationMode()
        self.slave.exitInitializationMode()

    def set(self, **values):
        names = list(values)
        self.slave.setReal([self.vr[n] for n in names], [values[n] for n in names])

    def get(self, *names):
        return self.slave.getReal([self.vr[n] for n in names])

    def errors(self):
        return [m for s, c, m in self.messages if s >= 3]

    def free(self):
        self.slave.freeInstance()


@pytest.fixture(scope="session")
def shared(md, unzipdir):
    """One Table 1 instance for the whole session: its model is built once, and fmi2Reset
    reuses it (each test resets before use)."""
    inst = Instance(md, unzipdir, "shared")
    yield inst
    inst.free()


@pytest.fixture
def fmu(shared):
    shared.slave.reset()
    LOG.clear()
    return shared
