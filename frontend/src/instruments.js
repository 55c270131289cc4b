// The instruments a class reads: a thermometer (kT now, its column, and its recent history), a
// pressure gauge (the window's pressure with its standard error as a band), the particle count,
// the piston's position, and the picked disk's speed and energy. Drawn on small 2D canvases.
import { element } from "./dom.js";
import { formatValue } from "./readouts.js";

/** Readouts of kT kept for the thermometer's history. */
const HISTORY = 120;
const THERMOMETER_RED = "#d62728";
const GAUGE_BLUE = "#1f77b4";

/** 1, 2 or 5 times a power of ten at or above `value` (the instruments' full scale). */
export function niceScale(value) {
  if (!(value > 0) || !Number.isFinite(value)) return 1;
  const power = 10 ** Math.floor(Math.log10(value));
  return [1, 2, 5, 10].map((m) => m * power).find((step) => step >= value * (1 - 1e-12));
}

function canvas(id, width, height) {
  return element("canvas", { id, width: String(width), height: String(height), style: `width: ${width}px; height: ${height}px` });
}

/** Sharp drawing on `node` (CSS size `width` x `height`) at the device's pixel ratio. */
function context2d(node, width, height) {
  const dpr = window.devicePixelRatio || 1;
  node.width = Math.round(width * dpr);
  node.height = Math.round(height * dpr);
  const context = node.getContext("2d");
  context.setTransform(dpr, 0, 0, dpr, 0, 0);
  context.clearRect(0, 0, width, height);
  context.font = "11px system-ui, sans-serif";
  return context;
}

function drawThermometer(node, history, full) {
  const width = 190;
  const height = 86;
  const context = context2d(node, width, height);
  const bulbX = 14;
  const top = 8;
  const bottom = height - 16;
  const level = history.length ? history[history.length - 1] : null;
  // The glass and the column.
  context.strokeStyle = "#5c6470";
  context.lineWidth = 1;
  context.strokeRect(bulbX - 4, top, 8, bottom - top);
  context.beginPath();
  context.arc(bulbX, bottom + 6, 7, 0, 2 * Math.PI);
  context.fillStyle = THERMOMETER_RED;
  context.fill();
  if (level !== null) {
    const y = bottom - (Math.min(level, full) / full) * (bottom - top);
    context.fillRect(bulbX - 3, y, 6, bottom - y + 1);
  }
  // Scale and history: kT over the last readouts, 0 to full scale.
  const left = 34;
  const right = width - 4;
  context.fillStyle = "#5c6470";
  context.fillText(formatValue(full), left, top + 8);
  context.fillText("0", left, bottom);
  context.strokeStyle = "#d6dbe2";
  context.strokeRect(left + 26, top, right - left - 26, bottom - top);
  if (history.length > 1) {
    context.beginPath();
    history.forEach((value, k) => {
      const x = left + 26 + ((right - left - 26) * k) / (HISTORY - 1);
      const y = bottom - (Math.min(value, full) / full) * (bottom - top);
      if (k === 0) context.moveTo(x, y);
      else context.lineTo(x, y);
    });
    context.strokeStyle = THERMOMETER_RED;
    context.lineWidth = 1.5;
    context.stroke();
  }
}

function drawGauge(node, pressure, error, full) {
  const width = 150;
  const height = 86;
  const context = context2d(node, width, height);
  const cx = width / 2;
  const cy = height - 14;
  const radius = 56;
  const angle = (value) => Math.PI * (1 + Math.min(Math.max(value / full, 0), 1));
  context.lineWidth = 8;
  context.strokeStyle = "#e8ecf1";
  context.beginPath();
  context.arc(cx, cy, radius, Math.PI, 2 * Math.PI);
  context.stroke();
  if (pressure !== null && error !== null) {
    context.strokeStyle = "rgba(31, 119, 180, 0.35)";
    context.beginPath();
    context.arc(cx, cy, radius, angle(pressure - error), angle(pressure + error));
    context.stroke();
  }
  context.fillStyle = "#5c6470";
  context.fillText("0", cx - radius - 4, cy + 12);
  const fullLabel = formatValue(full);
  context.fillText(fullLabel, cx + radius - context.measureText(fullLabel).width + 4, cy + 12);
  if (pressure !== null) {
    const a = angle(pressure);
    context.strokeStyle = GAUGE_BLUE;
    context.lineWidth = 2.5;
    context.beginPath();
    context.moveTo(cx, cy);
    context.lineTo(cx + (radius - 2) * Math.cos(a), cy + (radius - 2) * Math.sin(a));
    context.stroke();
  }
  context.beginPath();
  context.arc(cx, cy, 3, 0, 2 * Math.PI);
  context.fillStyle = "#1d2127";
  context.fill();
}

/** The instruments panel in `container`; `update(stats)` and `reset()` drive it. */
export function createInstruments(container) {
  const thermometer = canvas("thermometer", 190, 86);
  const gauge = canvas("pressure-gauge", 150, 86);
  const thermometerText = element("span", { id: "thermometer-value", className: "instrument-value", text: "kT –" });
  const gaugeText = element("span", { id: "gauge-value", className: "instrument-value", text: "P –" });
  const count = element("span", { id: "instrument-n", className: "instrument-value", text: "N –" });
  const piston = element("span", { id: "instrument-piston", className: "instrument-value", hidden: true });
  const picked = element("span", { id: "picked", className: "instrument-value", text: "click a disk to follow it" });
  container.append(
    element("div", { className: "instrument" }, [element("span", { className: "instrument-title", text: "thermometer" }), thermometer, thermometerText]),
    element("div", { className: "instrument" }, [element("span", { className: "instrument-title", text: "pressure gauge" }), gauge, gaugeText]),
    element("div", { className: "instrument instrument-list" }, [count, piston, picked]),
  );
  let history = [];
  let temperatureScale = 0;
  let pressureScale = 0;

  return {
    update(stats) {
      const kT = typeof stats.temperature === "number" ? stats.temperature : null;
      if (kT !== null) history.push(kT);
      if (history.length > HISTORY) history = history.slice(-HISTORY);
      // Full scales only grow while a scene runs, so the needle and column stay comparable.
      temperatureScale = Math.max(temperatureScale, niceScale(1.25 * Math.max(0, ...history)));
      drawThermometer(thermometer, history, temperatureScale);
      thermometerText.textContent = `kT ${formatValue(kT)} J`;
      const pressure = typeof stats.pressure === "number" ? stats.pressure : null;
      const error = typeof stats.pressure_error === "number" ? stats.pressure_error : null;
      if (pressure !== null) pressureScale = Math.max(pressureScale, niceScale(1.25 * pressure));
      drawGauge(gauge, pressure, error, pressureScale || 1);
      const kind = stats.pressure_kind ? ` (${stats.pressure_kind})` : "";
      gaugeText.textContent = `P${kind} ${formatValue(pressure)}${error !== null ? ` ± ${formatValue(error, 2)}` : ""} N/m`;
      gaugeText.dataset.error = error === null ? "" : String(error);
      count.textContent = `N = ${typeof stats.n === "number" ? stats.n : "–"}`;
      piston.hidden = !stats.piston;
      if (stats.piston) piston.textContent = `piston at ${formatValue(stats.piston.position)} m, moving ${formatValue(stats.piston.velocity)} m/s`;
      const traced = stats.traced;
      picked.textContent = traced
        ? `disk ${traced.index}: speed ${formatValue(traced.speed)} m/s, kinetic energy ${formatValue(traced.kinetic)} J (m = ${formatValue(traced.mass)} kg${traced.charge ? `, q = ${formatValue(traced.charge)} C` : ""})`
        : "click a disk to follow it";
    },
    /** A new scene: the history and the full scales start again. */
    reset() {
      history = [];
      temperatureScale = 0;
      pressureScale = 0;
    },
  };
}
