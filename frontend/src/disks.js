// WebGL (regl) drawing of the vessel: its outline, every disk in one draw call (round gl.POINTS
// sprites with a thin dark rim, sized from the radius; quads when a disk is larger than the GPU's
// point size limit) and, when the server sends velocities, one gl.LINES call for the momentum
// vectors. Buffers are reused between frames.
import createREGL from "regl";

export const POSITIVE = [0xd6, 0x27, 0x28];
export const NEGATIVE = [0x1f, 0x77, 0xb4];
export const NEUTRAL = [0x7f, 0x7f, 0x7f];
/** Species colours (matplotlib's tab10), in the order of the scene's species labels. */
export const SPECIES_PALETTE = [
  [0x1f, 0x77, 0xb4], [0xff, 0x7f, 0x0e], [0x2c, 0xa0, 0x2c], [0xd6, 0x27, 0x28], [0x94, 0x67, 0xbd],
  [0x8c, 0x56, 0x4b], [0xe3, 0x77, 0xc2], [0x7f, 0x7f, 0x7f], [0xbc, 0xbd, 0x22], [0x17, 0xbe, 0xcf],
];
/** Viridis at nine evenly spaced stops, for colour by speed (0 to the scene's speed scale). */
export const SPEED_STOPS = [
  [68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141],
  [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37],
];
const LETTERBOX = [0.91, 0.925, 0.945, 1];
/** Point particles (radius 0) are dots of this many CSS pixels; tiny disks never go below MIN. */
const DOT_CSS_PX = 4;
const MIN_DISK_CSS_PX = 2;
const RIM_CSS_PX = 1;
/** The median momentum vector is drawn this many typical disk diameters long. */
const MOMENTUM_DIAMETERS = 2;
const MOMENTUM_SAMPLE = 511;
/** A momentum arrow's head: its barbs' length (a third of the arrow, at most this many CSS
 * pixels) and their angle to the shaft. */
const ARROW_HEAD_CSS_PX = 7;
const ARROW_HEAD_ANGLE = 0.45;
/** Vertices per momentum arrow (gl.LINES): the shaft and two barbs. */
const ARROW_VERTICES = 6;

/** Quads and point sprites reach this many device pixels past the disk's edge, so the
 * anti-aliased edge pixels are always covered and both drawing paths shade the same pixels. */
const EDGE_PAD_PX = 1;

// The size of a disk in device pixels, shared by both vertex shaders.
const DISK_SIZE = `
uniform float devicePixelsPerMetre, dotSize, minSize;
float diskSize(vec4 style) {
  return style.w > 0.0 ? max(2.0 * style.w * devicePixelsPerMetre, minSize) : dotSize;
}`;

// Fast path: one gl.POINTS sprite per disk (its size is capped by ALIASED_POINT_SIZE_RANGE).
const POINT_VERT = `
precision highp float;
attribute vec2 position;
attribute vec4 style; // rgb colour, radius in metres
uniform vec2 scale;
varying vec3 vColor;
varying float vSize;
${DISK_SIZE}
void main() {
  float size = diskSize(style);
  vColor = style.rgb;
  vSize = size;
  gl_PointSize = size + ${(2 * EDGE_PAD_PX).toFixed(1)};
  gl_Position = vec4(position * scale, 0.0, 1.0);
}`;

// Large disks: a quad per disk (instanced, or two triangles); `corner` spans [-1, 1]².
const QUAD_VERT = `
precision highp float;
attribute vec2 corner;
attribute vec2 position;
attribute vec4 style;
uniform vec2 scale, clipPerPixel;
varying vec3 vColor;
varying float vSize;
varying vec2 vOffset;
${DISK_SIZE}
void main() {
  float size = diskSize(style);
  vColor = style.rgb;
  vSize = size;
  vOffset = corner * (0.5 * size + ${EDGE_PAD_PX.toFixed(1)});
  gl_Position = vec4(position * scale + vOffset * clipPerPixel, 0.0, 1.0);
}`;

// Distances are in device pixels so the rim and the anti-aliased edge stay ~1 px at any size.
// highp where available: mediump (fp16 on some GPUs) is too coarse across a 500 px disk.
const DISK_SHADE = `
#ifdef GL_FRAGMENT_PRECISION_HIGH
precision highp float;
#else
precision mediump float;
#endif
uniform float rimWidth;
varying vec3 vColor;
varying float vSize;
// The disk's colour (premultiplied) r device pixels from its centre.
vec4 shade(float r) {
  float edge = 0.5 * vSize;
  float alpha = clamp(edge - r + 0.5, 0.0, 1.0); // anti-aliased across the last pixel
  if (alpha <= 0.0) discard; // not at r > edge: a jump there makes rounding show as speckles
  float rim = smoothstep(edge - rimWidth - 0.5, edge - rimWidth + 0.5, r);
  vec3 colour = mix(vColor, vColor * 0.4, rim);
  return vec4(colour * alpha, alpha);
}`;

const POINT_FRAG = `${DISK_SHADE}
void main() {
  gl_FragColor = shade(length(2.0 * gl_PointCoord - 1.0) * (0.5 * vSize + ${EDGE_PAD_PX.toFixed(1)}));
}`;

const QUAD_FRAG = `${DISK_SHADE}
varying vec2 vOffset;
void main() {
  gl_FragColor = shade(length(vOffset));
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

/** Writes colour `rgb` (0-255) of particle `i` into the interleaved rgb + radius `styles`. */
function setColour(styles, i, rgb) {
  for (let c = 0; c < 3; c += 1) styles[4 * i + c] = rgb[c] / 255;
}

/** Colours every particle by charge or species (speed colours come with each frame). */
function colourStatic(styles, mode, charges, species) {
  const n = charges.length;
  for (let i = 0; i < n; i += 1) {
    const rgb = mode === "species" ? SPECIES_PALETTE[species[i] % SPECIES_PALETTE.length] : mode === "charge" ? chargeColour(charges[i]) : NEUTRAL;
    setColour(styles, i, rgb);
  }
}

/** Colours every particle by its speed as a fraction of `scale` (m/s). */
function colourBySpeed(styles, velocities, n, scale) {
  const steps = SPEED_STOPS.length - 1;
  for (let i = 0; i < n; i += 1) {
    const fraction = Math.hypot(velocities[2 * i], velocities[2 * i + 1]) / scale;
    const at = Math.min(1, fraction) * steps;
    const low = Math.min(Math.floor(at), steps - 1);
    const t = at - low;
    const a = SPEED_STOPS[low];
    const b = SPEED_STOPS[low + 1];
    for (let c = 0; c < 3; c += 1) styles[4 * i + c] = (a[c] + t * (b[c] - a[c])) / 255;
  }
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

/** A regl instance on `canvas`, or null where WebGL cannot be created (never throws). */
function createContext(canvas) {
  const warn = (error) => console.warn("collidium: WebGL is not available", error);
  try {
    return createREGL({
      canvas,
      attributes: { antialias: true, premultipliedAlpha: true, stencil: true },
      optionalExtensions: ["ANGLE_instanced_arrays"],
      onDone: (error) => error && warn(error), // regl's default onDone throws
    });
  } catch (error) {
    warn(error);
    return null;
  }
}

/** Frees `regl`'s resources and its WebGL context at once, rather than when it is collected. */
function destroyContext(regl) {
  const gl = regl._gl;
  regl.destroy();
  // Browsers keep only ~16 live contexts; re-rendered notebook widgets would use them all up.
  gl.getExtension("WEBGL_lose_context")?.loseContext();
}

const STRIP_CORNERS = [[-1, -1], [1, -1], [-1, 1], [1, 1]];
const TRIANGLE_CORNERS = [-1, -1, 1, -1, -1, 1, -1, 1, 1, -1, 1, 1];
const TRIANGLE_VERTICES = TRIANGLE_CORNERS.length / 2;

/** Copies `width` floats per item of `source` into `target`, each repeated `times` times. */
function repeatEach(source, width, n, times, target) {
  for (let i = 0; i < n; i += 1) {
    for (let v = 0; v < times; v += 1) {
      for (let c = 0; c < width; c += 1) target[(times * i + v) * width + c] = source[width * i + c];
    }
  }
}

/**
 * Quads without instancing (ANGLE_instanced_arrays missing): two triangles per disk, its
 * attributes repeated per vertex into reused arrays. Only re-expands what changed.
 */
function createTriangleQuads(regl) {
  const empty = () => regl.buffer({ usage: "dynamic", type: "float", length: 16 });
  const attributes = { corner: empty(), position: empty(), style: empty() };
  let capacity = 0;
  let positionData = new Float32Array(0);
  let styleData = new Float32Array(0);
  let uploaded = { positions: null, styles: -1 };

  function reserve(n) {
    if (n <= capacity) return;
    capacity = n;
    positionData = new Float32Array(2 * TRIANGLE_VERTICES * n);
    styleData = new Float32Array(4 * TRIANGLE_VERTICES * n);
    const corners = new Float32Array(TRIANGLE_CORNERS.length * n);
    for (let i = 0; i < n; i += 1) corners.set(TRIANGLE_CORNERS, TRIANGLE_CORNERS.length * i);
    attributes.corner({ usage: "static", type: "float", data: corners });
    uploaded = { positions: null, styles: -1 };
  }

  /** Makes the buffers hold `n` disks of `positions` (compared by identity) and `styles` (by
   * `stylesVersion`, bumped at each recolouring). */
  function update(positions, styles, stylesVersion, n) {
    reserve(n);
    if (stylesVersion !== uploaded.styles) {
      repeatEach(styles, 4, n, TRIANGLE_VERTICES, styleData);
      attributes.style({ usage: "static", type: "float", data: styleData.subarray(0, 4 * TRIANGLE_VERTICES * n) });
    }
    if (positions !== uploaded.positions) {
      repeatEach(positions, 2, n, TRIANGLE_VERTICES, positionData);
      attributes.position({ usage: "dynamic", type: "float", data: positionData.subarray(0, 2 * TRIANGLE_VERTICES * n) });
    }
    uploaded = { positions, styles: stylesVersion };
  }

  return { attributes, update };
}

/**
 * The renderer for `canvas`, mapping metres to pixels with `viewport`, or null where WebGL is not
 * available.
 */
export function createDiskRenderer(canvas, viewport) {
  const regl = createContext(canvas);
  if (!regl) return null;
  const blend = {
    enable: true,
    func: { srcRGB: 1, srcAlpha: 1, dstRGB: "one minus src alpha", dstAlpha: "one minus src alpha" },
  };
  // gl.POINTS sprites are clamped to this size (often 255-511 px on real GPUs); queried once.
  const maxPointSize = regl.limits.pointSizeDims[1];
  const instanced = regl.hasExtension("ANGLE_instanced_arrays");

  let capacity = 0;
  let count = 0;
  let lineVertices = 0;
  let masses = new Float32Array(0);
  let styles = new Float32Array(0);
  let stylesVersion = 0;
  let charges = new Float32Array(0);
  let species = new Float32Array(0);
  let colourMode = "speed";
  let momentumShown = false;
  let speedScale = 0;
  let shownPositions = new Float32Array(0); // the last frame's, for the triangle quads
  let typicalRadius = 0;
  let largestRadius = 0;
  let lineData = new Float32Array(0);
  let momenta = new Float32Array(0);
  let diskPath = "points";
  const medianScratch = new Float32Array(MOMENTUM_SAMPLE);
  const positionBuffer = regl.buffer({ usage: "dynamic", type: "float", length: 8 });
  const styleBuffer = regl.buffer({ usage: "dynamic", type: "float", length: 16 });
  const lineBuffer = regl.buffer({ usage: "dynamic", type: "float", length: 16 });
  // The vessel as the server sends it (m): its outline, stroked as a loop; the triangles that
  // fill it (any simple shape, convex or not); its partitions, stroked as separate lines.
  const vesselOutline = regl.buffer({ usage: "static", type: "float", length: 8 });
  const vesselFill = regl.buffer({ usage: "static", type: "float", length: 8 });
  const vesselPartitions = regl.buffer({ usage: "static", type: "float", length: 8 });
  // A piston's face, sent with every frame where it is now.
  const pistonBuffer = regl.buffer({ usage: "dynamic", type: "float", length: 16 });
  let pistonShown = false;
  let outlineCorners = 0;
  let fillVertices = 0;
  let partitionVertices = 0;

  const diskUniforms = {
    scale: regl.prop("scale"),
    devicePixelsPerMetre: regl.prop("devicePixelsPerMetre"),
    dotSize: regl.prop("dotSize"),
    minSize: regl.prop("minSize"),
    rimWidth: regl.prop("rimWidth"),
  };
  const quadUniforms = {
    ...diskUniforms,
    clipPerPixel: ({ viewportWidth, viewportHeight }) => [2 / viewportWidth, 2 / viewportHeight],
  };
  const diskState = { blend, depth: { enable: false } };

  const drawPoints = regl({
    ...diskState,
    vert: POINT_VERT,
    frag: POINT_FRAG,
    primitive: "points",
    attributes: { position: positionBuffer, style: styleBuffer },
    uniforms: diskUniforms,
    count: regl.prop("count"),
  });

  // A unit quad per disk, the disk's attributes advancing once per instance (divisor 1).
  const drawInstancedQuads =
    instanced &&
    regl({
      ...diskState,
      vert: QUAD_VERT,
      frag: QUAD_FRAG,
      primitive: "triangle strip",
      attributes: {
        corner: regl.buffer(STRIP_CORNERS),
        position: { buffer: positionBuffer, divisor: 1 },
        style: { buffer: styleBuffer, divisor: 1 },
      },
      uniforms: quadUniforms,
      count: STRIP_CORNERS.length,
      instances: regl.prop("count"),
    });

  const triangles = instanced ? null : createTriangleQuads(regl);
  const drawTriangleQuads =
    triangles &&
    regl({
      ...diskState,
      vert: QUAD_VERT,
      frag: QUAD_FRAG,
      primitive: "triangles",
      attributes: triangles.attributes,
      uniforms: quadUniforms,
      count: (context, props) => TRIANGLE_VERTICES * props.count,
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

  const stencilled = (stencil, colorMask = [true, true, true, true]) => regl({
    vert: FLAT_VERT,
    frag: FLAT_FRAG,
    primitive: regl.prop("primitive"),
    attributes: { position: regl.prop("positions") },
    uniforms: { scale: regl.prop("scale"), stretch: regl.prop("stretch"), colour: regl.prop("colour") },
    count: regl.prop("count"),
    blend,
    depth: { enable: false },
    stencil,
    colorMask,
  });
  // The vessel's triangles set the stencil to 1 (nothing drawn); then lines drawn only there.
  const markVesselStencil = stencilled({
    enable: true,
    mask: 0xff,
    func: { cmp: "always", ref: 1, mask: 0xff },
    op: { fail: "replace", zfail: "replace", zpass: "replace" },
  }, [false, false, false, false]);
  const markVessel = (props) => markVesselStencil({ ...props, primitive: "triangles", colour: [0, 0, 0, 0] });
  const drawInVessel = stencilled({ enable: true, mask: 0, func: { cmp: "equal", ref: 1, mask: 0xff } });

  let periodic = false;

  /** Fills a static buffer with points nested `depth` levels in arrays ([x, y] at depth 1,
   * [[x, y], ...] at 2), or one dummy point; returns how many points it holds. */
  function loadPoints(buffer, nested, depth) {
    const flat = Array.isArray(nested) ? nested.flat(depth) : [];
    buffer({ usage: "static", type: "float", data: flat.length ? flat : [0, 0] });
    return flat.length / 2;
  }

  /** Prepares the per-particle buffers for a new scene; nothing is drawn until a frame comes. */
  function setScene(scene) {
    const n = scene.n | 0;
    const radii = perParticle(scene.radius, n, 0);
    masses = perParticle(scene.mass, n, 1);
    typicalRadius = sampledMedian(radii, medianScratch);
    largestRadius = radii.reduce((most, radius) => Math.max(most, radius), 0);
    periodic = Boolean(scene.vessel?.periodic);
    outlineCorners = loadPoints(vesselOutline, scene.vessel?.outline, 1);
    fillVertices = loadPoints(vesselFill, scene.vessel?.fill, 2);
    partitionVertices = loadPoints(vesselPartitions, scene.vessel?.partition_lines, 2);
    charges = perParticle(scene.charge, n, 0);
    species = perParticle(scene.species, n, 0);
    styles = new Float32Array(4 * n);
    for (let i = 0; i < n; i += 1) styles[4 * i + 3] = radii[i];
    colourStatic(styles, colourMode, charges, species);
    uploadStyles();
    if (n !== capacity) reallocate(n);
    count = 0;
    lineVertices = 0;
    pistonShown = false;
  }

  function uploadStyles() {
    styleBuffer({ usage: "dynamic", type: "float", data: styles });
    stylesVersion += 1;
  }

  /** Colours by "speed" (from each frame's velocities, `scale` m/s at the top of the colormap),
   * "charge" or "species". */
  function setColouring(mode, scale) {
    if (Number.isFinite(scale) && scale > 0) speedScale = scale;
    if (mode === colourMode) return;
    colourMode = mode;
    colourStatic(styles, mode, charges, species);
    uploadStyles();
  }

  function reallocate(n) {
    capacity = n;
    const slots = Math.max(1, n);
    positionBuffer({ usage: "dynamic", type: "float", length: 8 * slots });
    lineBuffer({ usage: "dynamic", type: "float", length: 8 * ARROW_VERTICES * slots });
    lineData = new Float32Array(2 * ARROW_VERTICES * slots);
    momenta = new Float32Array(slots);
  }

  /** Uploads a decoded frame (its n must be the scene's). */
  function setFrame(frame) {
    if (frame.n !== capacity) return;
    positionBuffer.subdata(frame.positions);
    shownPositions = frame.positions;
    count = frame.n;
    pistonShown = Boolean(frame.piston);
    if (pistonShown) pistonBuffer.subdata(frame.piston);
    lineVertices = frame.velocities && momentumShown ? buildMomentumLines(frame.positions, frame.velocities, frame.n) : 0;
    if (colourMode === "speed" && frame.velocities && speedScale > 0) {
      colourBySpeed(styles, frame.velocities, frame.n, speedScale);
      uploadStyles();
    }
  }

  /** Arrows centre -> centre + s * m v, with s making the median |m v| a couple of diameters:
   * a shaft and two barbs each (gl.LINES). */
  function buildMomentumLines(positions, velocities, n) {
    for (let i = 0; i < n; i += 1) {
      momenta[i] = masses[i] * Math.hypot(velocities[2 * i], velocities[2 * i + 1]);
    }
    const median = sampledMedian(momenta.subarray(0, n), medianScratch);
    const diameter = typicalRadius > 0 ? 2 * typicalRadius : DOT_CSS_PX / viewport.pixelsPerMetre;
    const scale = median > 0 ? (MOMENTUM_DIAMETERS * diameter) / median : 0;
    const longestBarb = ARROW_HEAD_CSS_PX / viewport.pixelsPerMetre;
    const [cos, sin] = [Math.cos(ARROW_HEAD_ANGLE), Math.sin(ARROW_HEAD_ANGLE)];
    for (let i = 0; i < n; i += 1) {
      const x = positions[2 * i];
      const y = positions[2 * i + 1];
      const dx = scale * masses[i] * velocities[2 * i];
      const dy = scale * masses[i] * velocities[2 * i + 1];
      // A barb is the shaft turned back by +-ARROW_HEAD_ANGLE, shortened to `barb`.
      const length = Math.hypot(dx, dy);
      const barb = length > 0 ? Math.min(length / 3, longestBarb) / length : 0;
      const [bx, by] = [-barb * dx, -barb * dy];
      const [tipX, tipY] = [x + dx, y + dy];
      lineData.set([x, y, tipX, tipY,
        tipX, tipY, tipX + cos * bx - sin * by, tipY + sin * bx + cos * by,
        tipX, tipY, tipX + cos * bx + sin * by, tipY - sin * bx + cos * by], 2 * ARROW_VERTICES * i);
    }
    lineBuffer.subdata(lineData.subarray(0, 2 * ARROW_VERTICES * n));
    return ARROW_VERTICES * n;
  }

  /** Redraws everything with the current buffers and viewport (call after a frame or resize). */
  function draw() {
    regl.poll(); // picks up canvas size changes for the viewport
    regl.clear({ color: LETTERBOX, stencil: 0 });
    const scale = viewport.clipScale();
    const stretch = [1, 1];
    const dpr = viewport.pixelRatio;
    if (fillVertices > 2) {
      const fill = { positions: vesselFill, count: fillVertices, scale, stretch };
      drawFlat({ primitive: "triangles", ...fill, colour: [1, 1, 1, 1] });
    }
    if (outlineCorners > 2) {
      const corners = { positions: vesselOutline, count: outlineCorners, scale, stretch };
      const outline = periodic ? [0.62, 0.62, 0.62, 1] : [0.2, 0.2, 0.2, 1];
      drawFlat({ primitive: "line loop", ...corners, colour: outline });
    }
    if (partitionVertices > 1) {
      const walls = { positions: vesselPartitions, count: partitionVertices, scale, stretch };
      drawFlat({ primitive: "lines", ...walls, colour: [0.2, 0.2, 0.2, 1] });
    }
    if (pistonShown) {
      const face = { positions: pistonBuffer, count: 2, scale, stretch };
      drawFlat({ primitive: "lines", ...face, colour: [0.45, 0.25, 0.1, 1] });
    }
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
      // Clipped to the vessel: its fill marks the stencil, the arrows are drawn where it is set.
      const clipped = fillVertices > 2;
      if (clipped) markVessel({ positions: vesselFill, count: fillVertices, scale, stretch });
      const arrows = { primitive: "lines", positions: lineBuffer, count: lineVertices, scale, stretch };
      (clipped ? drawInVessel : drawFlat)({ ...arrows, colour: [0.13, 0.13, 0.13, 0.85] });
    }
  }

  /** Points while the largest disk fits the point size limit (most scenes), else quads. */
  function drawDisks(props) {
    const largest = Math.max(2 * largestRadius * props.devicePixelsPerMetre, props.minSize, props.dotSize);
    if (largest + 2 * EDGE_PAD_PX <= maxPointSize) {
      diskPath = "points";
      drawPoints(props);
    } else if (drawInstancedQuads) {
      diskPath = "instanced quads";
      drawInstancedQuads(props);
    } else {
      diskPath = "triangles";
      triangles.update(shownPositions, styles, stylesVersion, count);
      drawTriangleQuads(props);
    }
  }

  return {
    setScene,
    setColouring,
    /** Whether the momentum vectors are drawn (from the next frame with velocities). */
    setMomentumShown(shown) {
      momentumShown = shown;
    },
    setFrame,
    draw,
    destroy: () => destroyContext(regl),
    /** How the disks were last drawn: "points", "instanced quads" or "triangles". */
    get diskPath() {
      return diskPath;
    },
  };
}
