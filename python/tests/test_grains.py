"""The Python module against the command line (same files, same bits), theory (the settled
bed's forces carry its weight; Bauer's law recovered from its own points) and the GPU (same
bits as the CPU in f32 on lavapipe).

Needs the command-line binary (``cargo build --release``; ``GRAINS_BIN`` names another). Under
``CI=true`` a missing binary or GPU adapter fails; elsewhere the test is skipped."""

from __future__ import annotations

import math
import os
import re
import signal
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import grains

REPO = Path(__file__).resolve().parents[2]
CI = os.environ.get("CI") == "true"


def cli() -> Path:
    path = Path(os.environ.get("GRAINS_BIN", REPO / "target" / "release" / "grains"))
    if not path.exists():
        if CI:
            pytest.fail(f"no grains binary at {path}; build it with cargo build --release")
        pytest.skip(f"no grains binary at {path}; build it with cargo build --release")
    return path


def run_cli(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(cli()), *args], cwd=cwd, capture_output=True, text=True)


def small_scene(dir: Path, hold: float = 0.02) -> Path:
    """The quickstart with 200 grains, a pour of at most 0.08 s and a second stage that holds
    the bed for `hold` seconds (about 1.5 s of wall time on two cores in all)."""
    text = (REPO / "scenes" / "quickstart.toml").read_text()
    text = re.sub(r"(?m)^count = 600$", "count = 200", text)
    text = re.sub(r"(?m)^duration = 0\.3 .*$", "duration = 0.08", text)
    text += f'\n[[stage]]\nname = "hold"\nkind = "run"\nduration = {hold}\n'
    path = dir / "small.toml"
    path.write_text(text)
    return path


def same_files(a: Path, b: Path, names=("stats.csv", "stages.csv", "frames.mcap")) -> None:
    for name in names:
        assert (a / name).read_bytes() == (b / name).read_bytes(), f"{name} differs between {a} and {b}"


def test_quickstart_from_python_writes_the_clis_files(tmp_path: Path) -> None:
    """`Simulation(...).run()` on the README's quickstart writes stats.csv, stages.csv and
    frames.mcap byte-equal to `grains run`'s, and open_run reads them back."""
    scene_file = REPO / "scenes" / "quickstart.toml"
    done = run_cli("run", str(scene_file), "--out", str(tmp_path / "cli"), "--json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    sim = grains.Simulation(grains.Scene.load(scene_file), out=tmp_path / "py", progress=False)
    summary = sim.run()
    same_files(tmp_path / "cli", tmp_path / "py")
    r = grains.open_run(tmp_path / "py")
    assert r.summary["steps"] == summary["steps"] == sim.steps
    assert len(r.stats["step"]) == len(r.stats["time_s"]) > 10
    assert r.stats["step"][-1] == sim.steps
    assert list(r.stages["stage"]) == ["pour"]
    # The last frame at the frame interval (5 ms), before the settled end: the same grains,
    # none moved by a tenth of a diameter since.
    frame, state = r.last_frame(), sim.state()
    assert sim.time - 5e-3 <= frame["time"] <= sim.time
    assert np.array_equal(frame["ids"], state["ids"]) and np.array_equal(frame["radii"], state["radii"])
    assert np.abs(frame["positions"] - state["positions"]).max() < 1e-4


def test_a_settled_beds_contact_forces_carry_its_weight(tmp_path: Path) -> None:
    """Arrays have their documented shapes, dtypes and units: on the settled quickstart the
    grains' net contact forces sum to their weight, m g with m from the radii (m) and the
    density (kg/m^3), within 1%; each contact's force on i has `normal_force` along `normal`."""
    scene = grains.Scene.load(REPO / "scenes" / "quickstart.toml")
    sim = grains.Simulation(scene, progress=False)
    sim.run()
    s = sim.state()
    n = 600
    assert s["ids"].dtype == np.uint32 and np.array_equal(s["ids"], np.arange(n))
    assert s["materials"].dtype == np.uint16 and s["materials"].shape == (n,)
    assert s["radii"].dtype == np.float64 and s["radii"].shape == (n,)
    assert np.all((s["radii"] >= 0.425e-3) & (s["radii"] <= 0.575e-3))
    for key in ("positions", "velocities", "angular_velocities", "forces"):
        assert s[key].shape == (n, 3) and s[key].dtype == np.float64, key
    assert np.all((s["positions"] > -1e-4) & (s["positions"] < 18.1e-3))
    density = scene["material.sand.density"]
    weight = (density * 4.0 / 3.0 * math.pi * s["radii"] ** 3).sum() * 9.81
    total = s["forces"].sum(axis=0)
    assert abs(total[2] - weight) < 0.01 * weight, (total, weight)
    assert np.all(np.abs(total[:2]) < 0.01 * weight)
    c = sim.contacts()
    m = len(c["i"])
    assert m > n and c["normal"].shape == (m, 3) and np.all(c["i"] < c["j"])
    assert np.allclose(np.linalg.norm(c["normal"], axis=1), 1.0, atol=1e-12)
    along = np.einsum("ij,ij->i", c["force"], c["normal"])
    assert np.allclose(along, c["normal_force"], rtol=1e-9, atol=1e-12 * np.abs(c["normal_force"]).max())
    assert np.allclose(np.einsum("ij,ij->i", c["tangential_force"], c["normal"]), 0.0, atol=1e-12 * np.abs(c["normal_force"]).max())
    assert np.all(c["overlap"] > 0.0)
    stats = sim.stats()
    assert stats["step"] == sim.steps and stats["contacts"] == m


def test_a_parameter_set_from_python_runs_as_the_same_toml_edit(tmp_path: Path) -> None:
    """scene["material.sand.mu_s"] = 0.2 gives the bits of the same edit made in the file, and
    not those of the unedited scene."""
    path = small_scene(tmp_path)
    edited = tmp_path / "edited.toml"
    edited.write_text(re.sub(r"(?m)^mu_s = 0\.5 .*$", "mu_s = 0.2", path.read_text()))
    done = run_cli("run", str(edited), "--out", str(tmp_path / "cli"), "--json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    scene = grains.Scene.load(path)
    assert scene.unchanged and scene["material.sand.mu_s"] == 0.5
    scene["material.sand.mu_s"] = 0.2
    assert not scene.unchanged and scene["material.sand.mu_s"] == 0.2
    grains.Simulation(scene, out=tmp_path / "py", progress=False).run()
    same_files(tmp_path / "cli", tmp_path / "py")
    grains.Simulation(grains.Scene.load(path), out=tmp_path / "plain", progress=False).run()
    assert (tmp_path / "plain" / "stats.csv").read_bytes() != (tmp_path / "py" / "stats.csv").read_bytes()


def box_named_and_staged(tmp_path: Path, stage_keys: str) -> Path:
    """The small scene with its box named "bin": run by the command line into tmp_path/cli with
    `stage_keys` added to its second stage; returns the scene without them, for Python to do
    the same between the stages."""
    text = small_scene(tmp_path).read_text().replace('type = "box"', 'type = "box"\nname = "bin"')
    named = tmp_path / "named.toml"
    named.write_text(text)
    staged = tmp_path / "staged.toml"
    staged.write_text(text.replace('name = "hold"', f'name = "hold"\n{stage_keys}'))
    done = run_cli("run", str(staged), "--out", str(tmp_path / "cli"), "--json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    return named


def test_a_wall_set_moving_from_python_moves_as_a_stages_walls_do(tmp_path: Path) -> None:
    """The small scene's box given a name: its second stage moving the box by its `walls` key
    (run by the command line) and the same motion set from Python between the stages end in the
    same files; a name that moves nothing raises SceneError naming it."""
    sim = grains.Simulation(grains.Scene.load(box_named_and_staged(tmp_path, "walls = { bin = { velocity = [0.02, 0.0, 0.0] } }")), out=tmp_path / "py", progress=False)
    sim.run_stage()
    sim.set_wall_motion("bin", velocity=(0.02, 0.0, 0.0))
    sim.run()
    same_files(tmp_path / "cli", tmp_path / "py")
    with pytest.raises(grains.SceneError, match=r'set_wall_motion = "gate": names no wall'):
        sim.set_wall_motion("gate", velocity=(1.0, 0.0, 0.0))


def test_a_wall_taken_away_from_python_goes_as_a_stages_remove_walls_does(tmp_path: Path) -> None:
    """The small scene's box given a name: its second stage taking the box's floor away by its
    `remove_walls` key (run by the command line) and the same floor taken away from Python
    between the stages end in the same files, the grains falling out of the box; adding it back
    under the grains that fell through it raises SimulationError naming the wall."""
    sim = grains.Simulation(grains.Scene.load(box_named_and_staged(tmp_path, 'remove_walls = ["bin.bottom"]')), out=tmp_path / "py", progress=False)
    sim.run_stage()
    floor = sim.state()["positions"][:, 2].min()
    sim.set_wall_present("bin.bottom", False)
    sim.run()
    same_files(tmp_path / "cli", tmp_path / "py")
    assert sim.state()["positions"][:, 2].min() < floor - 1e-3
    with pytest.raises(grains.SimulationError, match=r"set_wall_present adds wall bin.bottom, which grain \d+ .* overlaps by"):
        sim.set_wall_present("bin.bottom", True)


def test_bad_scenes_raise_the_named_errors_with_the_clis_message(tmp_path: Path) -> None:
    """A negative friction coefficient: SceneError with the message `grains check` prints; a
    path that names nothing: KeyError; an invalid value set is not kept."""
    good = small_scene(tmp_path)
    bad = tmp_path / "bad.toml"
    bad.write_text(re.sub(r"(?m)^mu_s = 0\.5 .*$", "mu_s = -0.5", good.read_text()))
    done = run_cli("check", str(bad), cwd=tmp_path)
    assert done.returncode != 0
    with pytest.raises(grains.SceneError) as e:
        grains.Scene.load(bad)
    assert done.stderr.strip() == f"error: {e.value}"
    assert issubclass(grains.SceneError, grains.GrainsError)
    scene = grains.Scene.load(good)
    with pytest.raises(grains.SceneError, match="mu_s"):
        scene["material.sand.mu_s"] = -0.5
    assert scene["material.sand.mu_s"] == 0.5 and scene.unchanged
    with pytest.raises(KeyError, match="glass"):
        scene["material.glass.mu_s"] = 0.3
    with pytest.raises(grains.SceneError):
        grains.Scene.from_toml("name = 3")


def test_other_threads_run_while_the_engine_steps(tmp_path: Path) -> None:
    """`advance` releases the interpreter's lock: a Python thread counts meanwhile."""
    sim = grains.Simulation(grains.Scene.load(small_scene(tmp_path)), progress=False)
    count = [0]
    stop = threading.Event()

    def counter() -> None:
        while not stop.is_set():
            count[0] += 1

    t = threading.Thread(target=counter)
    t.start()
    time.sleep(0.05)
    before = count[0]
    started = time.perf_counter()
    sim.advance(steps=20_000)
    took = time.perf_counter() - started
    during = count[0] - before
    stop.set()
    t.join()
    assert sim.steps == 20_000
    # With the lock held the counter would have stood still for the whole advance.
    assert took > 0.05 and during > 1000, (took, during)


def test_ctrl_c_stops_an_advance_after_whole_steps(tmp_path: Path) -> None:
    """SIGINT during a long advance raises KeyboardInterrupt at the next statistics interval;
    the simulation goes on from there."""
    scene = grains.Scene.load(small_scene(tmp_path))
    sim = grains.Simulation(scene, progress=False)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        sim.advance(steps=10**9)
    timer.join()
    stopped = sim.steps
    assert 0 < stopped < 10**9 and stopped % sim.stats_interval == 0, (stopped, sim.stats_interval)
    sim.advance(steps=100)
    assert sim.steps == stopped + 100
    # By time: whole steps, rounded up.
    before, t0 = sim.steps, sim.time
    sim.advance(time=1e-4)
    assert sim.steps - before == math.ceil(1e-4 / sim.dt)
    assert abs((sim.time - t0) - (sim.steps - before) * sim.dt) < 1e-12
    with pytest.raises(ValueError):
        sim.advance(steps=10, time=1e-4)


def test_checkpoints_pass_between_python_and_the_cli(tmp_path: Path) -> None:
    """A checkpoint written from Python after the first stage resumes from the command line,
    and one the command line wrote after the first stage resumes from Python; each finished
    run's stats.csv and stages.csv are the uninterrupted run's bytes."""
    path = small_scene(tmp_path, hold=0.15)
    whole = run_cli("run", str(path), "--out", str(tmp_path / "whole"), "--json", cwd=tmp_path)
    assert whole.returncode == 0, whole.stderr

    py = tmp_path / "py"
    sim = grains.Simulation(grains.Scene.load(path), out=py, progress=False)
    first = sim.run_stage()
    assert first is not None and first["name"] == "pour"
    sim.save_checkpoint()
    del sim
    done = run_cli("run", "--resume", str(py), "--json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    same_files(tmp_path / "whole", py, names=("stats.csv", "stages.csv"))

    # The command line killed once its first checkpoint (the pour's end) is on disk.
    out = tmp_path / "cli"
    proc = subprocess.Popen([str(cli()), "run", str(path), "--out", str(out), "--json"], cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    while not (out / "checkpoint.grains").exists() and proc.poll() is None:
        time.sleep(0.002)
    proc.kill()
    proc.wait()
    assert not (out / "summary.json").exists(), "the hold stage ended before the kill; lengthen it"
    sim = grains.Simulation.resume(out, progress=False)
    assert sim.stages == (["pour", "hold"], 1)
    sim.run()
    same_files(tmp_path / "whole", out, names=("stats.csv", "stages.csv"))


def test_the_gpu_from_python_gives_the_cpus_bits_in_f32(tmp_path: Path) -> None:
    """The GPU engine (lavapipe in CI) and the CPU engine in f32 step the same scene to the
    same bits."""
    scene = grains.Scene.load(REPO / "scenes" / "elastic_gas.toml")
    try:
        gpu = grains.Simulation(scene, backend="gpu", progress=False)
    except grains.SimulationError as e:
        if CI:
            raise
        pytest.skip(f"no GPU adapter: {e}")
    cpu = grains.Simulation(scene, precision="f32", progress=False)
    for sim in (gpu, cpu):
        sim.advance(steps=500)
    a, b = gpu.state(), cpu.state()
    assert gpu.backend == "gpu" and cpu.precision == "f32"
    for key in ("positions", "velocities", "angular_velocities"):
        assert np.array_equal(a[key], b[key]), key


def test_bauers_law_is_recovered_from_its_own_points() -> None:
    """fit_bauer on points of e = e0 exp(-(p/h_s)^eta) returns h_s, eta and e0 to 1e-6."""
    e0, h_s, eta = 0.70, 2.0e8, 0.45
    p = np.geomspace(25e3, 1.6e6, 8)
    e = e0 * np.exp(-((p / h_s) ** eta))
    fit = grains.fit_bauer(p, e)
    assert abs(fit["h_s"]["value"] / h_s - 1) < 1e-6
    assert abs(fit["eta"]["value"] / eta - 1) < 1e-6
    assert abs(fit["e0"]["value"] / e0 - 1) < 1e-6
    with pytest.raises(ValueError):
        grains.fit_bauer([1e5, 2e5], [0.6])


def test_a_finished_runs_force_transmission_is_grains_analyzes(tmp_path: Path) -> None:
    """open_run(dir).force_transmission() equals `grains analyze DIR --json` on the same run
    (recorded with its contact forces, set from Python)."""
    import json

    scene = grains.Scene.load(small_scene(tmp_path))
    scene["output.contact_forces"] = True
    out = tmp_path / "run"
    grains.Simulation(scene, out=out, progress=False).run()
    ours = grains.open_run(out).force_transmission()
    done = run_cli("analyze", str(out), "--json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert ours == json.loads(done.stdout)
    # A settled bed's force network: most contacts carry less than the mean force.
    assert ours["force_scale_is"] == "mean force" and 0.5 < ours["below_mean"] < 0.75, ours["below_mean"]


def test_a_progress_callback_hears_every_statistics_read_and_can_stop_the_run(tmp_path: Path) -> None:
    """`progress=callable` is called at every statistics read inside a stage with the steps
    done and the stage's most; one that raises stops the stage there with that exception,
    keeping the files, and the run then says how to continue."""
    path = small_scene(tmp_path)
    heard = []
    sim = grains.Simulation(grains.Scene.load(path), progress=lambda stage, done, total: heard.append((stage, done, total)))
    sim.run()
    stages = sim.summary["stages"]
    assert [s["name"] for s in stages] == ["pour", "hold"]
    for s in stages:
        reads = [(d, t) for name, d, t in heard if name == s["name"]]
        assert reads[-1][0] == s["steps"] and all(d % sim.stats_interval == 0 or d == s["steps"] for d, _ in reads)
        assert len(reads) == math.ceil(s["steps"] / sim.stats_interval)

    class Enough(Exception):
        pass

    interval = sim.stats_interval

    def stop(stage: str, done: int, total: int) -> None:
        # The running simulation refuses calls from its own callback rather than deadlock.
        with pytest.raises(grains.SimulationError, match="running a call already"):
            sim2.steps
        if done >= 10 * interval:
            raise Enough(stage)

    out = tmp_path / "stopped"
    sim2 = grains.Simulation(grains.Scene.load(path), out=out, progress=stop)
    with pytest.raises(Enough):
        sim2.run()
    # It stops at the read after the one whose callback raised, with the rows up to it kept.
    assert sim2.steps == 11 * sim2.stats_interval
    assert (out / "stats.csv").read_text().count("\n") == 1 + 11
    with pytest.raises(grains.SimulationError, match="resume"):
        sim2.run_stage()


def test_a_changed_scene_with_a_mesh_resumes_from_its_run_folder(tmp_path: Path) -> None:
    """scenes/silo.toml names its mesh relative to its folder; changed from Python, its text is
    kept in the run folder as scene.toml, with the mesh named by an absolute path, so that
    `Simulation.resume` there reads the same plate and goes on after the first stage."""
    scene = grains.Scene.load(REPO / "scenes" / "silo.toml")
    scene.update({"generate.0.count": 200, "stage.0.duration": 0.01, "stage.1.duration": 0.005})
    out = tmp_path / "run"
    sim = grains.Simulation(scene, out=out, progress=False)
    sim.run_stage()
    kept = (out / "scene.toml").read_text()
    plate = str((REPO / "scenes" / "meshes" / "orifice_plate_10mm.stl").resolve())
    assert plate in kept, kept
    resumed = grains.Simulation.resume(out, progress=False)
    assert resumed.stages == (["fill", "discharge"], 1)
    resumed.run()
    assert resumed.time > sim.time


def test_ctrl_c_stops_a_run_which_resumes_from_its_last_checkpoint(tmp_path: Path) -> None:
    """SIGINT inside the second stage of `run()` raises KeyboardInterrupt with the files kept;
    the run then refuses to go on in place, and `Simulation.resume(out)` continues it from the
    first stage's checkpoint to the uninterrupted run's bytes."""
    path = small_scene(tmp_path, hold=0.15)
    whole = run_cli("run", str(path), "--out", str(tmp_path / "whole"), "--json", cwd=tmp_path)
    assert whole.returncode == 0, whole.stderr
    sent = []

    def interrupt_in_hold(stage: str, done: int, total: int) -> None:
        if stage == "hold" and not sent:
            sent.append(done)
            os.kill(os.getpid(), signal.SIGINT)

    out = tmp_path / "run"
    sim = grains.Simulation(grains.Scene.load(path), out=out, progress=interrupt_in_hold)
    with pytest.raises(KeyboardInterrupt):
        sim.run()
    assert sent and not (out / "summary.json").exists()
    rows = (out / "stats.csv").read_text().count("\n")
    assert rows > 1
    with pytest.raises(grains.SimulationError, match="resume"):
        sim.run()
    resumed = grains.Simulation.resume(out, progress=False)
    assert resumed.stages == (["pour", "hold"], 1)
    resumed.run()
    same_files(tmp_path / "whole", out, names=("stats.csv", "stages.csv"))
