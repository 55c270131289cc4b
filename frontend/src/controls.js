// The control panel: scene (preset and overrides), run (play, step, speed, reset, heat, cool),
// toggles and files. Controls send protocol messages; the server's status/scene set their state.
import { element, labelled } from "./dom.js";
import { formatValue } from "./readouts.js";

const SPEED_STEPS = 1000;
const SPEED_SEND_INTERVAL_MS = 100;
const HEAT_FACTOR = 1.25;
const COOL_FACTOR = 0.8;
const COLLISION_MODES = ["exact", "step", "off"];

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

/** The scene overrides the panel offers, when the selected preset takes them. */
const OVERRIDES = [
  { name: "n", label: "N", parse: (text) => (/^\s*\d+\s*$/.test(text) ? Number(text) : NaN) },
  { name: "dt", label: "dt (s)", parse: (text) => (text.trim() === "" ? NaN : Number(text)) },
  { name: "k", label: "k (N m²/C²)", parse: (text) => (text.trim() === "" ? NaN : Number(text)) },
  { name: "collisions", label: "collision mode", parse: (text) => text },
];

function overrideInput(name) {
  if (name === "collisions") {
    return element("select", { id: "set-collisions" }, COLLISION_MODES.map((mode) => element("option", { value: mode, text: mode })));
  }
  const integer = name === "n";
  const min = name === "k" ? undefined : "0";
  return element("input", { id: `set-${name}`, type: "number", step: integer ? "1" : "any", min, inputmode: integer ? "numeric" : "decimal" });
}

function checkbox(id, text) {
  const input = element("input", { id, type: "checkbox" });
  return { input, label: element("label", { className: "toggle" }, [input, element("span", { text })]) };
}

/**
 * Builds the panel in `container`. `send(message)` sends to the server; `report(field, reason)`
 * shows a problem found before sending. Returns setters for hello, scene and status.
 */
export function createControls(container, { send, report }) {
  let presets = new Map();
  let speedLimits = [0.01, 100];
  let maxMessageBytes = Infinity;
  let playing = false;
  let sliderHeld = false;

  // Scene: preset, its overrides, Apply.
  const presetSelect = element("select", { id: "preset", title: "preset" });
  const overrideFields = OVERRIDES.map((spec) => {
    const input = overrideInput(spec.name);
    return { spec, input, field: labelled(spec.label, input, "field override") };
  });
  const applyButton = element("button", { id: "apply", type: "button", text: "Apply" });

  // Run: play/pause, step, speed, reset, heat, cool.
  const playButton = element("button", { id: "play", type: "button", className: "primary", text: "Play" });
  const stepButton = element("button", { id: "step", type: "button", text: "Step" });
  const speedSlider = element("input", { id: "speed", type: "range", min: "0", max: String(SPEED_STEPS), step: "1" });
  const speedValue = element("span", { id: "speed-value", className: "speed-value", text: speedLabel(1) });
  const resetButton = element("button", { id: "reset", type: "button", text: "Reset" });
  const heatButton = element("button", { id: "heat", type: "button", text: "Heat", title: "kinetic energy × 1.25" });
  const coolButton = element("button", { id: "cool", type: "button", text: "Cool", title: "kinetic energy × 0.8" });

  // Display and physics toggles.
  const collisionsToggle = checkbox("toggle-collisions", "collisions");
  const chargesToggle = checkbox("toggle-charges", "charges");
  const momentumToggle = checkbox("toggle-momentum", "momentum vectors");

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
      ...overrideFields.map((entry) => entry.field),
      applyButton,
    ]),
    element("div", { className: "control-group run-group" }, [
      playButton,
      stepButton,
      element("label", { className: "field speed" }, [element("span", { text: "speed" }), speedSlider, speedValue]),
      resetButton,
      heatButton,
      coolButton,
    ]),
    element("div", { className: "control-group toggle-group" }, [
      collisionsToggle.label,
      chargesToggle.label,
      momentumToggle.label,
    ]),
    element("div", { className: "control-group file-group" }, [downloadButton, openLabel]),
  );

  // --- helpers --------------------------------------------------------------------------------

  function defaultsOf(name) {
    return presets.get(name)?.parameters ?? {};
  }

  /** Shows the overrides `preset` takes, filled with its defaults overlaid by `current`. */
  function fillOverrides(preset, current = {}) {
    const defaults = defaultsOf(preset);
    for (const { spec, input, field } of overrideFields) {
      const taken = preset !== null && spec.name in defaults;
      field.hidden = !taken;
      if (taken) input.value = String(current[spec.name] ?? defaults[spec.name]);
    }
    applyButton.hidden = !overrideFields.some(({ field }) => !field.hidden);
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
    const defaults = defaultsOf(presetSelect.value);
    const overrides = {};
    for (const { spec, input, field } of overrideFields) {
      if (field.hidden) continue;
      const value = spec.parse(input.value);
      if (typeof value === "number" && !Number.isFinite(value)) {
        report(spec.name, `"${input.value}" is not a valid number`);
        return null;
      }
      if (value !== defaults[spec.name]) overrides[spec.name] = value;
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
  chargesToggle.input.addEventListener("change", toggleSender(chargesToggle.input, "charges"));
  momentumToggle.input.addEventListener("change", toggleSender(momentumToggle.input, "momentum"));
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
      if (typeof limits.max_particles === "number") overrideFields[0].input.max = String(limits.max_particles);
      fillOverrides(null);
    },
    /** Reflects the scene: its preset and overrides; charges can only be toggled if it has any. */
    setScene(scene) {
      selectPreset(scene.preset ?? null);
      fillOverrides(scene.preset ?? null, scene.overrides ?? {});
      chargesToggle.input.disabled = !scene.has_charges;
      chargesToggle.label.classList.toggle("disabled", !scene.has_charges);
    },
    /** Reflects the server's status (the slider only when the user is not holding it). */
    setStatus(status) {
      playing = Boolean(status.playing);
      playButton.textContent = playing ? "Pause" : "Play";
      stepButton.disabled = playing;
      collisionsToggle.input.checked = Boolean(status.collisions);
      chargesToggle.input.checked = Boolean(status.charges);
      momentumToggle.input.checked = Boolean(status.momentum);
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
