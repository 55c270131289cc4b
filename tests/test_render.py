"""Figures and movies of a trajectory (collidium.render): PNG plots, GIF and MP4 movies, the GIF
fallback without imageio-ffmpeg, and files that appear complete or not at all."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import collidium as cd
from collidium import render
from collidium.errors import InputError
from collidium.io.trajectory import GSDWriter, Trajectory, read_trajectory
from collidium.observers.speeds import SpeedHistogram
from collidium.vessels import Box

DPI = 40  # small pictures keep the movies fast
TAB_BLUE = (31, 119, 180)
TAB_RED = (214, 39, 40)
TAB_GRAY = (127, 127, 127)


def record(folder: Path, name: str, **parameters: object) -> Trajectory:
    """Six frames (t = 0, 0.1, ..., 0.5 s) of a preset, through a GSD file."""
    sim = cd.load(name, **parameters)
    writer = GSDWriter(folder / f"{name}.gsd", trigger=10)
    sim.observers.append(writer)
    sim.run(time=0.5)
    writer.close()
    return read_trajectory(folder / f"{name}.gsd")


@pytest.fixture(scope="module")
def gas(tmp_path_factory) -> Trajectory:
    return record(tmp_path_factory.mktemp("gas"), "gas", n=20, seed=1)


@pytest.fixture(scope="module")
def charged(tmp_path_factory) -> Trajectory:
    return record(tmp_path_factory.mktemp("charged"), "charged-gas", n=20, seed=2)


def near(picture: np.ndarray, colour: tuple[int, int, int], tolerance: int = 30) -> int:
    """How many pixels of an (H, W, 3) picture lie within ``tolerance`` of ``colour``."""
    difference = np.abs(picture[..., :3].astype(int) - np.array(colour))
    return int(np.sum(difference.max(axis=-1) <= tolerance))


def vessel(picture: np.ndarray) -> np.ndarray:
    """The vessel panel of a movie picture: its left part below the title (the energy and speed
    panels, right, use the same colours)."""
    height, width = picture.shape[:2]
    return picture[height // 8 :, : int(0.45 * width)]


def gif_frames(path: Path) -> list[np.ndarray]:
    with Image.open(path) as gif:
        pictures = []
        for k in range(gif.n_frames):
            gif.seek(k)
            pictures.append(np.asarray(gif.convert("RGB")))
        return pictures


# -- plots ----------------------------------------------------------------------------------------


def test_write_plots_saves_two_pngs_of_the_expected_size(charged, tmp_path):
    folder = tmp_path / "made" / "here"
    paths = render.write_plots(charged, folder)
    assert paths == [folder / "energy.png", folder / "speeds.png"]
    assert sorted(p.name for p in folder.iterdir()) == ["energy.png", "speeds.png"]
    pictures = {}
    for path in paths:
        with Image.open(path) as image:
            assert image.format == "PNG"
            figure = (render.energy_figure if path.stem == "energy" else render.speed_figure)(
                charged
            )
            width, height = figure.get_size_inches() * render.PLOT_DPI
            assert image.size == (round(width), round(height))
            pictures[path.stem] = np.asarray(image.convert("RGB"))
    for picture in pictures.values():
        assert picture.std() > 20  # not blank
    energy, speeds = pictures["energy"], pictures["speeds"]
    assert near(energy, TAB_BLUE) > 50  # kinetic energy, the seed's blue
    assert np.sum(energy.max(axis=-1) < 40) > 200  # total energy in black, and the text
    assert near(speeds, TAB_RED) > 50  # the Maxwell-Boltzmann curve
    assert near(speeds, TAB_GRAY, 10) > 500  # the bars


def test_energy_figure_plots_the_logged_series(charged):
    figure = render.energy_figure(charged)
    ax = figure.axes[0]
    curves = {line.get_label(): line for a in figure.axes for line in a.get_lines()}
    assert set(curves) == {"kinetic", "potential", "total", "total speed"}
    np.testing.assert_allclose(curves["kinetic"].get_xdata(), charged.time)
    np.testing.assert_allclose(curves["kinetic"].get_ydata(), charged.log["energy/kinetic"][:, 0])
    np.testing.assert_allclose(
        curves["total speed"].get_ydata(), charged.log["energy/total_speed"][:, 0]
    )
    assert ax.get_ylabel() == "energy (J)"
    speed_panel = figure.axes[1]  # the total speed on a small panel of its own, below
    assert [line.get_label() for line in speed_panel.get_lines()] == ["total speed"]
    assert speed_panel.get_xlabel() == "time (s)"
    assert speed_panel.bbox.height < ax.bbox.height / 2


def test_speed_figure_pools_the_later_half_and_gives_each_frames_ks_p_value(gas):
    """The histogram pools the later frames; the title gives the KS p-values frame by frame
    (the last frame's, the median and spread), never the pooled speeds' (they are correlated)."""
    expected = SpeedHistogram()
    per_frame = []
    for k in range(gas.frames // 2, gas.frames):
        speeds, kT = np.hypot(*gas.velocity[k].T), float(gas.log["temperature"][k, 0])
        expected.add(speeds, gas.mass, kT)
        per_frame.append(SpeedHistogram().add(speeds, gas.mass, kT).ks()[1])
    ax = render.speed_figure(gas).axes[0]
    heights = [bar.get_height() for bar in ax.patches]
    np.testing.assert_allclose(heights, expected.density)
    title = ax.get_title()
    assert f"last frame: {per_frame[-1]:.3g}" in title
    assert f"median {np.median(per_frame):.2g}" in title
    assert f"p = {expected.ks()[1]:.3g}" not in title
    assert f"{gas.frames - gas.frames // 2} frames" in title


def test_speed_figures_last_frame_p_value_is_the_runs(tmp_path):
    """`collidium render` and `collidium run --json` of the same run give the same p-value (to
    the single precision the trajectory stores velocities in)."""
    import json
    import subprocess

    def cli(*args):
        command = [sys.executable, "-m", "collidium", *args]
        return subprocess.run(command, cwd=tmp_path, capture_output=True, text=True, check=True)

    summary = json.loads(cli("run", "gas", "--time", "5", "--json", "--out", "g.gsd").stdout)
    title = render.speed_figure(read_trajectory(tmp_path / "g.gsd")).axes[0].get_title()
    assert f"last frame: {summary['ks_pvalue']:.3g}" in title


def test_speed_figure_from_a_start_time(gas):
    ax = render.speed_figure(gas, bins=10, range=(0.0, 20.0), start=0.35).axes[0]
    assert len(ax.patches) == 10
    assert "2 frames" in ax.get_title()  # t = 0.4 and 0.5 s
    with pytest.raises(InputError) as error:
        render.speed_figure(gas, start=9.0)
    assert error.value.field == "start"


def test_temperature_and_kinetic_energy_come_from_the_velocities_without_a_log(gas):
    bare = dataclasses.replace(gas, log={"energy/potential": gas.log["energy/potential"]})
    figure = render.energy_figure(bare)
    kinetic = next(line for line in figure.axes[0].get_lines() if line.get_label() == "kinetic")
    # Velocities are stored in single precision, so the sums agree to about 1e-7.
    np.testing.assert_allclose(kinetic.get_ydata(), gas.log["energy/kinetic"][:, 0], rtol=1e-5)
    title = render.speed_figure(bare).axes[0].get_title()
    assert "last frame: " in title
    assert title.split("p, ")[1] == render.speed_figure(gas).axes[0].get_title().split("p, ")[1]


# -- movies ---------------------------------------------------------------------------------------


def test_gif_has_one_picture_per_frame_with_the_particles_coloured(charged, gas, tmp_path):
    path = render.write_movie(charged, tmp_path / "charged.gif", fps=10, dpi=DPI)
    assert path == tmp_path / "charged.gif"
    with Image.open(path) as gif:
        assert gif.format == "GIF"
        assert gif.n_frames == charged.frames
        assert gif.size[0] % 2 == 0 and gif.size[1] % 2 == 0
        assert gif.info["duration"] == 100
        assert gif.info["loop"] == 0
    pictures = gif_frames(path)
    for picture in pictures:
        assert near(vessel(picture), TAB_RED) > 20  # positive charges
        assert near(vessel(picture), TAB_BLUE) > 20  # negative charges
    assert not np.array_equal(vessel(pictures[0]), vessel(pictures[-1]))  # the particles move

    neutral = gif_frames(render.write_movie(gas, tmp_path / "gas.gif", dpi=DPI))[0]
    assert near(vessel(neutral), TAB_GRAY) > 100
    assert near(vessel(neutral), TAB_RED) == 0
    assert near(vessel(neutral), TAB_BLUE) == 0


def test_mp4_is_h264_yuv420p_with_one_picture_per_frame(charged, tmp_path):
    import imageio_ffmpeg

    path = render.write_movie(charged, tmp_path / "charged.mp4", fps=12, dpi=DPI)
    assert path == tmp_path / "charged.mp4"
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    frames = sum(1 for _ in reader)
    assert meta["codec"] == "h264"
    assert meta["pix_fmt"].startswith("yuv420p")
    assert meta["fps"] == 12
    width, height = meta["size"]
    assert width % 2 == 0 and height % 2 == 0
    assert (width, height) == gif_frames(
        render.write_movie(charged, tmp_path / "same.gif", dpi=DPI)
    )[0].shape[1::-1]
    assert frames == charged.frames
    assert sorted(p.name for p in tmp_path.iterdir()) == ["charged.mp4", "same.gif"]


def test_mp4_without_imageio_ffmpeg_falls_back_to_gif(gas, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # importing it now fails
    with pytest.warns(UserWarning, match=r"GIF.*pip install \"collidium\[movie\]\"") as warned:
        path = render.write_movie(gas, tmp_path / "movie.mp4", dpi=DPI)
    assert len(warned) == 1
    assert "\n" not in str(warned[0].message)
    assert path == tmp_path / "movie.gif"
    with Image.open(path) as gif:
        assert gif.format == "GIF"
        assert gif.n_frames == gas.frames
    assert [p.name for p in tmp_path.iterdir()] == ["movie.gif"]


def test_other_suffixes_are_refused(gas, tmp_path):
    with pytest.raises(InputError) as error:
        render.write_movie(gas, tmp_path / "movie.avi")
    assert error.value.field == "--movie"
    assert ".mp4 or .gif" in error.value.reason
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_failed_render_leaves_no_partial_file(gas, tmp_path, monkeypatch, suffix):
    target = tmp_path / f"movie{suffix}"
    target.write_bytes(b"an earlier movie")
    drawn = []
    frame = render._MovieFigure.frame

    def failing(self, k):
        drawn.append(k)
        if len(drawn) > 3:  # the first draw lays the figure out; fail two pictures later
            raise RuntimeError("drawing failed")
        return frame(self, k)

    monkeypatch.setattr(render._MovieFigure, "frame", failing)
    with pytest.raises(RuntimeError, match="drawing failed"):
        render.write_movie(gas, target, dpi=DPI)
    assert [p.name for p in tmp_path.iterdir()] == [target.name]
    assert target.read_bytes() == b"an earlier movie"


def test_trajectory_without_frames_is_refused(gas, tmp_path):
    empty = dataclasses.replace(
        gas,
        step=gas.step[:0],
        time=gas.time[:0],
        position=gas.position[:0],
        velocity=gas.velocity[:0],
        log={key: value[:0] for key, value in gas.log.items()},
    )
    for call in (
        lambda: render.write_movie(empty, tmp_path / "movie.gif"),
        lambda: render.write_plots(empty, tmp_path),
    ):
        with pytest.raises(InputError, match="no frames"):
            call()
    assert list(tmp_path.iterdir()) == []


def test_progress_bar_keeps_stdout_clean(gas, tmp_path, capsys):
    path = render.write_movie(gas, tmp_path / "movie.gif", dpi=DPI, progress=True)
    assert path.is_file()
    assert capsys.readouterr().out == ""


# -- the movie's picture --------------------------------------------------------------------------


def one_disk(radius: float, charge: float) -> Trajectory:
    """Two frames of one particle at rest at (2, -1) m in a 20 m x 10 m box."""
    frames = 2
    return Trajectory(
        vessel=Box(20.0, 10.0),
        step=np.arange(frames),
        time=np.array([0.0, 0.1]),
        position=np.tile([[[2.0, -1.0]]], (frames, 1, 1)),
        velocity=np.zeros((frames, 1, 2)),
        mass=np.ones(1),
        radius=np.array([radius]),
        charge=np.array([charge]),
        log={"energy/potential": np.zeros((frames, 1))},
    )


def test_disks_are_drawn_to_scale():
    radius = 2.0
    movie = render._MovieFigure(one_disk(radius, 1.0), 60, 30, (0.0, 30.0))
    picture = movie.frame(0)
    scale = movie.disk_artist.axes.transData.transform([[0.0, 0.0], [1.0, 0.0]])
    pixels_per_metre = scale[1, 0] - scale[0, 0]
    area = np.pi * (radius * pixels_per_metre) ** 2
    assert near(picture, TAB_RED) == pytest.approx(area, rel=0.1)
    red = np.argwhere(np.abs(picture.astype(int) - TAB_RED).max(axis=-1) <= 30)
    centre = movie.disk_artist.axes.transData.transform([2.0, -1.0])
    row = picture.shape[0] - centre[1]  # pixel rows count from the top
    np.testing.assert_allclose(red.mean(axis=0), [row, centre[0]], atol=1.5)


def test_points_of_radius_zero_are_drawn_as_markers():
    movie = render._MovieFigure(one_disk(0.0, -1.0), 100, 30, (0.0, 30.0))
    # A marker of 4 points is about 5.6 pixels across at 100 dpi, whatever the box.
    assert 10 < near(vessel(movie.frame(0)), TAB_BLUE) < 60


def test_pictures_are_redrawn_from_a_clean_background(charged):
    movie = render._MovieFigure(charged, DPI, 30, (0.0, 30.0))
    first = movie.frame(0)
    last = movie.frame(charged.frames - 1)
    assert first.shape == last.shape
    assert first.shape[0] % 2 == 0 and first.shape[1] % 2 == 0
    assert not np.array_equal(first, last)
    np.testing.assert_array_equal(movie.frame(0), first)  # nothing left over from the last


def test_snapshot_draws_the_frame_asked_for(charged):
    """The snapshot of frame k draws the particles where they were then, the energy up to then
    and the speeds then (the movie's picture of that frame); a frame that does not exist is
    refused by name."""
    from matplotlib.collections import EllipseCollection

    for k in (0, 3, -1):
        figure = render.snapshot(charged, k, dpi=DPI)
        scene, energy, _ = figure.axes[:3]
        assert scene.get_title().startswith(f"t = {charged.time[k]:.3f} s")
        (disks,) = [c for c in scene.collections if isinstance(c, EllipseCollection)]
        np.testing.assert_array_equal(disks.get_offsets(), charged.position[k])
        shown = k % charged.frames + 1
        assert all(len(line.get_xdata()) == shown for line in energy.get_lines()[:3])
        assert not any(artist.get_animated() for artist in disks.axes.get_children())
    for frame in (charged.frames, -charged.frames - 1, 1.5):
        with pytest.raises(InputError, match="frame"):
            render.snapshot(charged, frame)  # type: ignore[arg-type]
