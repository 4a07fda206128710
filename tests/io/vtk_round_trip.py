#!/usr/bin/python3
"""Reads gpa's snapshot files with VTK's own XML readers (Debian's python3-vtk9), an implementation
independent of gpa's writer and of its reader, and checks every array against expected.txt, which
SnapshotFiles.EveryFieldHoldsItsNodeValuesInBothPrecisions wrote from the node data: the array's
place (point or cell data, or the points), VTK type, components, tuples and every value, exactly
(a Float32 array holds the nearest float of each value).

Usage: vtk_round_trip.py FOLDER   (prints one line per file; exit 1 on any difference)
"""
import struct
import sys

try:
    import vtk
except ImportError:
    print("vtk_round_trip.py: Python's vtk module is not installed (Debian: python3-vtk9; scripts/install-deps.sh installs it)")
    sys.exit(1)

# The VTK data type each XML type name must be read as (vtkType.h). Int64 is read as long long
# or, where long is 64 bits wide, as long or vtkIdType; all of them hold the ids exactly.
VTK_TYPES = {
    "Float64": {vtk.VTK_DOUBLE},
    "Float32": {vtk.VTK_FLOAT},
    "Int32": {vtk.VTK_INT},
    "UInt8": {vtk.VTK_UNSIGNED_CHAR},
    "Int64": {vtk.VTK_LONG_LONG, vtk.VTK_LONG, vtk.VTK_ID_TYPE},
}


def nearest_float(v):
    return struct.unpack("<f", struct.pack("<f", v))[0]


def read_expected(path):
    """{file: [(location, name, type, components, tuples, values)]} in the order written."""
    files, current, array = {}, None, None
    with open(path) as text:
        for line in text:
            words = line.split()
            if words[0] == "file":
                current = files.setdefault(words[1], [])
            elif words[0] == "array":
                array = (words[1], words[2], words[3], int(words[4]), int(words[5]), [])
                current.append(array)
            else:
                array[5].append(float(words[0]))
    return files


def read_vtk(path):
    reader = vtk.vtkXMLPolyDataReader() if path.endswith(".vtp") else vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    if reader.GetErrorCode() != 0:
        raise RuntimeError(f"{path}: VTK's reader reports error {reader.GetErrorCode()}")
    return reader.GetOutput()


def check_file(folder, name, arrays):
    data = read_vtk(f"{folder}/{name}")
    problems = []
    named = {"point": 0, "cell": 0}
    for location, array_name, type_name, components, tuples, values in arrays:
        if array_name == "-":
            found = data.GetPoints().GetData()
        else:
            fields = data.GetPointData() if location == "point" else data.GetCellData()
            found = fields.GetAbstractArray(array_name)
            named[location] += 1
        if found is None:
            problems.append(f"{array_name}: not in the {location} data")
            continue
        if found.GetDataType() not in VTK_TYPES[type_name]:
            problems.append(f"{array_name}: VTK type {found.GetDataTypeAsString()}, expected {type_name}")
        if found.GetNumberOfComponents() != components or found.GetNumberOfTuples() != tuples:
            problems.append(f"{array_name}: {found.GetNumberOfTuples()} x {found.GetNumberOfComponents()}, "
                            f"expected {tuples} x {components}")
            continue
        for k, want in enumerate(values):
            if type_name == "Float32":
                want = nearest_float(want)
            got = found.GetComponent(k // components, k % components)
            if got != want:
                problems.append(f"{array_name}: value {k} reads {got!r}, expected {want!r}")
                break
    for location, fields in (("point", data.GetPointData()), ("cell", data.GetCellData())):
        if fields.GetNumberOfArrays() != named[location]:
            problems.append(f"{fields.GetNumberOfArrays()} {location} arrays, expected {named[location]}")
    return problems


def main():
    folder = sys.argv[1]
    expected = read_expected(f"{folder}/expected.txt")
    if len(expected) != 6:
        print(f"expected.txt lists {len(expected)} files, expected 6")
        return 1
    failures = 0
    for name, arrays in expected.items():
        problems = check_file(folder, name, arrays)
        values = sum(len(a[5]) for a in arrays)
        print(f"{name}: {len(arrays)} arrays, {values} values: {'ok' if not problems else 'DIFFERENT'}")
        for p in problems:
            print(f"  {p}")
        failures += bool(problems)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
