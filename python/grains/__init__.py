"""grains from Python: scenes, simulations and finished runs, with NumPy arrays in SI units.

The Rust library is the one implementation: a ``Simulation`` is the engine and host loop that
``grains run`` drives, and what it records into ``out`` is what ``grains run --out`` records.

    import grains
    scene = grains.Scene.load("scenes/quickstart.toml")
    scene["material.glass.mu_s"] = 0.3
    sim = grains.Simulation(scene, out="out/q")
    summary = sim.run()
    state = sim.state()          # positions (n, 3) in m, velocities in m/s, forces in N, ...

The API reference is docs/python.md in the repository.
"""

from __future__ import annotations

import csv
import json
import math
import os
import sys
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _grains
from ._grains import GrainsError, Scene, SceneError, SimulationError, __version__

__all__ = [
    "Scene",
    "Simulation",
    "RunResults",
    "open_run",
    "fit_bauer",
    "GrainsError",
    "SceneError",
    "SimulationError",
    "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]


class Simulation:
    """An engine on a scene, with the host loop's stages and the run's outputs.

    ``backend`` is ``"cpu"`` or ``"gpu"``; ``precision`` ``"f32"`` or ``"f64"`` (default: f64
    on the CPU, f32 on the GPU); ``threads`` the CPU's worker threads (None: one per core; the
    results are the same bits on any count); ``out`` a directory that receives what
    ``grains run --out`` writes (``stats.csv``, ``stages.csv``, ``frames.mcap``, checkpoints,
    ``summary.json``); ``progress``: True draws the command line's progress bar on a terminal
    and a line of text elsewhere (a notebook), False nothing, a callable is called as
    ``progress(stage, done, total)`` at every statistics read inside a stage (default: the bar
    when stderr is a terminal); ``force`` skips the practicality checks, as
    ``grains run --force`` does.
    """

    def __init__(
        self,
        scene: Union[Scene, PathLike],
        backend: str = "cpu",
        precision: Optional[str] = None,
        threads: Optional[int] = None,
        out: Optional[PathLike] = None,
        progress: Union[None, bool, Callable[[str, int, int], Any]] = None,
        adapter: Optional[str] = None,
        force: bool = False,
        *,
        _native: Any = None,
    ) -> None:
        if _native is not None:
            self._sim = _native
            return
        if not isinstance(scene, Scene):
            scene = Scene.load(os.fspath(scene))
        bar, on_progress = _progress(progress)
        self._sim = _grains.Simulation(
            scene,
            backend,
            precision,
            threads,
            None if out is None else os.fspath(out),
            bar,
            adapter,
            force,
            on_progress,
        )

    @classmethod
    def resume(
        cls,
        dir: PathLike,
        threads: Optional[int] = None,
        progress: Union[None, bool, Callable[[str, int, int], Any]] = None,
        adapter: Optional[str] = None,
    ) -> "Simulation":
        """Continues the run in ``dir`` from its checkpoint (``grains run --resume DIR``)."""
        bar, on_progress = _progress(progress)
        return cls(None, _native=_grains.Simulation.resume(os.fspath(dir), threads, bar, adapter, on_progress))  # type: ignore[arg-type]

    def run(self) -> Dict[str, Any]:
        """Runs every stage left; returns the summary (``summary.json``'s content)."""
        return json.loads(self._sim.run())

    def run_stage(self) -> Optional[Dict[str, Any]]:
        """Runs the next stage; returns its result (a row of ``stages.csv`` and more), or None
        when every stage has run. After the last stage the summary is written."""
        r = self._sim.run_stage()
        return None if r is None else json.loads(r)

    def advance(self, steps: Optional[int] = None, time: Optional[float] = None) -> None:
        """Advances by ``steps`` time steps or by ``time`` seconds (rounded up to whole steps),
        outside the stages: nothing is recorded, and the run is checked for instability at
        every statistics interval. Other Python threads run meanwhile; Ctrl-C stops it after
        a whole number of steps."""
        if (steps is None) == (time is None):
            raise ValueError("advance: give steps or time, not both and not neither")
        if time is not None:
            if not (time >= 0 and math.isfinite(time)):
                raise ValueError(f"advance: time = {time!r} s; fix: give a finite time of zero or more")
            steps = math.ceil(time / self.dt - 1e-9)
        if steps is None or steps < 0:
            raise ValueError(f"advance: steps = {steps!r}; fix: give zero or more")
        self._sim.advance_steps(int(steps))

    def state(self) -> Dict[str, np.ndarray]:
        """The grains now, in id order: ``ids`` (n,) uint32, ``radii`` (n,) m, ``materials``
        (n,) uint16 (index into the scene's materials), ``positions`` (n, 3) m,
        ``velocities`` (n, 3) m/s, ``angular_velocities`` (n, 3) rad/s, ``forces`` (n, 3) N
        (the net force of each grain's contacts, grains and walls), and ``orientations``
        (n, 4) as [w, x, y, z] where the scene tracks them."""
        return self._sim.state()

    def contacts(self) -> Dict[str, np.ndarray]:
        """The touching pairs, one row each: ``i``, ``j`` (ids, i < j), ``normal`` (m, 3) unit
        from j to i, ``normal_force`` (m,) N compressive positive, ``tangential_force``
        (m, 3) N on i, ``force`` and ``force_j`` (m, 3) N on i and on j, ``overlap`` (m,) m,
        ``bridge_volume`` (m,) m^3."""
        return self._sim.contacts()

    def stats(self) -> Dict[str, Any]:
        """The statistics now: energies (J), contacts, unbalanced force, walls, piston."""
        return json.loads(self._sim.stats_json())

    def analysis(self) -> Dict[str, Any]:
        """The force-transmission analysis of the state now (``analysis.json``'s content)."""
        return json.loads(self._sim.analysis_json())

    def compression_point(self, settled: bool = False) -> Dict[str, Any]:
        """The oedometric sample now, as a pressure step's end records it (a row of
        ``compression.csv``): ``target_pressure`` and ``pressure`` (Pa), ``piston_z`` (m),
        ``void_ratio``, ``stress`` (3x3, Pa, compression positive), ``stress_zz``,
        ``coordination``, ``kinetic_energy`` (J); ``settled`` as given. Needs a piston."""
        return json.loads(self._sim.compression_point_json(settled))

    def save_checkpoint(self, dir: Optional[PathLike] = None) -> Path:
        """Writes a checkpoint into ``dir`` (default: ``out``) that ``grains run --resume``
        and ``Simulation.resume`` continue; returns the file's path."""
        return Path(self._sim.save_checkpoint(None if dir is None else os.fspath(dir)))

    def set_piston_pressure(self, pressure: float) -> None:
        """Sets the piston's target pressure (Pa)."""
        self._sim.set_piston_pressure(float(pressure))

    def set_wall_motion(self, name: str, velocity: Sequence[float] = (0.0, 0.0, 0.0), angular_velocity: Sequence[float] = (0.0, 0.0, 0.0)) -> None:
        """Sets wall ``name`` (a plane, a cylinder or a mesh, or a box for every face) moving
        at ``velocity`` (m/s) and spinning at ``angular_velocity`` (rad/s) about its pivot from
        now on, as a stage's ``walls`` does (a plane off its normal and a mesh turn); raises
        SceneError for a wall it cannot move."""
        self._sim.set_wall_motion(name, [float(v) for v in velocity], [float(w) for w in angular_velocity])

    def set_wall_present(self, name: str, present: bool) -> None:
        """Takes the walls ``name`` names away (``present=False``: grains pass through them,
        a gate lifted out) or adds them back, as a stage's ``remove_walls`` and ``add_walls``
        do (a box by its name: every face); adding one onto a grain is refused."""
        self._sim.set_wall_present(name, bool(present))

    def set_servo(self, pressure: Optional[float] = None, axial_strain_rate: Optional[float] = None) -> None:
        """Sets the servo walls' target pressure (Pa) and the z walls' strain rate (1/s,
        positive closing; None: back to pressure control)."""
        self._sim.set_servo(pressure, axial_strain_rate)

    @property
    def dt(self) -> float:
        """The time step (s)."""
        return self._sim.dt

    @property
    def stats_interval(self) -> int:
        """Steps between statistics reads (``simulation.stats_interval``): where ``advance``
        checks the run and Ctrl-C stops it."""
        return self._sim.stats_interval

    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return self._sim.time

    @property
    def steps(self) -> int:
        """Steps taken."""
        return self._sim.steps

    @property
    def backend(self) -> str:
        return self._sim.backend

    @property
    def precision(self) -> str:
        return self._sim.precision

    @property
    def stages(self) -> Tuple[List[str], int]:
        """The stages' names and how many have run."""
        return self._sim.stages()

    @property
    def summary(self) -> Optional[Dict[str, Any]]:
        """The finished run's summary, once its last stage has run."""
        s = self._sim.summary_json()
        return None if s is None else json.loads(s)


def _progress(progress: Union[None, bool, Callable[[str, int, int], Any]]) -> Tuple[bool, Optional[Callable[[str, int, int], Any]]]:
    """The command line's bar (on a terminal) and the callback a `progress` argument asks for."""
    if callable(progress):
        return False, progress
    terminal = sys.stderr.isatty()
    if progress is None or not progress:
        return bool(progress is None and terminal), None
    return (True, None) if terminal else (False, _text_progress)


def _text_progress(stage: str, done: int, total: int) -> None:
    """A progress line rewritten in place where there is no terminal (a notebook's output)."""
    end = "\n" if done >= total else ""
    print(f"\r{stage:>14}: {done}/{total} steps ({100 * done / max(total, 1):.0f}%)", end=end, flush=True)


def _read_csv(path: Path) -> Dict[str, np.ndarray]:
    """A CSV file with a header row as a dict of columns: floats where every value is a
    number, strings otherwise."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    columns: Dict[str, np.ndarray] = {}
    for k, name in enumerate(header):
        values = [r[k] if k < len(r) else "" for r in body]
        try:
            columns[name] = np.array([float(v) if v != "" else math.nan for v in values], dtype=np.float64)
        except ValueError:
            columns[name] = np.array(values, dtype=str)
    return columns


class RunResults:
    """A run directory's results: ``summary``, ``stats`` and ``stages`` (dicts of columns),
    ``compression`` (columns, or None without an oedometer), ``analysis`` (or None)."""

    def __init__(self, dir: PathLike) -> None:
        self.dir = Path(dir)
        summary = self.dir / "summary.json"
        if not summary.exists():
            raise GrainsError(f"{self.dir}: no summary.json; fix: give the out directory of a finished run")
        self.summary: Dict[str, Any] = json.loads(summary.read_text())
        self.stats = _read_csv(self.dir / "stats.csv")
        self.stages = _read_csv(self.dir / "stages.csv")
        compression = self.dir / "compression.csv"
        self.compression = _read_csv(compression) if compression.exists() else None
        analysis = self.dir / "analysis.json"
        self.analysis = json.loads(analysis.read_text()) if analysis.exists() else None

    def last_frame(self) -> Dict[str, Any]:
        """The last frame of ``frames.mcap``: ``time`` (s) and arrays as ``Simulation.state``."""
        return _grains.last_frame(os.fspath(self.dir / "frames.mcap"))

    def force_transmission(self) -> Dict[str, Any]:
        """The force-transmission analysis of the last frame (recorded with
        ``output.contact_forces = true``), as ``grains analyze DIR --json`` gives it: the force
        and particle-pressure PDFs, the tails' rates with their errors, fabric, percolation."""
        return json.loads(_grains.analyze_run_json(os.fspath(self.dir)))

    def __repr__(self) -> str:
        return f"RunResults({os.fspath(self.dir)!r})"


def open_run(dir: PathLike) -> RunResults:
    """Opens a finished run directory (``grains run --out DIR`` or ``Simulation(out=DIR)``)."""
    return RunResults(dir)


def fit_bauer(pressure: Any, void_ratio: Any, e0: Optional[float] = None) -> Dict[str, Any]:
    """Bauer's law e = e0 exp(-(p/h_s)^eta) fitted to compression points (``pressure``, the
    vertical stress, in Pa; Oquendo et al. eq. 19),
    with e0 held when given: ``grains fit bauer --json``'s fit (h_s in Pa, eta, e0, each with
    its error)."""
    p = np.asarray(pressure, dtype=np.float64).ravel().tolist()
    e = np.asarray(void_ratio, dtype=np.float64).ravel().tolist()
    return json.loads(_grains.fit_bauer_json(p, e, e0))
