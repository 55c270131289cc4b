// The traced particle's recent path: a ring buffer of its last positions (metres), filled from
// every frame while a particle is traced and emptied on a new trace or scene.

export const TRACE_LENGTH = 2000;

export function createTracePath(capacity = TRACE_LENGTH) {
  const xs = new Float64Array(capacity);
  const ys = new Float64Array(capacity);
  let start = 0;
  let length = 0;

  return {
    /** Index of the traced particle, or null. */
    index: null,
    get length() {
      return length;
    },
    /** Starts tracing `index` (or stops, with null) with an empty path. */
    follow(index) {
      this.index = index;
      this.clear();
    },
    clear() {
      start = 0;
      length = 0;
    },
    /** Appends a position, dropping the oldest once full. */
    push(x, y) {
      const slot = (start + length) % capacity;
      xs[slot] = x;
      ys[slot] = y;
      if (length < capacity) length += 1;
      else start = (start + 1) % capacity;
    },
    /** Calls `visit(x, y, k)` for the positions, oldest first. */
    forEach(visit) {
      for (let k = 0; k < length; k += 1) {
        const slot = (start + k) % capacity;
        visit(xs[slot], ys[slot], k);
      }
    },
  };
}
