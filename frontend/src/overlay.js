// The 2D canvas above the WebGL one: the traced particle's path and marker, and the arrow shown
// while dragging a particle to give it a new velocity. Cheap to redraw, so it is redrawn whole.

const TRACE_COLOUR = "#ff7f0e";
const DRAG_COLOUR = "#2b2b2b";
const ARROW_HEAD_PX = 9;

export function createOverlay(canvas, viewport) {
  const context = canvas.getContext("2d");

  /**
   * Draws `trace` (a trace path) with a ring around `tracedAt` = {x, y, radius} when given, and the
   * drag arrow `drag` = {from: [x, y], to: [x, y]} in metres when given.
   */
  function draw({ trace, tracedAt, drag }) {
    const dpr = viewport.pixelRatio;
    context.setTransform(dpr, 0, 0, dpr, 0, 0);
    context.clearRect(0, 0, viewport.cssWidth, viewport.cssHeight);
    if (trace && trace.length > 1) drawPath(trace);
    if (tracedAt) drawMarker(tracedAt);
    if (drag) drawArrow(drag.from, drag.to);
  }

  /** The path as one polyline, lifted where it jumps more than half the box (periodic wrap). */
  function drawPath(trace) {
    const jumpX = viewport.boxWidth / 2;
    const jumpY = viewport.boxHeight / 2;
    let lastX = 0;
    let lastY = 0;
    context.beginPath();
    trace.forEach((x, y, k) => {
      const [px, py] = viewport.worldToCss(x, y);
      const wrapped = Math.abs(x - lastX) > jumpX || Math.abs(y - lastY) > jumpY;
      if (k === 0 || wrapped) context.moveTo(px, py);
      else context.lineTo(px, py);
      lastX = x;
      lastY = y;
    });
    context.strokeStyle = TRACE_COLOUR;
    context.lineWidth = 1.5;
    context.lineJoin = "round";
    context.stroke();
  }

  function drawMarker({ x, y, radius }) {
    const [px, py] = viewport.worldToCss(x, y);
    context.beginPath();
    context.arc(px, py, radius * viewport.pixelsPerMetre + 4, 0, 2 * Math.PI);
    context.strokeStyle = TRACE_COLOUR;
    context.lineWidth = 2;
    context.stroke();
  }

  /** Arrow from the particle to the pointer, labelled with the velocity it will get. */
  function drawArrow(from, to) {
    const [x0, y0] = viewport.worldToCss(from[0], from[1]);
    const [x1, y1] = viewport.worldToCss(to[0], to[1]);
    const angle = Math.atan2(y1 - y0, x1 - x0);
    context.strokeStyle = DRAG_COLOUR;
    context.fillStyle = DRAG_COLOUR;
    context.lineWidth = 2;
    context.beginPath();
    context.moveTo(x0, y0);
    context.lineTo(x1, y1);
    context.stroke();
    context.beginPath();
    context.moveTo(x1, y1);
    context.lineTo(x1 - ARROW_HEAD_PX * Math.cos(angle - 0.4), y1 - ARROW_HEAD_PX * Math.sin(angle - 0.4));
    context.lineTo(x1 - ARROW_HEAD_PX * Math.cos(angle + 0.4), y1 - ARROW_HEAD_PX * Math.sin(angle + 0.4));
    context.closePath();
    context.fill();
    const label = `v = (${(to[0] - from[0]).toFixed(2)}, ${(to[1] - from[1]).toFixed(2)}) m/s`;
    context.font = "12px system-ui, sans-serif";
    // Keep the label inside the canvas when the pointer is near an edge.
    const labelX = Math.min(x1 + 8, viewport.cssWidth - context.measureText(label).width - 4);
    const labelY = Math.max(y1 - 8, 14);
    context.fillText(label, Math.max(4, labelX), labelY);
  }

  return { draw };
}
