"""The ``collidium`` command line: presets, run, resume, export, inspect, convert, render, view.

Bad input of any kind prints one line ``error: <field>: <reason>`` on stderr and exits with
status 2 (no traceback, nothing half-written); a run that goes wrong exits with status 1.
"""

from __future__ import annotations

import gc
import importlib
import json
import sys
import tomllib
import warnings
from collections.abc import Sequence
from contextlib import nullcontext
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from pydantic import ValidationError

from collidium.errors import InputError, Interrupted, SimulationError
from collidium.kernels.compilation import interrupts_outside_compiling, on_first_compile

if TYPE_CHECKING:
    from collidium.runner import Job

app = typer.Typer(
    name="collidium",
    help="Particles in a 2D vessel: exact elastic collisions, Coulomb forces, leapfrog.",
    no_args_is_help=True,
    add_completion=True,  # --install-completion for bash, zsh, fish and PowerShell
    pretty_exceptions_enable=False,
)


def _print_version(value: bool) -> None:
    if value:
        from collidium import __version__

        typer.echo(f"collidium {__version__}")
        raise typer.Exit()


@app.callback()
def _options(
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_print_version, is_eager=True, help="Print the version and exit."
        ),
    ] = False,
) -> None:
    """Particles in a 2D vessel: exact elastic collisions, Coulomb forces, leapfrog."""  # fmt: skip


QuietOption = Annotated[
    bool,
    typer.Option(
        "--quiet", "-q", help="Print nothing on success; a drift warning is one line on stderr."
    ),
]
VerboseOption = Annotated[
    bool,
    typer.Option("--verbose", "-v",
                 help="Say what runs before it starts, and show its progress bar."),
]  # fmt: skip

MaxDriftOption = Annotated[
    float | None,
    typer.Option(
        "--max-drift",
        help="Fail (exit 1) if the total energy drifts by more than this fraction of its "
        "initial value (without it, a drift over 1e-3 only warns).",
    ),
]
SetOption = Annotated[
    list[str] | None,
    typer.Option(
        "--set",
        metavar="KEY=VALUE",
        help="Override a preset parameter (n=500) or a scenario field (run.dt=0.002); "
        "the value is read as TOML (a bare word is a string). Repeatable.",
    ),
]


@app.command("presets")
def presets_command(
    as_json: Annotated[bool, typer.Option("--json", help="Print a JSON list.")] = False,
) -> None:
    """List the presets (the seed report's configurations)."""
    from collidium.presets import describe_presets

    entries = describe_presets()
    if as_json:
        typer.echo(json.dumps(entries, indent=2))
        return
    from rich.console import Console
    from rich.table import Table

    table = Table(title="collidium presets")
    for column in ("name", "seed §", "description", "parameters"):
        table.add_column(column)
    for entry in entries:
        parameters = ", ".join(f"{k}={v}" for k, v in entry["parameters"].items())
        table.add_row(entry["name"], entry["section"], entry["description"], parameters)
    Console().print(table)


@app.command("run")
def run_command(
    scenario: Annotated[str, typer.Argument(help="Preset name or scenario .toml file.")],
    time: Annotated[
        float | None, typer.Option("--time", help="Duration in s (default: the scenario's).")
    ] = None,
    steps: Annotated[int | None, typer.Option("--steps", help="Number of steps.")] = None,
    dt: Annotated[float | None, typer.Option("--dt", help="Time step in s.")] = None,
    seed: Annotated[int | None, typer.Option("--seed", help="Random seed.")] = None,
    overrides: SetOption = None,
    out: Annotated[
        Path | None,
        typer.Option("--out", help="Write a trajectory: .gsd (OVITO, MDAnalysis, freud) or .xyz."),
    ] = None,
    every: Annotated[
        int | None, typer.Option("--every", help="Steps between frames (default: 0.1 s).")
    ] = None,
    checkpoint: Annotated[
        Path | None,
        typer.Option("--checkpoint", help="Checkpoint file, written at the end (and see below)."),
    ] = None,
    checkpoint_every: Annotated[
        int | None,
        typer.Option("--checkpoint-every", help="Also write the checkpoint every this many steps."),
    ] = None,
    max_drift: MaxDriftOption = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    quiet: QuietOption = False,
    verbose: VerboseOption = False,
) -> int:
    """Run a preset or scenario file and print a summary."""
    from collidium.loading import load_scenario
    from collidium.runner import prepare

    values = parse_settings(overrides or [])
    values |= {k: v for k, v in (("dt", dt), ("seed", seed)) if v is not None}
    sim, job = prepare(
        load_scenario(scenario, **values), time, steps, out, every, checkpoint, checkpoint_every,
        max_drift,
    )  # fmt: skip
    return _run(sim, job, as_json, quiet, verbose)


@app.command("resume")
def resume_command(
    checkpoint: Annotated[Path, typer.Argument(help="Checkpoint written by run --checkpoint.")],
    max_drift: MaxDriftOption = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
    quiet: QuietOption = False,
    verbose: VerboseOption = False,
) -> int:
    """Finish an interrupted run from its checkpoint (bitwise the same as never stopping)."""
    from collidium.runner import Job, resume

    sim, job = resume(checkpoint)
    if max_drift is not None:
        job.max_drift = Job(end_step=job.end_step, max_drift=max_drift).max_drift  # checked
    if sim.steps >= job.end_step:  # a finished run: its files are complete
        done = {"checkpoint": str(checkpoint), "finished": True, "steps": sim.steps,
                "time": sim.time}  # fmt: skip
        line = (f"{checkpoint}: the run finished at step {sim.steps} (t = {sim.time:g} s); "
                "nothing left to do")  # fmt: skip
        if not quiet:
            typer.echo(json.dumps(done) if as_json else line)
        return 0
    return _run(sim, job, as_json, quiet, verbose)


@app.command("inspect")
def inspect_command(
    path: Annotated[Path, typer.Argument(help="A .gsd trajectory or a checkpoint.")],
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Say what a trajectory or checkpoint file holds."""
    from collidium.io import describe_file

    facts = describe_file(path)
    if as_json:
        typer.echo(json.dumps(facts, indent=2))
        return
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"collidium inspect: {path}", show_header=False)
    table.add_column("field")
    table.add_column("value")
    for key, value in facts.items():
        table.add_row(key, value if isinstance(value, str) else json.dumps(value))
    Console().print(table)


@app.command("convert")
def convert_command(
    source: Annotated[Path, typer.Argument(help="A .gsd trajectory.")],
    target: Annotated[Path, typer.Argument(help="The extended-XYZ file to write (.xyz).")],
) -> None:
    """Export a GSD trajectory as extended XYZ."""
    from collidium.io.trajectory import read_trajectory, write_xyz

    if target.suffix != ".xyz":
        raise InputError("target", f"must end in .xyz, got {target}")
    write_xyz(read_trajectory(source), target)


@app.command("render")
def render_command(
    source: Annotated[str, typer.Argument(help="A .gsd trajectory, a preset or a .toml file.")],
    plots: Annotated[
        Path | None, typer.Option("--plots", help="Folder for energy.png and speeds.png.")
    ] = None,
    movie: Annotated[
        Path | None,
        typer.Option("--movie", help="Movie file: .mp4 (needs the movie extra) or .gif."),
    ] = None,
    time: Annotated[
        float | None, typer.Option("--time", help="Duration in s when running a scenario.")
    ] = None,
    every: Annotated[
        int | None, typer.Option("--every", help="Steps between frames when running a scenario.")
    ] = None,
    fps: Annotated[int, typer.Option("--fps", help="Movie frames per second.")] = 20,
    overrides: SetOption = None,
) -> None:
    """Draw the seed's plots and movie from a trajectory (or from running a scenario)."""
    from collidium import render

    if plots is None and movie is None:
        raise InputError("--plots", "give --plots DIR and/or --movie FILE")
    if fps < 1:
        raise InputError("--fps", f"must be >= 1, got {fps}")
    if movie is not None:
        render.movie_path(movie)  # before a scenario runs for it
    trajectory = _trajectory_of(source, time, every, parse_settings(overrides or []))
    show = sys.stderr.isatty()
    if plots is not None:
        for path in render.write_plots(trajectory, plots):
            typer.echo(str(path))
    if movie is not None:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            written = render.write_movie(trajectory, movie, fps=fps, progress=show)
        for warning in caught:  # one line each, not Python's two-line format
            _warn(str(warning.message))
        typer.echo(str(written))


def _trajectory_of(
    source: str, time: float | None, every: int | None, overrides: dict[str, Any]
) -> Any:
    """The trajectory in a .gsd file, or recorded by running a preset or scenario."""
    from collidium.io.trajectory import read_trajectory

    if source.endswith(".gsd"):
        return read_trajectory(source)
    from collidium.loading import load_scenario
    from collidium.runner import record

    return record(load_scenario(source, **overrides), time, every, progress=sys.stderr.isatty())


def _run(sim: Any, job: Job, as_json: bool, quiet: bool, verbose: bool) -> int:
    """Run the job as asked to say it: the summary, nothing (quiet) or a first line and the
    progress bar (verbose)."""
    from collidium.runner import execute

    if quiet and verbose:
        raise InputError("--quiet", "give --quiet or --verbose, not both")
    if verbose:
        sys.stderr.write(f"{_plan_line(sim, job)}\n")
    progress = verbose or (not as_json and not quiet and sys.stderr.isatty())
    return _report(execute(sim, job, progress=progress), job, as_json, quiet)


def _plan_line(sim: Any, job: Job) -> str:
    """What is about to run, in one line."""
    steps = job.end_step - sim.steps
    outputs = [f for f in (job.out, job.checkpoint) if f is not None]
    return (f"running {sim.name}: {sim.particles.n} particles, {steps} steps of {sim.dt:g} s "
            f"from t = {sim.time:g} s, {sim.collisions} collisions, {sim.integrator} "
            f"integrator" + (f"; writing {', '.join(outputs)}" if outputs else ""))  # fmt: skip


def _report(summary: dict[str, Any], job: Job, as_json: bool, quiet: bool = False) -> int:
    """Print the summary (quiet: only a drift warning, on stderr); exit status 1 if the energy
    drifted past ``--max-drift``."""
    from collidium.runner import drift_exceeded

    if job.max_drift is not None and drift_exceeded(job):
        if as_json and not quiet:
            typer.echo(json.dumps(summary))
        elif not quiet:
            _print_summary(summary)
        return _fail(f"--max-drift: {summary['energy']['warning']}", 1)
    if quiet:
        if summary["energy"]["warning"]:
            _warn(summary["energy"]["warning"])
    elif as_json:
        typer.echo(json.dumps(summary))
    else:
        _print_summary(summary)
    return 0


@app.command("export")
def export_command(
    preset: Annotated[str, typer.Argument(help="Preset name (or a scenario .toml file).")],
    overrides: SetOption = None,
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Write to this file (default stdout).")
    ] = None,
) -> None:
    """Write a preset's scenario as editable TOML."""
    from collidium.loading import load_scenario

    text = load_scenario(preset, **parse_settings(overrides or [])).to_toml()
    if output is None:
        sys.stdout.write(text)
    else:
        write_atomically(output, text)


@app.command("view")
def view_command(
    scenario: Annotated[
        str, typer.Argument(help="Preset name or scenario .toml file (default: gas).")
    ] = "gas",
    overrides: SetOption = None,
    host: Annotated[
        str,
        typer.Option("--host", help="Address to listen on; only this machine by default."),
    ] = "127.0.0.1",
    port: Annotated[int, typer.Option("--port", help="Port (0: any free one).")] = 8765,
    browser: Annotated[
        bool, typer.Option("--browser/--no-browser", help="Open the page in a web browser.")
    ] = True,
) -> None:
    """Watch and steer a simulation live in the browser (until Ctrl+C)."""
    from collidium.loading import load_scenario
    from collidium.presets import PRESETS
    from collidium.viewer.server import (
        LOOPBACK,
        LOOPBACK_HOSTS,
        bind,
        check_built,
        create_app,
        serve,
        url_of,
    )  # fmt: skip
    from collidium.viewer.session import ViewerSession

    check_built()
    if not 0 <= port <= 65535:
        raise InputError("--port", f"must be in [0, 65535], got {port}")
    values = parse_settings(overrides or [])
    spec = load_scenario(scenario, **values)
    if spec.observers:
        _warn(f"the viewer measures by itself; the [[observers]] of {scenario} are not run")
        spec = spec.model_copy(update={"observers": []})
    name = scenario if scenario in PRESETS else None
    shown = {k: v for k, v in values.items() if "." not in k} if name else {}
    ViewerSession(spec, preset=name, overrides=shown)  # refuse a bad scenario before listening
    sock = bind(host, port)
    if host not in LOOPBACK:
        _warn(f"--host {host} lets every machine that reaches this one run and steer simulations")
    url = url_of(sock, host)
    sys.stderr.write(f"collidium viewer at {url} (Ctrl+C to stop)\n")
    if browser:
        import webbrowser

        webbrowser.open(url)
    hosts = LOOPBACK_HOSTS if host in LOOPBACK else ("*",)
    serve(create_app(lambda: ViewerSession(spec, preset=name, overrides=shown), hosts=hosts), sock)


@app.command("sweep")
def sweep_command(
    scenario: Annotated[str, typer.Argument(help="Preset name or scenario .toml file.")],
    grid: Annotated[
        list[str] | None,
        typer.Option(
            "--grid",
            metavar="KEY=V1,V2,...",
            help="A parameter and its values (or start:stop:count). Repeatable: every "
            "combination runs.",
        ),
    ] = None,
    seeds: Annotated[int, typer.Option("--seeds", help="Seeds per point (1..N).")] = 1,
    time: Annotated[float | None, typer.Option("--time", help="Duration of each run in s.")] = None,
    out: Annotated[
        Path | None,
        typer.Option(
            "--out", help="The table (.parquet or .csv); a sweep run again skips the runs it holds."
        ),
    ] = None,
    measure: Annotated[
        list[str] | None,
        typer.Option("--measure", help="Keep only these quantities (pressure, temperature...)."),
    ] = None,
    trajectories: Annotated[
        Path | None, typer.Option("--trajectories", help="A folder for each run's .gsd file.")
    ] = None,
    scheduler: Annotated[
        str | None, typer.Option("--scheduler", help="A Dask scheduler's address.")
    ] = None,
    workers: Annotated[
        int | None, typer.Option("--workers", help="Local workers (default: one per core).")
    ] = None,
    plot: Annotated[
        Path | None,
        typer.Option("--plot", help="Draw --y against the first grid key, with errors (.png)."),
    ] = None,
    y: Annotated[str, typer.Option("--y", help="The quantity --plot draws.")] = "compressibility",
) -> int:
    """Run a scenario over a grid of parameters and seeds on Dask: one row per run."""  # fmt: skip
    from collidium.sweeps import sweep

    values = parse_grid(grid or [])
    if not values:
        raise InputError("--grid", "give at least one KEY=V1,V2,...")
    if plot is not None and plot.suffix.lower() not in (".png", ".svg", ".pdf"):
        raise InputError("--plot", f"must end in .png, .svg or .pdf, got {plot}")
    table = sweep(
        scenario, values, seeds=seeds, time=time, measure=measure, out=out,
        trajectories=trajectories, scheduler=scheduler, workers=workers,
        progress=sys.stderr.isatty(),
    )  # fmt: skip
    failed = table[table["status"] != "ok"]
    for _, row in failed.iterrows():
        _warn(f"run {row['run']} ({_point(row, values)}, seed {row['seed']}) failed: "
              f"{row['error']}")  # fmt: skip
    if plot is not None:
        _draw_sweep(table, next(iter(values)), y, plot)
    where = f"; {out}" if out is not None else ""
    typer.echo(f"{len(table)} runs: {len(table) - len(failed)} ok, {len(failed)} failed{where}")
    if out is None:
        typer.echo(table.to_string(index=False))
    return 0


def _point(row: Any, grid: dict[str, list[Any]]) -> str:
    return ", ".join(f"{key}={row[key]}" for key in grid)


def _draw_sweep(table: Any, x: str, y: str, path: Path) -> None:
    from matplotlib.figure import Figure

    from collidium.io.atomic import replacing
    from collidium.sweeps import plot

    figure = Figure(figsize=(6, 4), layout="constrained")
    plot(table, x, y, figure.add_subplot())
    with replacing(path) as temporary:
        figure.savefig(temporary, dpi=150)


def _warn(line: str) -> None:
    sys.stderr.write(f"warning: {line}\n")


def parse_settings(items: Sequence[str]) -> dict[str, Any]:
    """``["n=500", "run.dt=0.002", "collisions=step"]`` -> ``{"n": 500, ...}``.

    Values are read as TOML values (``500`` int, ``2.5`` float, ``true``, ``[1, 2]``); anything
    that is not valid TOML is kept as a string (``step``).
    """
    values: dict[str, Any] = {}
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise InputError("--set", f"expected KEY=VALUE, got {item!r}")
        values[key] = _toml_value(key, text.strip())
    return values


def _toml_value(key: str, text: str) -> Any:
    """``text`` read as a TOML value; kept as a string if it is not one (a bare word)."""
    try:
        return tomllib.loads(f"value = {text}")["value"]
    except tomllib.TOMLDecodeError:
        return text
    except ValueError:  # Python refuses to read an integer of over 4300 digits
        raise InputError(key, "a number with too many digits") from None
    except RecursionError:
        raise InputError(key, "arrays or tables nested too deeply") from None


def parse_grid(items: Sequence[str]) -> dict[str, list[Any]]:
    """``["packing=0.1,0.2", "n=100:400:4"]`` -> ``{"packing": [0.1, 0.2], "n": [100, 200, 300,
    400]}``: values split at the commas outside brackets, each read as by `parse_settings`;
    ``start:stop:count`` is ``count`` evenly spaced values from ``start`` to ``stop``
    (whole numbers if all three are)."""
    grid: dict[str, list[Any]] = {}
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise InputError("--grid", f"expected KEY=VALUE,VALUE,..., got {item!r}")
        if key in grid:
            raise InputError("--grid", f"{key} is given twice")
        parts = [part.strip() for part in _split_top_level(text) if part.strip()]
        grid[key] = [v for part in parts for v in _grid_values(key, part)]
    return grid


def _split_top_level(text: str) -> list[str]:
    """``"1,[2,3],4"`` -> ``["1", "[2,3]", "4"]``."""
    parts, depth, start = [], 0, 0
    for k, char in enumerate(text):
        depth += (char in "[{") - (char in "]}")
        if char == "," and depth == 0:
            parts.append(text[start:k])
            start = k + 1
    return [*parts, text[start:]]


def _grid_values(key: str, text: str) -> list[Any]:
    """One grid entry: a TOML value, or ``start:stop:count``."""
    pieces = text.split(":")
    if len(pieces) != 3:
        return [_toml_value(key, text)]
    start, stop, count = (_toml_value(key, piece) for piece in pieces)
    numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (start, stop))
    if not numbers or isinstance(count, bool) or not isinstance(count, int) or count < 1:
        raise InputError(key, f"a range is start:stop:count with count >= 1, got {text!r}")
    if count == 1:
        return [start]
    values = [start + (stop - start) * k / (count - 1) for k in range(count)]
    if isinstance(start, int) and isinstance(stop, int) and (stop - start) % (count - 1) == 0:
        return [round(v) for v in values]
    return [round(v, 12) for v in values]  # 0.05:0.65:13 gives 0.1, not 0.10000000000000002


def write_atomically(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file, so nothing is ever half-written."""
    from collidium.io.atomic import replacing

    with replacing(path) as temporary:
        temporary.write_text(text, encoding="utf-8")


def _print_summary(summary: dict[str, Any]) -> None:
    from rich.console import Console
    from rich.table import Table

    energy = summary["energy"]
    pressure = summary["pressure"]
    drift = energy["max_rel_drift"]
    rows = [
        ("particles", f"{summary['n']}"),
        ("simulated time", f"{summary['time']:.6g} s in {summary['steps']} steps"),
        ("wall time", f"{summary['wall_seconds']:.3g} s"),
        ("kinetic energy", f"{energy['kinetic']:.10g} J"),
        ("potential energy", f"{energy['potential']:.10g} J"),
        ("total energy", f"{energy['total']:.10g} J"),
        ("max relative energy drift", "n/a" if drift is None else f"{drift:.3g}"),
        *([("warning", energy["warning"])] if energy.get("warning") else []),
        ("momentum", "({:.6g}, {:.6g}) kg m/s".format(*summary["momentum"])),
        ("angular momentum", f"{summary['angular_momentum']:.10g} kg m^2/s"),
        ("pair collisions", f"{summary['collisions']['pair']}"),
        ("wall collisions", f"{summary['collisions']['wall']}"),
        ("all collisions", f"{summary['collisions']['pair'] + summary['collisions']['wall']}"),
        *_heat_rows(summary["wall_heat"]),
        *(
            [("force heat (given to the gas)", f"{summary['force_heat']:.6g} J")]
            if summary.get("force_heat")
            else []
        ),
        ("collision rate", _number(summary["collisions"]["rate"], "/s")),
        ("temperature kT", _for_a_gas(summary, _number(summary["temperature"], "J"))),
        ("wall pressure", _number(pressure["wall"], "N/m", pressure["wall_error"])),
        ("virial pressure", _number(pressure["virial"], "N/m", pressure["virial_error"])),
        (
            "compressibility Z = PA/NkT",
            _for_a_gas(
                summary, _number(summary["compressibility"], "", summary["compressibility_error"])
            ),
        ),
        ("Maxwell-Boltzmann KS p-value", _for_a_gas(summary, _number(summary["ks_pvalue"], ""))),
        ("escaped", f"{summary['escaped']}"),
        *_piston_rows(summary.get("piston")),
        *_effusion_rows(summary.get("observers", [])),
    ]
    table = Table(title=f"collidium run: {summary['scenario']}", show_header=False)
    table.add_column("quantity")
    table.add_column("value", justify="right")
    for row in rows:
        table.add_row(*row)
    Console().print(table)


def _heat_rows(heat: dict[str, float]) -> list[tuple[str, str]]:
    """A row of the energy the walls gave the gas, when any wall is not a mirror."""
    if not any(heat.values()):
        return []
    each = ", ".join(f"{name} {value:.6g}" for name, value in heat.items() if value)
    return [("wall heat (given to the gas)", f"{each} J")]


def _piston_rows(piston: dict[str, Any] | None) -> list[tuple[str, str]]:
    """A row of the piston's state, when the vessel has one."""
    if piston is None:
        return []
    where = f"piston ({piston['wall']})"
    return [
        (
            f"{where} position, velocity",
            f"{piston['position']:.6g} m, {piston['velocity']:.6g} m/s",
        ),
        (f"{where} work on the gas", f"{piston['work']:.6g} J"),
    ]


def _effusion_rows(observers: list[dict[str, Any]]) -> list[tuple[str, str]]:
    """Rows of each effusion observer: per-disk crossing rates by mass, their ratio against
    Graham's law, and the share of each species that has crossed."""
    rows = []
    for entry in observers:
        if entry["observer"] != "Effusion":
            continue
        where = entry["partition"]
        rows += [
            (f"crossings of {where} per disk, {m:g} kg", _number(rate, "/s", error))
            for m, rate, error in zip(
                entry["masses"], entry["rates"], entry["rate_errors"], strict=True
            )
        ]
        rows += [
            ("lightest / heaviest rate", f"{_number(entry['ratio'], '', entry['ratio_error'])} "
                                         f"(Graham: {_number(entry['graham'], '')})"),
            (f"share across {where}", ", ".join(_number(x, "") for x in entry["escaped"])),
        ]  # fmt: skip
    return rows


def _for_a_gas(summary: dict[str, Any], text: str) -> str:
    """``text``, or why a few bodies have no such statistic."""
    from collidium.runner import STATISTICS_FROM

    n = summary["n"]
    return text if n >= STATISTICS_FROM else f"n/a ({n} particles, not a gas)"


def _number(value: float | None, unit: str, error: float | None = None) -> str:
    if value is None:
        return "n/a"
    spread = f" ± {error:.2g}" if error is not None else ""
    return f"{value:.6g}{spread} {unit}".rstrip()


# --- entry point: every error becomes one line ---------------------------------------------------


def _click_exceptions() -> tuple[type[Exception], type[Exception]]:
    """``(ClickException, UsageError)`` of the click that typer uses (vendored or not)."""
    for module in ("typer._click.exceptions", "click.exceptions"):
        try:
            found = importlib.import_module(module)
        except ImportError:
            continue
        return found.ClickException, found.UsageError
    raise ImportError("typer without click")  # pragma: no cover


def _usage_line(exc: Exception) -> str:
    """``field: reason`` for a click usage error (the option or argument named when known)."""
    message = str(getattr(exc, "message", "") or exc).strip()
    param = getattr(exc, "param", None)
    option = getattr(exc, "option_name", None)
    if param is not None:
        names = getattr(param, "opts", None) or [getattr(param, "name", None) or "argument"]
        field = str(max(names, key=len))
        if type(exc).__name__ == "MissingParameter":
            field = field if field.startswith("-") else field.upper()
            message = "required but not given"
    elif option:
        field = str(option)
        message = message.replace(f"No such option: {option}", "no such option")
    elif message.lower().startswith("no such command"):
        field, message = (
            "command",
            message[len("no such command") :].strip(" .") + " is not a command",
        )
        message += "; choose from: " + ", ".join(_COMMANDS)
    else:
        field = "usage"
    message = " ".join(message.split()) or type(exc).__name__
    return f"{field}: {message[0].lower()}{message[1:]}"


_COMMANDS = ("presets", "run", "resume", "export", "inspect", "convert", "render", "view")


def _fail(line: str, code: int) -> int:
    sys.stderr.write(f"error: {line}\n")
    sys.stderr.flush()
    return code


def _flags_without_type(command: Any) -> None:
    """Flags take no value, so their help shows none (typer labels them ``<bool>``)."""
    for param in command.params:
        if getattr(param, "is_flag", False):
            param.metavar = ""
    make_help_option = command.get_help_option

    def help_option(ctx: Any) -> Any:
        option = make_help_option(ctx)
        if option is not None:
            option.metavar = ""
        return option

    command.get_help_option = help_option
    for subcommand in getattr(command, "commands", {}).values():
        _flags_without_type(subcommand)


def _compiling_notice() -> None:
    """Say at once why a first run is silent for a while."""
    sys.stderr.write("compiling kernels (first run only)...\n")
    sys.stderr.flush()


def console() -> int:
    """The ``collidium`` program and ``python -m collidium``: `main` on ``sys.argv``, then an
    exit without the interpreter's last garbage collections.

    Those walk every object that numba, scipy and the run made, 0.15 to 0.4 s of the 2 s a
    short run takes, to free memory the process is about to give back whole. So the objects
    left are frozen out of the collector's reach (`gc.freeze`); files are closed as before, by
    their owners. `main` does not do it, for callers that go on (tests, scripts).
    """
    status = main()
    gc.freeze()
    return status


def main(argv: Sequence[str] | None = None) -> int:
    """The command line: runs ``argv`` (default ``sys.argv[1:]``) and returns the exit status
    (0 ok, 1 failed run, 2 bad input)."""
    click_exception, usage_error = _click_exceptions()
    command = typer.main.get_command(app)
    _flags_without_type(command)
    args = list(sys.argv[1:] if argv is None else argv)
    # Like the progress bar, for a person at a terminal; --quiet says nothing but warnings.
    quiet = "--quiet" in args or "-q" in args or not sys.stderr.isatty()
    notice = nullcontext() if quiet else on_first_compile(_compiling_notice)
    try:
        with notice, interrupts_outside_compiling():
            result = command.main(
                args=args,
                prog_name="collidium",
                standalone_mode=False,
            )
    except InputError as exc:
        return _fail(str(exc), 2)
    except ValidationError as exc:
        from collidium.scenario import describe

        return _fail(describe(exc), 2)
    except SimulationError as exc:
        return _fail(f"run: {exc}", 1)
    except usage_error as exc:
        if type(exc).__name__ == "NoArgsIsHelpError":  # bare `collidium`: the help is the answer
            sys.stdout.write(str(getattr(exc, "message", "")))
            return 0
        return _fail(_usage_line(exc), 2)
    except click_exception as exc:
        message = exc.format_message() if hasattr(exc, "format_message") else str(exc)
        return _fail(f"input: {message}", 2)
    except Interrupted as exc:  # a run: where it stopped, what it kept
        return _fail(str(exc), 130)
    except (typer.Abort, KeyboardInterrupt):
        return _fail("interrupted", 130)
    except OSError as exc:  # e.g. the output stream is full or closed
        return _fail(f"output: {exc.strerror or exc}", 1)
    if result == 130:  # Ctrl-C outside a run, which typer answers with a silent exit 130
        return _fail("interrupted", 130)
    return result if isinstance(result, int) else 0
