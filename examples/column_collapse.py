"""Granular column collapses at several aspect ratios, against Lube et al. (2005).

scenes/column_collapse.toml pours a column of sand 20 mm long between a back wall and a gate
(a 5 mm slice of a channel, periodic across it) and pulls the gate away; here the column is
made taller or shorter by the number of grains poured, and each run gives the column's
aspect ratio a = H0 / L0 (H0 the settled column's top, after the pour) and its run-out
(L_inf - L0) / L0 (L_inf the front of the deposit: the farthest grain surface of the largest
cluster of touching grains, so that a grain that rolled away alone does not count; and, beside
it, where the deposit thins below two grains, leaving out the tongue one grain thick that
rolling spheres spread ahead of it). Lube,
Huppert, Sparks & Freundt (2005, Phys. Rev. E 72, 041301) measured 1.2 a for a < 1.8 and
1.9 a^(2/3) for a > 2.8 in their two-dimensional collapses. Writes column_collapse.csv and,
where matplotlib is installed, column_collapse.png.

    python examples/column_collapse.py [--out DIR] [--threads N] [--heights 0.5,1,1.5,2,3]
                                       [--set model.rolling_mu=0.3]

About 25 minutes on two cores for the default heights (the tallest column 9 of them).
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np

import grains
from plotting import pyplot, save

REPO = Path(__file__).resolve().parents[1]

# The shipped column: its grains, the height they are poured from, the gate's place (m).
GRAINS_AT_A1 = 2300
POUR_HEIGHT_AT_A1 = 65e-3
L0 = 20e-3
PERIOD_Y = 5e-3


def lube(a: float) -> float | None:
    """Lube et al.'s run-out (L_inf - L0) / L0 at aspect ratio a, where they give one."""
    if a < 1.8:
        return 1.2 * a
    if a > 2.8:
        return 1.9 * a ** (2.0 / 3.0)
    return None


def fronts(positions: np.ndarray, radii: np.ndarray) -> tuple[float, float]:
    """Two fronts of a deposit (m): the farthest grain surface of the largest cluster of
    touching grains (so that a grain that rolled away alone does not count), and the start of
    the first slice one mean diameter wide, counted from the back wall, where the deposit is
    less than two diameters thick (so that a tongue one grain thick does not count either)."""
    n = len(radii)
    order = np.argsort(positions[:, 0])
    p, r = positions[order], radii[order]
    parent = np.arange(n)

    def root(k: int) -> int:
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    reach = 2 * r.max()
    for i in range(n):
        end = np.searchsorted(p[:, 0], p[i, 0] + reach, side="right")
        d = p[i + 1:end] - p[i]
        d[:, 1] -= PERIOD_Y * np.round(d[:, 1] / PERIOD_Y)
        for j in np.nonzero((d * d).sum(axis=1) < (r[i] + r[i + 1:end]) ** 2)[0]:
            a, b = root(i), root(i + 1 + j)
            if a != b:
                parent[a] = b
    roots = np.array([root(k) for k in range(n)])
    x, top = p[:, 0] + r, p[:, 2] + r
    cluster = float(x[roots == np.bincount(roots).argmax()].max())
    d_mean = 2 * r.mean()
    slices = (x // d_mean).astype(int)
    thick = np.zeros(slices.max() + 1)
    np.maximum.at(thick, slices, top)
    thin = np.nonzero(thick < 2 * d_mean)[0]
    body = float(thin[0] * d_mean) if len(thin) else float(x.max())
    return cluster, body


def collapse(scale: float, threads: int | None, out: Path, edits: dict[str, float]) -> dict:
    """One collapse with `scale` times the shipped column's grains, poured from `scale` times
    its height, and the scene's keys `edits` set (dotted paths); returns its aspect ratio,
    run-out and times."""
    scene = grains.Scene.load(REPO / "scenes" / "column_collapse.toml")
    scene.update(edits)
    # Together: the count must fit the region.
    scene.update({"generate.0.region.max": [L0, PERIOD_Y, POUR_HEIGHT_AT_A1 * scale], "generate.0.count": round(GRAINS_AT_A1 * scale)})
    sim = grains.Simulation(scene, threads=threads, out=out / f"scale_{scale:g}", progress=False)
    pour = sim.run_stage()
    s = sim.state()
    h0 = float((s["positions"][:, 2] + s["radii"]).max())
    spread = sim.run_stage()
    sim.run()
    end = sim.state()
    cluster, body = fronts(end["positions"], end["radii"])
    a = h0 / L0
    return {
        "grains": len(s["ids"]),
        "a": a,
        "H0_m": h0,
        "L_inf_m": cluster,
        "runout": (cluster - L0) / L0,
        "body_front_m": body,
        "body_runout": (body - L0) / L0,
        "lube": lube(a),
        "collapse_s": spread["time_end"] - spread["time_start"],
        "settled": spread["settled"],
        "pour_settled": pour["settled"],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("out/column_collapse"))
    parser.add_argument("--threads", type=int, default=None)
    parser.add_argument("--heights", default="0.5,1,1.5,2,3", help="columns as multiples of the shipped one's grains, comma-separated")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="a scene key to change, e.g. model.rolling_mu=0.3 (repeatable)")
    args = parser.parse_args()
    edits = {k: float(v) for k, v in (e.split("=", 1) for e in args.set)}
    args.out.mkdir(parents=True, exist_ok=True)

    rows = []
    for scale in (float(h) for h in args.heights.split(",")):
        r = collapse(scale, args.threads, args.out, edits)
        rows.append(r)
        ref = "" if r["lube"] is None else f", Lube et al. {r['lube']:.2f}"
        print(f"{r['grains']:6d} grains: a = {r['a']:.2f}, run-out (L_inf - L0)/L0 = {r['runout']:.2f} (the deposit two grains thick: {r['body_runout']:.2f}){ref}; collapse {r['collapse_s']:.3f} s{'' if r['settled'] else ' (not settled)'}")

    table = args.out / "column_collapse.csv"
    with open(table, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {table}")

    plt = pyplot()
    if plt is None:
        return
    _, ax = plt.subplots(figsize=(5, 4))
    ax.plot([r["a"] for r in rows], [r["runout"] for r in rows], "o", label="grains: the touching deposit")
    ax.plot([r["a"] for r in rows], [r["body_runout"] for r in rows], "s", mfc="none", label="grains: two grains thick")
    lo, hi = np.linspace(0.3, 1.8, 20), np.linspace(2.8, 6.0, 20)
    ax.plot(lo, 1.2 * lo, "k-", label="Lube et al. 2005: 1.2 a")
    ax.plot(hi, 1.9 * hi ** (2 / 3), "k--", label="1.9 a^(2/3)")
    ax.set_xlabel("aspect ratio a = H0 / L0")
    ax.set_ylabel("run-out (L_inf - L0) / L0")
    ax.set_title("Column collapse, 20 mm columns of 1 mm sand")
    save(ax, args.out / "column_collapse.png")


if __name__ == "__main__":
    main()
