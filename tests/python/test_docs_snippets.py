"""Every command and example of the README and the guides (docs/*.md) runs as shown.

Each fenced `sh`/`bash`/`console`, `python` and `c` block is extracted and run in a fresh
temporary directory under `target/` (inside the workspace, so that `cargo run --release -- …`
finds it as the README says):

* shell blocks through `bash -euo pipefail`, with the release CLI (`target/release`) and `cargo`
  on PATH; `console` blocks run their `$ ` lines;
* Python blocks with this interpreter (the `.venv` that holds fmpy and `helical_gear`), in a
  directory where `target/fmu/…` leads to the built FMUs, with matplotlib's non-interactive
  backend;
* C blocks (statements of a `main`) compiled with gcc against `include/` and the release C
  library, as `test_c_api.py` does, and run.

A block that cannot run in a test is marked in the Markdown by an HTML comment on the line
right above it, `<!-- not run in tests: REASON -->`, and is reported as skipped with that
reason. A `rust` block must equal the crate docs' example of `src/lib.rs`, which `cargo test
--doc` runs. Everything else must exit with status 0.
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
RELEASE = ROOT / "target" / "release"
PAGES = [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))
LANGS = {"sh", "bash", "console", "python", "c", "rust"}
SKIP = re.compile(r"^<!--\s*not run in tests:\s*(.*?)\s*-->$")
TIMEOUT_S = 300


def blocks():
    """(page, line, language, code, skip reason or None) of every runnable fenced block."""
    out = []
    for page in PAGES:
        lines = page.read_text(encoding="utf-8").splitlines()
        i = 0
        while i < len(lines):
            m = re.match(r"^(```|~~~)\s*(\w*)\s*$", lines[i])
            if not m:
                i += 1
                continue
            fence, lang = m.group(1), m.group(2)
            j = i + 1
            while j < len(lines) and not lines[j].startswith(fence):
                j += 1
            if lang in LANGS:
                above = lines[i - 1].strip() if i > 0 else ""
                skip = SKIP.match(above)
                out.append((page, i + 1, lang, "\n".join(lines[i + 1:j]) + "\n",
                            skip.group(1) if skip else None))
            i = j + 1
    return out


BLOCKS = blocks()


def _id(b):
    return f"{b[0].relative_to(ROOT)}:{b[1]}-{b[2]}"


def _workdir():
    """A fresh directory inside the workspace, with `target` leading to the repository's."""
    base = ROOT / "target" / "docs-snippets"
    base.mkdir(parents=True, exist_ok=True)
    d = Path(tempfile.mkdtemp(dir=base))
    (d / "target").symlink_to(ROOT / "target")
    return d


def _env():
    env = dict(os.environ)
    cargo = shutil.which("cargo")
    path = [str(RELEASE)] + ([str(Path(cargo).parent)] if cargo else [])
    env["PATH"] = os.pathsep.join(path + [env.get("PATH", "")])
    env["MPLBACKEND"] = "Agg"
    return env


def _run(cmd, cwd, **kw):
    r = subprocess.run(cmd, cwd=cwd, env=_env(), capture_output=True, text=True,
                       timeout=TIMEOUT_S, **kw)
    print(r.stdout[-4000:])
    assert r.returncode == 0, f"exit {r.returncode}\n{r.stdout[-2000:]}\n{r.stderr[-4000:]}"
    return r


def _rust_doc_example():
    """The code of the first Rust example (a ``` or ```rust fence) in the crate docs of
    src/lib.rs."""
    code, fence = [], None
    for line in (ROOT / "src" / "lib.rs").read_text(encoding="utf-8").splitlines():
        if not line.startswith("//!"):
            continue
        text = line[4:] if line.startswith("//! ") else line[3:]
        if text.strip().startswith("```"):
            if fence is None:
                fence, code = text.strip()[3:] or "rust", []
            elif fence == "rust":
                return "\n".join(code) + "\n"
            else:
                fence = None
            continue
        if fence == "rust":
            code.append(text)
    pytest.fail("src/lib.rs has no ``` example in its crate docs")


def test_every_page_has_been_scanned():
    # The README carries one block per audience; a parser that found none would pass vacuously.
    langs = {b[2] for b in BLOCKS if b[0].name == "README.md"}
    assert {"sh", "python", "c", "rust"} <= langs, langs


@pytest.mark.parametrize("block", BLOCKS, ids=_id)
def test_snippet_runs_as_shown(block):
    page, line, lang, code, skip = block
    if skip is not None:
        pytest.skip(skip)
    if lang == "rust":
        assert code == _rust_doc_example(), (
            f"{page.name}:{line}: the Rust block differs from the crate docs' example in "
            "src/lib.rs (which cargo test --doc runs); keep them equal"
        )
        return
    cwd = _workdir()
    try:
        if lang in ("sh", "bash"):
            _run(["bash", "-euo", "pipefail", "-c", code], cwd)
        elif lang == "console":
            cmds = [ln[2:] for ln in code.splitlines() if ln.startswith("$ ")]
            _run(["bash", "-euo", "pipefail", "-c", "\n".join(cmds)], cwd)
        elif lang == "python":
            (cwd / "snippet.py").write_text(code, encoding="utf-8")
            _run([sys.executable, "snippet.py"], cwd)
        elif lang == "c":
            gcc = shutil.which("gcc")
            if gcc is None:
                pytest.skip("gcc is not installed: the C snippet is not compiled")
            lib = RELEASE / "libhelical_gear_mesh.so"
            if not lib.exists():
                pytest.fail(f"{lib} is missing: build it with `cargo run --release -p fmu-build`")
            includes = [ln for ln in code.splitlines() if ln.startswith("#include")]
            body = [ln for ln in code.splitlines() if not ln.startswith("#include")]
            src = "\n".join(["#include <stdio.h>"] + includes + ["int main(void) {"]
                            + ["    " + ln for ln in body] + ["    return 0;", "}", ""])
            (cwd / "snippet.c").write_text(src, encoding="utf-8")
            _run([gcc, "-std=c11", "-Wall", "-Werror", f"-I{ROOT / 'include'}", "snippet.c",
                  f"-L{RELEASE}", "-lhelical_gear_mesh", f"-Wl,-rpath,{RELEASE}", "-lm",
                  "-o", "snippet"], cwd)
            _run([str(cwd / "snippet")], cwd)
    finally:
        shutil.rmtree(cwd, ignore_errors=True)
