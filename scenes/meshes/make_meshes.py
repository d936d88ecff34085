"""Writes the mesh walls the shipped scenes read, as ASCII STL in millimetres (the scenes give
scale = 0.001): a flat plate with a circular orifice (scenes/silo.toml) and a conical hopper
(scenes/hopper.toml); `tube` gives examples/drum.py its faceted drum. Plain Python, no
packages.

    python scenes/meshes/make_meshes.py [--orifice MM] [--out DIR]

With --orifice it writes only the silo's plate, with that orifice diameter, into --out (the
silo example's other diameters).
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

SIDES = 48  # polygon sides standing for a circle


def write_stl(path: Path, name: str, triangles: list[tuple[tuple[float, float, float], ...]]) -> None:
    """The triangles (corners in mm) as an ASCII STL file."""
    lines = [f"solid {name}"]
    for a, b, c in triangles:
        u = [b[k] - a[k] for k in range(3)]
        v = [c[k] - a[k] for k in range(3)]
        n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
        length = math.sqrt(sum(x * x for x in n)) or 1.0
        lines.append("  facet normal {:.6e} {:.6e} {:.6e}".format(*(x / length for x in n)))
        lines.append("    outer loop")
        for p in (a, b, c):
            lines.append("      vertex {:.9e} {:.9e} {:.9e}".format(*p))
        lines.append("    endloop")
        lines.append("  endfacet")
    lines.append(f"endsolid {name}")
    path.write_text("\n".join(lines) + "\n")


def circle(radius: float, z: float) -> list[tuple[float, float, float]]:
    """A circle of `radius` at height z as SIDES corners (mm)."""
    return [(radius * math.cos(2 * math.pi * k / SIDES), radius * math.sin(2 * math.pi * k / SIDES), z) for k in range(SIDES)]


def ring(inner: list, outer: list) -> list:
    """Triangles between two polygons of SIDES corners each."""
    out = []
    for k in range(SIDES):
        j = (k + 1) % SIDES
        out += [(inner[k], outer[k], outer[j]), (inner[k], outer[j], inner[j])]
    return out


def tube(radius: float, facets: int, z_lo: float, z_hi: float) -> list:
    """An open tube along z from z_lo to z_hi (mm) of `facets` flat facets whose middles touch
    the circle of `radius` (a drum), one facet's middle facing +x; two triangles a facet."""
    out = radius / math.cos(math.pi / facets)
    corner = lambda k, z: (out * math.cos(2 * math.pi * (k - 0.5) / facets), out * math.sin(2 * math.pi * (k - 0.5) / facets), z)
    tris = []
    for k in range(facets):
        tris += [(corner(k, z_lo), corner(k + 1, z_lo), corner(k + 1, z_hi)), (corner(k, z_lo), corner(k + 1, z_hi), corner(k, z_hi))]
    return tris


def orifice_plate(orifice: float, outer: float) -> list:
    """A flat annulus at z = 0 from the orifice's radius to `outer` (mm), in rings about a
    millimetre or two wide, so that no triangle is much longer than the grains."""
    radii = [orifice / 2]
    while radii[-1] < outer:
        radii.append(min(outer, radii[-1] + max(1.5, 0.15 * radii[-1])))
    tris = []
    for r0, r1 in zip(radii, radii[1:]):
        tris += ring(circle(r0, 0.0), circle(r1, 0.0))
    return tris


def hopper(top: float, orifice: float, cone_height: float, wall_height: float) -> list:
    """A conical hopper (mm): a cone from the orifice's radius at z = 0 up to `top` at
    `cone_height`, then a vertical wall of that radius `wall_height` higher; open at both ends."""
    tris = []
    steps = 8
    for s in range(steps):
        z0, z1 = cone_height * s / steps, cone_height * (s + 1) / steps
        r0 = orifice / 2 + (top - orifice / 2) * s / steps
        r1 = orifice / 2 + (top - orifice / 2) * (s + 1) / steps
        tris += ring(circle(r0, z0), circle(r1, z1))
    for s in range(4):
        z0 = cone_height + wall_height * s / 4
        z1 = cone_height + wall_height * (s + 1) / 4
        tris += ring(circle(top, z0), circle(top, z1))
    return tris


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--orifice", type=float, help="the silo plate's orifice diameter (mm); only that plate is written")
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if args.orifice is not None:
        write_stl(args.out / f"orifice_plate_{args.orifice:g}mm.stl", "orifice_plate", orifice_plate(args.orifice, 22.0))
        return
    write_stl(args.out / "orifice_plate_10mm.stl", "orifice_plate", orifice_plate(10.0, 22.0))
    write_stl(args.out / "hopper.stl", "hopper", hopper(top=20.0, orifice=10.0, cone_height=15.0, wall_height=70.0))


if __name__ == "__main__":
    main()
