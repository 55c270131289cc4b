// The two uPlot charts: energies and total speed against time (a rolling window), and the speed
// histogram with the Maxwell-Boltzmann density. Each fills its container and follows its size.
import uPlot from "uplot";

export const MAX_ENERGY_POINTS = 2000;
const KINETIC = "#1f77b4";
const POTENTIAL = "#e377c2";
const TOTAL = "#000000";
const SPEED = "#2ca02c";
const MEASURED = "#7f7f7f";
const MAXWELL_BOLTZMANN = "#d62728";

/** Tick labels: plain numbers normally, exponents for very large or small magnitudes. */
export function formatTick(value) {
  if (value === null || value === undefined) return "";
  const magnitude = Math.abs(value);
  if (magnitude !== 0 && (magnitude >= 1e5 || magnitude < 1e-3)) return value.toExponential(1);
  return String(Number(value.toPrecision(6)));
}

const tickValues = (plot, splits) => splits.map(formatTick);

/** Tick area width from the longest tick label, so long or exponent labels are not clipped. */
function axisSize(plot, values) {
  const longest = (values ?? []).reduce((most, text) => Math.max(most, String(text ?? "").length), 0);
  return Math.max(36, 14 + 7 * longest);
}

function valueAxis(label, scale, extra = {}) {
  return { label, scale, values: tickValues, size: axisSize, labelSize: 18, ...extra };
}

/** A uPlot inside `container`, resized to it (less the legend) whenever it changes size. */
function mountPlot(container, options, data) {
  const plot = new uPlot({ ...options, width: 300, height: 150 }, data, container);
  const fit = () => {
    const legend = plot.root.querySelector(".u-legend");
    const width = Math.floor(container.clientWidth);
    const height = Math.floor(container.clientHeight - (legend ? legend.offsetHeight : 0));
    if (width > 0 && height > 0) plot.setSize({ width, height: Math.max(60, height) });
  };
  const observer = new ResizeObserver(fit);
  observer.observe(container);
  fit();
  return {
    plot,
    destroy() {
      observer.disconnect();
      plot.destroy();
    },
  };
}

/** Energies (left axis) and total speed (right axis) against simulated time. */
export function createEnergyPlot(container) {
  const columns = [[], [], [], [], []]; // time, kinetic, potential, total, total speed
  const { plot, destroy } = mountPlot(
    container,
    {
      scales: { x: { time: false }, energy: {}, speed: {} },
      axes: [
        { label: "time (s)", values: tickValues, labelSize: 18 },
        valueAxis("energy (J)", "energy"),
        valueAxis("total speed (m/s)", "speed", { side: 1, grid: { show: false } }),
      ],
      series: [
        { label: "time (s)" },
        { label: "kinetic", stroke: KINETIC, scale: "energy", width: 1.5 },
        { label: "potential", stroke: POTENTIAL, scale: "energy", width: 1.5 },
        { label: "total", stroke: TOTAL, scale: "energy", width: 1.5 },
        { label: "total speed", stroke: SPEED, scale: "speed", width: 1.5 },
      ],
      legend: { live: false },
      cursor: { drag: { x: false, y: false } },
    },
    columns,
  );

  return {
    get points() {
      return columns[0].length;
    },
    /** Appends one stats message's values, dropping the oldest beyond MAX_ENERGY_POINTS. */
    append(stats) {
      const energy = stats.energy ?? {};
      const row = [stats.time, energy.kinetic, energy.potential, energy.total, stats.total_speed];
      row.forEach((value, i) => columns[i].push(typeof value === "number" ? value : null));
      const excess = columns[0].length - MAX_ENERGY_POINTS;
      if (excess > 0) columns.forEach((column) => column.splice(0, excess));
      plot.setData(columns);
    },
    clear() {
      columns.forEach((column) => (column.length = 0));
      plot.setData(columns);
    },
    destroy,
  };
}

/** Measured speed density as bars, with the Maxwell-Boltzmann density as a line. */
export function createSpeedPlot(container) {
  let edges = [0, 1];
  const { plot, destroy } = mountPlot(
    container,
    {
      scales: {
        x: { time: false, range: () => [edges[0], edges[edges.length - 1]] },
        y: { range: (self, min, max) => [0, max > 0 ? 1.1 * max : 1] },
      },
      axes: [
        { label: "speed (m/s)", values: tickValues, labelSize: 18 },
        valueAxis("probability density (s/m)", "y"),
      ],
      series: [
        { label: "speed (m/s)" },
        {
          label: "measured",
          stroke: MEASURED,
          fill: "rgba(127, 127, 127, 0.45)",
          paths: uPlot.paths.bars({ size: [1, Infinity], gap: 1 }),
          points: { show: false },
        },
        { label: "Maxwell–Boltzmann", stroke: MAXWELL_BOLTZMANN, width: 2, points: { show: false } },
      ],
      legend: { live: false },
      cursor: { drag: { x: false, y: false } },
    },
    [[], [], []],
  );

  return {
    /** Replaces the histogram with `histogram` = {edges, density, maxwell_boltzmann}. */
    update(histogram) {
      if (!histogram || !Array.isArray(histogram.edges) || histogram.edges.length < 2) return;
      edges = histogram.edges;
      const centres = edges.slice(0, -1).map((left, i) => (left + edges[i + 1]) / 2);
      const bins = centres.length;
      const column = (values) => Array.from({ length: bins }, (_, i) => values?.[i] ?? null);
      plot.setData([centres, column(histogram.density), column(histogram.maxwell_boltzmann)]);
    },
    clear() {
      edges = [0, 1];
      plot.setData([[], [], []]);
    },
    destroy,
  };
}
