// The live viewer: builds the UI inside a root element and connects it to a transport (page
// WebSocket or Jupyter widget). Frames are drawn from requestAnimationFrame, newest first, and
// every received frame is acknowledged there, which is the server's backpressure.
import { createControls, saveTextFile } from "./controls.js";
import { createDiskRenderer, perParticle } from "./disks.js";
import { element } from "./dom.js";
import { decodeFrame } from "./frame.js";
import { createViewport } from "./geometry.js";
import { createMessageBar } from "./message.js";
import { createOverlay } from "./overlay.js";
import { createInstruments } from "./instruments.js";
import { createLegend } from "./legend.js";
import { createEnergyPlot, createSpeedPlot, createTotalSpeedPlot } from "./plots.js";
import { attachPointer } from "./pointer.js";
import { createReadouts } from "./readouts.js";
import { createTracePath } from "./trace.js";
import { createMovableWall, WALL } from "./wall.js";

/** Extra reach, in CSS pixels, around a disk when clicking on it. */
const PICK_SLACK_PX = 3;
const STARTING = "starting… (the first run on this machine compiles the simulation's kernels: up to half a minute)";
const NO_WEBGL = "WebGL is not available in this browser: the disks cannot be drawn";

/** Stands in for the disk renderer without WebGL, so plots, readouts, controls and acks go on. */
const NO_RENDERER = { setScene() {}, setColouring() {}, setMomentumShown() {}, setFrame() {}, draw() {}, destroy() {}, diskPath: null };

/** The static DOM: vessel (WebGL canvas + overlay), plots, readouts, controls, message bar. */
function buildLayout(root) {
  const particles = element("canvas", { id: "particles" });
  const overlay = element("canvas", { id: "overlay" });
  const vessel = element("div", { id: "vessel" }, [particles, overlay]);
  const energy = element("div", { id: "energy-plot", className: "plot" });
  const totalSpeed = element("div", { id: "total-speed-plot", className: "plot small-plot" });
  const speed = element("div", { id: "speed-plot", className: "plot" });
  const readouts = element("div", { className: "collidium-readouts" });
  const instruments = element("div", { id: "instruments", className: "collidium-instruments" });
  const controls = element("div", { className: "collidium-controls" });
  const message = element("div", { id: "message", role: "status", text: "connecting…" });
  const explanation = element("p", { id: "explanation", className: "explanation", hidden: true });
  root.classList.add("collidium");
  root.replaceChildren(
    vessel,
    element("div", { className: "collidium-plots" }, [instruments, energy, totalSpeed, speed]),
    readouts,
    explanation,
    controls,
    message,
  );
  return { vessel, particles, overlay, energy, totalSpeed, speed, readouts, instruments, explanation, controls, message };
}

function describeScene(scene) {
  return `${scene.name}: ${scene.n} particles in a ${scene.vessel?.description ?? "vessel"}`;
}

/** Mounts the viewer in `root`; returns `{ destroy(), hooks }` (hooks: the test hook object). */
export function mountViewer(root, transport) {
  const layout = buildLayout(root);
  const viewport = createViewport();
  const messageBar = createMessageBar(layout.message);
  const renderer = createDiskRenderer(layout.particles, viewport) ?? NO_RENDERER;
  if (renderer === NO_RENDERER) messageBar.lasting(NO_WEBGL);
  const overlay = createOverlay(layout.overlay, viewport);
  const energyPlot = createEnergyPlot(layout.energy);
  const totalSpeedPlot = createTotalSpeedPlot(layout.totalSpeed);
  const speedPlot = createSpeedPlot(layout.speed);
  const readouts = createReadouts(layout.readouts);
  const legend = createLegend(layout.vessel);
  const instruments = createInstruments(layout.instruments);
  const trace = createTracePath();
  const send = (message) => transport.send(message);
  const movableWall = createMovableWall(viewport, send);
  const report = (field, reason) => messageBar.error(field ? `${field}: ${reason}` : reason);
  const temperature = () => state.stats?.temperature ?? null;
  const controls = createControls(layout.controls, { send, report, temperature });

  const state = {
    connected: false,
    destroyed: false,
    stopped: false,
    scene: null,
    status: null,
    stats: null,
    lastError: null,
    radii: new Float32Array(0),
    charges: new Float32Array(0),
    decorated: false, // charge marks or a highlighted disk: the overlay follows every frame
    framesReceived: 0,
    framesDrawn: 0,
    pendingFrame: null, // newest accepted frame not drawn yet
    drawnFrame: null, // the frame on screen (used for picking and dragging)
    pendingAcks: [],
    drag: null, // {index, pointer: [x, y] in metres}
    draggingWall: false,
    needsRedraw: false,
    overlayDirty: false,
    rafId: 0,
    warnedSize: false,
  };

  // --- rendering ------------------------------------------------------------------------------

  function requestRender() {
    if (!state.rafId && !state.stopped) state.rafId = requestAnimationFrame(renderTick);
  }

  /** One animation frame: draw the newest frame (if any), the overlay if needed, then ack. */
  function renderTick() {
    state.rafId = 0;
    if (state.stopped) return;
    const frame = state.pendingFrame;
    if (frame) {
      state.pendingFrame = null;
      state.drawnFrame = frame;
      renderer.setFrame(frame);
      state.framesDrawn += 1;
      state.needsRedraw = true;
      if (trace.index !== null || state.drag || state.decorated) state.overlayDirty = true;
    }
    redraw();
    for (const seq of state.pendingAcks) send({ type: "ack", frame: seq });
    state.pendingAcks.length = 0;
  }

  function redraw() {
    if (state.needsRedraw) renderer.draw();
    if (state.overlayDirty) drawOverlay();
    state.needsRedraw = false;
    state.overlayDirty = false;
  }

  function particleAt(index) {
    const frame = state.drawnFrame;
    if (!frame || index === null || index >= frame.n) return null;
    return [frame.positions[2 * index], frame.positions[2 * index + 1]];
  }

  function drawOverlay() {
    const traced = particleAt(trace.index);
    const tracedAt = traced && { x: traced[0], y: traced[1], radius: state.radii[trace.index] ?? 0 };
    const dragFrom = state.drag && particleAt(state.drag.index);
    const drag = dragFrom && { from: dragFrom, to: state.drag.pointer };
    const frame = state.drawnFrame;
    const scene = state.scene;
    const marks = frame && scene?.has_charges && { positions: frame.positions, charges: state.charges, radii: state.radii, n: frame.n };
    const ringed = scene && particleAt(scene.highlight ?? null);
    const highlight = ringed && { x: ringed[0], y: ringed[1], radius: state.radii[scene.highlight] ?? 0, label: scene.highlight_label };
    const grip = movableWall.face(frame);
    overlay.draw({ marks, highlight, trace, tracedAt, drag, grip });
  }

  /** Matches both canvases to the vessel's size in device pixels and redraws at once. */
  function resizeVessel() {
    if (state.destroyed) return;
    const width = layout.vessel.clientWidth;
    const height = layout.vessel.clientHeight;
    const dpr = window.devicePixelRatio || 1;
    for (const canvas of [layout.particles, layout.overlay]) {
      canvas.width = Math.max(1, Math.round(width * dpr));
      canvas.height = Math.max(1, Math.round(height * dpr));
    }
    viewport.setCanvasSize(width, height, dpr);
    state.needsRedraw = true;
    state.overlayDirty = true;
    redraw(); // now, not next frame: resizing cleared the canvases
  }

  // --- frames ---------------------------------------------------------------------------------

  function receiveFrame(buffer) {
    state.framesReceived += 1;
    const frame = decodeFrame(buffer);
    if (frame.seq !== null) state.pendingAcks.push(frame.seq);
    if (!frame.ok) console.warn(`collidium: ignoring a frame (${frame.reason})`);
    else if (belongsToScene(frame)) acceptFrame(frame);
    requestRender();
  }

  /** Frames of an older scene are dropped (still acknowledged); so is one of the wrong size. */
  function belongsToScene(frame) {
    const scene = state.scene;
    if (!scene || frame.generation !== scene.generation) return false;
    if (frame.n === scene.n) return true;
    if (!state.warnedSize) console.warn(`collidium: frame has ${frame.n} particles, scene has ${scene.n}`);
    state.warnedSize = true;
    return false;
  }

  function acceptFrame(frame) {
    state.pendingFrame = frame;
    const index = trace.index;
    if (index !== null && index < frame.n) trace.push(frame.positions[2 * index], frame.positions[2 * index + 1]);
  }

  // --- pointer: trace and drag ----------------------------------------------------------------

  /** The movable wall (WALL) if (cssX, cssY) is on its face, else the particle whose centre is
   * nearest within its radius + a few pixels. */
  function pick(cssX, cssY) {
    const frame = state.drawnFrame;
    if (movableWall.grabs(frame, cssX, cssY)) return WALL;
    if (!frame) return null;
    const [x, y] = viewport.cssToWorld(cssX, cssY);
    const slack = PICK_SLACK_PX / viewport.pixelsPerMetre;
    const positions = frame.positions;
    let best = null;
    let bestDistance = Infinity;
    for (let i = 0; i < frame.n; i += 1) {
      const distance = Math.hypot(positions[2 * i] - x, positions[2 * i + 1] - y);
      if (distance <= state.radii[i] + slack && distance < bestDistance) {
        best = i;
        bestDistance = distance;
      }
    }
    return best;
  }

  const detachPointer = attachPointer(layout.overlay, pick, {
    onClick(index) {
      if (index !== WALL) send({ type: "trace", index });
    },
    onDrag(index, cssX, cssY) {
      if (index === WALL) {
        state.draggingWall = true;
        movableWall.drag(cssX, cssY);
        return;
      }
      state.drag = { index, pointer: viewport.cssToWorld(cssX, cssY) };
      state.overlayDirty = true;
      requestRender();
    },
    onDrop(index, cssX, cssY) {
      if (index === WALL) {
        state.draggingWall = false;
        movableWall.drop(cssX, cssY);
        return;
      }
      const centre = particleAt(index);
      const [x, y] = viewport.cssToWorld(cssX, cssY);
      // The displacement in metres is read as the new velocity in m/s.
      if (centre) send({ type: "set_velocity", index, vx: x - centre[0], vy: y - centre[1] });
      state.drag = null;
      state.overlayDirty = true;
      requestRender();
    },
    onCancel() {
      if (state.draggingWall) movableWall.cancel();
      state.draggingWall = false;
      state.drag = null;
      state.overlayDirty = true;
      requestRender();
    },
  });

  // The cursor says where the wall can be grabbed.
  function hover(event) {
    const rect = layout.overlay.getBoundingClientRect();
    const onWall = movableWall.grabs(state.drawnFrame, event.clientX - rect.left, event.clientY - rect.top);
    layout.overlay.style.cursor = onWall || state.draggingWall ? movableWall.cursor : "";
  }
  layout.overlay.addEventListener("pointermove", hover);

  // --- messages -------------------------------------------------------------------------------

  function applyScene(scene) {
    state.scene = scene;
    state.stats = null;
    state.radii = perParticle(scene.radius, scene.n | 0, 0);
    state.charges = perParticle(scene.charge, scene.n | 0, 0);
    movableWall.setScene(scene);
    state.draggingWall = false;
    state.decorated = Boolean(scene.has_charges) || Number.isInteger(scene.highlight) || movableWall.present;
    layout.explanation.textContent = scene.explanation ?? "";
    layout.explanation.hidden = !scene.explanation;
    state.pendingFrame = null;
    state.drawnFrame = null;
    state.drag = null;
    state.warnedSize = false;
    state.warnedDrift = false;
    viewport.setVessel(scene.vessel?.bounds);
    renderer.setScene(scene);
    trace.follow(null);
    energyPlot.clear();
    energyPlot.setForces(Boolean(scene.has_forces));
    totalSpeedPlot.clear();
    speedPlot.clear();
    readouts.reset(scene.n);
    instruments.reset();
    controls.setScene(scene);
    messageBar.neutral(describeScene(scene));
    messageBar.settle();
    state.needsRedraw = true;
    state.overlayDirty = true;
    requestRender();
  }

  /** Colours the disks and shows the legend as the status and the latest stats say. */
  function applyColouring() {
    const mode = state.status?.colour ?? "speed";
    const scale = state.stats?.speed_scale ?? 0;
    renderer.setColouring(mode, scale);
    renderer.setMomentumShown(Boolean(state.status?.momentum));
    legend.update(mode, state.scene, scale);
  }

  function applyStats(stats) {
    state.stats = stats;
    applyColouring();
    readouts.update(stats);
    instruments.update(stats);
    if (stats.warning && !state.warnedDrift) report("energy", stats.warning); // once a scene
    state.warnedDrift = Boolean(stats.warning);
    energyPlot.append(stats);
    totalSpeedPlot.append(stats);
    speedPlot.update(stats.histogram);
  }

  const handlers = {
    hello: (message) => controls.setHello(message),
    scene: applyScene,
    status(message) {
      const wasStarting = state.status?.phase === "starting";
      state.status = message;
      controls.setStatus(message);
      applyColouring();
      layout.vessel.classList.toggle("starting", message.phase === "starting");
      if (message.phase === "starting") messageBar.neutral(STARTING);
      else if (wasStarting && state.scene) messageBar.neutral(describeScene(state.scene));
      messageBar.settle();
    },
    stats: applyStats,
    traced(message) {
      trace.follow(Number.isInteger(message.index) ? message.index : null);
      state.overlayDirty = true;
      requestRender();
    },
    export: (message) => saveTextFile(root, message.filename, message.toml ?? ""),
    error(message) {
      state.lastError = message;
      report(message.field, message.reason ?? "error");
    },
  };

  function receiveMessage(message) {
    if (state.destroyed) return;
    const handler = handlers[message.type];
    if (!handler) return; // newer servers may send more; ignoring them keeps the page working
    try {
      handler(message);
    } catch (error) {
      console.error(`collidium: failed to handle a "${message.type}" message`, error);
    }
  }

  // --- connection -----------------------------------------------------------------------------

  transport.onOpen(() => {
    if (state.destroyed) return;
    state.connected = true;
    messageBar.neutral("connected");
    send({ type: "ready" });
  });
  transport.onMessage(receiveMessage);
  transport.onFrame((buffer) => !state.destroyed && !state.stopped && receiveFrame(buffer));
  transport.onClose(() => {
    if (state.destroyed) return;
    state.connected = false;
    stopRendering();
    messageBar.disconnected();
    controls.setEnabled(false);
  });

  function stopRendering() {
    state.stopped = true;
    if (state.rafId) cancelAnimationFrame(state.rafId);
    state.rafId = 0;
  }

  // A hidden page gets no animation frames, so drawing and acks pause and the server stops
  // advancing: intended. On return, restart the loop: every frame received meanwhile is acked
  // and the newest drawn (a fresh request, should a browser drop one made while hidden).
  const page = root.ownerDocument;
  function resumeWhenVisible() {
    if (page.visibilityState === "hidden" || state.stopped) return;
    if (state.rafId) cancelAnimationFrame(state.rafId);
    state.rafId = 0;
    state.needsRedraw = true;
    state.overlayDirty = true;
    requestRender();
  }
  page.addEventListener("visibilitychange", resumeWhenVisible);

  const resizeObserver = new ResizeObserver(resizeVessel);
  resizeObserver.observe(layout.vessel);
  window.addEventListener("resize", resizeVessel); // devicePixelRatio changes (zoom) land here
  resizeVessel();

  const hooks = {
    send,
    sendRaw: (text) => transport.sendRaw(text),
    get framesDrawn() {
      return state.framesDrawn;
    },
    get framesReceived() {
      return state.framesReceived;
    },
    get lastError() {
      return state.lastError;
    },
    get scene() {
      return state.scene;
    },
    get stats() {
      return state.stats;
    },
    get status() {
      return state.status;
    },
    /** Where the point (x, y) m is on the vessel's canvas, in CSS pixels from its corner. */
    toCanvas: (x, y) => viewport.worldToCss(x, y),
    /** The movable wall's face as drawn, [[x0, y0], [x1, y1]] m, or null. */
    get wallFace() {
      return movableWall.face(state.drawnFrame);
    },
    get pixelsPerMetre() {
      return viewport.pixelsPerMetre;
    },
    /** Particle `i` as drawn: {x, y} in m and, when the frame has them, {vx, vy} in m/s. */
    particle(i) {
      const frame = state.drawnFrame;
      if (!frame || i >= frame.n) return null;
      const at = { x: frame.positions[2 * i], y: frame.positions[2 * i + 1] };
      return frame.velocities ? { ...at, vx: frame.velocities[2 * i], vy: frame.velocities[2 * i + 1] } : at;
    },
    get energyPoints() {
      return energyPlot.points;
    },
    /** The energy plot's lines shown, by label. */
    get energyLines() {
      return energyPlot.shown;
    },
    get connected() {
      return state.connected;
    },
    /** How the disks are drawn: "points", "instanced quads", "triangles"; null without WebGL. */
    get diskPath() {
      return renderer.diskPath;
    },
  };

  function destroy() {
    if (state.destroyed) return;
    state.destroyed = true;
    state.connected = false;
    stopRendering();
    resizeObserver.disconnect();
    window.removeEventListener("resize", resizeVessel);
    page.removeEventListener("visibilitychange", resumeWhenVisible);
    detachPointer();
    layout.overlay.removeEventListener("pointermove", hover);
    movableWall.destroy();
    controls.destroy();
    messageBar.destroy();
    energyPlot.destroy();
    totalSpeedPlot.destroy();
    speedPlot.destroy();
    renderer.destroy();
    transport.close();
    root.replaceChildren();
    root.classList.remove("collidium");
  }

  return { destroy, hooks };
}
