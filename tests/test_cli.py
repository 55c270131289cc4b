"""The command line, run as ``python -m collidium`` in a subprocess."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from collidium.cli import parse_settings
from collidium.presets import presets


def collidium(*args: str | Path, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "collidium", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=300,
        check=False,
    )


def without_wall_time(summary: dict) -> dict:
    return {key: value for key, value in summary.items() if key != "wall_seconds"}


def test_presets_json():
    result = collidium("presets", "--json")
    assert result.returncode == 0, result.stderr
    entries = json.loads(result.stdout)
    assert [e["name"] for e in entries] == presets()
    assert {"name", "section", "description", "parameters"} <= set(entries[0])


def test_presets_table():
    result = collidium("presets")
    assert result.returncode == 0, result.stderr
    assert "pool-break" in result.stdout and "4.1.1" in result.stdout


def test_run_head_on_json():
    result = collidium("run", "head-on", "--time", "1", "--json")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["scenario"] == "head-on"
    assert summary["n"] == 2
    assert summary["time"] == pytest.approx(1.0)
    assert summary["steps"] == 100
    assert summary["wall_seconds"] >= 0
    energy = summary["energy"]
    assert set(energy) >= {"kinetic", "potential", "total", "initial_total", "max_rel_drift"}
    assert energy["total"] == pytest.approx(25.0, rel=1e-12)
    assert energy["initial_total"] == pytest.approx(25.0, rel=1e-12)
    assert energy["max_rel_drift"] < 1e-12
    assert summary["momentum"] == pytest.approx([0.0, 0.0], abs=1e-12)
    assert summary["collisions"]["pair"] == 1
    assert summary["escaped"] == 0


def test_run_table_and_steps():
    result = collidium("run", "right-angle", "--steps", "20", "--dt", "0.005")
    assert result.returncode == 0, result.stderr
    assert "right-angle" in result.stdout and "escaped" in result.stdout


def test_export_then_run_file_gives_the_same_numbers(tmp_path):
    path = tmp_path / "gas.toml"
    exported = collidium("export", "gas", "--set", "n=60", "--set", "seed=4", "-o", path)
    assert exported.returncode == 0, exported.stderr
    assert exported.stdout == ""
    assert [p.name for p in tmp_path.iterdir()] == ["gas.toml"]  # no temporary left behind
    from_preset = collidium("run", "gas", "--set", "n=60", "--seed", "4", "--time", "0.5", "--json")
    from_file = collidium("run", path, "--time", "0.5", "--json")
    assert from_preset.returncode == 0, from_preset.stderr
    assert from_file.returncode == 0, from_file.stderr
    a, b = json.loads(from_preset.stdout), json.loads(from_file.stdout)
    assert without_wall_time(a) == without_wall_time(b)
    assert a["n"] == 60 and a["collisions"]["pair"] + a["collisions"]["wall"] > 0


def test_export_to_stdout_and_set_dotted_path():
    result = collidium("export", "orbit", "--set", "run.collisions=step")
    assert result.returncode == 0, result.stderr
    assert 'name = "orbit"' in result.stdout and 'collisions = "step"' in result.stdout


def test_run_file_with_set_and_aliases(tmp_path):
    path = tmp_path / "h.toml"
    assert collidium("export", "head-on", "-o", path).returncode == 0
    result = collidium("run", path, "--set", "run.dt=0.02", "--steps", "5", "--json")
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["dt"] == 0.02


BAD_TOML = 'name = "x"\n[box\nwidth = 3\n'
EXTRA = '[[particles]]\nkind = "random"\nn = 3\ncolour = "red"\n'
NEGATIVE_MASS = '[[particles]]\nkind = "explicit"\nposition = [[0.0, 0.0]]\nmass = -1.0\n'
OVERLAP = '[[particles]]\nkind = "explicit"\nposition = [[0.0, 0.0], [0.3, 0.0]]\n'
OUTSIDE = '[[particles]]\nkind = "explicit"\nposition = [[0.0, 0.0], [12.0, 0.0]]\n'
DT_ZERO = '[run]\ndt = 0.0\n[[particles]]\nkind = "random"\nn = 3\n'
UNKNOWN_FORCE = '[[forces]]\ntype = "yukawa"\n[[particles]]\nkind = "random"\nn = 3\n'
NEGATIVE_G = '[[forces]]\ntype = "newton"\nG = -1.0\n[[particles]]\nkind = "random"\nn = 3\n'
COLD_BATH = (
    '[[forces]]\ntype = "langevin"\ntemperature = 0.0\n[[particles]]\nkind = "random"\nn = 3\n'
)
NEGATIVE_GAMMA = (
    '[[forces]]\ntype = "linear_drag"\ngamma = -2.0\n[[particles]]\nkind = "random"\nn = 3\n'
)
BAD_MAP = (
    '[[forces]]\ntype = "field_map"\npotential = [[1.0, 2.0], [3.0]]\n'
    '[[particles]]\nkind = "random"\nn = 3\n'
)
PISTON_OUTSIDE = (
    '[vessel.walls.top]\nresponse = "piston"\nposition = 11.0\n'
    '[[particles]]\nkind = "random"\nn = 3\n'
)
DEEP_TABLE = "a." * 500 + "a = 1\n"
DEEP_ARRAY = "a = " + "[" * 5000 + "]" * 5000 + "\n"
LONG_SEED = "seed = " + "9" * 5000 + '\n[[particles]]\nkind = "random"\nn = 3\n'
HUGE_BOX = '[vessel]\nwidth = 1e308\nheight = 1e308\n[[particles]]\nkind = "random"\nn = 3\n'
PISTON_STEP = (
    '[vessel.walls.top]\nresponse = "piston"\nposition = 5.0\n[run]\ncollisions = "step"\n'
    '[[particles]]\nkind = "random"\nn = 3\n'
)


@pytest.mark.parametrize(
    ("args", "toml", "field"),
    [
        (["run", "no-such-preset"], None, "preset"),
        (["export", "no-such-preset"], None, "preset"),
        (["run", "{file}"], BAD_TOML, "{file}"),
        (["run", "{file}"], EXTRA, "particles.0.colour"),
        (["run", "{file}"], NEGATIVE_MASS, "particles.0.mass"),
        (["run", "{file}"], DT_ZERO, "run.dt"),
        (["run", "{file}"], UNKNOWN_FORCE, "forces.0.type"),
        (["run", "{file}"], NEGATIVE_G, "forces.0.G"),
        (["run", "{file}"], COLD_BATH, "forces.0.temperature"),
        (["run", "{file}"], NEGATIVE_GAMMA, "forces.0.gamma"),
        (["run", "{file}"], BAD_MAP, "forces.0.potential"),
        (["run", "drag", "--set", "gamma=-1"], None, "gamma"),
        (["run", "{file}"], OVERLAP, "particles.0.position.1"),
        (["run", "{file}"], OUTSIDE, "particles.0.position.1"),
        (["run", "{file}"], PISTON_OUTSIDE, "vessel.walls.top.position"),
        (["run", "{file}"], PISTON_STEP, "run.collisions"),
        (["run", "piston", "--set", "force=-1"], None, "force"),
        (["run", "{file}"], DEEP_TABLE, "a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a"),
        (["run", "{file}"], DEEP_ARRAY, "{file}"),
        (["run", "{file}"], LONG_SEED, "{file}"),
        (["run", "{file}"], HUGE_BOX, "vessel.width"),
        (["run", "gas", "--set", "vessel." + "a." * 600 + "a=1"], None, "vessel" + ".a" * 16),
        (["run", "gas", "--set", "n=" + "9" * 5000], None, "n"),
        (["run", "gas", "--set", "x=" + "[" * 3000 + "]" * 3000], None, "x"),
        (["run", "gas", "--set", "width=1e308", "--set", "height=1e308"], None, "vessel.width"),
        (["run", "gas", "--set", "speed=1e308"], None, "speed"),  # past light's
        (["run", "gas", "--set", "mass=1e300", "--set", "speed=1e8"], None, "particles.velocity"),
        (["run", "/dev/zero"], None, "/dev/zero"),
        (["run", "gas", "--set", "name=0"], None, "name"),  # not the preset's own name
        (["run", "effusion", "--set", "gap=30"], None, "vessel.partitions.divider.gap"),
        (["run", "head-on", "--dt", "0"], None, "dt"),
        (["run", "head-on", "--dt", "nan"], None, "dt"),
        (["run", "head-on", "--set", "run.dt=nan"], None, "run.dt"),
        (["run", "head-on", "--set", "mass=-1"], None, "mass"),
        (["run", "orbit", "--set", "run.tolerance=0"], None, "run.tolerance"),
        (["run", "orbit", "--set", "run.tolerance=nan"], None, "run.tolerance"),
        (["run", "orbit", "--set", "tolerance=-1e-3"], None, "tolerance"),
        (["run", "orbit", "--set", "run.integrator=rk4"], None, "run.integrator"),
        (["run", "orbit", "--max-drift", "0"], None, "--max-drift"),
        (["run", "orbit", "--max-drift", "nan"], None, "--max-drift"),
        (["run", "head-on", "--time", "1", "--steps", "3"], None, "--time"),
        (["run", "head-on", "--time", "abc"], None, "--time"),
        (["run", "head-on", "--steps", "1.5"], None, "--steps"),
        (["run", "head-on", "--set", "n=5"], None, "n"),
        (["run", "head-on", "--set", "novalue"], None, "--set"),
        (["run", "head-on", "--frobnicate"], None, "--frobnicate"),
        (["run", "missing.toml"], None, "missing.toml"),
        (["export", "gas", "-o", "no/such/dir/gas.toml"], None, "no/such/dir/gas.toml"),
        (["dance"], None, "command"),
        (["run", "head-on", "--out", "run.txt"], None, "--out"),
        (["run", "head-on", "--out", "run.gsd", "--every", "0"], None, "--every"),
        (["run", "head-on", "--checkpoint-every", "5"], None, "--checkpoint-every"),
        (["run", "head-on", "--out", "no/such/dir/run.gsd"], None, "--out"),
        (["run", "head-on", "--checkpoint", "no/such/dir/r.ckpt"], None, "--checkpoint"),
        (["resume", "missing.ckpt"], None, "missing.ckpt"),
        (["resume", "{file}"], BAD_TOML, "{file}"),
        (["inspect", "{file}"], BAD_TOML, "{file}"),
        (["inspect", "missing.gsd"], None, "missing.gsd"),
        (["convert", "missing.gsd", "out.xyz"], None, "missing.gsd"),
        (["convert", "missing.gsd", "out.txt"], None, "target"),
        (["render", "head-on"], None, "--plots"),
        (["render", "head-on", "--movie", "m.avi"], None, "--movie"),
        (["render", "head-on", "--plots", "p", "--fps", "0"], None, "--fps"),
        (["render", "{file}", "--plots", "p"], EXTRA, "particles.0.colour"),
    ],
)
def test_bad_input_gives_one_line_and_exit_2(tmp_path, args, toml, field):
    file = tmp_path / "scenario.toml"
    if toml is not None:
        file.write_text(toml)
    result = collidium(*(a.replace("{file}", str(file)) for a in args), cwd=tmp_path)
    assert result.returncode == 2, result.stdout + result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(f"error: {field.replace('{file}', str(file))}: "), lines[0]
    assert "Traceback" not in result.stderr
    assert result.stdout == ""
    # Nothing half-written: the folder holds at most the scenario file the test wrote.
    assert {p.name for p in tmp_path.iterdir()} <= {"scenario.toml"}


def test_a_pipe_is_refused_at_once_rather_than_read_forever(tmp_path):
    pipe = tmp_path / "scenario.toml"
    os.mkfifo(pipe)
    result = collidium("run", pipe)
    assert result.returncode == 2 and result.stderr == f"error: {pipe}: not a regular file\n"


@pytest.mark.parametrize("limit", [0, 20_000])
@pytest.mark.parametrize("output", [("--out", "run.gsd"), ("--out", "run.xyz"),
                                    ("--checkpoint", "run.ckpt")])  # fmt: skip
def test_a_file_that_cannot_grow_gets_one_line_and_exit_2(tmp_path, output, limit):
    """Writes that fail as on a full disk (here: past a file-size limit, EFBIG) end the run with
    one line naming the user's file; no staging or temporary file is left behind."""
    import resource

    def limit_file_size() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    result = subprocess.run(
        [sys.executable, "-m", "collidium", "run", "gas", "--time", "5", *output],
        capture_output=True, text=True, cwd=tmp_path, timeout=300, preexec_fn=limit_file_size,
    )  # fmt: skip
    name = output[1]
    assert result.returncode == 2, result.stderr
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr
    assert f"{tmp_path / name}: cannot write" in result.stderr and "File too large" in result.stderr
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == (["run.gsd"] if name == "run.gsd" and limit > 0 else [])
    if left:  # the frames flushed before the failure are readable
        inspected = collidium("inspect", "run.gsd", "--json", cwd=tmp_path)
        assert inspected.returncode == 0 and json.loads(inspected.stdout)["frames"] >= 1


def test_bad_toml_error_names_the_line(tmp_path):
    file = tmp_path / "broken.toml"
    file.write_text(BAD_TOML)
    result = collidium("run", file)
    assert "line 2" in result.stderr


def test_failed_export_leaves_no_file(tmp_path):
    target = tmp_path / "out.toml"
    result = collidium("export", "gas", "--set", "n=-1", "-o", target)
    assert result.returncode == 2
    assert list(tmp_path.iterdir()) == []


def test_parse_settings_reads_toml_values():
    values = parse_settings(["n=500", "k=2.5", "collisions=step", "flag=true", "apex=[1, 2]"])
    assert values == {"n": 500, "k": 2.5, "collisions": "step", "flag": True, "apex": [1, 2]}
    assert type(values["n"]) is int and type(values["k"]) is float


class _Terminal:
    """A stderr that says it is a terminal, keeping what is written."""

    def __init__(self) -> None:
        self.text = ""

    def write(self, text: str) -> None:
        self.text += text

    def flush(self) -> None:
        pass

    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize("quiet", [False, True])
def test_a_first_compile_is_announced_once_at_a_terminal(monkeypatch, quiet):
    """A first run, made here (the suite's cache is warm) by compiling two fresh kernels while
    the command loads its scenario: one notice for both, none with --quiet."""
    import numba

    import collidium.loading
    from collidium.cli import main

    load = collidium.loading.load_scenario

    def compile_then_load(source, **overrides):
        numba.njit(lambda x: x + 1)(1)
        numba.njit(lambda x: x + 2)(1)
        return load(source, **overrides)

    terminal = _Terminal()
    monkeypatch.setattr(collidium.loading, "load_scenario", compile_then_load)
    monkeypatch.setattr(sys, "stderr", terminal)
    # --json: no progress bar on the terminal beside the notice
    assert main(["run", "head-on", "--steps", "1", "--json", *(["-q"] if quiet else [])]) == 0
    notice = "compiling kernels (first run only)...\n"
    assert terminal.text == ("" if quiet else notice)


def test_the_program_exits_with_the_status_of_main_and_its_objects_out_of_the_collector(
    monkeypatch, capsys
):
    """`console` (the ``collidium`` program) returns what `main` does on ``sys.argv`` and leaves
    the objects it made frozen, so that the interpreter's last collections pass them by."""
    import gc

    from collidium.cli import console

    monkeypatch.setattr(sys, "argv", ["collidium", "run", "gas", "--set", "n=-1"])
    try:
        assert console() == 2
        assert gc.get_freeze_count() > 0
    finally:
        gc.unfreeze()
    assert capsys.readouterr().err == "error: n: must be >= 0, got -1\n"


def test_failed_run_gives_one_line_and_exit_1(monkeypatch, capsys):
    import collidium.loading
    from collidium.cli import main
    from collidium.errors import SimulationError

    def explode(source, **overrides):
        raise SimulationError("step 3 (t = 0.03 s): particle(s) 0, 1 a non-finite position")

    monkeypatch.setattr(collidium.loading, "load_scenario", explode)
    assert main(["run", "head-on", "--json"]) == 1
    captured = capsys.readouterr()
    assert (
        captured.err == "error: run: step 3 (t = 0.03 s): particle(s) 0, 1 a non-finite position\n"
    )
    assert captured.out == ""


def test_no_arguments_shows_help():
    result = collidium()
    assert result.returncode == 0
    assert "run" in result.stdout and "export" in result.stdout


def test_run_json_reports_thermodynamics():
    result = collidium("run", "gas", "--time", "20", "--json")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    kT = summary["energy"]["kinetic"] / 200
    assert summary["temperature"] == pytest.approx(kT, rel=1e-12)  # hard disks: KE constant
    pressure = summary["pressure"]
    assert set(pressure["walls"]) == {"left", "right", "bottom", "top"}
    spread = 3 * (pressure["wall_error"] ** 2 + pressure["virial_error"] ** 2) ** 0.5
    assert abs(pressure["wall"] - pressure["virial"]) < spread
    assert 0.01 < summary["ks_pvalue"] <= 1.0
    collisions = summary["collisions"]
    assert collisions["rate"] == pytest.approx(collisions["pair"] / 20.0, rel=1e-12)
    assert collisions["mean_free_time"] == pytest.approx(200 * 20.0 / (2 * collisions["pair"]))


def test_run_table_shows_temperature_and_pressure():
    result = collidium("run", "charged-gas", "--time", "1")
    assert result.returncode == 0, result.stderr
    for label in ("temperature kT", "wall pressure", "virial pressure", "KS p-value"):
        assert label in result.stdout


@pytest.mark.slow
def test_run_effusion_reports_each_species_crossings_and_grahams_ratio():
    result = collidium("run", "effusion", "--time", "30", "--json")
    assert result.returncode == 0, result.stderr
    (effusion,) = json.loads(result.stdout)["observers"]
    assert effusion["observer"] == "Effusion" and effusion["partition"] == "divider"
    assert effusion["masses"] == [1.0, 4.0] and effusion["graham"] == 2.0
    assert effusion["crossings"][0] > effusion["crossings"][1] > 0
    table = collidium("run", "effusion", "--time", "30")
    assert "lightest / heaviest rate" in table.stdout and "(Graham: 2)" in table.stdout
    piston = collidium("run", "piston", "--time", "1")
    assert "piston (top) work on the gas" in piston.stdout


def test_trajectory_inspect_and_convert(tmp_path):
    result = collidium("run", "gas", "--time", "1", "--out", "run.gsd", "--every", "20",
                       cwd=tmp_path)  # fmt: skip
    assert result.returncode == 0, result.stderr
    facts = json.loads(collidium("inspect", "run.gsd", "--json", cwd=tmp_path).stdout)
    assert facts["frames"] == 6 and facts["n"] == 200 and facts["steps"] == [0, 100]
    assert "energy/total" in facts["log"]
    table = collidium("inspect", "run.gsd", cwd=tmp_path)
    assert table.returncode == 0 and "frames" in table.stdout
    assert collidium("convert", "run.gsd", "run.xyz", cwd=tmp_path).returncode == 0
    assert (tmp_path / "run.xyz").read_text().count("Lattice=") == 6


def test_xyz_output_directly(tmp_path):
    result = collidium("run", "head-on", "--steps", "10", "--out", "run.xyz", "--every", "5",
                       cwd=tmp_path)  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.xyz"]  # the staging .gsd is gone
    assert (tmp_path / "run.xyz").read_text().count("Lattice=") == 3


@pytest.mark.slow
def test_killed_run_resumes_bitwise(tmp_path):
    """SIGKILL a checkpointed run once its first checkpoint is on disk, resume it, and compare
    the final state and the whole trajectory with the same run never stopped."""
    import collidium as cd
    from collidium.io.trajectory import read_trajectory

    # Seconds of work with a checkpoint half-way, so frames past it reach the disk (flushed
    # every second, and at each checkpoint) well before the run ends.
    args = ["run", "gas", "--set", "n=600", "--set", "speed=40", "--steps", "24000", "--every",
            "1500"]  # fmt: skip
    whole = collidium(*args, "--out", "whole.gsd", "--checkpoint", "whole.ckpt", cwd=tmp_path)
    assert whole.returncode == 0, whole.stderr
    command = [sys.executable, "-m", "collidium", *args, "--out", "part.gsd", "--checkpoint",
               "part.ckpt", "--checkpoint-every", "12000"]  # fmt: skip
    process = subprocess.Popen(command, cwd=tmp_path, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120

    def past_checkpoint() -> bool:
        """A checkpoint is on disk and frames after it too (the resume must cut them)."""
        if not (tmp_path / "part.ckpt").exists():
            return False
        try:
            last = read_trajectory(tmp_path / "part.gsd").step[-1]
            return bool(last > cd.restore(tmp_path / "part.ckpt").steps)
        except cd.InputError:  # caught mid-write
            return False

    while not past_checkpoint() and time.monotonic() < deadline and process.poll() is None:
        time.sleep(0.05)
    process.send_signal(signal.SIGKILL)
    process.wait()
    assert process.returncode == -signal.SIGKILL
    stopped = cd.restore(tmp_path / "part.ckpt").steps
    assert stopped < 24000
    assert read_trajectory(tmp_path / "part.gsd").step[-1] > stopped
    resumed = collidium("resume", "part.ckpt", "--json", cwd=tmp_path)
    assert resumed.returncode == 0, resumed.stderr
    assert json.loads(resumed.stdout)["steps"] == 24000
    a, b = cd.restore(tmp_path / "whole.ckpt"), cd.restore(tmp_path / "part.ckpt")
    assert a.steps == b.steps == 24000
    np.testing.assert_array_equal(a.particles.position, b.particles.position)
    np.testing.assert_array_equal(a.particles.velocity, b.particles.velocity)
    ta, tb = read_trajectory(tmp_path / "whole.gsd"), read_trajectory(tmp_path / "part.gsd")
    np.testing.assert_array_equal(ta.step, 1500 * np.arange(17))
    np.testing.assert_array_equal(ta.step, tb.step)
    np.testing.assert_array_equal(ta.position, tb.position)
    for key in ta.log:
        np.testing.assert_array_equal(ta.log[key], tb.log[key])


def test_render_from_a_scenario_and_from_a_trajectory(tmp_path):
    result = collidium("render", "charged-gas", "--time", "0.5", "--every", "10", "--plots",
                       "plots", "--movie", "m.gif", cwd=tmp_path)  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["plots/energy.png", "plots/speeds.png", "m.gif"]
    for name in ("plots/energy.png", "plots/speeds.png", "m.gif"):
        assert (tmp_path / name).stat().st_size > 10_000
    collidium("run", "head-on", "--steps", "20", "--out", "r.gsd", "--every", "5", cwd=tmp_path)
    result = collidium("render", "r.gsd", "--movie", "r.mp4", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "r.mp4").read_bytes()[4:8] == b"ftyp"  # an MP4 container


def test_scenario_trajectory_is_complete_after_a_cli_run(tmp_path):
    from collidium.io.trajectory import read_trajectory
    from collidium.loading import load_scenario

    text = load_scenario("gas").to_toml()
    text += '\n[[observers]]\nkind = "trajectory"\npath = "mine.gsd"\nevery = 10\n'
    (tmp_path / "gas.toml").write_text(text)
    result = collidium("run", "gas.toml", "--steps", "100", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert read_trajectory(tmp_path / "mine.gsd").frames == 11


@pytest.mark.parametrize("kind", ["gsd", "ckpt"])
def test_truncated_files_give_one_line_on_every_command(tmp_path, kind):
    extra = ["--out", "run.gsd"] if kind == "gsd" else ["--checkpoint", "run.ckpt"]
    assert collidium("run", "gas", "--steps", "50", *extra, cwd=tmp_path).returncode == 0
    path = tmp_path / f"run.{kind}"
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    commands = [["inspect", path.name]]
    commands += (
        [["render", path.name, "--plots", "p"], ["convert", path.name, "x.xyz"]]
        if (kind == "gsd")
        else [["resume", path.name]]
    )
    for command in commands:
        result = collidium(*command, cwd=tmp_path)
        assert result.returncode == 2, result.stderr
        assert result.stderr.startswith(f"error: {path.name}: ") and result.stderr.count("\n") == 1
        assert "Traceback" not in result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


def test_a_bad_movie_name_is_refused_before_the_scenario_runs(tmp_path, monkeypatch, capsys):
    from collidium import runner
    from collidium.cli import main

    def record(*args, **kwargs):
        raise AssertionError("the scenario ran")

    monkeypatch.setattr(runner, "record", record)
    code = main(["render", "head-on", "--movie", str(tmp_path / "m.avi")])
    assert code == 2
    assert capsys.readouterr().err == "error: --movie: must end in .mp4 or .gif, got 'm.avi'\n"


def test_movie_without_ffmpeg_falls_back_to_gif_with_a_one_line_warning(tmp_path, capsys):
    import sys as system

    from collidium.cli import main

    saved = system.modules.get("imageio_ffmpeg")
    system.modules["imageio_ffmpeg"] = None  # type: ignore[assignment]
    try:
        code = main(["render", "head-on", "--time", "0.2", "--every", "5", "--movie",
                     str(tmp_path / "m.mp4")])  # fmt: skip
    finally:
        if saved is not None:
            system.modules["imageio_ffmpeg"] = saved
        else:
            del system.modules["imageio_ffmpeg"]
    captured = capsys.readouterr()
    assert code == 0
    assert captured.out.strip() == str(tmp_path / "m.gif")
    (line,) = captured.err.splitlines()
    assert line.startswith("warning: imageio-ffmpeg is not installed") and "[movie]" in line


@pytest.mark.parametrize(
    ("args", "line"),
    [
        (["nope"], "error: preset: unknown preset 'nope'"),
        (["gas", "--set", "n=300000"], "error: n: 300000 particles; the viewer takes at most"),
        (["gas", "--port", "70000"], "error: --port: must be in [0, 65535], got 70000"),
        (["gas", "--host", "nosuchhost.invalid"], "error: --host: cannot resolve"),
    ],
)
def test_view_refuses_bad_input_in_one_line(args, line):
    result = collidium("view", *args, "--no-browser")
    assert result.returncode == 2
    assert result.stderr.startswith(line) and result.stderr.count("\n") == 1


def _ends_within(process: subprocess.Popen[str], seconds: float) -> tuple[str, str]:
    """What ``process`` wrote, once it has ended within ``seconds``; else it is killed (not left
    running beside the rest of the suite) and the test fails."""
    try:
        return process.communicate(timeout=seconds)
    except subprocess.TimeoutExpired:
        process.kill()
        process.communicate()
        raise


def test_view_serves_the_page_until_interrupted():
    import urllib.request

    process = subprocess.Popen(
        [sys.executable, "-m", "collidium", "view", "gas", "--port", "0", "--no-browser"],
        stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        line = process.stderr.readline()
        assert line.startswith("collidium viewer at http://127.0.0.1:")
        url = line.split()[3]
        with urllib.request.urlopen(url, timeout=10) as page:
            assert b"collidium viewer" in page.read()
        taken = collidium("view", "--port", url.rsplit(":", 1)[1].strip("/"), "--no-browser")
        assert taken.returncode == 2 and "error: --port: cannot listen" in taken.stderr
    finally:
        process.send_signal(signal.SIGINT)
        _, rest = _ends_within(process, 20)
    assert process.returncode == 0
    assert "Traceback" not in rest


def test_view_warns_when_it_listens_beyond_this_machine():
    process = subprocess.Popen(
        [sys.executable, "-m", "collidium", "view", "--host", "0.0.0.0", "--port", "0",
         "--no-browser"],
        stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        warning = process.stderr.readline()
        assert warning.startswith("warning: --host 0.0.0.0 lets every machine")
        assert process.stderr.readline().startswith("collidium viewer at http://127.0.0.1:")
    finally:
        process.send_signal(signal.SIGINT)
        _ends_within(process, 20)


def test_energy_drift_warns_and_max_drift_fails_the_run():
    """The seed's fixed step drifts 0.6% in 2 s of the charged gas: a warning in the table and
    the JSON; with --max-drift the run exits 1 with one line. The adaptive default stays clean."""
    fixed = ["run", "charged-gas", "--time", "2", "--set", "run.integrator=fixed"]
    table = collidium(*fixed)
    assert table.returncode == 0, table.stderr
    assert "warning" in table.stdout and "drifted by" in table.stdout
    failed = collidium(*fixed, "--json", "--max-drift", "1e-3")
    assert failed.returncode == 1
    summary = json.loads(failed.stdout)
    assert summary["energy"]["max_rel_drift"] > 1e-3
    assert "drifted by" in summary["energy"]["warning"]
    assert failed.stderr.splitlines() == [f"error: --max-drift: {summary['energy']['warning']}"]
    clean = collidium("run", "charged-gas", "--time", "1", "--json", "--max-drift", "1e-5")
    assert clean.returncode == 0, clean.stderr
    assert json.loads(clean.stdout)["energy"]["warning"] is None


def test_version_and_help_without_flag_types_or_empty_brackets(capsys):
    import collidium as cd
    from collidium.cli import main

    assert collidium("--version").stdout == f"collidium {cd.__version__}\n"
    commands = ["", "presets", "run", "resume", "inspect", "convert", "render", "export",
                "sweep", "view"]  # fmt: skip
    for command in commands:  # in this process: ten interpreters would take seconds
        assert main([*([command] if command else []), "--help"]) == 0
        shown = capsys.readouterr().out
        assert "Usage: collidium" in shown
        assert "<bool>" not in shown and "()" not in shown, shown


def test_a_few_bodies_get_no_temperature_compressibility_or_maxwell_boltzmann_test():
    table = collidium("run", "orbit", "--time", "1").stdout
    assert table.count("n/a (2 particles, not a gas)") == 3
    summary = json.loads(collidium("run", "orbit", "--time", "1", "--json").stdout)
    assert summary["ks_pvalue"] is None and summary["temperature"] > 0  # kT = KE/N is defined


def test_ctrl_c_says_where_the_run_stopped_and_what_it_kept(tmp_path):
    command = [sys.executable, "-m", "collidium", "run", "gas", "--set", "n=600", "--time",
               "100000", "--out", "r.gsd", "--checkpoint", "r.ckpt", "--checkpoint-every",
               "2000"]  # fmt: skip
    process = subprocess.Popen(command, cwd=tmp_path, stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE, text=True)  # fmt: skip
    deadline = time.monotonic() + 120
    while not (tmp_path / "r.ckpt").exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    process.send_signal(signal.SIGINT)
    _, stderr = _ends_within(process, 120)
    assert process.returncode == 130
    assert stderr.count("\n") == 1 and stderr.startswith("error: interrupted at step "), stderr
    from collidium.io.trajectory import read_trajectory

    last = int(read_trajectory(tmp_path / "r.gsd").step[-1])
    assert f"{tmp_path / 'r.gsd'} (frames to step {last})" in stderr
    assert f"{tmp_path / 'r.ckpt'} (step " in stderr and "collidium resume" in stderr


@pytest.mark.parametrize("name", ["effusion", "piston", "heat-flow"])
def test_the_run_table_fits_80_columns(name):
    """The presets with the most rows and the longest values (walls, species, the piston)."""
    result = collidium("run", name, "--time", "1")
    assert result.returncode == 0, result.stderr
    assert max(len(line) for line in result.stdout.splitlines()) <= 80


def test_quiet_says_nothing_but_warnings_and_verbose_says_what_runs(tmp_path):
    quiet = collidium("run", "gas", "--time", "1", "-q")
    assert (quiet.returncode, quiet.stdout, quiet.stderr) == (0, "", "")
    exploding = ["run", "charged-gas", "--time", "1", "--set", "k=5000", "--set",
                 "run.integrator=fixed", "-q"]  # fmt: skip
    warned = collidium(*exploding)
    assert warned.returncode == 0 and warned.stdout == ""
    assert warned.stderr.startswith("warning: the total energy drifted by")
    assert warned.stderr.count("\n") == 1
    failed = collidium(*exploding, "--max-drift", "0.1")
    assert failed.returncode == 1 and failed.stdout == "" and failed.stderr.count("\n") == 1
    verbose = collidium("run", "gas", "--time", "1", "-v", "--out", "v.gsd", cwd=tmp_path)
    assert verbose.returncode == 0
    assert verbose.stderr.startswith(
        "running gas: 200 particles, 100 steps of 0.01 s from t = 0 s, exact collisions, "
        f"adaptive integrator; writing {tmp_path / 'v.gsd'}\n"
    )
    assert "collidium run: gas" in verbose.stdout  # the summary as usual
    both = collidium("run", "gas", "-q", "-v")
    assert both.returncode == 2 and both.stderr.startswith("error: --quiet:")
