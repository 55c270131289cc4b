"""Build hook: bundle the viewer's front end (``frontend/``) into the package with npm, and
put the presets' compiled kernels into the wheel.

``pip install .`` from a clone, every wheel and every sdist get ``src/collidium/viewer/static/
{app,widget}.{js,css}``, built by esbuild from the sources and the locked npm dependencies
(regl, uPlot); the bundles are build outputs, never committed. They are rebuilt only when
missing or older than a source, so a wheel built from an sdist needs no Node.js. Building from a
clone needs Node.js (>= 18) and npm; ``COLLIDIUM_SKIP_FRONTEND=1`` builds without the viewer
(``collidium view`` then says the front end is missing).

A wheel (not an editable install) also carries numba's cache of the kernels that the presets run
(``python -m collidium.precompile``, run on a copy of the package in the build's environment, which
holds collidium's dependencies for it), so that the first run after ``pip install .`` loads them
instead of compiling them. Their cache is stamped with the content of every kernel's source
(``collidium.kernels.compilation``), numba's version and the CPU, so a wheel used elsewhere, or
with another numba, compiles on its first run as without it. The compiled copy stays in
``build/kernels/`` for the next build from the same sources. ``COLLIDIUM_PRECOMPILE=0`` builds
without it (a wheel to publish).
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

from hatchling.builders.hooks.plugin.interface import BuildHookInterface

BUNDLES = ("app.js", "app.css", "widget.js", "widget.css")


class BuildHook(BuildHookInterface):  # type: ignore[type-arg]
    """Bundles the front end before a wheel or sdist is made; compiles the kernels into a wheel."""

    PLUGIN_NAME = "custom"

    def initialize(self, version: str, build_data: dict[str, Any]) -> None:
        self._bundle_front_end(build_data)
        if self.target_name == "wheel" and version == "standard":
            root = Path(self.root)
            _precompile(root / "src" / "collidium", root / "build" / "kernels", build_data)

    def _bundle_front_end(self, build_data: dict[str, Any]) -> None:
        """Runs ``npm ci`` and ``npm run build`` in ``frontend/`` where the bundles are stale."""
        root = Path(self.root)
        frontend = root / "frontend"
        static = root / "src" / "collidium" / "viewer" / "static"
        outputs = [static / name for name in BUNDLES]
        if _stale(outputs, frontend):
            if os.environ.get("COLLIDIUM_SKIP_FRONTEND") == "1":
                sys.stderr.write(
                    "collidium: COLLIDIUM_SKIP_FRONTEND=1, building without the viewer\n"
                )
                return
            _bundle(frontend)
        build_data["artifacts"] += [str(path.relative_to(root)) for path in outputs]


def _precompile(package: Path, folder: Path, build_data: dict[str, Any]) -> None:
    """Compile the presets' kernels on a copy of ``package`` in ``folder`` and add numba's cache
    files to the wheel (``force_include``). The copy is kept, with a stamp of what it was
    compiled from (`_sources_stamp`): a build from the same sources ships it again without
    compiling (``pip install ".[test]"`` after ``pip install .``). A failure leaves the wheel
    without them (its first run compiles), with a line saying why."""
    if os.environ.get("COLLIDIUM_PRECOMPILE") == "0":
        sys.stderr.write("collidium: COLLIDIUM_PRECOMPILE=0, building without compiled kernels\n")
        return
    copy, stamp_file = folder / "collidium", folder / "compiled-from"
    stamp = _sources_stamp(package)
    if not (stamp_file.is_file() and stamp_file.read_text() == stamp):
        shutil.rmtree(folder, ignore_errors=True)
        shutil.copytree(package, copy, ignore=shutil.ignore_patterns("__pycache__"))
        environment = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
        # The copy first, whose own __pycache__ numba fills; then pip's isolated build
        # environment, which it puts on the path the same way.
        paths = [str(folder), *filter(None, environment.get("PYTHONPATH", "").split(os.pathsep))]
        environment["PYTHONPATH"] = os.pathsep.join(paths)
        result = subprocess.run(
            [sys.executable, "-m", "collidium.precompile"],
            cwd=folder, env=environment, capture_output=True, text=True,
        )  # fmt: skip
        if result.returncode != 0:
            reason = (result.stderr.strip().splitlines() or ["no output"])[-1]
            sys.stderr.write(f"collidium: building without compiled kernels: {reason}\n")
            return
        stamp_file.write_text(stamp)
    for path in sorted(copy.rglob("__pycache__/*.nb[ic]")):
        build_data["force_include"][str(path)] = f"collidium/{path.relative_to(copy).as_posix()}"


def _sources_stamp(package: Path) -> str:
    """A digest of every file of ``package`` (but caches), the Python running the build and the
    versions of the compiler's packages: what numba's cache depends on, on this machine."""
    digest = hashlib.sha256(sys.version.encode())
    for name in ("numba", "llvmlite", "numpy"):
        try:
            version = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:  # the precompile will say so
            version = "missing"
        digest.update(f"{name} {version}".encode())
    for path in sorted(package.rglob("*")):
        if path.is_file() and "__pycache__" not in path.parts:
            digest.update(path.relative_to(package).as_posix().encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()


def _sources(frontend: Path) -> list[Path]:
    files = [frontend / "package.json", frontend / "package-lock.json", frontend / "build.mjs"]
    return files + sorted((frontend / "src").rglob("*"))


def _stale(outputs: list[Path], frontend: Path) -> bool:
    if not all(path.is_file() for path in outputs):
        return True
    if not frontend.is_dir():  # a source tree of bundles only: nothing to rebuild from
        return False
    newest_source = max(path.stat().st_mtime for path in _sources(frontend) if path.is_file())
    return min(path.stat().st_mtime for path in outputs) < newest_source


def _bundle(frontend: Path) -> None:
    npm = shutil.which("npm")
    if npm is None or not frontend.is_dir():
        raise RuntimeError(
            "collidium's viewer front end must be built with Node.js (>= 18) and npm: install "
            "them (e.g. `apt install nodejs npm`) and build again, or set "
            "COLLIDIUM_SKIP_FRONTEND=1 to build without the viewer"
        )
    installed = frontend / "node_modules" / ".package-lock.json"
    lock = frontend / "package-lock.json"
    if not installed.is_file() or installed.stat().st_mtime < lock.stat().st_mtime:
        _run([npm, "ci", "--no-audit", "--no-fund"], frontend)
    _run([npm, "run", "build"], frontend)


def _run(command: list[str], folder: Path) -> None:
    result = subprocess.run(command, cwd=folder, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(
            f"`{' '.join(command[1:])}` failed in {folder}:\n{result.stdout}\n{result.stderr}"
        )
