"""Run by pvpython (ParaView's Python; not a pytest module): open an XDMF sidecar of
ropedyn with one of ParaView's ways to open it and check what ParaView sees against
EXPECTED.json.

usage: pvpython --force-offscreen-rendering pv_check_xdmf.py RUN.xmf EXPECTED.json [READER]

READER: open (OpenDataFile: ParaView's own choice for the file, as File > Open does),
XDMFReader (legacy "XDMF Reader", the default), Xdmf3ReaderS or Xdmf3ReaderT.

EXPECTED.json: {"times": [...], "elements": n, "checks": [{"record": k, "tip": [x, y],
"tension": [n values]}, ...]}. Checks: the time step values, the number of points (2 n)
and cells (n), the cell arrays tension, curvature, speed, velocity and the point array
joint_tension, and at each listed record the tip position and the cell tension (so the
geometry and fields really change with time). Prints what it sees, exits 1 on a failure.
"""
import json
import sys

from paraview import servermanager
from paraview import simple


def fail(message):
    print(f"FAIL {message}")
    sys.exit(1)


def fetch(reader, t):
    """The unstructured grid ParaView reads at time t."""
    reader.UpdatePipeline(time=t)
    data = servermanager.Fetch(reader)
    return data.GetBlock(0) if data.IsA("vtkMultiBlockDataSet") else data


def array_names(field_data):
    return [field_data.GetArrayName(i) for i in range(field_data.GetNumberOfArrays())]


def check_record(reader, steps, check, elements):
    k = check["record"]
    block = fetch(reader, steps[k])
    points, cells = block.GetNumberOfPoints(), block.GetNumberOfCells()
    if points != 2 * elements or cells != elements:
        fail(f"record {k}: {points} points / {cells} cells, expected "
             f"{2 * elements} / {elements}")
    for name in ("tension", "curvature", "speed", "velocity"):
        if name not in array_names(block.GetCellData()):
            fail(f"record {k}: cell array {name} missing")
    if "joint_tension" not in array_names(block.GetPointData()):
        fail(f"record {k}: point array joint_tension missing")
    tip = block.GetPoint(points - 1)
    want = check["tip"]
    if abs(tip[0] - want[0]) > 1e-12 or abs(tip[1] - want[1]) > 1e-12 or tip[2] != 0.0:
        fail(f"record {k}: tip {tip}, expected ({want[0]}, {want[1]}, 0)")
    tension = block.GetCellData().GetArray("tension")
    got = [tension.GetValue(i) for i in range(cells)]
    if max(abs(a - b) for a, b in zip(got, check["tension"])) > 1e-12:
        fail(f"record {k}: tension {got}, expected {check['tension']}")
    print(f"record {k} t={steps[k]:g}: {points} points, {cells} cells, tip {tip[:2]}, "
          f"cell arrays {array_names(block.GetCellData())}")


def main(argv):
    if len(argv) not in (3, 4):
        fail("usage: pv_check_xdmf.py RUN.xmf EXPECTED.json [READER]")
    with open(argv[2]) as f:
        expected = json.load(f)
    which = argv[3] if len(argv) == 4 else "XDMFReader"
    if which == "open":
        reader = simple.OpenDataFile(argv[1])
    elif which == "XDMFReader":
        reader = simple.XDMFReader(registrationName="rope", FileNames=[argv[1]])
    elif which in ("Xdmf3ReaderS", "Xdmf3ReaderT"):
        reader = getattr(simple, which)(registrationName="rope", FileName=[argv[1]])
    else:
        fail(f"unknown reader {which}")
    print(f"reader {which}: {reader.GetXMLName()}")
    values = reader.TimestepValues
    steps = list(values) if hasattr(values, "__iter__") else [values]
    print(f"timesteps {len(steps)}")
    if len(steps) != len(expected["times"]):
        fail(f"{len(steps)} time steps, expected {len(expected['times'])}")
    if max(abs(a - b) for a, b in zip(steps, expected["times"])) > 1e-12:
        fail(f"time step values {steps[:5]}... differ from {expected['times'][:5]}...")
    for check in expected["checks"]:
        check_record(reader, steps, check, expected["elements"])
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
