// WebGL (regl) drawing of the vessel: the box, every disk in one gl.POINTS call (round sprites
// with a thin dark rim, sized from the radius) and, when the server sends velocities, one
// gl.LINES call for the momentum vectors. Buffers are reused between frames.
import createREGL from "regl";

const POSITIVE = [0xd6, 0x27, 0x28];
const NEGATIVE = [0x1f, 0x77, 0xb4];
const NEUTRAL = [0x7f, 0x7f, 0x7f];
const LETTERBOX = [0.91, 0.925, 0.945, 1];
/** Point particles (radius 0) are dots of this many CSS pixels; tiny disks never go below MIN. */
const DOT_CSS_PX = 4;
const MIN_DISK_CSS_PX = 2;
const RIM_CSS_PX = 1;
/** The median momentum vector is drawn this many typical disk diameters long. */
const MOMENTUM_DIAMETERS = 2;
const MOMENTUM_SAMPLE = 511;

const DISK_VERT = `
precision highp float;
attribute vec2 position;
attribute vec4 style; // rgb colour, radius in metres
uniform vec2 scale;
uniform float devicePixelsPerMetre, dotSize, minSize;
varying vec3 vColor;
varying float vSize;
void main() {
  float size = style.w > 0.0 ? max(2.0 * style.w * devicePixelsPerMetre, minSize) : dotSize;
  vColor = style.rgb;
  vSize = size;
  gl_PointSize = size;
  gl_Position = vec4(position * scale, 0.0, 1.0);
}`;

// Distances are in device pixels so the rim and the anti-aliased edge stay ~1 px at any size.
const DISK_FRAG = `
precision mediump float;
uniform float rimWidth;
varying vec3 vColor;
varying float vSize;
void main() {
  float edge = 0.5 * vSize;
  float r = length(2.0 * gl_PointCoord - 1.0) * edge;
  if (r > edge) discard;
  float alpha = clamp(edge - r + 0.5, 0.0, 1.0);
  float rim = smoothstep(edge - rimWidth - 0.5, edge - rimWidth + 0.5, r);
  vec3 colour = mix(vColor, vColor * 0.4, rim);
  gl_FragColor = vec4(colour * alpha, alpha);
}`;

const FLAT_VERT = `
precision highp float;
attribute vec2 position;
uniform vec2 scale, stretch;
void main() {
  gl_Position = vec4(position * stretch * scale, 0.0, 1.0);
}`;

const FLAT_FRAG = `
precision mediump float;
uniform vec4 colour;
void main() {
  gl_FragColor = colour;
}`;

/** Per-particle values of a scene field that is either one number or an array of n. */
export function perParticle(value, n, fallback) {
  const out = new Float32Array(n);
  if (Array.isArray(value)) {
    for (let i = 0; i < n; i += 1) out[i] = Number(value[i] ?? fallback);
  } else {
    out.fill(typeof value === "number" ? value : fallback);
  }
  return out;
}

function chargeColour(charge) {
  if (charge > 0) return POSITIVE;
  if (charge < 0) return NEGATIVE;
  return NEUTRAL;
}

/** Interleaved rgb + radius per particle for the `style` attribute. */
function buildStyles(radii, charges) {
  const styles = new Float32Array(4 * radii.length);
  for (let i = 0; i < radii.length; i += 1) {
    const colour = chargeColour(charges[i]);
    for (let c = 0; c < 3; c += 1) styles[4 * i + c] = colour[c] / 255;
    styles[4 * i + 3] = radii[i];
  }
  return styles;
}

/** Median of a strided sample (exact for small n): cheap enough to run every frame. */
function sampledMedian(values, scratch) {
  const stride = Math.max(1, Math.ceil(values.length / scratch.length));
  let count = 0;
  for (let i = 0; i < values.length; i += stride) scratch[count++] = values[i];
  if (count === 0) return 0;
  const sample = scratch.subarray(0, count).sort();
  return sample[count >> 1];
}

/** The renderer for `canvas`, mapping metres to pixels with `viewport`. */
export function createDiskRenderer(canvas, viewport) {
  const regl = createREGL({ canvas, attributes: { antialias: true, premultipliedAlpha: true } });
  const blend = {
    enable: true,
    func: { srcRGB: 1, srcAlpha: 1, dstRGB: "one minus src alpha", dstAlpha: "one minus src alpha" },
  };

  let capacity = 0;
  let count = 0;
  let lineVertices = 0;
  let masses = new Float32Array(0);
  let typicalRadius = 0;
  let lineData = new Float32Array(0);
  let momenta = new Float32Array(0);
  const medianScratch = new Float32Array(MOMENTUM_SAMPLE);
  const positionBuffer = regl.buffer({ usage: "dynamic", type: "float", length: 8 });
  const styleBuffer = regl.buffer({ usage: "static", type: "float", length: 16 });
  const lineBuffer = regl.buffer({ usage: "dynamic", type: "float", length: 16 });
  // Unit square corners, stretched to the box by a uniform.
  const boxFill = regl.buffer([[-0.5, -0.5], [0.5, -0.5], [-0.5, 0.5], [0.5, 0.5]]);
  const boxOutline = regl.buffer([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]);

  const drawDisks = regl({
    vert: DISK_VERT,
    frag: DISK_FRAG,
    primitive: "points",
    attributes: { position: positionBuffer, style: styleBuffer },
    uniforms: {
      scale: regl.prop("scale"),
      devicePixelsPerMetre: regl.prop("devicePixelsPerMetre"),
      dotSize: regl.prop("dotSize"),
      minSize: regl.prop("minSize"),
      rimWidth: regl.prop("rimWidth"),
    },
    count: regl.prop("count"),
    blend,
    depth: { enable: false },
  });

  const drawFlat = regl({
    vert: FLAT_VERT,
    frag: FLAT_FRAG,
    primitive: regl.prop("primitive"),
    attributes: { position: regl.prop("positions") },
    uniforms: {
      scale: regl.prop("scale"),
      stretch: regl.prop("stretch"),
      colour: regl.prop("colour"),
    },
    count: regl.prop("count"),
    blend,
    depth: { enable: false },
  });

  let boundary = "reflecting";

  /** Prepares the per-particle buffers for a new scene; nothing is drawn until a frame comes. */
  function setScene(scene) {
    const n = scene.n | 0;
    const radii = perParticle(scene.radius, n, 0);
    masses = perParticle(scene.mass, n, 1);
    typicalRadius = sampledMedian(radii, medianScratch);
    boundary = scene.box?.boundary ?? "reflecting";
    styleBuffer({ usage: "static", type: "float", data: buildStyles(radii, perParticle(scene.charge, n, 0)) });
    if (n !== capacity) reallocate(n);
    count = 0;
    lineVertices = 0;
  }

  function reallocate(n) {
    capacity = n;
    const slots = Math.max(1, n);
    positionBuffer({ usage: "dynamic", type: "float", length: 8 * slots });
    lineBuffer({ usage: "dynamic", type: "float", length: 16 * slots });
    lineData = new Float32Array(4 * slots);
    momenta = new Float32Array(slots);
  }

  /** Uploads a decoded frame (its n must be the scene's). */
  function setFrame(frame) {
    if (frame.n !== capacity) return;
    positionBuffer.subdata(frame.positions);
    count = frame.n;
    lineVertices = frame.velocities ? buildMomentumLines(frame.positions, frame.velocities, frame.n) : 0;
  }

  /** Segments centre -> centre + s * m v, with s making the median |m v| a couple of diameters. */
  function buildMomentumLines(positions, velocities, n) {
    for (let i = 0; i < n; i += 1) {
      momenta[i] = masses[i] * Math.hypot(velocities[2 * i], velocities[2 * i + 1]);
    }
    const median = sampledMedian(momenta.subarray(0, n), medianScratch);
    const diameter = typicalRadius > 0 ? 2 * typicalRadius : DOT_CSS_PX / viewport.pixelsPerMetre;
    const scale = median > 0 ? (MOMENTUM_DIAMETERS * diameter) / median : 0;
    for (let i = 0; i < n; i += 1) {
      const x = positions[2 * i];
      const y = positions[2 * i + 1];
      const k = scale * masses[i];
      lineData[4 * i] = x;
      lineData[4 * i + 1] = y;
      lineData[4 * i + 2] = x + k * velocities[2 * i];
      lineData[4 * i + 3] = y + k * velocities[2 * i + 1];
    }
    lineBuffer.subdata(lineData.subarray(0, 4 * n));
    return 2 * n;
  }

  /** Redraws everything with the current buffers and viewport (call after a frame or resize). */
  function draw() {
    regl.poll(); // picks up canvas size changes for the viewport
    regl.clear({ color: LETTERBOX });
    const scale = viewport.clipScale();
    const stretch = [viewport.boxWidth, viewport.boxHeight];
    const dpr = viewport.pixelRatio;
    drawFlat({ primitive: "triangle strip", positions: boxFill, count: 4, scale, stretch, colour: [1, 1, 1, 1] });
    const outline = boundary === "periodic" ? [0.62, 0.62, 0.62, 1] : [0.2, 0.2, 0.2, 1];
    drawFlat({ primitive: "line loop", positions: boxOutline, count: 4, scale, stretch, colour: outline });
    if (count > 0) {
      drawDisks({
        count,
        scale,
        devicePixelsPerMetre: viewport.pixelsPerMetre * dpr,
        dotSize: DOT_CSS_PX * dpr,
        minSize: MIN_DISK_CSS_PX * dpr,
        rimWidth: RIM_CSS_PX * dpr,
      });
    }
    if (lineVertices > 0) {
      drawFlat({ primitive: "lines", positions: lineBuffer, count: lineVertices, scale, stretch: [1, 1], colour: [0.13, 0.13, 0.13, 0.85] });
    }
  }

  return { setScene, setFrame, draw, destroy: () => regl.destroy() };
}
