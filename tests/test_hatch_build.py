"""The build hook's compiled kernels (``hatch_build.py`` at the repository's root)."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]


def _hook_module() -> Any:
    spec = importlib.util.spec_from_file_location("hatch_build", ROOT / "hatch_build.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


#: A stand-in for ``collidium.precompile``: writes what numba would, where numba would (the
#: package's own __pycache__ folders), unless NUMBA_CACHE_DIR would send them elsewhere or the
#: build environment's packages (pip puts them on PYTHONPATH) are out of reach.
FAKE_PRECOMPILE = """
import os, pathlib, sys
if "NUMBA_CACHE_DIR" in os.environ:
    sys.exit("NUMBA_CACHE_DIR is set")
if "/pip-build-env/site" not in os.environ["PYTHONPATH"].split(os.pathsep):
    sys.exit("the build environment is off the path")
here = pathlib.Path(__file__).parent
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


def test_the_wheel_gets_the_cache_the_precompile_writes_into_a_copy(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "elsewhere"))
    monkeypatch.setenv("PYTHONPATH", "/pip-build-env/site")
    monkeypatch.delenv("COLLIDIUM_PRECOMPILE", raising=False)
    package = _package(tmp_path, FAKE_PRECOMPILE)
    build_data: dict[str, Any] = {"force_include": {}}
    folder = _hook_module()._precompile(package, build_data)
    included = {Path(source).read_bytes(): target
                for source, target in build_data["force_include"].items()}  # fmt: skip
    assert included == {
        b"index": "collidium/kernels/__pycache__/events.run-9.py311.nbi",
        b"code": "collidium/kernels/__pycache__/events.run-9.py311.1.nbc",
    }  # the source tree's stale cache and the bytecode stay out
    assert all(Path(source).is_relative_to(folder) for source in build_data["force_include"])
    assert not (package / "kernels" / "__pycache__" / "events.run-9.py311.nbi").exists()


def test_a_failed_precompile_builds_the_wheel_without_a_cache_and_says_why(
    tmp_path, monkeypatch, capsys
):
    monkeypatch.delenv("COLLIDIUM_PRECOMPILE", raising=False)
    package = _package(tmp_path, "import sys; sys.exit('numba: no such CPU')")
    build_data: dict[str, Any] = {"force_include": {}}
    _hook_module()._precompile(package, build_data)
    assert build_data["force_include"] == {}
    assert capsys.readouterr().err == (
        "collidium: building without compiled kernels: numba: no such CPU\n"
    )


def test_precompile_0_builds_without_running_it(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("COLLIDIUM_PRECOMPILE", "0")
    package = _package(tmp_path, "raise SystemExit('must not run')")
    build_data: dict[str, Any] = {"force_include": {}}
    assert _hook_module()._precompile(package, build_data) is None
    assert build_data["force_include"] == {}
    assert "COLLIDIUM_PRECOMPILE=0" in capsys.readouterr().err
