"""Headless chromium for the viewer's browser tests and benchmarks (driven by Playwright)."""

from __future__ import annotations

import os
import shutil

#: Chromium's options for a headless run on a machine without a display, GPU or network
#: (WebGL through SwiftShader, no background connections).
HEADLESS_CHROMIUM_ARGS = (
    "--headless=new", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader", "--disable-background-networking",
    "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-quic",
)  # fmt: skip


def chromium_path() -> str | None:
    """The chromium binary: ``$COLLIDIUM_CHROMIUM``, else ``chromium`` on the PATH (Debian's)."""
    return os.environ.get("COLLIDIUM_CHROMIUM") or shutil.which("chromium")
