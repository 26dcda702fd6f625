"""Write an XDMF sidecar for a ropedyn run so that ParaView opens it as a time series of
polylines (one line cell per element) with per-element and per-point fields.

usage: scripts/xdmf RUN.h5 [--every K] [--force]   writes RUN.xmf and RUN_fields.h5 next
       to RUN.h5 (python -m ropedyn.xdmf)

The geometry (the run's /rope/points, one plain dataset per described record) and the
fields (the model's stored internal forces: tension, shear, moment; curvature, speed,
velocity, angle; definitions in docs/guide/visualization.md) go into the sidecar RUN_fields.h5. The run file is only read, never
modified. RUN.xmf opens in ParaView with File > Open (OpenDataFile) and with each of its
XDMF readers ("XDMF Reader", "Xdmf3 Reader S", "Xdmf3 Reader T"): the layout avoids what
the Xdmf3 readers cannot read (a HyperSlab in a Geometry crashes them). The coordinates are the run's: x
points down (gravity), y horizontal, z = 0.
"""
import argparse
import os
import pathlib
import sys
import xml.etree.ElementTree as ET

import h5py
import numpy as np

from ropedyn import fields as derived
from ropedyn import io
from ropedyn.plot import load_records, made_by, written_whole
from ropedyn.docstrings import summary

FIELD_UNITS = {"tension": "N", "curvature": "1/m", "speed": "m/s", "velocity": "m/s",
               "angle": "rad", "joint_tension": "N", "joint_curvature": "1/m",
               "joint_shear": "N", "joint_moment": "N m"}


WRITTEN_BY = "ropedyn.xdmf (scripts/xdmf)"
PROVENANCE = ("version", "scene", "units_convention")


def refusal(path, kind):
    """Why the existing `path` is not a sidecar file of `kind` ('xmf' or 'fields') that this
    script may replace (None when it is one, or when there is none)."""
    if not os.path.lexists(path):
        return None
    if not path.is_file():
        return f"{path}: exists and is not a regular file: not replaced"
    if kind == "fields":
        try:
            with h5py.File(path, "r") as f:
                ours = io.text(f.attrs.get("written_by", "")) == WRITTEN_BY
        except OSError:
            ours = False
    else:
        # an XDMF file of another program has the same DOCTYPE: ours names the script (in its
        # comment) or, written before the comment, our RUN_fields.h5 in its first grid
        with open(path, "rb") as f:
            head = f.read(1000)
        ours = b"<!DOCTYPE Xdmf" in head and (
            f"<!-- {WRITTEN_BY} from ".encode() in head
            or f">{path.stem}_fields.h5:/connectivity<".encode() in head)
    if ours:
        return None
    return (f"{path}: exists and is not a file of scripts/xdmf: not replaced "
            f"(--force replaces it)")


def derived_fields(run):
    """({'cell': {name: (T, n[, 3])}, 'point': {name: (T, 2n)}}, notes)."""
    kappa = derived.joint_curvature(run)
    vel = derived.velocity(run)
    cell = {"curvature": derived.joints_to_elements(kappa),
            "speed": derived.speed(run),
            "velocity": np.concatenate([vel, np.zeros(vel.shape[:2] + (1,))], axis=-1),
            "angle": derived.element_angles(run)}
    point = {"joint_curvature": derived.joints_to_points(kappa)}
    notes = {"curvature": "joint curvature wrap(phi_{j+1} - phi_j)/h (0 at pinned and free "
                          "ends); cell: mean of the element's two joints",
             "speed": "|(xdot, ydot)| of the element centre (/state/qdot)",
             "velocity": "(xdot, ydot, 0) of the element centre",
             "angle": "element direction from x towards y, from the polyline",
             "joint_curvature": "joint curvature at the element end points: A_i takes its "
                                "upper joint, B_i its lower joint"}
    force, message = derived.axial_force(run)
    if force is not None:
        cell["tension"] = force.per_element
        point["joint_tension"] = force.per_point
        notes["tension"] = force.definition
        notes["joint_tension"] = ("the stored axial force (/forces/axial) at the element end "
                                  "points: A_i takes its upper joint, B_i its lower joint")
        for name in ("shear", "moment"):
            point[f"joint_{name}"] = derived.joints_to_points(run.forces[name])
            notes[f"joint_{name}"] = (f"the stored {name} (/forces/{name}) at the element end "
                                      "points, as joint_tension")
    else:
        notes["tension"] = message
    return {"cell": cell, "point": point}, notes


def write_fields(path, run, fields, notes, picked, points):
    """The sidecar HDF5: /connectivity, /time, /cell/*, /point/* (all records), each with
    units; for each described record K, /geometry/record_K (2n, 2: the points of
    /rope/points) and /records/record_K/{cell,point}/NAME. What RUN.xmf names is a plain
    dataset per time, which every XDMF reader of ParaView reads: the Xdmf3 readers crash
    on a HyperSlab in a Geometry and skip HyperSlab attributes."""
    with h5py.File(path, "w") as f:
        f.attrs["source"] = pathlib.Path(run.path).name
        f.attrs["model"] = run.model
        f.attrs["written_by"] = WRITTEN_BY
        # what made the data: the run file's code version, effective scene and convention
        for name in PROVENANCE:
            if name in run.attrs:
                f.attrs[name] = run.attrs[name]
        conn = np.arange(2 * run.n, dtype=np.int32).reshape(run.n, 2)
        f.create_dataset("connectivity", data=conn)
        f.create_dataset("time", data=run.time).attrs["units"] = "s"
        for center, group in fields.items():
            for name, values in group.items():
                ds = f.create_dataset(f"{center}/{name}", data=values, chunks=True,
                                      compression="gzip", compression_opts=4, shuffle=True)
                ds.attrs["units"] = FIELD_UNITS[name]
                ds.attrs["definition"] = notes[name]
        geometry = f.create_group("geometry")
        geometry.attrs["definition"] = ("record_K: the element end points (x, y) of record K "
                                        "of the run file's /rope/points")
        records = f.create_group("records")
        records.attrs["definition"] = ("record_K/{cell,point}/NAME: record K of /cell/NAME, "
                                       "/point/NAME (what RUN.xmf names, one dataset per time)")
        for k in picked:
            geometry.create_dataset(_record_name(k), data=points[k]).attrs["units"] = "m"
            for center, group in fields.items():
                for name, values in group.items():
                    records.create_dataset(f"{_record_name(k)}/{center}/{name}",
                                           data=values[k])


def _record_name(k):
    return f"record_{k:06d}"


def _hdf_item(parent, file_name, path, shape, number_type="Float", precision=8):
    item = ET.SubElement(parent, "DataItem", Format="HDF", NumberType=number_type,
                         Precision=str(precision), Dimensions=" ".join(map(str, shape)))
    item.text = f"{file_name}:{path}"
    return item


def build_xdmf(run_path, fields_path, records, points_shape, fields):
    """The XDMF tree: a temporal collection with one uniform grid per selected record."""
    fields_name = pathlib.Path(fields_path).name
    n = points_shape[1] // 2
    root = ET.Element("Xdmf", Version="2.0")
    domain = ET.SubElement(root, "Domain")
    series = ET.SubElement(domain, "Grid", Name="rope", GridType="Collection",
                           CollectionType="Temporal")
    for k, t in records:
        grid = ET.SubElement(series, "Grid", Name=f"record {k}", GridType="Uniform")
        ET.SubElement(grid, "Time", Value=repr(float(t)))
        topo = ET.SubElement(grid, "Topology", TopologyType="Polyline", NodesPerElement="2",
                             NumberOfElements=str(n))
        _hdf_item(topo, fields_name, "/connectivity", (n, 2), "Int", 4)
        geom = ET.SubElement(grid, "Geometry", GeometryType="XY")
        _hdf_item(geom, fields_name, f"/geometry/{_record_name(k)}", (2 * n, 2))
        for center, group in fields.items():
            for name, values in group.items():
                kind = "Vector" if values.ndim == 3 else "Scalar"
                attr = ET.SubElement(grid, "Attribute", Name=name, AttributeType=kind,
                                     Center={"cell": "Cell", "point": "Node"}[center])
                _hdf_item(attr, fields_name, f"/records/{_record_name(k)}/{center}/{name}",
                          values.shape[1:])
    ET.indent(root, space=" ")
    return ET.ElementTree(root)


def main(argv=None):
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("run", help="HDF5 output of ropedyn run")
    parser.add_argument("--every", type=int, default=1,
                        help="describe every K-th record only (default 1: all)")
    parser.add_argument("--force", action="store_true",
                        help="replace RUN.xmf and RUN_fields.h5 even when they are not "
                             "files of this script")
    args = parser.parse_args(argv)
    if args.every < 1:
        parser.error("--every must be >= 1")
    run_path = pathlib.Path(args.run)
    base = run_path.with_suffix("")
    xmf_path = base.with_name(base.name + ".xmf")
    fields_path = base.with_name(base.name + "_fields.h5")
    for path, kind in ((xmf_path, "xmf"), (fields_path, "fields")):
        why = refusal(path, kind)
        if why and (not args.force or not path.is_file()):
            print(f"xdmf: {why}", file=sys.stderr)
            return 2

    run, code = load_records("xdmf", run_path)
    if run is None:
        return code
    # both files are written whole as .part and then renamed (the fields first): an
    # interrupted script leaves the earlier pair as it was, and a reader holding them keeps
    # reading them
    with written_whole(xmf_path) as xmf_part, written_whole(fields_path) as fields_part:
        with h5py.File(run_path, "r") as f:
            points = f["rope/points"]  # may be one record longer than /time
            points_shape = points.shape
            picked = range(0, run.time.size, args.every)
            fields, notes = derived_fields(run)
            write_fields(fields_part, run, fields, notes, picked, points)
        tree = build_xdmf(run_path, fields_path, [(k, run.time[k]) for k in picked],
                          points_shape, fields)
        with open(xmf_part, "wb") as out:
            out.write(b'<?xml version="1.0" ?>\n<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>\n')
            out.write(f"<!-- {made_by(run, WRITTEN_BY)} -->\n".encode())
            tree.write(out, encoding="utf-8", xml_declaration=False)
    if "tension" not in fields["cell"]:
        print(f"xdmf: {notes['tension']}", file=sys.stderr)
    print(f"xdmf: {xmf_path} ({len(picked)} times, {run.n} elements; fields in "
          f"{fields_path.name})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
