"""What the viewer tells a class about each preset: a short explanation (what to watch, what to
try), the disk to highlight, how to colour the disks at first, and the labels and units of the
parameters the page offers. The page builds its controls from these (sent in ``hello``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

ColourMode = Literal["speed", "charge", "species"]
#: Ways to colour the disks: by speed (a colormap), by the sign of the charge, by species.
COLOUR_MODES: tuple[ColourMode, ...] = ("speed", "charge", "species")


@dataclass(frozen=True)
class Guide:
    """The viewer's notes on one preset.

    Parameters
    ----------
    explanation : str
        One or two sentences for the class.
    colour : {"speed", "charge", "species"}
        How the disks are coloured when the preset opens.
    highlight : int, optional
        The particle drawn with a ring (negative: counted from the end), e.g. the cue ball.
    highlight_label : str
        What the ring is labelled.
    """

    explanation: str
    colour: ColourMode = "speed"
    highlight: int | None = None
    highlight_label: str = ""


GUIDES: dict[str, Guide] = {
    "head-on": Guide(
        "Two equal disks meet head-on and swap velocities: momentum and kinetic energy are both "
        "kept. Drag one disk to give it another velocity and watch the exchange."
    ),
    "right-angle": Guide(
        "Equal disks that meet at right angles leave at right angles to each other: each keeps "
        "the part of its velocity along the contact's tangent."
    ),
    "gas": Guide(
        "Disks that start with one speed soon share out their energy: the histogram settles "
        "onto the Maxwell-Boltzmann curve. Heat or cool the gas and watch the thermometer and "
        "the pressure gauge move together (PA = NkT). Drag the grip on the right wall inwards: "
        "the gas heats as it is squeezed."
    ),
    "charged-like": Guide(
        "Two like charges slow each other down and turn back before they touch: kinetic energy "
        "becomes potential energy and back.",
        colour="charge",
    ),
    "charged-opposite": Guide(
        "Opposite charges attract, collide, fly apart and fall back together again; the total "
        "energy stays flat while kinetic and potential trade places.",
        colour="charge",
    ),
    "orbit": Guide(
        "A bound pair of opposite charges orbits its centre of mass on an ellipse, as a planet "
        "orbits a star (the force is also 1/r^2).",
        colour="charge",
    ),
    "bohr-atom": Guide(
        "Two light electrons orbit a heavy nucleus, pulling on each other as they pass: a "
        "classical atom, whose orbits are not the quantised ones of Bohr's.",
        colour="charge",
    ),
    "charged-gas": Guide(
        "A gas of positive and negative charges: opposite charges pair up for a while, so "
        "potential energy falls and the gas warms up.",
        colour="charge",
    ),
    "pool-break": Guide(
        "The cue ball (ringed) breaks a rack: its energy spreads over all the balls, and after a "
        "while their speeds follow the Maxwell-Boltzmann curve.",
        highlight=-1,
        highlight_label="cue ball",
    ),
    "charged-no-collisions": Guide(
        "Point charges pass through each other. With a time step too large for the close "
        "passage the energy jumps (the fixed-step integrator) or holds (adaptive substeps).",
        colour="charge",
    ),
    "circle-gas": Guide(
        "A gas in a round vessel: the rim keeps the angular momentum as well as the energy."
    ),
    "hard-disks": Guide(
        "A dense fluid of hard disks: raise the packing and the pressure climbs far above the "
        "ideal gas's; near 0.7 the disks freeze into a crystal."
    ),
    "pi-blocks": Guide(
        "A heavy block pushes a light one into a wall. Count the collisions: with a mass ratio "
        "of 100^d they spell the first d + 1 digits of pi.",
        colour="species",
    ),
    "brownian": Guide(
        "A large heavy disk (ringed) is jostled by many small ones: its random walk is Brownian "
        "motion, the evidence for molecules that Einstein explained.",
        highlight=0,
        highlight_label="heavy disk",
    ),
    "heat-flow": Guide(
        "The left wall is hot, the right one cold: energy flows through the gas from one to the "
        "other, and the gas near each wall takes its temperature.",
    ),
    "granular": Guide(
        "Collisions lose energy (like sand or snow): the gas cools by itself, and the "
        "histogram leaves the Maxwell-Boltzmann curve as clusters form.",
    ),
    "piston": Guide(
        "A weighted piston squeezes the gas until the gas pushes back as hard as the weight "
        "(P L = F). Heat the gas: the piston rises. Drag the piston down and let it go: it "
        "bounces on the gas.",
    ),
    "effusion": Guide(
        "Light and heavy disks leak through a hole: the light ones escape faster, in the ratio "
        "sqrt(m_heavy / m_light) (Graham's law).",
        colour="species",
    ),
    "atmosphere": Guide(
        "A gas under gravity in a tall box: the disks crowd at the bottom and thin out upwards, "
        "the density halving every 0.69 kT / (m g) of height (the barometric law), while the "
        "temperature is the same at every height."
    ),
    "projectile": Guide(
        "A positive charge moves along a negatively charged plate: the field pulls it down with "
        "a constant force, so it falls on a parabola, like a thrown ball, and bounces.",
        colour="charge",
    ),
    "spectrometer": Guide(
        "Three ions with the same charge and speed but different masses fly into a magnetic "
        "field. It turns each on a half circle whose radius grows with the mass, r = m v / (q B), "
        "so they come down and land apart: the heavier, the further.",
        colour="charge",
    ),
    "galaxy": Guide(
        "Thousands of disks pull on each other by gravity. Starting too slow to hold themselves "
        "up, they fall together, overshoot and settle into a round cluster, where the kinetic "
        "energy is half the depth of the potential energy (the virial theorem)."
    ),
    "drag": Guide(
        "Three disks of different masses fall through a fluid. Drag grows with speed until it "
        "balances the weight: each then falls at its terminal velocity m g / gamma, the "
        "heaviest the fastest."
    ),
}

#: Label and unit of the parameters the page offers, by name (unknown ones show their name).
PARAMETER_LABELS: dict[str, tuple[str, str]] = {
    "n": ("N", ""),
    "dt": ("dt", "s"),
    "k": ("k", "N m²/C²"),
    "collisions": ("collision mode", ""),
    "speed": ("speed", "m/s"),
    "charge": ("charge", "C"),
    "softening": ("softening", "m"),
    "packing": ("packing", ""),
    "digits": ("digits of π", ""),
    "heavy_mass": ("heavy mass", "kg"),
    "heavy_radius": ("heavy radius", "m"),
    "hot": ("hot wall kT", "J"),
    "cold": ("cold wall kT", "J"),
    "restitution": ("restitution", ""),
    "piston_mass": ("piston mass", "kg"),
    "force": ("force on piston", "N"),
    "compress": ("compression speed", "m/s"),
    "gap": ("hole", "m"),
    "boundary": ("boundary", ""),
    "start": ("piston starts at", "m"),
    "columns": ("columns", ""),
    "rows": ("rows", ""),
    "g": ("gravity g", "m/s²"),
    "gamma": ("drag γ", "kg/s"),
    "G": ("G", "N m²/kg²"),
}
#: The values a parameter given as a word may take.
CHOICES: dict[str, tuple[str, ...]] = {
    "collisions": ("exact", "step", "off"),
    "boundary": ("reflecting", "periodic"),
}
#: Shared settings the page does not offer (the rest of a preset's parameters it does).
NOT_OFFERED = frozenset(
    {"seed", "time", "integrator", "tolerance", "mass", "radius", "width", "height",
     "vessel_radius"}
)  # fmt: skip


def guide(name: str | None) -> Guide:
    """The guide of preset ``name`` (a plain one for a scenario of the user's own)."""
    return GUIDES.get(name or "", Guide(""))


def parameter_specs(parameters: dict[str, Any]) -> list[dict[str, Any]]:
    """The controls for a preset's parameters (name -> default): name, label, unit, kind
    ("integer", "number", "boolean" or "choice"), default and, for a choice, its choices."""
    specs = []
    for name, default in parameters.items():
        if name in NOT_OFFERED:
            continue
        label, unit = PARAMETER_LABELS.get(name, (name.replace("_", " "), ""))
        spec: dict[str, Any] = {"name": name, "label": label, "unit": unit, "default": default}
        if name in CHOICES:
            spec |= {"kind": "choice", "choices": list(CHOICES[name])}
        elif isinstance(default, bool):
            spec["kind"] = "boolean"
        elif isinstance(default, int):
            spec["kind"] = "integer"
        else:
            spec["kind"] = "number"
        specs.append(spec)
    return specs
