#!/usr/bin/env python3
"""Reads grains' VTK output back with VTK's own XML reader (Debian's python3-vtk9), for
tests/vtk.rs: for each .pvd collection given, every file it lists is read (a reader error
fails the script), and the last one's points, cells and arrays are printed as JSON.

usage: vtk_read_back.py COLLECTION.pvd [...]   -> JSON on stdout
"""
import json
import os
import sys
import xml.etree.ElementTree as ET

import vtk


def read(path):
    errors = []
    reader = vtk.vtkXMLPolyDataReader()
    reader.AddObserver("ErrorEvent", lambda obj, event: errors.append(event))
    reader.SetFileName(path)
    reader.Update()
    if errors or not reader.CanReadFile(path):
        sys.exit(f"{path}: VTK's reader failed")
    return reader.GetOutput()


def cells(cell_array):
    out, ids = [], vtk.vtkIdList()
    cell_array.InitTraversal()
    while cell_array.GetNextCell(ids):
        out.append([ids.GetId(k) for k in range(ids.GetNumberOfIds())])
    return out


def arrays(data):
    out = {}
    for k in range(data.GetNumberOfArrays()):
        a = data.GetArray(k)
        c = a.GetNumberOfComponents()
        out[a.GetName()] = {
            "type": a.GetDataTypeAsString(),
            "components": c,
            "values": [[a.GetComponent(t, j) for j in range(c)] for t in range(a.GetNumberOfTuples())],
        }
    return out


def main():
    report = {}
    for pvd in sys.argv[1:]:
        root = ET.parse(pvd).getroot()
        if root.get("type") != "Collection":
            sys.exit(f"{pvd}: not a VTK Collection")
        entries = [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]
        base = os.path.dirname(pvd)
        last = None
        for _, name in entries:
            last = read(os.path.join(base, name))
        kind = os.path.basename(pvd)[: -len(".pvd")]
        report[kind] = {"entries": entries}
        if last is not None:
            pts = last.GetPoints()
            report[kind]["last"] = {
                "points": [list(pts.GetPoint(k)) for k in range(last.GetNumberOfPoints())] if pts else [],
                "verts": cells(last.GetVerts()),
                "lines": cells(last.GetLines()),
                "polys": cells(last.GetPolys()),
                "point_data": arrays(last.GetPointData()),
                "cell_data": arrays(last.GetCellData()),
            }
    json.dump(report, sys.stdout)


main()
