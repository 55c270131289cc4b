"""Figures and movies of a trajectory: the seed's energy plot, the speed histogram against the
Maxwell-Boltzmann law, and a movie of the vessel beside both (MP4 through imageio-ffmpeg, else GIF
through Pillow).

Figures are `matplotlib.figure.Figure` objects drawn on the Agg canvas, never pyplot's global
state, so nothing needs a display and nothing stays open after a call. A movie builds its figure
once and moves the artists from frame to frame.
"""

from __future__ import annotations

import contextlib
import math
import warnings
from collections.abc import Generator, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import EllipseCollection, LineCollection
from matplotlib.figure import Figure
from matplotlib.patches import Polygon, Rectangle

from collidium.errors import InputError
from collidium.io.atomic import replacing
from collidium.io.trajectory import Trajectory, type_ids
from collidium.observers.energy import plot_energy
from collidium.observers.speeds import SpeedHistogram
from collidium.state import FloatArray

if TYPE_CHECKING:
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.lines import Line2D
    from matplotlib.text import Text

#: Particle colours by type (`collidium.io.trajectory.TYPES`): neutral, positive, negative.
TYPE_COLOURS = ("tab:gray", "tab:red", "tab:blue")

#: Resolution of the saved plots, dots per inch.
PLOT_DPI = 110

#: Movie suffixes written, and what installs the MP4 writer.
MOVIE_SUFFIXES = (".mp4", ".gif")
MOVIE_EXTRA = 'pip install "collidium[movie]"'

_CURVE_POINTS = 300  # samples of the Maxwell-Boltzmann curve
_PANEL_HEIGHT = 6.0  # movie height in inches; the vessel panel is as wide as its aspect asks


# -- series read from a trajectory ----------------------------------------------------------------


def _require_frames(trajectory: Trajectory) -> None:
    if trajectory.frames == 0:
        raise InputError("trajectory", "has no frames to draw")


def _logged(trajectory: Trajectory, key: str) -> FloatArray | None:
    """The first column of log entry ``key`` as a (K,) float array, or None when absent."""
    if key not in trajectory.log:
        return None
    values = np.asarray(trajectory.log[key], dtype=float)
    return values.reshape(values.shape[0], -1)[:, 0]


def _kinetic(trajectory: Trajectory) -> FloatArray:
    """Kinetic energy of each frame, shape (K,), in J: the log entry, else from the velocities."""
    logged = _logged(trajectory, "energy/kinetic")
    if logged is not None:
        return logged
    return 0.5 * np.einsum(
        "i,kij,kij->k", trajectory.mass, trajectory.velocity, trajectory.velocity
    )


def _speed_array(trajectory: Trajectory) -> FloatArray:
    """Speed of every particle in every frame, shape (K, N), in m/s."""
    return np.hypot(trajectory.velocity[..., 0], trajectory.velocity[..., 1])


def _temperatures(trajectory: Trajectory) -> FloatArray:
    """kT = KE / N of each frame, shape (K,), in J: the log entry, else from the velocities."""
    logged = _logged(trajectory, "temperature")
    if logged is not None:
        return logged
    return _kinetic(trajectory) / max(trajectory.n, 1)


def _energy_series(trajectory: Trajectory) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Kinetic (J), potential (J) and total speed (m/s) of each frame, each shape (K,)."""
    potential = _logged(trajectory, "energy/potential")
    if potential is None:
        raise InputError("trajectory", "has no energy/potential log entry to plot")
    total_speed = _logged(trajectory, "energy/total_speed")
    if total_speed is None:
        total_speed = _speed_array(trajectory).sum(axis=1)
    return _kinetic(trajectory), potential, total_speed


def _histogram(
    speed: FloatArray, kT: FloatArray, mass: FloatArray, bins: int, span: tuple[float, float]
) -> SpeedHistogram:
    """A `SpeedHistogram` of F snapshots: speeds (F, N) in m/s, each at its own kT (F,) in J,
    masses (N,) in kg."""
    histogram = SpeedHistogram(bins=bins, range=span)
    for snapshot, temperature in zip(speed, kT, strict=True):
        histogram.add(snapshot, mass, float(temperature))
    return histogram


# -- still figures --------------------------------------------------------------------------------


def _figure(width: float, height: float, dpi: float = PLOT_DPI) -> Figure:
    """A figure on its own Agg canvas (no pyplot), constrained layout, size in inches."""
    figure = Figure(figsize=(width, height), dpi=dpi, layout="constrained")
    FigureCanvasAgg(figure)
    return figure


def energy_figure(trajectory: Trajectory) -> Figure:
    """The seed's energy plot of a trajectory (`collidium.observers.energy.plot_energy`).

    Parameters
    ----------
    trajectory : Trajectory
        K >= 1 frames; its log holds ``energy/potential`` (J) and, optionally,
        ``energy/kinetic`` (J) and ``energy/total_speed`` (m/s), else those come from the
        velocities.

    Returns
    -------
    Figure
        Kinetic, potential and total energy (J) and the total speed (m/s) against time (s).
    """
    _require_frames(trajectory)
    figure = _figure(7.0, 5.2)
    grid = figure.add_gridspec(2, 1, height_ratios=(3, 1))
    energy = figure.add_subplot(grid[0])
    speed = figure.add_subplot(grid[1], sharex=energy)
    energy.tick_params(labelbottom=False)  # the time axis is the panel's below
    _energy_plot(energy, trajectory, speed)
    figure.suptitle(f"energy of {trajectory.n} particles")
    return figure


def _energy_plot(ax: Axes, trajectory: Trajectory, speed_ax: Axes) -> list[Line2D]:
    """`plot_energy` on ``ax``, the total speed on its own small panel ``speed_ax``, with the
    legend moved above the axes, clear of the curves; returns the curves of both."""
    plot_energy(ax, trajectory.time, *_energy_series(trajectory), speed_ax=speed_ax)
    lines = ax.get_lines() + speed_ax.get_lines()
    ax.tick_params(labelbottom=False)
    legend = ax.get_legend()
    if legend is not None:
        legend.remove()
    ax.legend(
        ax.get_lines(),
        [str(line.get_label()) for line in ax.get_lines()],
        loc="lower left",
        ncols=3,
        bbox_to_anchor=(0.0, 1.01, 1.0, 0.1),
        mode="expand",
        frameon=False,
        fontsize="small",
    )
    return lines


def _later_frames(trajectory: Trajectory, start: float | None) -> np.ndarray:
    """Indices of the frames at or after time ``start`` (s); by default the later half."""
    if start is None:
        return np.arange(trajectory.frames // 2, trajectory.frames)
    if not math.isfinite(start):
        raise InputError("start", f"must be a finite time in s, got {start!r}")
    chosen = np.flatnonzero(trajectory.time >= start)
    if chosen.size == 0:
        last = float(trajectory.time[-1])
        raise InputError("start", f"no frame at or after t = {start:g} s (the last is {last:g} s)")
    return chosen


def speed_figure(
    trajectory: Trajectory,
    bins: int = 30,
    range: tuple[float, float] = (0.0, 30.0),
    start: float | None = None,
) -> Figure:
    """Speeds pooled over the later frames, against the 2D Maxwell-Boltzmann law.

    Parameters
    ----------
    trajectory : Trajectory
        K >= 1 frames. Each frame's kT (J) is its ``temperature`` log entry, else KE / N.
    bins : int
        Number of histogram bins.
    range : tuple of float
        Lowest and highest speed binned, m/s.
    start : float, optional
        Pool the frames from this time on, s (default: the later half of the frames).

    Returns
    -------
    Figure
        Probability density (s/m) against speed (m/s) with the Maxwell-Boltzmann curve at the
        mean kT; the title gives the Kolmogorov-Smirnov p-values of the frames one by one (the
        last frame's, and their median and spread), never that of the pooled speeds, which are
        correlated.
    """
    _require_frames(trajectory)
    frames = _later_frames(trajectory, start)
    speed, kT = _speed_array(trajectory)[frames], _temperatures(trajectory)[frames]
    histogram = _histogram(speed, kT, trajectory.mass, bins, range)
    figure = _figure(7.0, 4.5)
    histogram.plot(figure.add_subplot()).set_title(
        _speed_title(trajectory, frames, histogram), fontsize="medium"
    )
    return figure


def _speed_title(trajectory: Trajectory, frames: np.ndarray, histogram: SpeedHistogram) -> str:
    """What the histogram pools, and the Kolmogorov-Smirnov p-values of the frames one by one:
    the last frame's (what ``collidium run --json`` reports for the same run) and the spread
    over the frames. Frames close in time hold nearly the same speeds, so the pooled speeds are
    not independent draws and their own p-value would mean nothing."""
    t0, t1 = float(trajectory.time[frames[0]]), float(trajectory.time[frames[-1]])
    title = f"{histogram.speeds.size} speeds, {len(frames)} frames, t = {t0:.4g} to {t1:.4g} s"
    speed, kT = _speed_array(trajectory), _temperatures(trajectory)
    p = [
        SpeedHistogram().add(speed[k], trajectory.mass, float(kT[k])).ks()[1]
        for k in frames
        if kT[k] > 0 and trajectory.n > 0
    ]
    if p:
        low, middle, high = np.percentile(p, [10, 50, 90])
        title += (f"\nKolmogorov-Smirnov p, last frame: {p[-1]:.3g}; per frame: median "
                  f"{middle:.2g}, 10-90% {low:.2g}-{high:.2g}")  # fmt: skip
    return title


def write_plots(trajectory: Trajectory, folder: str | Path) -> list[Path]:
    """Save ``energy.png`` and ``speeds.png`` (`energy_figure`, `speed_figure`) in ``folder``.

    Parameters
    ----------
    trajectory : Trajectory
        K >= 1 frames.
    folder : str or Path
        Created if missing; files there of the same names are replaced.

    Returns
    -------
    list of Path
        The files written: energy plot, speed histogram.
    """
    folder = Path(folder)
    _require_frames(trajectory)
    created = not folder.exists()
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(str(folder), f"cannot create the folder ({exc.strerror})") from None
    written = []
    try:
        for name, make in (("energy.png", energy_figure), ("speeds.png", speed_figure)):
            figure = make(trajectory)
            path = folder / name
            with replacing(path) as temporary:
                figure.savefig(temporary, dpi=PLOT_DPI)
            figure.clear()
            written.append(path)
    except InputError:
        if created and not written:  # a full disk: leave no empty folder behind
            folder.rmdir()
        raise
    return written


# -- movie ----------------------------------------------------------------------------------------


class _MovieFigure:
    """The movie's figure, built once: the vessel (left), energy and speeds (right).

    The axes, ticks and labels are drawn once into a background; `frame` restores it, moves
    the artists that change (disks, curves, bars, clock) to frame k and draws only those.
    """

    def __init__(
        self, trajectory: Trajectory, dpi: float, bins: int, span: tuple[float, float]
    ) -> None:
        self.trajectory = trajectory
        aspect = min(max(trajectory.width / trajectory.height, 0.5), 2.5)
        vessel_width = 0.85 * _PANEL_HEIGHT * aspect + 0.6
        width = _even_inches(vessel_width + 5.5, dpi)
        height = _even_inches(_PANEL_HEIGHT, dpi)
        self.figure = Figure(figsize=(width, height), dpi=dpi, layout="constrained")
        self.canvas = FigureCanvasAgg(self.figure)
        grid = self.figure.add_gridspec(2, 2, width_ratios=(vessel_width, 5.5))
        self._vessel(self.figure.add_subplot(grid[:, 0]))
        rows = grid[0, 1].subgridspec(2, 1, height_ratios=(3, 1), hspace=0.05)
        energy = self.figure.add_subplot(rows[0])
        self._energy(energy, self.figure.add_subplot(rows[1], sharex=energy))
        self._speeds(self.figure.add_subplot(grid[1, 1]), bins, span)
        self.moving: list[Artist] = [
            self.disk_artist,
            self.point_artist,
            self.piston_artist,
            self.clock,
            *(c[0] for c in self.curves),
            *self.bars,
            self.mb_line,
            *self.legends,
            *self.spines,
        ]
        # Lay out once with the last frame's texts, then keep the axes where they are and keep
        # everything that does not move as the background.
        self._update(int(np.argmax(trajectory.time)))
        self.canvas.draw()
        self.figure.set_layout_engine("none")
        for artist in self.moving:
            artist.set_animated(True)
        self.canvas.draw()
        self.background = self.canvas.copy_from_bbox(self.figure.bbox)

    def _vessel(self, ax: Axes) -> None:
        t = self.trajectory
        ax.add_patch(
            Polygon(
                t.vessel.outline(),
                closed=True,
                fill=False,
                edgecolor="black",
                linewidth=1.2,
                linestyle="--" if t.periodic else "-",
            )
        )
        ax.add_collection(LineCollection(list(t.vessel.partition_lines()), colors="black",
                                         linewidths=1.2))  # fmt: skip
        self.piston_at = t.log.get("piston/position")
        (self.piston_artist,) = ax.plot([], [], color="dimgray", linewidth=4, zorder=4)
        (x0, y0), (x1, y1) = t.vessel.bounds
        margin = 0.02 * max(x1 - x0, y1 - y0)
        ax.set_xlim(x0 - margin, x1 + margin)
        ax.set_ylim(y0 - margin, y1 + margin)
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        colours = np.array(TYPE_COLOURS)[type_ids(t.charge)]
        self.disks = t.radius > 0
        diameter = 2.0 * t.radius[self.disks]
        self.disk_artist = EllipseCollection(
            diameter,
            diameter,
            np.zeros_like(diameter),
            units="xy",
            offsets=t.position[0, self.disks],
            offset_transform=ax.transData,
            facecolors=colours[self.disks],
            edgecolors="black",
            linewidths=0.3,
        )
        ax.add_collection(self.disk_artist, autolim=False)
        points = t.position[0, ~self.disks]
        self.point_artist = ax.scatter(
            points[:, 0], points[:, 1], s=16, c=list(colours[~self.disks]), zorder=3
        )
        self.clock: Text = ax.set_title(" ")
        self.boundary = "periodic" if t.periodic else "reflecting walls"

    def _energy(self, ax: Axes, speed_ax: Axes) -> None:
        self.curves: list[tuple[Line2D, FloatArray, FloatArray]] = [
            (line, np.asarray(line.get_xdata()), np.asarray(line.get_ydata()))
            for line in _energy_plot(ax, self.trajectory, speed_ax)
        ]

    def _speeds(self, ax: Axes, bins: int, span: tuple[float, float]) -> None:
        t = self.trajectory
        speed, kT = _speed_array(t), _temperatures(t)
        frames = [
            _histogram(speed[k : k + 1], kT[k : k + 1], t.mass, bins, span) for k in range(t.frames)
        ]
        self.density = np.stack([h.density for h in frames])
        self.kT = np.array([h.temperature for h in frames])
        self.speed_axis = np.linspace(span[0], span[1], _CURVE_POINTS)
        self.mb = np.stack([_pdf(h, self.speed_axis) for h in frames])
        frames[0].plot(ax)
        self.bars = [bar for bar in ax.patches if isinstance(bar, Rectangle)]
        self.mb_line = ax.get_lines()[0] if ax.get_lines() else ax.plot([], [], "tab:red")[0]
        legend = ax.get_legend()
        texts = legend.get_texts() if legend is not None else []
        self.mb_label = next((t for t in texts if t.get_text().startswith("Maxwell")), None)
        self.legends = [legend] if legend is not None else []
        self.spines = list(ax.spines.values())  # drawn again over the bars
        top = np.nanmax([np.max(self.density), np.nanmax(self.mb, initial=0.0)])
        ax.set_ylim(0.0, 1.1 * top if top > 0 else 1.0)
        ax.set_title("speeds now")

    def _update(self, k: int) -> None:
        """Move the artists to frame ``k``."""
        t = self.trajectory
        self.disk_artist.set_offsets(t.position[k, self.disks])
        self.point_artist.set_offsets(t.position[k, ~self.disks])
        if self.piston_at is not None:
            face = t.vessel.piston_line(float(self.piston_at[k, 0]))
            self.piston_artist.set_data(face[:, 0], face[:, 1])
        self.clock.set_text(f"t = {t.time[k]:.3f} s, {t.n} particles, {self.boundary}")
        for line, x, y in self.curves:
            line.set_data(x[: k + 1], y[: k + 1])
        for bar, height in zip(self.bars, self.density[k], strict=True):
            bar.set_height(height)
        self.mb_line.set_data(self.speed_axis, self.mb[k])
        if self.mb_label is not None:
            self.mb_label.set_text(f"Maxwell-Boltzmann, kT = {self.kT[k]:.4g} J")

    def frame(self, k: int) -> np.ndarray:
        """Draw frame ``k``; the RGB picture, shape (H, W, 3) uint8 (a copy), H and W even."""
        self._update(k)
        self.canvas.restore_region(self.background)
        for artist in self.moving:
            self.figure.draw_artist(artist)
        rgb = np.asarray(self.canvas.buffer_rgba())[..., :3]
        return rgb[: rgb.shape[0] // 2 * 2, : rgb.shape[1] // 2 * 2].copy()

    def close(self) -> None:
        self.figure.clear()


def _pdf(histogram: SpeedHistogram, speed: FloatArray) -> FloatArray:
    """Maxwell-Boltzmann density (s/m) at ``speed``; NaN where the temperature is not > 0."""
    if not histogram.temperature > 0:
        return np.full_like(speed, np.nan)
    return histogram.maxwell_boltzmann().pdf(speed)


def _even_inches(inches: float, dpi: float) -> float:
    """``inches`` rounded so that it spans an even number of pixels at ``dpi``."""
    pixels = max(2, 2 * round(inches * dpi / 2))
    return (pixels + 0.01) / dpi  # a hair more, so that truncation keeps the even count


def write_movie(
    trajectory: Trajectory,
    path: str | Path,
    fps: float = 20,
    progress: bool = False,
    dpi: float = 100,
    *,
    bins: int = 30,
    range: tuple[float, float] = (0.0, 30.0),
) -> Path:
    """A movie with one picture per trajectory frame: the vessel with every particle to scale
    (red positive, blue negative, grey neutral), the energy so far and the current speeds.

    Parameters
    ----------
    trajectory : Trajectory
        K >= 1 frames.
    path : str or Path
        ``.mp4`` (H.264, yuv420p: browsers play it; needs ``collidium[movie]``) or ``.gif``.
        Without imageio-ffmpeg an MP4 request writes a GIF of the same name instead and warns.
        The file appears complete or not at all (written aside, then moved into place). A GIF
        holds its pictures in memory (a byte a pixel) until written: use MP4 for long movies.
    fps : float
        Pictures per second.
    progress : bool
        Show a progress bar on stderr.
    dpi : float
        Pixels per inch of the 6-inch-high picture (100 gives 600 pixels).
    bins : int
        Bins of the speed histogram.
    range : tuple of float
        Speeds histogrammed, m/s.

    Returns
    -------
    Path
        The movie written (the GIF when an MP4 could not be).

    Raises
    ------
    InputError
        For another suffix, no frames, or ``fps`` or ``dpi`` not > 0.
    """
    path = movie_path(path)
    suffix = path.suffix.lower()
    for name, value in (("fps", fps), ("dpi", dpi)):
        if isinstance(value, bool) or not (isinstance(value, int | float) and value > 0):
            raise InputError(name, f"must be a number > 0, got {value!r}")
        if not math.isfinite(value):
            raise InputError(name, f"must be finite, got {value!r}")
    _require_frames(trajectory)
    SpeedHistogram(bins=bins, range=range)  # checks bins and range before any drawing
    if suffix == ".mp4" and not _mp4_available():
        path = path.with_suffix(".gif")
        warnings.warn(
            f"imageio-ffmpeg is not installed, so the movie is written as a GIF, {path}; "
            f"for MP4: {MOVIE_EXTRA}",
            stacklevel=2,
        )
    writer = _write_mp4 if path.suffix.lower() == ".mp4" else _write_gif
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError("--movie", f"cannot create {path.parent} ({exc.strerror})") from None

    movie = _MovieFigure(trajectory, dpi, bins, range)
    pictures = _pictures(movie, trajectory.frames, progress)
    try:
        with replacing(path) as temporary:
            writer(temporary, pictures, fps)
    finally:
        pictures.close()
        movie.close()
    return path


def movie_path(path: str | Path) -> Path:
    """``path`` as a movie's `Path`, refused (`InputError` naming ``--movie``) unless it ends
    in one of `MOVIE_SUFFIXES`: the command line checks it before it runs a scenario."""
    path = Path(path)
    if path.suffix.lower() not in MOVIE_SUFFIXES:
        raise InputError("--movie", f"must end in .mp4 or .gif, got {path.name!r}")
    return path


def snapshot(
    trajectory: Trajectory,
    frame: int = -1,
    dpi: float = 100,
    *,
    bins: int = 30,
    range: tuple[float, float] = (0.0, 30.0),
) -> Figure:
    """The movie's picture of one frame as a figure: the vessel with its particles then, the
    energy up to then and the speeds then (`write_movie`), for a notebook or a report.

    Parameters
    ----------
    trajectory : Trajectory
        K >= 1 frames.
    frame : int
        The frame, counted from the end when negative.
    dpi, bins, range
        As for `write_movie`.
    """
    _require_frames(trajectory)
    if (
        isinstance(frame, bool)
        or not isinstance(frame, int)
        or not -trajectory.frames <= frame < (trajectory.frames)
    ):
        raise InputError("frame", f"must be a frame of the {trajectory.frames}, got {frame!r}")
    SpeedHistogram(bins=bins, range=range)
    movie = _MovieFigure(trajectory, dpi, bins, range)
    movie._update(frame % trajectory.frames)
    for artist in movie.moving:  # drawn with the rest, not blitted
        artist.set_animated(False)
    return movie.figure


def _mp4_available() -> bool:
    """True when imageio-ffmpeg and its ffmpeg binary can be used."""
    try:
        import imageio_ffmpeg

        imageio_ffmpeg.get_ffmpeg_exe()
    except (ImportError, RuntimeError):
        return False
    return True


def _pictures(
    movie: _MovieFigure, frames: int, progress: bool
) -> Generator[np.ndarray, None, None]:
    """Each frame's picture in turn, with a transient progress bar on stderr if asked."""
    bar: contextlib.AbstractContextManager[Any] = contextlib.nullcontext()
    if progress:
        from rich.console import Console
        from rich.progress import Progress

        bar = Progress(console=Console(stderr=True), transient=True)
    with bar as shown:
        task = shown.add_task("rendering", total=frames) if progress else None
        for k in range(frames):
            yield movie.frame(k)
            if task is not None:
                shown.advance(task)


def _write_mp4(target: Path, pictures: Iterator[np.ndarray], fps: float) -> None:
    """H.264 in yuv420p (the pixel format browsers decode) through imageio-ffmpeg."""
    import imageio_ffmpeg

    first = next(pictures)
    height, width = first.shape[:2]
    stream = imageio_ffmpeg.write_frames(
        str(target),
        (width, height),
        fps=fps,
        codec="libx264",
        pix_fmt_out="yuv420p",
        quality=7,
        macro_block_size=2,
        output_params=["-movflags", "+faststart"],
    )
    stream.send(None)  # start ffmpeg
    try:
        stream.send(np.ascontiguousarray(first))
        for picture in pictures:
            stream.send(np.ascontiguousarray(picture))
    finally:
        stream.close()


def _write_gif(target: Path, pictures: Iterator[np.ndarray], fps: float) -> None:
    """An endlessly looping GIF through Pillow, every picture on the first one's palette."""
    from PIL import Image

    first = Image.fromarray(next(pictures)).quantize(colors=256)

    def on_palette(picture: np.ndarray) -> Image.Image:
        return Image.fromarray(picture).quantize(palette=first, dither=Image.Dither.NONE)

    rest = [on_palette(picture) for picture in pictures]
    first.save(
        target, format="GIF", save_all=True, append_images=rest, duration=1000.0 / fps, loop=0
    )
