"""The build hook's compiled kernels (``hatch_build.py`` at the repository's root)."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _hook_module() -> Any:
    spec = importlib.util.spec_from_file_location("hatch_build", ROOT / "hatch_build.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


#: A stand-in for ``collidium.precompile``: writes what numba would, where numba would (the
#: package's own __pycache__ folders), unless NUMBA_CACHE_DIR would send them elsewhere or the
#: build environment's packages (pip puts them on PYTHONPATH) are out of reach; counts its runs.
FAKE_PRECOMPILE = """
import os, pathlib, sys
if "NUMBA_CACHE_DIR" in os.environ:
    sys.exit("NUMBA_CACHE_DIR is set")
if "/pip-build-env/site" not in os.environ["PYTHONPATH"].split(os.pathsep):
    sys.exit("the build environment is off the path")
here = pathlib.Path(__file__).parent
with open(here.parents[1] / "runs", "a") as runs:  # beside the kept copy's folder
    runs.write("run\\n")
for folder in (here / "__pycache__", here / "kernels" / "__pycache__"):
    folder.mkdir(exist_ok=True)
(here / "kernels" / "__pycache__" / "events.run-9.py311.nbi").write_bytes(b"index")
(here / "kernels" / "__pycache__" / "events.run-9.py311.1.nbc").write_bytes(b"code")
(here / "__pycache__" / "cli.cpython-311.pyc").write_bytes(b"bytecode")
"""


def _package(tmp_path: Path, precompile: str) -> Path:
    package = tmp_path / "src" / "collidium"
    (package / "kernels" / "__pycache__").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "kernels" / "__init__.py").write_text("")
    (package / "kernels" / "__pycache__" / "stale.f-1.py311.nbi").write_bytes(b"old")
    (package / "precompile.py").write_text(precompile)
    return package


def _build(package: Path, folder: Path) -> dict[str, str]:
    """What one wheel build force-includes: {file's content: its path in the wheel}."""
    build_data: dict[str, Any] = {"force_include": {}}
    _hook_module()._precompile(package, folder, build_data)
    assert all(Path(source).is_relative_to(folder) for source in build_data["force_include"])
    return {Path(source).read_bytes(): target
            for source, target in build_data["force_include"].items()}  # fmt: skip


@pytest.fixture
def build_environment(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "elsewhere"))
    monkeypatch.setenv("PYTHONPATH", "/pip-build-env/site")
    monkeypatch.delenv("COLLIDIUM_PRECOMPILE", raising=False)


COMPILED = {
    b"index": "collidium/kernels/__pycache__/events.run-9.py311.nbi",
    b"code": "collidium/kernels/__pycache__/events.run-9.py311.1.nbc",
}  # the source tree's stale cache and the bytecode stay out


@pytest.mark.usefixtures("build_environment")
def test_the_wheel_gets_the_cache_the_precompile_writes_into_a_copy(tmp_path):
    package = _package(tmp_path, FAKE_PRECOMPILE)
    assert _build(package, tmp_path / "build" / "kernels") == COMPILED
    assert not (package / "kernels" / "__pycache__" / "events.run-9.py311.nbi").exists()


@pytest.mark.usefixtures("build_environment")
def test_a_second_build_of_the_same_sources_ships_the_copy_without_compiling_again(tmp_path):
    package = _package(tmp_path, FAKE_PRECOMPILE)
    folder = tmp_path / "build" / "kernels"
    assert _build(package, folder) == _build(package, folder) == COMPILED
    runs = folder.parent / "runs"  # beside the copy, which a new compilation starts afresh
    assert runs.read_text() == "run\n"
    (package / "kernels" / "events.py").write_text("changed = True\n")
    assert _build(package, folder) == COMPILED
    assert runs.read_text() == "run\nrun\n"
    assert (folder / "collidium" / "kernels" / "events.py").read_text() == "changed = True\n"


@pytest.mark.usefixtures("build_environment")
def test_a_failed_precompile_builds_the_wheel_without_a_cache_and_says_why(tmp_path, capsys):
    package = _package(tmp_path, "import sys; sys.exit('numba: no such CPU')")
    folder = tmp_path / "build" / "kernels"
    assert _build(package, folder) == {}
    assert capsys.readouterr().err == (
        "collidium: building without compiled kernels: numba: no such CPU\n"
    )
    assert _build(package, folder) == {}  # tried again, not taken for compiled
    assert capsys.readouterr().err.count("no such CPU") == 1


def test_precompile_0_builds_without_running_it(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("COLLIDIUM_PRECOMPILE", "0")
    package = _package(tmp_path, "raise SystemExit('must not run')")
    assert _build(package, tmp_path / "build" / "kernels") == {}
    assert "COLLIDIUM_PRECOMPILE=0" in capsys.readouterr().err
