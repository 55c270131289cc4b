// The uPlot charts: energies and, on a small panel of its own, total speed against time (a
// rolling window), and the speed histogram with the Maxwell-Boltzmann density. Each fills its
// container and follows its size.
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

/**
 * Lines against simulated time in a rolling window: `series` = [{label, stroke}], their values
 * read from each stats message by `read(stats)` (an array, one per series), on the axis `label`.
 * A `compact` plot has no legend and no time label (a small panel under another).
 */
function createTimePlot(container, label, series, read, compact = false) {
  const columns = [[], ...series.map(() => [])];
  const { plot, destroy } = mountPlot(
    container,
    {
      scales: { x: { time: false }, y: {} },
      axes: [
        compact ? { values: tickValues, size: 24 } : { label: "time (s)", values: tickValues, labelSize: 18 },
        valueAxis(label, "y"),
      ],
      series: [{ label: "time (s)" }, ...series.map((line) => ({ ...line, scale: "y", width: 1.5 }))],
      legend: { live: false, show: !compact },
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
      const row = [stats.time, ...read(stats)];
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

/** Kinetic, potential and total energy against simulated time; without forces the total alone
 * (the kinetic energy would lie under it, and the potential at 0 says nothing). */
export function createEnergyPlot(container) {
  const names = (forces) => (forces ? ["kinetic", "potential", "total"] : ["total"]);
  const colours = { kinetic: KINETIC, potential: POTENTIAL, total: TOTAL };
  let forces = false;
  let lines = null;
  function mount() {
    const shown = names(forces);
    const read = (stats) => shown.map((name) => stats.energy?.[name]);
    lines = createTimePlot(container, "energy (J)", shown.map((label) => ({ label, stroke: colours[label] })), read);
  }
  mount();
  return {
    get points() {
      return lines.points;
    },
    get shown() {
      return names(forces);
    },
    /** Whether the scene has forces (the plot is rebuilt with its lines when that changes). */
    setForces(value) {
      if (Boolean(value) === forces) return;
      forces = Boolean(value);
      lines.destroy();
      mount();
    },
    append: (stats) => lines.append(stats),
    clear: () => lines.clear(),
    destroy: () => lines.destroy(),
  };
}

/** The seed's "total speed", the sum of the speeds, on a panel of its own (it is the noisiest
 * line, and not an energy). */
export function createTotalSpeedPlot(container) {
  return createTimePlot(container, "Σ|v| (m/s)", [{ label: "total speed", stroke: SPEED }], (stats) => [stats.total_speed], true);
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
