"""Build hook: bundle the viewer's front end (``frontend/``) into the package with npm.

``pip install .`` from a clone, every wheel and every sdist get ``src/collidium/viewer/static/
{app,widget}.{js,css}``, built by esbuild from the sources and the locked npm dependencies
(regl, uPlot); the bundles are build outputs, never committed. They are rebuilt only when
missing or older than a source, so a wheel built from an sdist needs no Node.js. Building from a
clone needs Node.js (>= 18) and npm; ``COLLIDIUM_SKIP_FRONTEND=1`` builds without the viewer
(``collidium view`` then says the front end is missing).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

from hatchling.builders.hooks.plugin.interface import BuildHookInterface

BUNDLES = ("app.js", "app.css", "widget.js", "widget.css")


class FrontEndBuildHook(BuildHookInterface):  # type: ignore[type-arg]
    """Runs ``npm ci`` and ``npm run build`` in ``frontend/`` before a wheel or sdist is made."""

    PLUGIN_NAME = "custom"

    def initialize(self, version: str, build_data: dict[str, Any]) -> None:
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
