// The wall a user may drag to change the volume (the scene's `movable_wall`: a box's piston or
// one of its walls): where its face is now, whether the pointer is on it, and the `move_wall`
// messages of a drag, throttled (the server moves the wall towards the last one it got).

/** The pointer grabs the wall within this many CSS pixels of its face. */
const GRAB_PX = 8;
/** At most one `move_wall` message this often while dragging, ms. */
const SEND_EVERY_MS = 60;
/** What `pick` returns for the wall (a particle's pick is its index). */
export const WALL = "wall";

export function createMovableWall(viewport, send) {
  let wall = null; // the scene's movable_wall: {name, axis, rest, low, high}
  let bounds = null; // the vessel's bounding box, [[xmin, ymin], [xmax, ymax]] m
  let lastSent = -Infinity;
  let timer = 0;
  let latest = null;

  function setScene(scene) {
    wall = scene.movable_wall ?? null;
    bounds = scene.vessel?.bounds ?? null;
    clearTimeout(timer);
    timer = 0;
  }

  /** The face now, [[x0, y0], [x1, y1]] m: the frame's piston where there is one, else the wall
   * where it rests; null without a movable wall. */
  function face(frame) {
    if (!wall || !bounds) return null;
    if (frame?.piston) {
      const p = frame.piston;
      return [[p[0], p[1]], [p[2], p[3]]];
    }
    const [[x0, y0], [x1, y1]] = bounds;
    return wall.axis === 0 ? [[wall.rest, y0], [wall.rest, y1]] : [[x0, wall.rest], [x1, wall.rest]];
  }

  /** Whether (cssX, cssY) is on the face drawn in `frame`. */
  function grabs(frame, cssX, cssY) {
    const line = face(frame);
    if (!line) return false;
    const [a, b] = line.map(([x, y]) => viewport.worldToCss(x, y));
    const along = wall.axis === 0 ? 0 : 1;
    const across = 1 - along;
    const point = [cssX, cssY];
    const [lo, hi] = [Math.min(a[across], b[across]), Math.max(a[across], b[across])];
    return Math.abs(point[along] - a[along]) <= GRAB_PX && point[across] >= lo && point[across] <= hi;
  }

  function flush() {
    timer = 0;
    if (latest === null) return;
    send({ type: "move_wall", to: latest });
    lastSent = performance.now();
    latest = null;
  }

  /** The pointer, dragging the wall, is at (cssX, cssY): the wall is sent there. */
  function drag(cssX, cssY) {
    if (!wall) return;
    latest = viewport.cssToWorld(cssX, cssY)[wall.axis];
    const wait = lastSent + SEND_EVERY_MS - performance.now();
    if (wait <= 0) flush();
    else if (!timer) timer = setTimeout(flush, wait);
  }

  /** Let go: a free piston moves freely again (a box's wall goes on to the last place sent). */
  function release() {
    clearTimeout(timer);
    timer = 0;
    send({ type: "move_wall", to: null });
  }

  /** Released at (cssX, cssY): the last place is sent, then the wall is let go. */
  function drop(cssX, cssY) {
    if (!wall) return;
    latest = viewport.cssToWorld(cssX, cssY)[wall.axis];
    flush();
    release();
  }

  return {
    setScene,
    face,
    grabs,
    drag,
    drop,
    /** The drag was abandoned (the pointer was lost): the wall is let go where it is headed. */
    cancel: release,
    /** The cursor over the face: a resize arrow along its axis. */
    get cursor() {
      return wall?.axis === 1 ? "ns-resize" : "ew-resize";
    },
    get present() {
      return wall !== null;
    },
    destroy: () => clearTimeout(timer),
  };
}
