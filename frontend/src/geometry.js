// The vessel's world <-> screen mapping: the smallest box centred on the origin (y up) that holds
// the vessel's bounding box is letterboxed into the canvas with its aspect ratio kept and a 2 px
// margin, so the outline stays visible.

const MARGIN_CSS_PX = 2;

/** A mutable viewport; `setVessel` and `setCanvasSize` update it, the rest read it. */
export function createViewport() {
  const view = {
    boxWidth: 20,
    boxHeight: 20,
    cssWidth: 1,
    cssHeight: 1,
    pixelRatio: 1,
    /** CSS pixels per metre. */
    pixelsPerMetre: 1,
  };

  function update() {
    const usableWidth = Math.max(1, view.cssWidth - 2 * MARGIN_CSS_PX);
    const usableHeight = Math.max(1, view.cssHeight - 2 * MARGIN_CSS_PX);
    view.pixelsPerMetre = Math.max(1e-9, Math.min(usableWidth / view.boxWidth, usableHeight / view.boxHeight));
  }

  /** Fits the view to `bounds`, the vessel's bounding box `[[xmin, ymin], [xmax, ymax]]` (m). */
  view.setVessel = (bounds) => {
    const [[x0, y0], [x1, y1]] = Array.isArray(bounds) ? bounds : [[-0.5, -0.5], [0.5, 0.5]];
    const width = 2 * Math.max(Math.abs(x0), Math.abs(x1));
    const height = 2 * Math.max(Math.abs(y0), Math.abs(y1));
    view.boxWidth = width > 0 ? width : 1;
    view.boxHeight = height > 0 ? height : 1;
    update();
  };
  view.setCanvasSize = (cssWidth, cssHeight, pixelRatio) => {
    view.cssWidth = Math.max(1, cssWidth);
    view.cssHeight = Math.max(1, cssHeight);
    view.pixelRatio = pixelRatio || 1;
    update();
  };
  view.worldToCss = (x, y) => [
    view.cssWidth / 2 + x * view.pixelsPerMetre,
    view.cssHeight / 2 - y * view.pixelsPerMetre,
  ];
  view.cssToWorld = (px, py) => [
    (px - view.cssWidth / 2) / view.pixelsPerMetre,
    (view.cssHeight / 2 - py) / view.pixelsPerMetre,
  ];
  /** World metres -> clip space is a pure scale because both are centred. */
  view.clipScale = () => [
    (2 * view.pixelsPerMetre) / view.cssWidth,
    (2 * view.pixelsPerMetre) / view.cssHeight,
  ];
  return view;
}
