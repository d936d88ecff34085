"""A cyclic oedometer driven from Python: what the scene files' stages cannot express.

The shipped 280-grain oedometer (scenes/oedometer.toml, Oquendo et al.'s parameters) is poured
and loaded by its own stages from 12.5 kPa to 400 kPa (doubling), then unloaded step by step to
25 kPa and reloaded to 1.6 MPa from here, each step held until the sample has settled by the
stages' own criteria. Writes the compression points to cyclic_oedometer.csv and, where
matplotlib is installed, the e-log(p) loop to cyclic_oedometer.png.

    python examples/cyclic_oedometer.py [--out DIR] [--threads N] [--ramp SECONDS]

About 80 s on two cores (2.5 minutes with --ramp 0.02).
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

import grains
from plotting import pyplot, save

REPO = Path(__file__).resolve().parents[1]

# The stages' settle criteria (scenes/oedometer.toml's oedometer stage): the piston's pressure
# within 1% of its target, translational kinetic energy below 1e-3 of the contacts' elastic
# energy (rattlers left out), the loaded grains' unbalanced force below 1e-4; at most 0.1 s.
PRESSURE_TOLERANCE = 0.01
KE_RATIO = 1e-3
UNBALANCED = 1e-4
MAX_STEP_TIME = 0.1

# Increments of the target over a ramp (--ramp).
RAMP_STEPS = 50


def hold(sim: grains.Simulation, pressure: float, previous: float, ramp: float) -> dict:
    """Moves the piston's target from `previous` to `pressure` (Pa), at once (`ramp` = 0, as
    the stages do) or in RAMP_STEPS even steps over `ramp` seconds, and advances until the
    sample settles (or for MAX_STEP_TIME); returns the compression point there."""
    if ramp > 0:
        for k in range(1, RAMP_STEPS + 1):
            sim.set_piston_pressure(previous + (pressure - previous) * k / RAMP_STEPS)
            sim.advance(time=ramp / RAMP_STEPS)
    sim.set_piston_pressure(pressure)
    start = sim.time
    settled = False
    while sim.time - start < MAX_STEP_TIME:
        sim.advance(steps=sim.stats_interval)
        s = sim.stats()
        near = abs(s["piston"]["pressure"] - pressure) < PRESSURE_TOLERANCE * pressure
        still = s["ke_translational"] - s["ke_rattlers"] < KE_RATIO * s["elastic_energy"]
        if near and still and s["unbalanced_force_loaded"] < UNBALANCED:
            settled = True
            break
    return sim.compression_point(settled=settled)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("out/cyclic_oedometer"))
    parser.add_argument("--threads", type=int, default=None)
    parser.add_argument("--ramp", type=float, default=0.0, help="seconds over which each unload and reload step moves the target (0: at once, as the stages do)")
    args = parser.parse_args()

    scene = grains.Scene.load(REPO / "scenes" / "oedometer.toml")
    scene["stage.oedometer.p_max"] = 400e3  # the stages load to 400 kPa; the rest is ours
    sim = grains.Simulation(scene, threads=args.threads, out=args.out)
    points = []
    while (r := sim.run_stage()) is not None:
        if r.get("compression") and not r["compression"]["seating"]:
            points.append(("load", r["compression"]))
            print(f"{r['name']:>22}: e = {r['compression']['void_ratio']:.4f}")

    unload = [200e3, 100e3, 50e3, 25e3]
    reload = [50e3, 100e3, 200e3, 400e3, 800e3, 1.6e6]
    previous = 400e3
    for branch, pressures in (("unload", unload), ("reload", reload)):
        for p in pressures:
            c = hold(sim, p, previous, args.ramp)
            previous = p
            points.append((branch, c))
            print(f"{branch:>10} {p / 1e3:7.1f} kPa: e = {c['void_ratio']:.4f}{'' if c['settled'] else ' (not settled)'}")

    table = args.out / "cyclic_oedometer.csv"
    with open(table, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["branch", "target_pressure_Pa", "pressure_Pa", "void_ratio", "coordination", "settled"])
        for branch, c in points:
            w.writerow([branch, c["target_pressure"], c["pressure"], c["void_ratio"], c["coordination"], c["settled"]])
    print(f"wrote {table}")

    plt = pyplot()
    if plt is None:
        return
    _, ax = plt.subplots(figsize=(6, 4))
    for branch, style in (("load", "o-"), ("unload", "s--"), ("reload", "^-")):
        pts = [c for b, c in points if b == branch]
        if branch != "load":
            # Each branch starts where the last ended.
            pts = [c for b, c in points if b == {"unload": "load", "reload": "unload"}[branch]][-1:] + pts
        ax.plot([c["pressure"] / 1e3 for c in pts], [c["void_ratio"] for c in pts], style, label=branch)
    ax.set_xscale("log")
    ax.set_xlabel("vertical pressure on the piston (kPa)")
    ax.set_ylabel("void ratio e")
    ax.set_title("280-grain oedometer: loaded, unloaded, reloaded")
    save(ax, args.out / "cyclic_oedometer.png")


if __name__ == "__main__":
    main()
