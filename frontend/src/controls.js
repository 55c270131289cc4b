// The control panel: scene (preset and overrides), run (play, step, speed, reset, heat, cool),
// toggles and files. Controls send protocol messages; the server's status/scene set their state.
import { element, labelled } from "./dom.js";
import { formatValue } from "./readouts.js";

const SPEED_STEPS = 1000;
const SPEED_SEND_INTERVAL_MS = 100;
const HEAT_FACTOR = 1.25;
const COOL_FACTOR = 0.8;

// ---------------------------------------------------------------------------------------------
// Files

/** Saves `text` as a download named `filename` (Blob + temporary <a download>). */
export function saveTextFile(parent, filename, text) {
  const url = URL.createObjectURL(new Blob([text], { type: "application/toml" }));
  const link = element("a", { href: url, download: filename || "scenario.toml", hidden: true });
  parent.append(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000); // revoking at once can abort the download
}

// ---------------------------------------------------------------------------------------------
// Speed slider (logarithmic)

function speedFromSlider(position, [low, high]) {
  const speed = low * (high / low) ** (position / SPEED_STEPS);
  return Number(speed.toPrecision(3));
}

function sliderFromSpeed(speed, [low, high]) {
  const fraction = Math.log(speed / low) / Math.log(high / low);
  return Math.round(SPEED_STEPS * Math.min(1, Math.max(0, fraction)));
}

const speedLabel = (speed) => `${formatValue(speed)}×`;

/** Calls `send(value)` at most every `interval` ms, always sending the last value. */
function throttle(send, interval) {
  let last = 0;
  let timer = null;
  let pending;
  const flush = () => {
    timer = null;
    last = Date.now();
    send(pending);
  };
  const call = (value) => {
    pending = value;
    if (timer !== null) return;
    const wait = last + interval - Date.now();
    if (wait <= 0) flush();
    else timer = setTimeout(flush, wait);
  };
  call.cancel = () => clearTimeout(timer);
  return call;
}

// ---------------------------------------------------------------------------------------------
// Control panel

/** Holding "heat" or "cool" keeps the walls at this many times the gas's kT. */
const HOLD_FACTORS = { heat: 2, cool: 0.5 };
/** Readouts the speed histogram may be averaged over. */
const HISTOGRAM_WINDOWS = [1, 5, 20, 50];
const COLOUR_LABELS = { speed: "speed", charge: "charge", species: "species" };

/** Reads a parameter field as its kind says: a number (NaN when not one), a word or a flag. */
function parseParameter(spec, input) {
  if (spec.kind === "boolean") return input.checked;
  if (spec.kind === "choice") return input.value;
  const text = input.value.trim();
  if (spec.kind === "integer") return /^[-+]?\d+$/.test(text) ? Number(text) : NaN;
  return text === "" ? NaN : Number(text);
}

/** The input of one preset parameter, built from the server's description of it. */
function parameterInput(spec) {
  const id = `set-${spec.name}`;
  if (spec.kind === "choice") {
    return element("select", { id }, (spec.choices ?? []).map((choice) => element("option", { value: choice, text: choice })));
  }
  if (spec.kind === "boolean") return element("input", { id, type: "checkbox" });
  const integer = spec.kind === "integer";
  return element("input", { id, type: "number", step: integer ? "1" : "any", inputmode: integer ? "numeric" : "decimal" });
}

function parameterLabel(spec) {
  return spec.unit ? `${spec.label} (${spec.unit})` : spec.label;
}

function checkbox(id, text) {
  const input = element("input", { id, type: "checkbox" });
  return { input, label: element("label", { className: "toggle" }, [input, element("span", { text })]) };
}

/**
 * Builds the panel in `container`. `send(message)` sends to the server; `report(field, reason)`
 * shows a problem found before sending. Returns setters for hello, scene and status.
 */
export function createControls(container, { send, report, temperature }) {
  let presets = new Map();
  let overrideFields = [];
  let maxParticles = Infinity;
  let speedLimits = [0.01, 100];
  let maxMessageBytes = Infinity;
  let playing = false;
  let sliderHeld = false;

  // Scene: preset, its overrides, Apply.
  const presetSelect = element("select", { id: "preset", title: "preset" });
  const overrideBox = element("span", { className: "overrides" });
  const applyButton = element("button", { id: "apply", type: "button", text: "Apply" });

  // Run: play/pause, step, speed, reset, heat, cool.
  const playButton = element("button", { id: "play", type: "button", className: "primary", text: "Play" });
  const stepButton = element("button", { id: "step", type: "button", text: "Step" });
  const speedSlider = element("input", { id: "speed", type: "range", min: "0", max: String(SPEED_STEPS), step: "1" });
  const speedValue = element("span", { id: "speed-value", className: "speed-value", text: speedLabel(1) });
  const resetButton = element("button", { id: "reset", type: "button", text: "Reset" });
  const heatButton = element("button", { id: "heat", type: "button", text: "Heat", title: "kinetic energy × 1.25" });
  const coolButton = element("button", { id: "cool", type: "button", text: "Cool", title: "kinetic energy × 0.8" });
  const holdHeatButton = element("button", { id: "hold-heat", type: "button", text: "Hold: hot walls", title: "while held, the walls are at twice the gas's kT" });
  const holdCoolButton = element("button", { id: "hold-cool", type: "button", text: "Hold: cold walls", title: "while held, the walls are at half the gas's kT" });
  const histogramSelect = element("select", { id: "histogram-window", title: "average the speed histogram over the last readouts" },
    HISTOGRAM_WINDOWS.map((count) => element("option", { value: String(count), text: count === 1 ? "now" : `last ${count}` })));

  // Display and physics toggles.
  const collisionsToggle = checkbox("toggle-collisions", "collisions");
  const forcesToggle = checkbox("toggle-forces", "forces");
  const momentumToggle = checkbox("toggle-momentum", "momentum vectors");
  const colourSelect = element("select", { id: "colour", title: "colour the disks by" });

  // Pump: particles in through the hatch (the middle of the first wall) or out.
  const pumpCount = element("input", { id: "pump-count", type: "number", step: "1", min: "1", max: "100", value: "10", inputmode: "numeric" });
  const pumpTemperature = element("input", { id: "pump-temperature", type: "number", step: "any", min: "0", placeholder: "gas's", inputmode: "decimal" });
  const pumpInButton = element("button", { id: "pump-in", type: "button", text: "Pump in", title: "let particles in through the hatch in the middle of the first wall" });
  const pumpOutButton = element("button", { id: "pump-out", type: "button", text: "Let out", title: "let out the particles nearest the hatch" });

  // Files.
  const downloadButton = element("button", { id: "download", type: "button", text: "Download TOML" });
  const openInput = element("input", { id: "open-scenario", type: "file", accept: ".toml", className: "file-input" });
  const openLabel = element("label", { className: "button-like", title: "load a scenario TOML file" }, [
    "Open scenario…",
    openInput,
  ]);

  speedSlider.value = String(sliderFromSpeed(1, speedLimits));
  container.append(
    element("div", { className: "control-group scene-group" }, [
      labelled("preset", presetSelect),
      overrideBox,
      applyButton,
    ]),
    element("div", { className: "control-group run-group" }, [
      playButton,
      stepButton,
      element("label", { className: "field speed" }, [element("span", { text: "speed" }), speedSlider, speedValue]),
      resetButton,
      heatButton,
      coolButton,
      holdHeatButton,
      holdCoolButton,
    ]),
    element("div", { className: "control-group toggle-group" }, [
      collisionsToggle.label,
      forcesToggle.label,
      momentumToggle.label,
      labelled("colour by", colourSelect),
      labelled("histogram", histogramSelect),
    ]),
    element("div", { className: "control-group pump-group" }, [
      labelled("particles", pumpCount),
      labelled("at kT (J)", pumpTemperature),
      pumpInButton,
      pumpOutButton,
    ]),
    element("div", { className: "control-group file-group" }, [downloadButton, openLabel]),
  );

  // --- helpers --------------------------------------------------------------------------------

  /** Shows the parameters `preset` takes (as the server describes them), filled with their
   * defaults overlaid by `current`. */
  function fillOverrides(preset, current = {}) {
    const specs = presets.get(preset)?.parameters ?? [];
    overrideFields = specs.map((spec) => {
      const input = parameterInput(spec);
      const value = current[spec.name] ?? spec.default;
      if (spec.kind === "boolean") input.checked = Boolean(value);
      else input.value = String(value);
      if (spec.name === "n") input.max = String(maxParticles);
      return { spec, input, field: labelled(parameterLabel(spec), input, "field override") };
    });
    overrideBox.replaceChildren(...overrideFields.map((entry) => entry.field));
    applyButton.hidden = overrideFields.length === 0;
  }

  /** Selects `preset` in the list, or a placeholder for a scenario opened from a file. */
  function selectPreset(preset) {
    let custom = presetSelect.querySelector("option[data-custom]");
    if (preset === null || !presets.has(preset)) {
      if (!custom) {
        custom = element("option", { value: "", text: "(custom scenario)", disabled: true, "data-custom": "" });
        presetSelect.prepend(custom);
      }
      presetSelect.value = "";
    } else {
      custom?.remove();
      presetSelect.value = preset;
    }
  }

  /** The overrides that differ from the preset's defaults, or null after reporting a bad input. */
  function changedOverrides() {
    const overrides = {};
    for (const { spec, input } of overrideFields) {
      const value = parseParameter(spec, input);
      if (typeof value === "number" && !Number.isFinite(value)) {
        const what = spec.kind === "integer" ? "a whole number" : "a number";
        report(spec.name, `"${input.value}" is not ${what}`);
        return null;
      }
      if (value !== spec.default) overrides[spec.name] = value;
    }
    return overrides;
  }

  async function openScenario() {
    const file = openInput.files?.[0];
    openInput.value = ""; // so choosing the same file again fires "change"
    if (!file) return;
    const toml = await file.text();
    const size = new TextEncoder().encode(JSON.stringify({ type: "scenario", toml })).length;
    if (size > maxMessageBytes) report("scenario", `${file.name} is too large (${size} bytes, limit ${maxMessageBytes})`);
    else send({ type: "scenario", toml });
  }

  const sendSpeed = throttle((value) => send({ type: "speed", value }), SPEED_SEND_INTERVAL_MS);
  const toggleSender = (input, type) => () => send({ type, enabled: input.checked });

  // --- events ---------------------------------------------------------------------------------

  presetSelect.addEventListener("change", () => {
    fillOverrides(presetSelect.value);
    send({ type: "load", preset: presetSelect.value, overrides: {} });
  });
  applyButton.addEventListener("click", () => {
    const overrides = changedOverrides();
    if (overrides) send({ type: "load", preset: presetSelect.value, overrides });
  });
  playButton.addEventListener("click", () => send({ type: playing ? "pause" : "play" }));
  stepButton.addEventListener("click", () => send({ type: "step" }));
  speedSlider.addEventListener("pointerdown", () => (sliderHeld = true));
  speedSlider.addEventListener("input", () => {
    const speed = speedFromSlider(Number(speedSlider.value), speedLimits);
    speedValue.textContent = speedLabel(speed);
    sendSpeed(speed);
  });
  for (const name of ["pointerup", "pointercancel", "change"]) {
    speedSlider.addEventListener(name, () => (sliderHeld = false));
  }
  resetButton.addEventListener("click", () => send({ type: "reset" }));
  heatButton.addEventListener("click", () => send({ type: "heat", factor: HEAT_FACTOR }));
  coolButton.addEventListener("click", () => send({ type: "heat", factor: COOL_FACTOR }));
  collisionsToggle.input.addEventListener("change", toggleSender(collisionsToggle.input, "collisions"));
  forcesToggle.input.addEventListener("change", toggleSender(forcesToggle.input, "forces"));
  momentumToggle.input.addEventListener("change", toggleSender(momentumToggle.input, "momentum"));
  let holding = false;
  function hold(kind) {
    const kT = temperature();
    if (!(kT > 0)) {
      report("temperature", "the gas has no temperature to hold the walls near; give a disk a velocity first");
      return;
    }
    holding = true;
    send({ type: "wall_temperature", temperature: HOLD_FACTORS[kind] * kT });
  }
  function release() {
    if (holding) send({ type: "wall_temperature", temperature: null });
    holding = false;
  }
  for (const [button, kind] of [[holdHeatButton, "heat"], [holdCoolButton, "cool"]]) {
    button.addEventListener("pointerdown", () => hold(kind));
    for (const name of ["pointerup", "pointerleave", "pointercancel"]) button.addEventListener(name, release);
  }
  function pump(sign) {
    const count = Number(pumpCount.value);
    if (!Number.isInteger(count) || count < 1 || count > 100) {
      report("count", `"${pumpCount.value}" is not a whole number from 1 to 100`);
      return;
    }
    const text = pumpTemperature.value.trim();
    const temperature = text === "" ? null : Number(text);
    if (temperature !== null && !(temperature > 0)) {
      report("temperature", `"${text}" is not a temperature > 0`);
      return;
    }
    send({ type: "pump", count: sign * count, temperature });
  }
  pumpInButton.addEventListener("click", () => pump(1));
  pumpOutButton.addEventListener("click", () => pump(-1));
  histogramSelect.addEventListener("change", () => send({ type: "histogram_window", readouts: Number(histogramSelect.value) }));
  colourSelect.addEventListener("change", () => send({ type: "colour", mode: colourSelect.value }));
  downloadButton.addEventListener("click", () => send({ type: "export" }));
  openInput.addEventListener("change", () => openScenario().catch((error) => report("scenario", String(error))));

  return {
    /** Fills the preset list and takes the limits. */
    setHello(hello) {
      presets = new Map((hello.presets ?? []).map((preset) => [preset.name, preset]));
      presetSelect.replaceChildren(
        ...[...presets.values()].map((preset) =>
          element("option", { value: preset.name, text: preset.name, title: preset.description ?? "" }),
        ),
      );
      const limits = hello.limits ?? {};
      if (Array.isArray(limits.speed) && limits.speed[0] > 0 && limits.speed[1] > limits.speed[0]) {
        speedLimits = limits.speed;
      }
      if (typeof limits.max_message_bytes === "number") maxMessageBytes = limits.max_message_bytes;
      if (typeof limits.max_particles === "number") maxParticles = limits.max_particles;
      fillOverrides(null);
    },
    /** Reflects the scene: its preset and overrides; forces can only be toggled if it has any. */
    setScene(scene) {
      selectPreset(scene.preset ?? null);
      fillOverrides(scene.preset ?? null, scene.overrides ?? {});
      forcesToggle.input.disabled = !scene.has_forces;
      forcesToggle.label.classList.toggle("disabled", !scene.has_forces);
      const modes = Array.isArray(scene.colour_modes) ? scene.colour_modes : ["speed"];
      colourSelect.replaceChildren(...modes.map((mode) => element("option", { value: mode, text: COLOUR_LABELS[mode] ?? mode })));
      colourSelect.disabled = modes.length < 2;
    },
    /** Reflects the server's status (the slider only when the user is not holding it). */
    setStatus(status) {
      playing = Boolean(status.playing);
      playButton.textContent = playing ? "Pause" : "Play";
      stepButton.disabled = playing;
      collisionsToggle.input.checked = Boolean(status.collisions);
      forcesToggle.input.checked = Boolean(status.forces);
      momentumToggle.input.checked = Boolean(status.momentum);
      if (typeof status.colour === "string") colourSelect.value = status.colour;
      if (typeof status.histogram_window === "number") histogramSelect.value = String(status.histogram_window);
      const held = typeof status.wall_temperature === "number";
      holdHeatButton.classList.toggle("held", held && holding);
      holdCoolButton.classList.toggle("held", held && holding);
      for (const button of [holdHeatButton, holdCoolButton, pumpInButton, pumpOutButton]) button.disabled = status.has_walls === false;
      if (typeof status.speed === "number" && status.speed > 0 && !sliderHeld) {
        speedSlider.value = String(sliderFromSpeed(status.speed, speedLimits));
        speedValue.textContent = speedLabel(status.speed);
      }
    },
    /** Disables everything (after the connection closes). */
    setEnabled(enabled) {
      for (const control of container.querySelectorAll("button, input, select")) control.disabled = !enabled;
    },
    destroy: () => sendSpeed.cancel(),
  };
}
