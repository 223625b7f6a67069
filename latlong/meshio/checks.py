"""Checks of mesh files before a third-party reader (VTK through pyvista) sees them.

VTK trusts the element counts of a PLY header: a header declaring 10^8 vertices over a
few kilobytes of data makes it read past its buffers (a segmentation fault, not an
exception). :func:`ply_size_problem` compares the counts with the file's size first, so
that :func:`latlong.meshio.readers.read_mesh` raises a one-line ``ValueError`` instead.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["MAX_HEADER_BYTES", "check_mesh_file", "ply_min_bytes", "ply_size_problem"]

#: Longest PLY header read (bytes); real headers are a few hundred bytes.
MAX_HEADER_BYTES = 1 << 16
_PLY_SIZES = {"char": 1, "uchar": 1, "int8": 1, "uint8": 1, "short": 2, "ushort": 2,
              "int16": 2, "uint16": 2, "int": 4, "uint": 4, "int32": 4, "uint32": 4,
              "float": 4, "float32": 4, "double": 8, "float64": 8}


def ply_min_bytes(header: str) -> int:
    """The fewest bytes of data (after ``end_header``) that a PLY header's element
    counts need: fixed-size properties in full, each list at least its count field
    (binary) or two characters per value (ASCII). ``ValueError`` for a malformed
    header.

    Examples
    --------
    >>> ply_min_bytes("ply\\nformat binary_little_endian 1.0\\nelement vertex 10\\n"
    ...               "property float x\\nproperty float y\\nproperty float z\\nend_header\\n")
    120
    """
    lines = [ln.split() for ln in header.splitlines()]
    fmt = next((ln[1] for ln in lines if len(ln) >= 2 and ln[0] == "format"), None)
    if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise ValueError(f"PLY header: unknown format {fmt!r}")
    total, count, size, n_props = 0, 0, 0, 0

    def close():
        per = size if fmt != "ascii" else 2 * max(n_props, 1)
        return count * per

    for ln in lines:
        if not ln or ln[0] not in ("element", "property"):
            continue
        if ln[0] == "element":
            total += close()
            if len(ln) != 3 or not ln[2].isdigit():
                raise ValueError(f"PLY header: bad element line {' '.join(ln)!r}")
            count, size, n_props = int(ln[2]), 0, 0
            continue
        n_props += 1
        if len(ln) >= 5 and ln[1] == "list":
            type_ = ln[2]
        elif len(ln) == 3:
            type_ = ln[1]
        else:
            raise ValueError(f"PLY header: bad property line {' '.join(ln)!r}")
        if type_ not in _PLY_SIZES:
            raise ValueError(f"PLY header: unknown property type {type_!r}")
        size += _PLY_SIZES[type_]
    return total + close()


def ply_size_problem(path) -> str | None:
    """Why a PLY file cannot hold what its header declares (one line), or None (also for
    any other format)."""
    path = Path(path)
    if path.suffix.lower() != ".ply":
        return None
    size = path.stat().st_size
    with open(path, "rb") as fh:
        head = fh.read(MAX_HEADER_BYTES)
    end = head.find(b"end_header")
    if not head.startswith(b"ply") or end < 0:
        return (f"it is not a PLY file (no 'ply' ... 'end_header' header in its first "
                f"{MAX_HEADER_BYTES} bytes)")
    stop = head.find(b"\n", end)
    data_start = (stop + 1) if stop >= 0 else len(head)
    try:
        need = ply_min_bytes(head[:end].decode("ascii", errors="replace"))
    except ValueError as exc:
        return str(exc)
    have = size - data_start
    if need > have:
        return (f"its header declares elements that need at least {need} bytes; the file "
                f"holds {have} after the header (truncated or corrupt)")
    return None


def check_mesh_file(path, what: str = "mesh file") -> None:
    """Refuse a PLY file whose header declares more elements than its size can hold
    (one-line ``ValueError``, :func:`ply_size_problem`); other formats pass unchanged."""
    problem = ply_size_problem(path)
    if problem:
        raise ValueError(f"{what} {str(Path(path))!r}: {problem}")
