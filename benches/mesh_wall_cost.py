"""What a mesh wall costs against a plane (docs/performance.md, "Mesh walls").

A bed of 2,000 beads of 2 mm settled in a 30 mm box on a floor that is a plane, a mesh of two
triangles, or a mesh of 450 triangles (2 mm squares, as fine as the beads), still or turning
at 1 rad/s about the vertical through the box's middle (a turntable: the surface stays in
place, the turning mesh's arithmetic runs), the walls around planes: each floor's bed, once
settled, is advanced in interleaved rounds, and the time above the plane's, per bead-step of
a bead touching the floor, is the mesh's cost (the medians of the rounds). The beads near the
floor that do not touch it pay their look-up too, and are in the figure.

    python benches/mesh_wall_cost.py [--steps 2000] [--rounds 5] [--threads N]
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import tempfile
import time
from pathlib import Path

import grains

REPO = Path(__file__).resolve().parents[1]
SIDE = 30.0  # mm

SCENE = """
seed = 2
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.3
mu_s = 0.5
restitution = 0.5

[[generate]]
material = "glass"
count = 2000
diameter = {{ min = 1.8e-3, max = 2.2e-3 }}
region = {{ shape = "box", min = [0.0, 0.0, 1.2e-3], max = [0.03, 0.03, 0.06] }}

[[wall]]
type = "box"
material = "glass"
min = [0.0, 0.0, -0.01]
max = [0.03, 0.03, 0.1]
open_top = true

{floor}

[model]
normal = "hertz"
damping = "restitution"
tangential = "mindlin"

[simulation]
gravity = [0.0, 0.0, -9.81]

[[stage]]
kind = "fill"
duration = 0.5
"""


def square(n: int) -> list:
    """The floor z = 0 over the box as n x n squares of two triangles (mm)."""
    h = SIDE / n
    out = []
    for i in range(n):
        for j in range(n):
            a, b, c, d = ((i * h, j * h, 0.0), ((i + 1) * h, j * h, 0.0), ((i + 1) * h, (j + 1) * h, 0.0), (i * h, (j + 1) * h, 0.0))
            out += [(a, b, c), (a, c, d)]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--threads", type=int, default=None)
    args = parser.parse_args()
    spec = importlib.util.spec_from_file_location("make_meshes", REPO / "scenes" / "meshes" / "make_meshes.py")
    make = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make)
    with tempfile.TemporaryDirectory() as tmp:
        dir = Path(tmp)
        floors = {"plane": '[[wall]]\ntype = "plane"\nmaterial = "glass"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]'}
        for n in (1, 15):
            make.write_stl(dir / f"floor_{n}.stl", "floor", square(n))
            floors[f"mesh of {2 * n * n} triangles"] = f'[[wall]]\ntype = "mesh"\nmaterial = "glass"\nfile = "floor_{n}.stl"\nscale = 0.001'
        # Settled still, then set turning.
        floors["mesh of 450 triangles, turning"] = floors["mesh of 450 triangles"] + '\nname = "floor"\ncenter = [0.015, 0.015, 0.0]'
        sims = {}
        for name, floor in floors.items():
            scene = grains.Scene.from_toml(SCENE.format(floor=floor), path=dir / "bed.toml")
            sims[name] = grains.Simulation(scene, threads=args.threads)
            sims[name].run_stage()
            if name.endswith("turning"):
                sims[name].set_wall_motion("floor", angular_velocity=(0.0, 0.0, 1.0))
        times = {name: [] for name in sims}
        for _ in range(args.rounds):
            for name, sim in sims.items():
                started = time.perf_counter()
                sim.advance(steps=args.steps)
                times[name].append((time.perf_counter() - started) / args.steps)
        plane = statistics.median(times["plane"])
        for name, sim in sims.items():
            touching = sim.stats()["walls"][-1]["contacts"]
            t = statistics.median(times[name])
            extra = "" if name == "plane" else f"; {(t - plane) / max(touching, 1) * 1e9:.0f} ns more per bead-step of a bead touching it"
            print(f"floor {name}: {t * 1e6:.1f} us a step, {touching} beads touching the floor{extra}")


if __name__ == "__main__":
    main()
