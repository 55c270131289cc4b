// Pointer interaction on the vessel: a click traces the particle under the pointer (or stops
// tracing on empty space); pressing on a particle and moving at least 5 px drags out a velocity.

const DRAG_THRESHOLD_PX = 5;

/**
 * Wires pointer events on `target`. `pick(cssX, cssY)` gives the particle index there or null;
 * `callbacks` get: onClick(index|null), onDrag(index, cssX, cssY) while dragging,
 * onDrop(index, cssX, cssY) on release and onCancel() when a drag is abandoned.
 * Returns a function that removes the listeners.
 */
export function attachPointer(target, pick, callbacks) {
  let press = null; // {id, x, y, index, dragging}

  const local = (event) => {
    const rect = target.getBoundingClientRect();
    return [event.clientX - rect.left, event.clientY - rect.top];
  };

  function down(event) {
    if (event.button !== 0 || press) return;
    const [x, y] = local(event);
    press = { id: event.pointerId, x, y, index: pick(x, y), dragging: false };
    target.setPointerCapture?.(event.pointerId);
  }

  function move(event) {
    if (!press || event.pointerId !== press.id) return;
    const [x, y] = local(event);
    if (!press.dragging && press.index !== null && Math.hypot(x - press.x, y - press.y) >= DRAG_THRESHOLD_PX) {
      press.dragging = true;
    }
    if (press.dragging) callbacks.onDrag(press.index, x, y);
  }

  function up(event) {
    if (!press || event.pointerId !== press.id) return;
    const [x, y] = local(event);
    const { index, dragging } = press;
    const moved = Math.hypot(x - press.x, y - press.y) >= DRAG_THRESHOLD_PX;
    press = null;
    if (dragging) callbacks.onDrop(index, x, y);
    else if (!moved) callbacks.onClick(index); // a drag over empty space does nothing
  }

  function cancel(event) {
    if (!press || event.pointerId !== press.id) return;
    const wasDragging = press.dragging;
    press = null;
    if (wasDragging) callbacks.onCancel();
  }

  const listeners = { pointerdown: down, pointermove: move, pointerup: up, pointercancel: cancel };
  for (const [name, listener] of Object.entries(listeners)) target.addEventListener(name, listener);
  return () => {
    for (const [name, listener] of Object.entries(listeners)) target.removeEventListener(name, listener);
  };
}
