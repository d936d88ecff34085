"""A rotating drum at several Froude numbers: its dynamic angle of repose and its regimes.

scenes/drum.toml pours 800 glass beads of 2 mm into a slice of a drum of radius R = 25 mm
(axis along z, periodic; gravity along -y); here the drum is turned at omega for each Froude
number Fr = omega^2 R / g, and every 20 ms of the last `--measure` seconds the bed is read:

* the angle of its free surface: the top of the bed (the highest bead surface) in columns one
  bead wide across the middle half of the drum, |x| < R/2, and a straight line through them;
* the angle of its centre of mass about the axis, atan2(x_cm, -y_cm) (the same angle for a
  flat surface; it averages a curved one);
* the distance of the centre of mass from the axis over R: 0.59 for the bed at rest, falling
  towards 0 as the bed centrifuges into a ring on the wall;
* the share of beads in flight (touching nothing): thrown off the surface when cataracting.

Mellmann (2001, Powder Technol. 118, 251) gives the regimes' ranges of Fr: slumping 1e-5 to
1e-3, rolling 1e-4 to 1e-2, cascading 1e-3 to 0.1, cataracting 0.1 to 1, centrifuging from 1
(for a bed that does not slip on the wall). Writes drum.csv and, where matplotlib is
installed, drum.png.

With --facets N the drum is a triangle mesh instead, a tube of N facets whose middles touch
the cylinder, turning about its axis (the mesh itself turns; the cylinder wall spins in place):
the turning mesh's check against the analytic wall.

    python examples/drum.py [--out DIR] [--threads N] [--froude 0.001,0.01,0.1,0.3,1,1.5,2,3]
                            [--turn 2.0] [--measure 1.0] [--facets N]

About 10 minutes on two cores for the default Froude numbers.
"""

from __future__ import annotations

import argparse
import csv
import importlib.util
import math
from pathlib import Path

import numpy as np

import grains
from plotting import pyplot, save

REPO = Path(__file__).resolve().parents[1]
G = 9.81
DRUM_RADIUS = 25e-3  # m, the scene's cylinder
SAMPLE = 0.02  # s between readings


def omega_of(froude: float) -> float:
    """The drum's angular velocity (rad/s) at Froude number `froude`."""
    return math.sqrt(froude * G / DRUM_RADIUS)


def surface_angle(p: np.ndarray, r: np.ndarray) -> float:
    """The free surface's angle (degrees, rising towards +x) across the middle half of the
    drum: the highest bead surface in each column one mean diameter wide, a straight line
    through them."""
    d = 2 * float(r.mean())
    middle = np.abs(p[:, 0]) < DRUM_RADIUS / 2
    columns = np.floor(p[middle, 0] / d).astype(int)
    tops = p[middle, 1] + r[middle]
    xs, ys = [], []
    for c in np.unique(columns):
        xs.append((c + 0.5) * d)
        ys.append(float(tops[columns == c].max()))
    slope = np.polyfit(xs, ys, 1)[0]
    return math.degrees(math.atan(slope))


def reading(s: dict) -> tuple[float, float, float, float]:
    """Of one state: the surface angle and the centre of mass's angle (degrees), its distance
    from the axis over R, and the share of beads in flight."""
    p, r = s["positions"], s["radii"]
    m = r ** 3
    cm = (p[:, :2] * m[:, None]).sum(axis=0) / m.sum()
    flying = float((np.abs(s["forces"]).sum(axis=1) == 0).mean())
    return surface_angle(p, r), math.degrees(math.atan2(cm[0], -cm[1])), float(np.hypot(*cm)) / DRUM_RADIUS, flying


CYLINDER = """[[wall]]
name = "drum"
type = "cylinder"
material = "liner"
center = [0.0, 0.0]
radius = 25.0e-3
"""


def faceted(facets: int, run: Path) -> grains.Scene:
    """scenes/drum.toml with its cylinder replaced by a mesh tube of `facets` facets whose
    middles touch it, longer than the periodic slice (z from -2 to 10 mm), written into `run`
    and turning about the z axis."""
    spec = importlib.util.spec_from_file_location("make_meshes", REPO / "scenes" / "meshes" / "make_meshes.py")
    make = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make)
    make.write_stl(run / "drum.stl", "drum", make.tube(DRUM_RADIUS * 1e3, facets, -2.0, 10.0))
    text = (REPO / "scenes" / "drum.toml").read_text()
    assert CYLINDER in text, "scenes/drum.toml's drum wall changed: update examples/drum.py"
    mesh = 'name = "drum"\ntype = "mesh"\nmaterial = "liner"\nfile = "drum.stl"\nscale = 0.001\ncenter = [0.0, 0.0, 0.0]\n'
    return grains.Scene.from_toml(text.replace(CYLINDER, "[[wall]]\n" + mesh), path=run / "drum.toml")


def turn(froude: float, threads: int | None, out: Path, duration: float, measure: float, facets: int | None = None) -> dict:
    """Fills the drum, turns it at `froude` for `duration` (s), or longer where the drum would
    not turn by a radian before the last `measure` seconds (the bed rises to its angle over
    about half a radian), and averages the readings of those last seconds; with `facets`, the
    drum is a mesh of that many facets ([`faceted`])."""
    run = out / f"Fr_{froude:g}"
    run.mkdir(parents=True, exist_ok=True)
    scene = grains.Scene.load(REPO / "scenes" / "drum.toml") if facets is None else faceted(facets, run)
    sim = grains.Simulation(scene, threads=threads, out=run, progress=False)
    fill = sim.run_stage()
    omega = omega_of(froude)
    duration = max(duration, 1.0 / omega + measure)
    sim.set_wall_motion("drum", angular_velocity=(0.0, 0.0, omega))
    readings = []
    t = 0.0
    while t < duration - 1e-9:
        sim.advance(time=SAMPLE)
        t += SAMPLE
        if t > duration - measure - 1e-9:
            readings.append(reading(sim.state()))
    a = np.array(readings)
    return {
        "Fr": froude,
        "omega_rad_s": omega,
        "turns": omega * duration / (2 * math.pi),
        "surface_deg": float(a[:, 0].mean()),
        "surface_sd_deg": float(a[:, 0].std()),
        "cm_deg": float(a[:, 1].mean()),
        "cm_sd_deg": float(a[:, 1].std()),
        "cm_radius": float(a[:, 2].mean()),
        "in_flight": float(a[:, 3].mean()),
        "fill_settled": fill["settled"],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("out/drum"))
    parser.add_argument("--threads", type=int, default=None)
    parser.add_argument("--froude", default="0.001,0.01,0.1,0.3,1,1.5,2,3", help="Froude numbers, comma-separated")
    parser.add_argument("--turn", type=float, default=2.0, help="seconds the drum turns at each (at least a radian before the last --measure seconds)")
    parser.add_argument("--measure", type=float, default=1.0, help="the last seconds of each turn that are read")
    parser.add_argument("--facets", type=int, default=None, help="a turning mesh drum of this many facets instead of the cylinder")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    rows = []
    for fr in (float(x) for x in args.froude.split(",")):
        r = turn(fr, args.threads, args.out, args.turn, args.measure, args.facets)
        rows.append(r)
        print(f"Fr = {fr:g} (omega {r['omega_rad_s']:.3g} rad/s, {r['turns']:.2f} turns): surface {r['surface_deg']:.1f} +- {r['surface_sd_deg']:.1f} deg, "
              f"centre of mass {r['cm_deg']:.1f} +- {r['cm_sd_deg']:.1f} deg at {r['cm_radius']:.2f} R, {100 * r['in_flight']:.1f}% of the beads in flight"
              f"{'' if r['fill_settled'] else ' (fill not settled)'}", flush=True)

    with open(args.out / "drum.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    plot(rows, args.out / "drum.png")


#: The regimes' ranges of Fr after Mellmann (2001), for the plot.
REGIMES = ((1e-5, 1e-3, "slumping"), (1e-4, 1e-2, "rolling"), (1e-3, 1e-1, "cascading"), (1e-1, 1.0, "cataracting"), (1.0, 10.0, "centrifuging"))


def plot(rows: list[dict], path: Path) -> None:
    """The angles against Fr where the bed has a surface (its centre of mass 0.2 R or more
    from the axis), and the centre of mass's distance and the beads in flight against Fr."""
    plt = pyplot()
    if plt is None:
        return
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    fr = np.array([r["Fr"] for r in rows])
    bed = np.array([r["cm_radius"] >= 0.2 for r in rows])
    for key, marker, label in (("surface", "o", "free surface, |x| < R/2"), ("cm", "s", "centre of mass")):
        left.errorbar(fr[bed], [r[f"{key}_deg"] for r, b in zip(rows, bed) if b], yerr=[r[f"{key}_sd_deg"] for r, b in zip(rows, bed) if b], marker=marker, capsize=3, label=label)
    right.plot(fr, [r["cm_radius"] for r in rows], "o-", label="centre of mass from the axis / R")
    right.plot(fr, [r["in_flight"] for r in rows], "s-", label="share of beads touching nothing")
    for ax, low in ((left, 20.0), (right, 0.0)):
        for k, (lo, hi, name) in enumerate(REGIMES):
            ax.plot([lo, hi], [low + (2.5 if ax is left else 0.06) * k] * 2, color="grey", lw=3, alpha=0.5)
            ax.text(math.sqrt(lo * hi), low + (2.5 if ax is left else 0.06) * k + (0.6 if ax is left else 0.015), name, ha="center", fontsize=7)
        ax.set_xscale("log")
        ax.set_xlabel("Froude number $\\omega^2 R / g$")
    left.set_ylabel("angle (degrees)")
    left.set_title("Dynamic angle (Mellmann's regimes below)")
    right.set_title("Centrifuging and flight")
    right.legend(fontsize=8)
    save(left, path)


if __name__ == "__main__":
    main()
