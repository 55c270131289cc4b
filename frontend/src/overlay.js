// The 2D canvas above the WebGL one: the traced particle's path and marker, and the arrow shown
// while dragging a particle to give it a new velocity, charge marks, the highlighted disk and the
// grip on a wall that can be dragged. Cheap to redraw, so it is redrawn whole.

const TRACE_COLOUR = "#ff7f0e";
const HIGHLIGHT_COLOUR = "#e6a700";
/** Charge marks are drawn on disks at least this many CSS pixels in radius, and on few disks. */
const MARK_MIN_RADIUS_PX = 5;
const MARK_MOST_DISKS = 5000;
const DRAG_COLOUR = "#2b2b2b";
const ARROW_HEAD_PX = 9;
const GRIP_COLOUR = "#8a5a2b";
/** The grip on a movable wall: its length and thickness, CSS pixels. */
const GRIP_LENGTH_PX = 30;
const GRIP_WIDTH_PX = 7;

export function createOverlay(canvas, viewport) {
  const context = canvas.getContext("2d");

  /**
   * Draws the + and - `marks` = {positions, charges, radii, n} on charged disks, the highlighted
   * disk `highlight` = {x, y, radius, label}, `trace` (a trace path) with a ring around
   * `tracedAt` = {x, y, radius}, the drag arrow `drag` = {from: [x, y], to: [x, y]} in metres,
   * and a grip on the middle of the movable wall's face `grip` = [[x0, y0], [x1, y1]] m, each
   * when given.
   */
  function draw({ marks, highlight, trace, tracedAt, drag, grip }) {
    const dpr = viewport.pixelRatio;
    context.setTransform(dpr, 0, 0, dpr, 0, 0);
    context.clearRect(0, 0, viewport.cssWidth, viewport.cssHeight);
    if (marks) drawMarks(marks);
    if (highlight) drawHighlight(highlight);
    if (trace && trace.length > 1) drawPath(trace);
    if (tracedAt) drawMarker(tracedAt);
    if (drag) drawArrow(drag.from, drag.to);
    if (grip) drawGrip(grip);
  }

  /** A bar along the face's middle, with ridges across it: "this can be dragged". */
  function drawGrip([[x0, y0], [x1, y1]]) {
    const [a, b] = [viewport.worldToCss(x0, y0), viewport.worldToCss(x1, y1)];
    const [cx, cy] = [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2];
    const vertical = Math.abs(b[1] - a[1]) > Math.abs(b[0] - a[0]);
    const [w, h] = vertical ? [GRIP_WIDTH_PX, GRIP_LENGTH_PX] : [GRIP_LENGTH_PX, GRIP_WIDTH_PX];
    context.fillStyle = GRIP_COLOUR;
    context.fillRect(cx - w / 2, cy - h / 2, w, h);
    context.strokeStyle = "#fff";
    context.lineWidth = 1;
    context.beginPath();
    for (const offset of [-6, 0, 6]) {
      if (vertical) {
        context.moveTo(cx - w / 2 + 1, cy + offset);
        context.lineTo(cx + w / 2 - 1, cy + offset);
      } else {
        context.moveTo(cx + offset, cy - h / 2 + 1);
        context.lineTo(cx + offset, cy + h / 2 - 1);
      }
    }
    context.stroke();
  }

  /** A white + or - across each charged disk large enough to carry one. */
  function drawMarks({ positions, charges, radii, n }) {
    if (n > MARK_MOST_DISKS) return;
    context.strokeStyle = "#fff";
    context.lineCap = "round";
    context.beginPath();
    for (let i = 0; i < n; i += 1) {
      const size = radii[i] * viewport.pixelsPerMetre;
      if (charges[i] === 0 || size < MARK_MIN_RADIUS_PX) continue;
      const [px, py] = viewport.worldToCss(positions[2 * i], positions[2 * i + 1]);
      const arm = 0.6 * size;
      context.moveTo(px - arm, py);
      context.lineTo(px + arm, py);
      if (charges[i] > 0) {
        context.moveTo(px, py - arm);
        context.lineTo(px, py + arm);
      }
    }
    context.lineWidth = 1.5;
    context.stroke();
  }

  function drawHighlight({ x, y, radius, label }) {
    const [px, py] = viewport.worldToCss(x, y);
    const ring = radius * viewport.pixelsPerMetre + 5;
    context.beginPath();
    context.arc(px, py, ring, 0, 2 * Math.PI);
    context.strokeStyle = HIGHLIGHT_COLOUR;
    context.lineWidth = 3;
    context.stroke();
    if (label) {
      context.font = "bold 12px system-ui, sans-serif";
      context.fillStyle = "#6b4e00";
      context.fillText(label, Math.min(px + ring + 3, viewport.cssWidth - context.measureText(label).width - 4), Math.max(py - ring, 14));
    }
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
