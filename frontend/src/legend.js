// The colour legend in a corner of the vessel: the speed colormap with its scale, the charges'
// colours (with the + and - marks drawn on the disks) or the species' colours.
import { NEGATIVE, NEUTRAL, POSITIVE, SPECIES_PALETTE, SPEED_STOPS } from "./disks.js";
import { element } from "./dom.js";
import { formatValue } from "./readouts.js";

const css = (rgb) => `rgb(${rgb.map((value) => Math.round(value)).join(", ")})`;

function swatch(rgb, text) {
  return element("span", { className: "legend-entry" }, [
    element("span", { className: "legend-swatch", style: `background: ${css(rgb)}` }),
    element("span", { text }),
  ]);
}

/** The legend, in `container`; `update(mode, scene, speedScale)` redraws it when it changes. */
export function createLegend(container) {
  const box = element("div", { id: "legend", className: "legend", hidden: true });
  container.append(box);
  let shown = "";

  function speedLegend(scale) {
    const gradient = SPEED_STOPS.map((rgb, k) => `${css(rgb)} ${(100 * k) / (SPEED_STOPS.length - 1)}%`);
    return [
      element("span", { className: "legend-title", text: "speed" }),
      element("span", { className: "legend-bar", style: `background: linear-gradient(to right, ${gradient.join(", ")})` }),
      element("span", { className: "legend-scale" }, [
        element("span", { text: "0" }),
        element("span", { id: "legend-top", text: `${formatValue(scale)} m/s` }),
      ]),
    ];
  }

  function chargeLegend(charges) {
    const entries = [];
    if (charges.some((q) => q > 0)) entries.push(swatch(POSITIVE, "+ positive"));
    if (charges.some((q) => q < 0)) entries.push(swatch(NEGATIVE, "− negative"));
    if (charges.some((q) => q === 0)) entries.push(swatch(NEUTRAL, "neutral"));
    return [element("span", { className: "legend-title", text: "charge" }), ...entries];
  }

  function speciesLegend(labels) {
    const entries = labels.map((label, k) => swatch(SPECIES_PALETTE[k % SPECIES_PALETTE.length], label));
    return [element("span", { className: "legend-title", text: "species" }), ...entries];
  }

  return {
    update(mode, scene, speedScale) {
      if (!scene) return;
      const charges = Array.isArray(scene.charge) ? scene.charge : [scene.charge ?? 0];
      const key = `${scene.generation}:${mode}:${mode === "speed" ? speedScale : ""}`;
      if (key === shown) return;
      shown = key;
      let children = [];
      if (mode === "speed" && speedScale > 0) children = speedLegend(speedScale);
      else if (mode === "charge") children = chargeLegend(charges);
      else if (mode === "species") children = speciesLegend(scene.species_labels ?? []);
      box.dataset.mode = mode;
      box.replaceChildren(...children);
      box.hidden = children.length === 0;
    },
  };
}
