"""What the Python module costs beside the engine (docs/python.md, "What it costs").

1. One `advance(1)` call from Python against the same step inside one `advance(n)` call (the
   engine's own loop, as `grains run` steps), on the two-sphere collision and on the 600-grain
   quickstart after its pour: interleaved rounds, median per step.
2. Reading the state (`state()`: ids, radii, materials, positions, velocities, angular
   velocities, forces) of 10^6 grains into NumPy arrays, and the contacts.

    python benches/python_overhead.py [--grains 1000000] [--rounds 5]
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import grains

REPO = Path(__file__).resolve().parents[1]


def per_step(sim: grains.Simulation, steps: int, one_call: bool) -> float:
    started = time.perf_counter()
    if one_call:
        sim.advance(steps=steps)
    else:
        for _ in range(steps):
            sim.advance(steps=1)
    return (time.perf_counter() - started) / steps


def step_costs(name: str, sim: grains.Simulation, steps: int, rounds: int) -> None:
    alone, called = [], []
    for _ in range(rounds):
        alone.append(per_step(sim, steps, True))
        called.append(per_step(sim, steps, False))
    a, c = statistics.median(alone), statistics.median(called)
    print(f"{name}: one step inside advance({steps}) {a * 1e6:.2f} us; advance(1) from Python {c * 1e6:.2f} us; the call costs {(c - a) * 1e6:.2f} us")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grains", type=int, default=1_000_000)
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()

    step_costs("two spheres", grains.Simulation(REPO / "scenes" / "two_spheres.toml", progress=False), 20_000, args.rounds)
    quick = grains.Simulation(REPO / "scenes" / "quickstart.toml", progress=False)
    quick.run()
    step_costs("quickstart, 600 settled grains", quick, 2_000, args.rounds)

    n = args.grains
    side = 2e-3 * round(n ** (1 / 3) * 1.6)  # m: a loose cube, about 0.12 solid
    scene = grains.Scene.from_toml(
        f"""
name = "state read"
[[material]]
name = "glass"
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.3
mu_s = 0.3
restitution = 0.5
[[generate]]
material = "glass"
count = {n}
diameter = {{ min = 0.9e-3, max = 1.1e-3 }}
region = {{ shape = "box", min = [0.0, 0.0, 0.0], max = [{side}, {side}, {side}] }}
[model]
normal = "hertz"
damping = "restitution"
tangential = "mindlin"
[simulation]
gravity = [0.0, 0.0, 0.0]
dt = 1.0e-6
[[stage]]
name = "idle"
kind = "run"
duration = 1.0e-6
"""
    )
    started = time.perf_counter()
    sim = grains.Simulation(scene, progress=False, force=True)
    sim.advance(steps=1)
    setup = time.perf_counter() - started
    reads, contacts = [], []
    for _ in range(args.rounds):
        t = time.perf_counter()
        s = sim.state()
        reads.append(time.perf_counter() - t)
        t = time.perf_counter()
        sim.contacts()
        contacts.append(time.perf_counter() - t)
    size = sum(a.nbytes for a in s.values())
    r = statistics.median(reads)
    print(f"state() of {n} grains: {r * 1e3:.1f} ms ({size / 1e6:.0f} MB of arrays, {size / r / 1e9:.2f} GB/s); contacts() {statistics.median(contacts) * 1e3:.1f} ms; setup {setup:.1f} s")


if __name__ == "__main__":
    main()
