"""A flat-bottomed silo discharging through circular orifices, against Beverloo's law.

scenes/silo.toml fills a cylinder of radius 21 mm standing on a plate with a circular orifice
(a triangle mesh) with 4,000 glass beads of 2 mm while a shutter closes the orifice; here each
orifice diameter D gets its plate (scenes/meshes/make_meshes.py), the silo is filled, the
shutter drops away, and the discharged mass is read every 10 ms. Its steady rate W (a straight
line through the mass from 0.1 s on) against Beverloo, Leniger & van de Velde (1961):

    W = C rho_b sqrt(g) (D - k d)^(5/2),

rho_b the fill's bulk density (measured in the silo before the discharge), d the mean bead
diameter: W^(2/5) is a straight line in D whose slope gives C and whose intercept gives k
(the experiments' C is about 0.58, k about 1.4-1.5). Writes silo.csv and, where matplotlib is
installed, silo.png.

    python examples/silo.py [--out DIR] [--threads N] [--orifices 8,10,12,14] [--time 0.4]
    python examples/silo.py --hopper    # scenes/hopper.toml's discharge rate instead

About 15 minutes on two cores for the default orifices.
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
SILO_RADIUS = 21e-3  # m, the scene's cylinder
START = 0.1  # s of discharge left out of the rate (the flow sets up)


def meshes():
    """scenes/meshes/make_meshes.py as a module."""
    spec = importlib.util.spec_from_file_location("make_meshes", REPO / "scenes" / "meshes" / "make_meshes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def bulk_density(s: dict, density: float) -> float:
    """The fill's bulk density (kg/m^3): the beads' volume whose centres lie in a core of the
    silo (a grain diameter and more from the wall, the plate and the top) over the core's."""
    p, r = s["positions"], s["radii"]
    top = float((p[:, 2] + r).max())
    d = 2 * r.mean()
    rho = np.hypot(p[:, 0], p[:, 1])
    core = (rho < SILO_RADIUS - 2 * d) & (p[:, 2] > 2 * d) & (p[:, 2] < top - 2 * d)
    volume = math.pi * (SILO_RADIUS - 2 * d) ** 2 * (top - 4 * d)
    return density * float((4.0 / 3.0 * math.pi * r[core] ** 3).sum()) / volume


def discharge(orifice_mm: float, threads: int | None, out: Path, duration: float) -> dict:
    """One silo with an orifice of `orifice_mm`: fills it, opens it, and returns the discharged
    mass every 10 ms with its steady rate and the fill's bulk density."""
    run = out / f"D_{orifice_mm:g}mm"
    run.mkdir(parents=True, exist_ok=True)
    make = meshes()
    plate = run / f"orifice_plate_{orifice_mm:g}mm.stl"
    make.write_stl(plate, "orifice_plate", make.orifice_plate(orifice_mm, 22.0))
    scene = grains.Scene.load(REPO / "scenes" / "silo.toml")
    scene.update({"wall.1.file": str(plate.resolve())})
    return {"D_mm": orifice_mm, **measure(scene, threads, run, duration)}


def measure(scene: grains.Scene, threads: int | None, run: Path, duration: float) -> dict:
    """Fills `scene`'s container (its first stage), drops its shutter away and returns the
    mass below z = 0 every 10 ms for `duration` (s), its steady rate, and the fill's bulk
    density where the container is the silo."""
    sim = grains.Simulation(scene, threads=threads, out=run, progress=False)
    fill = sim.run_stage()
    s = sim.state()
    density = float(scene["material.0.density"])
    rho_b = bulk_density(s, density)
    mass = (4.0 / 3.0 * math.pi * s["radii"] ** 3) * density
    sim.set_wall_motion("shutter", (0.0, 0.0, -1.0))
    times, out_mass = [0.0], [0.0]
    t = 0.0
    while t < duration - 1e-9:
        sim.advance(time=0.01)
        t += 0.01
        below = sim.state()["positions"][:, 2] < -s["radii"].max()
        times.append(t)
        out_mass.append(float(mass[below].sum()))
    times, out_mass = np.array(times), np.array(out_mass)
    steady = times >= START
    rate, offset = np.polyfit(times[steady], out_mass[steady], 1)
    return {
        "d_mm": 2e3 * float(s["radii"].mean()),
        "grains": len(s["ids"]),
        "fill_settled": fill["settled"],
        "fill_height_mm": 1e3 * float((s["positions"][:, 2] + s["radii"]).max()),
        "bulk_density": rho_b,
        "W_kg_s": float(rate),
        "discharged_kg": float(out_mass[-1]),
        "fill_kg": float(mass.sum()),
        "curve": (times, out_mass),
    }


def beverloo_fit(rows: list[dict]) -> tuple[float, float]:
    """C and k of W = C rho_b sqrt(g) (D - k d)^(5/2) through the rows (least squares of
    W^(2/5) on D)."""
    D = np.array([r["D_mm"] for r in rows]) * 1e-3
    w = np.array([r["W_kg_s"] for r in rows]) ** 0.4
    slope, intercept = np.polyfit(D, w, 1)
    rho_b = float(np.mean([r["bulk_density"] for r in rows]))
    d = float(np.mean([r["d_mm"] for r in rows])) * 1e-3
    return slope ** 2.5 / (rho_b * math.sqrt(G)), -intercept / (slope * d)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("out/silo"))
    parser.add_argument("--threads", type=int, default=None)
    parser.add_argument("--orifices", default="8,10,12,14", help="orifice diameters (mm), comma-separated")
    parser.add_argument("--time", type=float, default=0.4, help="seconds of discharge per orifice")
    parser.add_argument("--hopper", action="store_true", help="run scenes/hopper.toml instead (its 10 mm orifice under a 45-degree cone)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if args.hopper:
        r = measure(grains.Scene.load(REPO / "scenes" / "hopper.toml"), args.threads, args.out / "hopper", args.time)
        print(f"hopper: W = {1e3 * r['W_kg_s']:.2f} g/s, {1e3 * r['discharged_kg']:.1f} of {1e3 * r['fill_kg']:.1f} g out in {args.time:g} s{'' if r['fill_settled'] else ' (fill not settled)'}")
        return

    rows = []
    for D in (float(x) for x in args.orifices.split(",")):
        r = discharge(D, args.threads, args.out, args.time)
        rows.append(r)
        print(f"D = {D:g} mm ({D / r['d_mm']:.1f} d): W = {1e3 * r['W_kg_s']:.2f} g/s, {1e3 * r['discharged_kg']:.1f} of {1e3 * r['fill_kg']:.1f} g out in {args.time:g} s; fill {r['fill_height_mm']:.1f} mm high, bulk density {r['bulk_density']:.0f} kg/m^3{'' if r['fill_settled'] else ' (fill not settled)'}")
    C, k = beverloo_fit(rows) if len(rows) >= 2 else (float("nan"), float("nan"))
    print(f"Beverloo fit: C = {C:.3f}, k = {k:.2f} (experiments: C about 0.58, k about 1.4-1.5)")
    with open(args.out / "silo.csv", "w", newline="") as f:
        fields = [k for k in rows[0] if k != "curve"]
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for r in rows:
            w.writerow({k: r[k] for k in fields})
        f.write(f"# Beverloo fit: C = {C:.4f}, k = {k:.3f}\n")

    plt = pyplot()
    if plt is None:
        return
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    for r in rows:
        t, m = r["curve"]
        left.plot(t, 1e3 * m, label=f"D = {r['D_mm']:g} mm")
    left.set_xlabel("time since the shutter opened (s)")
    left.set_ylabel("discharged mass (g)")
    left.legend()
    D = np.array([r["D_mm"] for r in rows])
    W = np.array([r["W_kg_s"] for r in rows])
    rho_b = float(np.mean([r["bulk_density"] for r in rows]))
    d = float(np.mean([r["d_mm"] for r in rows]))
    fine = np.linspace(max(D.min() - 1, k * d + 0.1), D.max() + 1, 100)
    right.plot(D, 1e3 * W, "o", label="grains")
    right.plot(fine, 1e3 * C * rho_b * math.sqrt(G) * ((fine - k * d) * 1e-3) ** 2.5, "-", label=f"Beverloo fit C = {C:.2f}, k = {k:.2f}")
    right.plot(fine, 1e3 * 0.58 * rho_b * math.sqrt(G) * (np.clip(fine - 1.5 * d, 0, None) * 1e-3) ** 2.5, "--", label="C = 0.58, k = 1.5")
    right.set_xlabel("orifice diameter D (mm)")
    right.set_ylabel("mass flow rate W (g/s)")
    right.set_title("Silo discharge, 2 mm glass beads")
    save(right, args.out / "silo.png")


if __name__ == "__main__":
    main()
