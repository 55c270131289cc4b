"""The live viewer: the seed's window in a browser (``collidium view``) and in Jupyter (`Widget`).

One JavaScript front end (``frontend/`` in the repository, bundled into ``static/`` when the
package is built) draws the disks with regl and the plots with uPlot. It talks to a
`ViewerSession` through the messages of `collidium.viewer.protocol`: over a websocket served by
`collidium.viewer.server`, or as the custom messages of the anywidget `Widget`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from collidium.viewer.session import ViewerSession

if TYPE_CHECKING:
    from collidium.viewer.widget import Widget

__all__ = ["ViewerSession", "Widget"]


def __getattr__(name: str) -> Any:
    if name == "Widget":  # anywidget is an extra: import it only when asked for
        try:
            from collidium.viewer.widget import Widget
        except ModuleNotFoundError as exc:
            raise ImportError(
                f"collidium.viewer.Widget needs {exc.name}: pip install 'collidium[jupyter]'"
            ) from None
        return Widget
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
