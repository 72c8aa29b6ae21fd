#!/usr/bin/python3
"""What ParaView shows of a result (issue 13, item 5), checked with ParaView's own readers through pvpython:
contact-solve on api/examples/hertz_cylinder_gmsh.json (triangles, and a block mixing them with quadrilaterals),
then the sidecar opened as ./name.xmf with the Xdmf3 Reader has one block per body, named after it, and one
named "contacts" for the pairs' slave polylines (format version 3: the contact tables), with every cell; the stresses' components are named XX, YY, ZZ, XY (and YZ, XZ) in the sidecar and
in the .hdf's /VTKHDF grid, whose cells are the bodies' triangles and quadrilaterals and the pair's segments.
ParaView is not a dependency of the project: exits 77 (CTest: skipped) saying so when pvpython is absent."""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import h5py

SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
BIN = os.environ.get("CONTACT_BINARY_DIR", os.path.join(SRC, "build"))
sys.path.insert(0, os.path.join(SRC, "tests"))  # checks.py
from checks import check, finish, show_passes, skip  # noqa: E402

# Run by pvpython in the result's directory; prints one JSON object.
PROBE = r"""
import json
from paraview import servermanager
from paraview.simple import Xdmf3ReaderT, VTKHDFReader
out = {}
xmf = Xdmf3ReaderT(FileName="./result.xmf")
xmf.UpdatePipeline()
data = servermanager.Fetch(xmf)
blocks = {}
it = data.NewIterator()
it.InitTraversal()
while not it.IsDoneWithTraversal():
    name, block = it.GetCurrentMetaData().Get(data.NAME()), it.GetCurrentDataObject()
    blocks[name] = block.GetNumberOfCells()
    if name == "contacts":
        pd = block.GetPointData()
        out["xmf_contact_arrays"] = sorted(pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays()))
        out["xmf_contact_points"] = block.GetNumberOfPoints()
    it.GoToNextItem()
out["xmf_blocks"] = blocks
out["xmf_stress_node"] = [xmf.PointData["stress_node"].GetComponentName(i) for i in range(6)]
out["xmf_stress_cell"] = [xmf.CellData["stress_cell"].GetComponentName(i) for i in range(6)]
hdf = VTKHDFReader(FileName="./result.hdf")
hdf.UpdatePipeline()
grid = servermanager.Fetch(hdf)
out["hdf_stress_point"] = [hdf.PointData["stress"].GetComponentName(i) for i in range(6)]
out["hdf_stress_cell"] = [hdf.CellData["stress"].GetComponentName(i) for i in range(6)]
types = {}
for piece in range(grid.GetNumberOfPartitions()) if hasattr(grid, "GetNumberOfPartitions") else [None]:
    g = grid.GetPartition(piece) if piece is not None else grid
    for c in range(g.GetNumberOfCells()):
        types[g.GetCellType(c)] = types.get(g.GetCellType(c), 0) + 1
out["hdf_cell_types"] = {str(k): v for k, v in types.items()}
print("PROBE " + json.dumps(out))
"""


def main():
    show_passes()
    pvpython = shutil.which("pvpython")
    if pvpython is None:
        skip("pvpython is not installed (Debian's paraview); ParaView's view of a result was not checked")
    with tempfile.TemporaryDirectory() as tmp:
        job = os.path.join(SRC, "api", "examples", "hertz_cylinder_gmsh.json")
        r = subprocess.run([os.path.join(BIN, "contact-solve"), job, "-o", os.path.join(tmp, "result.hdf"), "-q"],
                           capture_output=True, text=True, timeout=300)
        if not check("contact-solve solves hertz_cylinder_gmsh.json", r.returncode == 0, r.stderr[-800:]):
            finish()
        with open(os.path.join(tmp, "probe.py"), "w") as f:
            f.write(PROBE)
        r = subprocess.run([pvpython, "--force-offscreen-rendering", "probe.py"], cwd=tmp, capture_output=True,
                           text=True, timeout=300)
        line = next((l for l in r.stdout.splitlines() if l.startswith("PROBE ")), None)
        if not check("pvpython reads the result", r.returncode == 0 and line, (r.stdout + r.stderr)[-1500:]):
            finish()
        seen = json.loads(line[len("PROBE "):])
        with h5py.File(os.path.join(tmp, "result.hdf")) as h:
            last = h["steps"][str(h["steps"].attrs["count"] - 1)]
            bodies = {name: last["bodies"][name]["cells"].shape[0] for name in last.attrs["body_names"]}
            pairs = {"contacts": last["contacts/segments"].shape[0]}  # every pair's segments, one block
            contact_points = last["contacts/position"].shape[0]
            triangles = sum(int((last["bodies"][n]["cell_types"][()] == 5).sum()) for n in bodies)
    names = ["XX", "YY", "ZZ", "XY", "YZ", "XZ"]
    check("the sidecar's blocks are named after the bodies, and 'contacts' holds the pairs' segments, with all "
          "their cells", seen["xmf_blocks"] == {**bodies, **pairs}, (seen["xmf_blocks"], bodies, pairs))
    check("the contact block has every slave node with pressure, gap, active and each node's pair",
          seen.get("xmf_contact_points") == contact_points
          and {"pressure", "gap", "active", "pair"} <= set(seen.get("xmf_contact_arrays", [])),
          (seen.get("xmf_contact_points"), contact_points, seen.get("xmf_contact_arrays")))
    for key in ("xmf_stress_node", "xmf_stress_cell", "hdf_stress_point", "hdf_stress_cell"):
        check(f"{key}: the stress components are named {names}", seen[key] == names, seen[key])
    types = seen["hdf_cell_types"]
    check("/VTKHDF: the bodies' triangles (5) and quadrilaterals (9), the pair's segments (3)",
          types.get("5") == triangles and types.get("5", 0) + types.get("9", 0) == sum(bodies.values())
          and types.get("3") == sum(pairs.values()) and triangles > 0, (types, triangles, bodies, pairs))
    finish()


if __name__ == "__main__":
    main()
