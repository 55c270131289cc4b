// The readouts row (time, N, kT, pressure, collision rate, energy drift) and number formatting.
// Each value element shows the formatted number; its data-value holds the raw one ("" for null).
import { element } from "./dom.js";

/** Three significant digits, exponent notation for very large or small magnitudes; "–" for null. */
export function formatValue(value, digits = 3) {
  if (typeof value !== "number" || !Number.isFinite(value)) return "–";
  const magnitude = Math.abs(value);
  if (magnitude === 0) return "0";
  if (magnitude >= 1e5 || magnitude < 1e-3) return value.toExponential(digits - 1);
  return String(Number(value.toPrecision(digits)));
}

const formatTime = (value) => (typeof value === "number" ? value.toFixed(2) : "–");
const formatCount = (value) => (typeof value === "number" ? String(Math.round(value)) : "–");
const formatDrift = (value) =>
  typeof value === "number" ? (value === 0 ? "0" : value.toExponential(1)) : "–";

const READOUTS = [
  { id: "readout-time", label: "time", unit: "s", read: (s) => s.time, format: formatTime },
  { id: "readout-n", label: "N", unit: "", read: (s) => s.n, format: formatCount },
  { id: "readout-temperature", label: "kT", unit: "J", read: (s) => s.temperature, format: formatValue },
  { id: "readout-pressure", label: "pressure", unit: "N/m", read: (s) => s.pressure, format: formatValue },
  { id: "readout-collisions", label: "collisions", unit: "/s", read: (s) => s.collision_rate, format: formatValue },
  { id: "readout-drift", label: "energy drift", unit: "", read: (s) => s.drift, format: formatDrift },
];

/** The readouts row: each value element shows the formatted number, its data-value the raw one. */
export function createReadouts(container) {
  const cells = READOUTS.map((spec) => {
    const label = element("span", { className: "readout-label", text: spec.label });
    const value = element("span", { id: spec.id, className: "readout-value", "data-value": "", text: "–" });
    const unit = element("span", { className: "readout-unit", text: spec.unit });
    container.append(element("div", { className: "readout" }, [label, value, unit]));
    return { spec, label, value };
  });

  function show(cell, raw) {
    const number = typeof raw === "number" && Number.isFinite(raw) ? raw : null;
    cell.value.textContent = cell.spec.format(number);
    cell.value.dataset.value = number === null ? "" : String(number);
  }

  return {
    /** Shows a stats message; the pressure label says whether it is the wall or virial pressure,
     * and the drift is marked (its warning line as the tooltip) once it passed the limit. */
    update(stats) {
      for (const cell of cells) show(cell, cell.spec.read(stats));
      const pressure = cells.find((cell) => cell.spec.id === "readout-pressure");
      pressure.label.textContent = stats.pressure_kind ? `pressure (${stats.pressure_kind})` : "pressure";
      const drift = cells.find((cell) => cell.spec.id === "readout-drift");
      const warning = typeof stats.warning === "string" ? stats.warning : "";
      drift.value.classList.toggle("warning", warning !== "");
      drift.value.title = warning;
      drift.value.dataset.warning = warning;
    },
    /** Blanks every readout but N (a new scene has no stats yet). */
    reset(n) {
      this.update({ n });
    },
  };
}
