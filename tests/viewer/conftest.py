"""Fixtures of the browser tests: a viewer server on a free port, and Debian's chromium driven
by Playwright (``.ci/run`` installs it; ``COLLIDIUM_CHROMIUM`` names another binary)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from collidium.presets import preset
from collidium.viewer.server import create_app, running
from collidium.viewer.session import ViewerSession
from collidium.viewer.testing import HEADLESS_CHROMIUM_ARGS, chromium_path


@pytest.fixture(scope="session")
def artifacts() -> Path:
    """Folder where the tests leave files worth looking at (the page's screenshot)."""
    folder = Path(__file__).resolve().parents[2] / "test-artifacts"
    folder.mkdir(exist_ok=True)
    return folder


@pytest.fixture(scope="session")
def browser() -> Iterator[object]:
    from playwright.sync_api import sync_playwright

    path = chromium_path()
    if path is None:  # a failure, never a skip: CI installs it
        pytest.fail("the viewer's browser tests need chromium: apt-get install chromium")
    with sync_playwright() as playwright:
        launched = playwright.chromium.launch(
            executable_path=path, args=list(HEADLESS_CHROMIUM_ARGS)
        )
        yield launched
        launched.close()


@pytest.fixture(scope="module")
def viewer_url() -> Iterator[str]:
    app = create_app(lambda: ViewerSession(preset("gas"), preset="gas"))
    with running(app) as url:
        yield url


@pytest.fixture
def page(browser, viewer_url) -> Iterator[object]:
    context = browser.new_context(viewport={"width": 1280, "height": 800}, accept_downloads=True)
    opened = context.new_page()
    problems: list[str] = []
    opened.on("pageerror", lambda error: problems.append(str(error)))
    opened.on(
        "console",
        lambda message: problems.append(message.text) if message.type == "error" else None,
    )
    opened.goto(viewer_url)
    opened.wait_for_function("window.collidiumViewer && window.collidiumViewer.framesDrawn > 2")
    yield opened
    context.close()
    assert problems == [], problems
