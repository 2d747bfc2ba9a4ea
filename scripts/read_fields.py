#!/usr/bin/env python3
"""Read FrostMPM particle field output (fields.xdmf + fields.h5) the way a visualiser does.

    read_fields.py OUTPUT_DIR                            print a JSON summary of every frame
    read_fields.py OUTPUT_DIR --dump                     ... including all values
    read_fields.py OUTPUT_DIR --check-against EXPECTED.json

fields.xdmf is parsed with xml.etree; every DataItem "fields.h5:/path" is resolved relative to
the XDMF file and read with h5py, so only what the XDMF describes is trusted. The XDMF-declared
Dimensions must match the HDF5 dataset shapes, and the Polyvertex connectivity must be 0..N-1.

Every dataset's "units" attribute (a UDUNITS-2 string: "degC", "Pa", "m/s", "1" for
dimensionless) comes back as frame["units"][name] (None for output written before FrostMPM
recorded units) and is printed in the summary.

EXPECTED.json:
    {"frames": [{"time": 0.0, "step": 0, "count": 3,
                 "coordinates": [[x, y], ...],              # dim or 3 columns
                 "fields": {"T": [..], "v": [[vx, vy], ...]},
                 "types": {"T": "Scalar", "v": "Vector"},   # "types" optional
                 "units": {"T": "degC", "v": "m/s"}}]}      # "units" optional
Every key of a frame except "time" is optional. Values must match exactly. Fewer columns than
stored are accepted when they equal the dataset's "components" attribute (2D coordinates,
2-vectors padded to 3); the padding must then be zero. The field set must match exactly.

Exit status: 0 ok (or summary printed), 1 mismatch, 2 unreadable output or bad arguments.
"""
import argparse
import json
import os
import sys
import xml.etree.ElementTree as ET

try:
    import h5py
    import numpy as np
except ImportError as error:  # pragma: no cover - depends on the machine
    sys.stderr.write(f"read_fields.py: {error}; install python3-h5py and python3-numpy "
                     "(run scripts/setup-debian.sh)\n")
    sys.exit(2)

NUMBER_TYPES = {("Float", 4): np.float32, ("Float", 8): np.float64,
                ("Int", 1): np.int8, ("Int", 2): np.int16, ("Int", 4): np.int32, ("Int", 8): np.int64,
                ("UInt", 1): np.uint8, ("UInt", 2): np.uint16, ("UInt", 4): np.uint32,
                ("UInt", 8): np.uint64, ("Char", 1): np.int8, ("UChar", 1): np.uint8}
ATTRIBUTE_COMPONENTS = {"Scalar": 1, "Vector": 3, "Tensor6": 6, "Tensor": 9}


class FormatError(Exception):
    """The output cannot be read as described."""


class DataItemReader:
    """Reads DataItems, keeping the HDF5 files it opens."""

    def __init__(self, base_dir):
        self.base_dir = base_dir
        self.files = {}

    def close(self):
        for handle in self.files.values():
            handle.close()

    def dataset(self, item):
        """(array, h5py dataset or None) for a DataItem element."""
        if item is None:
            raise FormatError("missing DataItem")
        dims = tuple(int(d) for d in item.get("Dimensions", "").split())
        fmt = item.get("Format", "XML")
        text = (item.text or "").strip()
        if fmt == "HDF":
            if ":" not in text:
                raise FormatError(f"DataItem '{text}' is not of the form file.h5:/path")
            filename, path = text.split(":", 1)
            full = os.path.join(self.base_dir, filename)
            if full not in self.files:
                try:
                    self.files[full] = h5py.File(full, "r")
                except OSError as error:
                    raise FormatError(f"cannot open {full}: {error}") from error
            h5 = self.files[full]
            if path not in h5:
                raise FormatError(f"{filename}:{path} does not exist")
            dset = h5[path]
            data = dset[()]
            if dims and tuple(data.shape) != dims:
                raise FormatError(f"{filename}:{path} has shape {data.shape}, XDMF says {dims}")
            ntype = (item.get("NumberType", item.get("DataType", "Float")), int(item.get("Precision", "4")))
            expected_dtype = NUMBER_TYPES.get(ntype)
            if expected_dtype is not None and data.dtype != np.dtype(expected_dtype):
                raise FormatError(f"{filename}:{path} is {data.dtype}, XDMF says {ntype[0]}{8 * ntype[1]}")
            return data, dset
        if fmt == "XML":
            values = np.array([float(v) for v in text.split()])
            return (values.reshape(dims) if dims else values), None
        raise FormatError(f"unsupported DataItem Format '{fmt}'")


def uniform_grids(root):
    """The Uniform grids of the first Domain, in time order as listed."""
    domain = root.find("Domain")
    if domain is None:
        raise FormatError("no Domain element")
    grids = []

    def visit(grid):
        if grid.get("GridType", "Uniform") == "Collection":
            for child in grid.findall("Grid"):
                visit(child)
        else:
            grids.append(grid)

    for grid in domain.findall("Grid"):
        visit(grid)
    return grids


def read_frames(folder):
    """Parses <folder>/fields.xdmf and reads every frame it lists."""
    xdmf_path = os.path.join(folder, "fields.xdmf")
    try:
        root = ET.parse(xdmf_path).getroot()
    except (OSError, ET.ParseError) as error:
        raise FormatError(f"cannot parse {xdmf_path}: {error}") from error
    if root.tag != "Xdmf":
        raise FormatError(f"{xdmf_path}: root element is {root.tag}, not Xdmf")
    reader = DataItemReader(os.path.dirname(os.path.abspath(xdmf_path)))
    frames = []
    try:
        for grid in uniform_grids(root):
            name = grid.get("Name", "")
            time_element = grid.find("Time")
            if time_element is None or time_element.get("Value") is None:
                raise FormatError(f"grid {name}: no <Time Value=...>")
            frame = {"name": name, "time": float(time_element.get("Value"))}

            topology = grid.find("Topology")
            if topology is None or topology.get("TopologyType", topology.get("Type")) != "Polyvertex":
                raise FormatError(f"grid {name}: Topology is not Polyvertex")
            count = int(topology.get("NumberOfElements", topology.get("Dimensions", "-1")))
            connectivity, _ = reader.dataset(topology.find("DataItem"))
            if connectivity.size != count or not np.array_equal(connectivity.reshape(-1), np.arange(count)):
                raise FormatError(f"grid {name}: Polyvertex connectivity is not 0..{count - 1}")
            frame["count"] = count

            geometry = grid.find("Geometry")
            gtype = None if geometry is None else geometry.get("GeometryType", geometry.get("Type", "XYZ"))
            if gtype not in ("XYZ", "XY"):
                raise FormatError(f"grid {name}: unsupported Geometry {gtype}")
            coordinates, coord_dset = reader.dataset(geometry.find("DataItem"))
            width = 3 if gtype == "XYZ" else 2
            if coordinates.shape != (count, width):
                raise FormatError(f"grid {name}: coordinates shape {coordinates.shape}, expected ({count}, {width})")
            frame["coordinates"] = coordinates
            frame["coordinates_components"] = _components(coord_dset, width)
            frame["coordinates_units"] = _units(coord_dset)
            if coord_dset is not None:
                group = coord_dset.parent
                for key in ("time", "step"):
                    if key in group.attrs:
                        frame["h5_" + key] = group.attrs[key].item()

            fields, types, components, units = {}, {}, {}, {}
            for attribute in grid.findall("Attribute"):
                fname = attribute.get("Name")
                if not fname or fname in fields:
                    raise FormatError(f"grid {name}: missing or repeated Attribute Name '{fname}'")
                if attribute.get("Center", "Node") != "Node":
                    raise FormatError(f"grid {name}: Attribute {fname} is not Node-centred")
                atype = attribute.get("AttributeType", attribute.get("Type", "Scalar"))
                values, dset = reader.dataset(attribute.find("DataItem"))
                if values.shape[0] != count:
                    raise FormatError(f"grid {name}: Attribute {fname} has {values.shape[0]} rows, not {count}")
                ncomp = 1 if values.ndim == 1 else values.shape[1]
                if atype in ATTRIBUTE_COMPONENTS and ATTRIBUTE_COMPONENTS[atype] != ncomp:
                    raise FormatError(f"grid {name}: {atype} Attribute {fname} has {ncomp} components")
                fields[fname], types[fname] = values, atype
                components[fname] = _components(dset, ncomp)
                units[fname] = _units(dset)
            frame.update(fields=fields, types=types, components=components, units=units)
            frames.append(frame)
    finally:
        reader.close()
    return frames


def _components(dset, stored):
    if dset is not None and "components" in dset.attrs:
        return int(dset.attrs["components"])
    return stored


def _units(dset):
    """The dataset's "units" attribute as text, or None when it has none."""
    if dset is None or "units" not in dset.attrs:
        return None
    value = dset.attrs["units"]
    return value.decode("utf-8") if isinstance(value, bytes) else str(value)


def summary(frames, dump):
    out = {"frames": []}
    for frame in frames:
        entry = {"name": frame["name"], "time": frame["time"], "count": frame["count"]}
        if "h5_step" in frame:
            entry["step"] = frame["h5_step"]
        entry["dim"] = frame["coordinates_components"]
        entry["fields"] = {}
        for fname, values in frame["fields"].items():
            info = {"type": frame["types"][fname], "units": frame["units"][fname], "shape": list(values.shape),
                    "components": frame["components"][fname]}
            if values.size:
                info["min"], info["max"] = float(np.min(values)), float(np.max(values))
            if dump:
                info["values"] = np.asarray(values).tolist()
            entry["fields"][fname] = info
        if dump:
            entry["coordinates"] = frame["coordinates"].tolist()
        out["frames"].append(entry)
    return out


def compare_array(label, stored, stored_components, expected, problems):
    expected = np.asarray(expected, dtype=float)
    if stored.ndim == 1:
        if expected.shape != stored.shape or not np.array_equal(stored, expected):
            problems.append(f"{label}: values differ{_first_difference(stored, expected)}")
        return
    if expected.ndim == 1 and stored.shape[1] == 1:
        expected = expected.reshape(-1, 1)
    if expected.ndim != 2 or expected.shape[0] != stored.shape[0]:
        problems.append(f"{label}: expected shape {expected.shape}, stored {stored.shape}")
        return
    columns = expected.shape[1]
    if columns != stored.shape[1]:
        if columns != stored_components:
            problems.append(f"{label}: expected {columns} columns, stored {stored.shape[1]} "
                            f"(components attribute {stored_components})")
            return
        if np.any(stored[:, columns:] != 0.0):
            problems.append(f"{label}: padding columns {columns}.. are not zero")
    if not np.array_equal(stored[:, :columns], expected):
        problems.append(f"{label}: values differ{_first_difference(stored[:, :columns], expected)}")


def _first_difference(a, b):
    if a.shape != b.shape:
        return f" (shape {a.shape} vs expected {b.shape})"
    index = tuple(np.argwhere(a != b)[0]) if np.any(a != b) else None
    return "" if index is None else f" (first at {index}: stored {a[index]!r}, expected {b[index]!r})"


def check(frames, expected):
    problems = []
    wanted = expected.get("frames", [])
    if len(frames) != len(wanted):
        problems.append(f"{len(frames)} frames in fields.xdmf, expected {len(wanted)}")
    for index, (frame, want) in enumerate(zip(frames, wanted)):
        label = f"frame {index} ({frame['name']})"
        if "time" in want:
            if frame["time"] != want["time"]:
                problems.append(f"{label}: XDMF time {frame['time']!r}, expected {want['time']!r}")
            if "h5_time" in frame and frame["h5_time"] != want["time"]:
                problems.append(f"{label}: HDF5 time attribute {frame['h5_time']!r}, expected {want['time']!r}")
        if "step" in want and frame.get("h5_step") != want["step"]:
            problems.append(f"{label}: step {frame.get('h5_step')!r}, expected {want['step']!r}")
        if "count" in want and frame["count"] != want["count"]:
            problems.append(f"{label}: {frame['count']} particles, expected {want['count']}")
        if "coordinates" in want:
            compare_array(f"{label} coordinates", frame["coordinates"], frame["coordinates_components"],
                          want["coordinates"], problems)
        if "fields" in want:
            have, need = set(frame["fields"]), set(want["fields"])
            if have != need:
                problems.append(f"{label}: fields {sorted(have)}, expected {sorted(need)}")
            for fname in sorted(have & need):
                compare_array(f"{label} field {fname}", frame["fields"][fname], frame["components"][fname],
                              want["fields"][fname], problems)
        for fname, atype in want.get("types", {}).items():
            if frame["types"].get(fname) != atype:
                problems.append(f"{label}: field {fname} has AttributeType {frame['types'].get(fname)!r}, "
                                f"expected {atype!r}")
        for fname, unit in want.get("units", {}).items():
            if frame["units"].get(fname) != unit:
                problems.append(f"{label}: field {fname} has units {frame['units'].get(fname)!r}, expected {unit!r}")
    return problems


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", help="output folder holding fields.xdmf and fields.h5")
    parser.add_argument("--check-against", metavar="FILE.json", help="compare with expected values")
    parser.add_argument("--dump", action="store_true", help="include every value in the summary")
    args = parser.parse_args(argv)
    try:
        frames = read_frames(args.folder)
    except FormatError as error:
        print(f"read_fields.py: {error}", file=sys.stderr)
        return 2
    if args.check_against:
        try:
            with open(args.check_against, encoding="utf-8") as handle:
                expected = json.load(handle)
        except (OSError, ValueError) as error:
            print(f"read_fields.py: cannot read {args.check_against}: {error}", file=sys.stderr)
            return 2
        problems = check(frames, expected)
        for problem in problems:
            print(f"MISMATCH {problem}")
        if problems:
            return 1
        print(f"OK: {len(frames)} frames match {args.check_against}")
        return 0
    json.dump(summary(frames, args.dump), sys.stdout, indent=1)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
