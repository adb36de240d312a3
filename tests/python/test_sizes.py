"""Size of what is shipped: each packed FMU (linux64 and, when cross-built, win64 inside) at
most 6.5 MB zipped, and the linux64 library inside at most 8 MB.

The library carries only the model (no command line, figures or font: those are the
applications' crate, app/) and no debug info (release profile: ``debug = false``,
``strip = "symbols"``). With line tables and the applications linked in, the library was
31.7 MB and each FMU 16.8 MB. The FMU budget was 6 MB up to the fifth model, HelicalGearbox,
whose table and engine took each FMU from just under 6 MB to 6.06 MB (both libraries inside
grew; the Mesh FMU measured then: linux64 2.37 MB, win64 2.97 MB, the compliance resource
0.72 MB, zipped). 1 MB = 10^6 bytes.
"""

import zipfile
from pathlib import Path

import pytest

from conftest import MODELS, fmu_file

MB = 1e6
FMU_LIMIT_MB = 6.5
LIBRARY_LIMIT_MB = 8.0


@pytest.mark.parametrize("model", MODELS)
def test_fmu_is_at_most_6_mb_zipped(model):
    path = Path(fmu_file(model))
    size = path.stat().st_size / MB
    assert size <= FMU_LIMIT_MB, f"{path.name} is {size:.2f} MB zipped (limit {FMU_LIMIT_MB} MB)"


@pytest.mark.parametrize("model", MODELS)
def test_linux64_library_in_the_fmu_is_at_most_8_mb(model):
    path = Path(fmu_file(model))
    with zipfile.ZipFile(path) as z:
        libs = [i for i in z.infolist() if i.filename == f"binaries/linux64/{model}.so"]
    assert libs, f"{path.name} has no binaries/linux64/{model}.so"
    size = libs[0].file_size / MB
    assert size <= LIBRARY_LIMIT_MB, (
        f"{path.name}: binaries/linux64/{model}.so is {size:.2f} MB "
        f"(limit {LIBRARY_LIMIT_MB} MB)"
    )
