"""Zarr DEMs: GDAL's Zarr driver (Zarr format 2, zlib-compressed 512 x 512 chunks).

``dem.write(dem, "out.zarr")``, :class:`dem.io.WindowWriter` and every ``dem`` command
that writes one DEM take a ``.zarr`` output, and :func:`dem.read` reads one back: a
folder holding the group ``.zgroup``, its consolidated ``.zmetadata``, the float32 array
``height`` (NaN = unknown; its attributes hold the tags a GeoTIFF would, the CRS as
``_CRS`` WKT/PROJJSON and the dimension names xarray reads) and GDAL's coordinate arrays
``X`` and ``Y`` (pixel centres in CRS units).

GDAL creates the store and its metadata; the heights go into the chunks through
:class:`ChunkWriter` (numpy and zlib, Zarr's own encoding), because GDAL pads a chunk at
the array's edge with zeros or NaN depending on how the windows that wrote it were cut.
Here a chunk's file depends only on its final heights (padding NaN, the fill value; a
chunk with no known height is not stored, as Zarr allows), so the same DEM always gives
the same files, byte for byte, whether written whole or window by window in any order.

Why format 2: GDAL 3.10 writes format-3 metadata from a draft of the specification that
zarr-python 3 rejects (no array-to-bytes codec), while its format-2 stores read in
zarr-python 2 and 3, xarray and GDAL alike.

The store is written into a temporary folder beside the output and renamed into place
at the end (an error leaves nothing); an existing output is replaced only if it is a Zarr
DEM (nothing but the entries above), a symbolic link only as a link.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import zlib
from pathlib import Path

import numpy as np

from craters._shared import check_parent_folder, replace_output, sweep_temporaries, temp_folder
from craters._shared.outputs import claim

__all__ = ["ARRAY", "ZARR_OPTIONS", "ZARR_SUFFIXES", "ChunkWriter", "ZarrStore",
           "check_zarr_output", "drop_unresolvable_crs_id", "is_zarr", "is_zarr_store"]

#: Suffixes of Zarr outputs.
ZARR_SUFFIXES = (".zarr",)
#: Name of the heights array in the store.
ARRAY = "height"
#: GDAL creation options of the Zarr driver (format 2: see the module notes).
ZARR_OPTIONS = {"FORMAT": "ZARR_V2", "COMPRESS": "ZLIB", "ZLIB_LEVEL": "6",
                "ARRAY_NAME": ARRAY, "BLOCKSIZE": "512,512"}
# the array metadata ChunkWriter writes chunks for (what GDAL makes of ZARR_OPTIONS)
_ARRAY_META = {"chunks": [512, 512], "compressor": {"id": "zlib", "level": 6},
               "dtype": "<f4", "fill_value": "NaN", "filters": None, "order": "C",
               "zarr_format": 2}
# the identifier GDAL gives an IAU_2015 CRS in a store's `_CRS` (the version dropped)
_IAU_ID = re.compile(r',ID\["IAU",[0-9]+\]\]$')
# what a store craterform writes holds (and all --force may replace)
_ENTRIES = frozenset({".zgroup", ".zattrs", ".zmetadata", "X", "Y", ARRAY})


def is_zarr(path) -> bool:
    """Whether ``path`` names a Zarr output (its suffix)."""
    return Path(path).suffix.lower() in ZARR_SUFFIXES


def is_zarr_store(path) -> bool:
    """Whether ``path`` is a folder holding a Zarr group or array (format 2 or 3)."""
    path = Path(path)
    return path.is_dir() and any((path / name).is_file()
                                 for name in (".zgroup", ".zarray", "zarr.json"))


def check_zarr_output(path, *, force: bool) -> Path:
    """Validate a ``.zarr`` output before any work: its folder exists and is writable; an
    existing one is replaced only with ``force`` and only if it is a Zarr DEM (a
    symbolic link is replaced as a link, its target never touched)."""
    path = Path(path)
    check_parent_folder(path)
    if os.path.lexists(path):
        if not force:
            raise ValueError(f"output {str(path)!r} exists; use --force to overwrite")
        if path.is_dir() and not path.is_symlink():
            foreign = sorted(p.name for p in path.iterdir() if p.name not in _ENTRIES)
            if foreign or not (path / ".zgroup").is_file():
                what = (f"holds {foreign[0]!r}, which a Zarr DEM does not" if foreign
                        else "is a folder without .zgroup, not a Zarr DEM")
                raise ValueError(f"output {str(path)!r} {what}; refusing to replace it")
    sweep_temporaries(path.parent if str(path.parent) else Path("."))
    claim(path, force=force)
    return path


class ZarrStore:
    """A fresh store path (``store``, in a temporary folder beside ``path``) for GDAL to
    create; :meth:`commit` moves it onto ``path``, :meth:`discard` leaves nothing. As a
    context manager: commit on success, discard on any exception."""

    def __init__(self, path):
        self.path = Path(path)
        self._holder = temp_folder(self.path, ".zarr")
        self.store = self._holder / f"store{ZARR_SUFFIXES[0]}"

    def commit(self) -> Path:
        try:  # GDAL made the store with the umask's modes (only the holder is private)
            replace_output(self.store, self.path)
        finally:
            self.discard()
        return self.path

    def discard(self) -> None:
        shutil.rmtree(self._holder, ignore_errors=True)

    def __enter__(self) -> ZarrStore:
        return self

    def __exit__(self, exc_type, *exc) -> None:
        if exc_type is None:
            self.commit()
        else:
            self.discard()


class ChunkWriter:
    """Float32 heights into the chunks of the array ``ARRAY`` of a store GDAL created
    with :data:`ZARR_OPTIONS` (checked), window by window in any order: each chunk a
    window touches is read back (NaN where not yet written), updated, and stored
    zlib-compressed, or removed when it holds no known height."""

    def __init__(self, store):
        self._folder = Path(store) / ARRAY
        meta = json.loads((self._folder / ".zarray").read_text(encoding="utf-8"))
        shape = meta.pop("shape")
        sep = meta.pop("dimension_separator", ".")
        if meta != _ARRAY_META or len(shape) != 2:
            raise RuntimeError(f"GDAL made an unexpected Zarr array: {meta}")
        self.shape = tuple(int(v) for v in shape)
        self._chunk = tuple(_ARRAY_META["chunks"])
        self._sep = sep

    def write(self, z: np.ndarray, row_off: int, col_off: int) -> None:
        """``z`` (float32, inside the array) at pixel (row_off, col_off)."""
        ch, cw = self._chunk
        rows, cols = z.shape
        for i in range(row_off // ch, (row_off + rows - 1) // ch + 1):
            for j in range(col_off // cw, (col_off + cols - 1) // cw + 1):
                r0, r1 = max(row_off, i * ch), min(row_off + rows, (i + 1) * ch)
                c0, c1 = max(col_off, j * cw), min(col_off + cols, (j + 1) * cw)
                path = self._folder / f"{i}{self._sep}{j}"
                if r1 - r0 == ch and c1 - c0 == cw:
                    block = np.empty((ch, cw), dtype="<f4")
                else:
                    block = self._read(path)
                block[r0 - i * ch:r1 - i * ch, c0 - j * cw:c1 - j * cw] = \
                    z[r0 - row_off:r1 - row_off, c0 - col_off:c1 - col_off]
                if np.isnan(block).all():
                    path.unlink(missing_ok=True)
                else:
                    path.write_bytes(zlib.compress(block.tobytes(), 6))

    def _read(self, path: Path) -> np.ndarray:
        try:
            raw = zlib.decompress(path.read_bytes())
        except FileNotFoundError:
            return np.full(self._chunk, np.nan, dtype="<f4")
        return np.frombuffer(raw, dtype="<f4").reshape(self._chunk).copy()


def drop_unresolvable_crs_id(store) -> None:
    """Remove from the store's ``_CRS`` the identifier GDAL writes for an ``IAU_2015`` CRS,
    ``ID["IAU",30100]`` (no version), which no PROJ resolves: GDAL, rasterio and pyproj
    then read a CRS without a code (``to_authority()`` None, the Moon's sphere unnamed)
    where the same CRS in a GeoTIFF is identified as ``IAU_2015:30100``. Without it they
    identify the CRS by its definition, as they do the GeoTIFF's. Other CRSs unchanged."""
    store = Path(store)
    paths = (store / ARRAY / ".zattrs", store / ".zmetadata")
    docs = [json.loads(path.read_text(encoding="utf-8")) for path in paths]
    changed = False
    for attrs in (docs[0], docs[1]["metadata"][f"{ARRAY}/.zattrs"]):
        crs = attrs.get("_CRS")
        if not isinstance(crs, dict) or not _IAU_ID.search(crs.get("wkt", "")):
            continue
        crs["wkt"] = _IAU_ID.sub("]", crs["wkt"])
        ident = crs.get("projjson", {}).get("id", {})
        if ident.get("authority") == "IAU" and "version" not in ident:
            del crs["projjson"]["id"]
        changed = True
    if changed:
        for path, doc in zip(paths, docs, strict=True):
            path.write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
