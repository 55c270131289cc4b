// Decodes the server's binary frames: a 32-byte little-endian header ("CLD1", n, flags, seq,
// time, generation, reserved) followed by float32 positions and, if flagged, velocities and the
// piston's face (x0 y0 x1 y1).

export const HEADER_BYTES = 32;
export const FLAG_VELOCITIES = 1;
export const FLAG_PISTON = 2;
const MAGIC = "CLD1";

/**
 * Returns `{ ok: true, n, seq, time, generation, positions, velocities, piston }` (typed-array views on
 * `buffer`, no copy) or `{ ok: false, reason, seq }`; `seq` is kept when the header is readable so
 * the caller can still acknowledge the frame and the server does not lose a credit.
 */
export function decodeFrame(buffer) {
  if (!(buffer instanceof ArrayBuffer) || buffer.byteLength < HEADER_BYTES) {
    return { ok: false, reason: "frame shorter than its header", seq: null };
  }
  const view = new DataView(buffer);
  if (readMagic(view) !== MAGIC) return { ok: false, reason: "bad magic", seq: null };

  const n = view.getUint32(4, true);
  const flags = view.getUint32(8, true);
  const seq = view.getUint32(12, true);
  const hasVelocities = (flags & FLAG_VELOCITIES) !== 0;
  const hasPiston = (flags & FLAG_PISTON) !== 0;
  const particleBytes = n * 8 * (hasVelocities ? 2 : 1);
  const expected = HEADER_BYTES + particleBytes + (hasPiston ? 16 : 0);
  if (buffer.byteLength !== expected) {
    return { ok: false, reason: `length ${buffer.byteLength}, expected ${expected}`, seq };
  }
  return {
    ok: true,
    n,
    seq,
    time: view.getFloat64(16, true),
    generation: view.getUint32(24, true),
    positions: new Float32Array(buffer, HEADER_BYTES, 2 * n),
    velocities: hasVelocities ? new Float32Array(buffer, HEADER_BYTES + 8 * n, 2 * n) : null,
    piston: hasPiston ? new Float32Array(buffer, HEADER_BYTES + particleBytes, 4) : null,
  };
}

function readMagic(view) {
  let text = "";
  for (let i = 0; i < 4; i += 1) text += String.fromCharCode(view.getUint8(i));
  return text;
}
