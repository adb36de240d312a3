"""Cost of one setReal + getReal through fmpy (Table 1, default options): the inputs change at
every call (a full mesh evaluation), over one mesh period at a static TE of 31 µm; and, for
comparison, the call overhead alone (inputs unchanged, outputs cached). Not a test; see
docs/c-api.md. Run: .venv/bin/python tests/python/bench_fmu_call.py"""

import math
import time

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

FMU = "target/fmu/HelicalGearMesh.fmu"
G_P, G_G, TE = 0.042860629350090065, 0.06714831931514112, 31e-6

md = read_model_description(FMU)
vr = {v.name: v.valueReference for v in md.modelVariables}
s = FMU2Slave(guid=md.guid, unzipDirectory=extract(FMU), modelIdentifier="HelicalGearMesh",
              instanceName="bench")
s.instantiate()
s.setupExperiment(startTime=0.0)
s.enterInitializationMode()
s.exitInitializationMode()
inputs = [vr[n] for n in ("phi_p", "phi_g", "w_p", "w_g")]
outputs = [vr[n] for n in ("M_F_p", "M_F_g", "M_D_p", "M_D_g")]
n = 2000
pitch = 2 * math.pi / 30
for rep in range(2):  # the first pass warms up
    t0 = time.perf_counter()
    for k in range(n):
        phi_p = pitch * k / n
        s.setReal(inputs, [phi_p, (TE - phi_p * G_P) / G_G, 100.0, -63.83])
        s.getReal(outputs)
    full = (time.perf_counter() - t0) / n
t0 = time.perf_counter()
for k in range(n):
    s.setReal(inputs, [0.0, TE / G_G, 100.0, -63.83])
    s.getReal(outputs)
overhead = (time.perf_counter() - t0) / n
print(f"fmpy setReal+getReal: {full * 1e6:.1f} us per call with a new state, "
      f"{overhead * 1e6:.1f} us call overhead (state unchanged)")
s.terminate()
s.freeInstance()
