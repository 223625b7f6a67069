"""The photometric models' codes, shared by :mod:`latlong.sensors.photometry` (which
describes a model without loading numba) and its kernels (which dispatch on them)."""

LAMBERT, LOMMEL_SEELIGER, LUNAR_LAMBERT, HAPKE = 0, 1, 2, 3
