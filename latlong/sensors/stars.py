"""Stars behind the body: the 5 080 stars of V <= 6.0 of the Yale Bright Star Catalogue
(Hoffleit & Warren 1991; ``data/bright_stars.csv``, provenance in its header) as point
sources where a pixel sees no surface.

A star of magnitude V gives an irradiance 10^(-0.4 (V - V_sun)) of the sun's at the
same distance (V_sun = -26.76, Willmer 2018); spread over a pixel of solid angle
Omega (cos^3 of its angle off the axis over fx fy) it is the I/F
pi 10^(-0.4 (V - V_sun)) / Omega, split bilinearly over the four pixels around its
sub-pixel position (the sum is kept; the sensor's PSF blurs it further). Directions are
J2000 (epoch 2000, no proper motion, no aberration); ``body_to_j2000`` turns them into the
body frame (a SPICE run gives it per frame; without one the body frame is taken as
J2000). So exposed for a sunlit surface (I/F ~ 0.1) a first-magnitude star is ~1e-3 of
full scale, as in real frames; a frame of sky alone is auto-exposed on its stars.
"""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

import numpy as np

from .camera import Camera, Pose
from .sensor import expose, exposure_for

__all__ = ["STAR_FILE", "SUN_V_MAG", "bright_stars", "star_reflectance", "with_stars"]

#: The bundled catalogue (module notes).
STAR_FILE = Path(__file__).parent / "data" / "bright_stars.csv"
#: The sun's apparent V magnitude at 1 au (Willmer 2018, Table 3).
SUN_V_MAG = -26.76


@functools.cache
def bright_stars() -> tuple[np.ndarray, np.ndarray]:
    """(unit J2000 directions (n, 3), V magnitudes (n,)) of the bundled catalogue."""
    data = np.loadtxt(STAR_FILE, delimiter=",", comments="#", skiprows=6)
    ra, dec = np.radians(data[:, 1]), np.radians(data[:, 2])
    dirs = np.column_stack([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)])
    dirs.setflags(write=False)
    vmag = data[:, 3]
    vmag.setflags(write=False)
    return dirs, vmag


def star_reflectance(camera: Camera, pose: Pose, *,
                     body_to_j2000: np.ndarray | None = None) -> np.ndarray:
    """(H, W) I/F of the catalogue's stars seen by ``camera`` at ``pose`` (module notes;
    everywhere, surface or not)."""
    dirs, vmag = bright_stars()
    rot = np.eye(3) if body_to_j2000 is None else np.asarray(body_to_j2000, dtype=float)
    cam = (dirs @ rot) @ pose.rotation  # J2000 -> body (rot^T d) -> camera (R^T d)
    ahead = cam[:, 2] > 1e-6
    cam, vmag = cam[ahead], vmag[ahead]
    xd, yd = camera.distort(cam[:, 0] / cam[:, 2], cam[:, 1] / cam[:, 2])
    u = camera.fx * xd + camera.cx - 0.5  # pixel-centre coordinates: centres at integers
    v = camera.fy * yd + camera.cy - 0.5
    cos_off = cam[:, 2] / np.linalg.norm(cam, axis=1)
    omega = cos_off**3 / (camera.fx * camera.fy)
    value = np.pi * 10.0 ** (-0.4 * (vmag - SUN_V_MAG)) / omega
    out = np.zeros((camera.height, camera.width))
    i0, j0 = np.floor(u).astype(np.int64), np.floor(v).astype(np.int64)
    fu, fv = u - i0, v - j0
    for di, dj, w in ((0, 0, (1 - fu) * (1 - fv)), (1, 0, fu * (1 - fv)),
                      (0, 1, (1 - fu) * fv), (1, 1, fu * fv)):
        i, j = i0 + di, j0 + dj
        inside = (i >= 0) & (i < camera.width) & (j >= 0) & (j < camera.height)
        np.add.at(out, (j[inside], i[inside]), (w * value)[inside])
    return out


def with_stars(frame, sensor, *, body_to_j2000: np.ndarray | None = None, seed: int = 0):
    """``frame`` (a :class:`~latlong.sensors.render.Frame`) with the stars added where it
    sees no surface, exposed again (auto-exposure sees them too)."""
    stars = star_reflectance(frame.camera, frame.pose, body_to_j2000=body_to_j2000)
    if frame.reflectance.ndim == 3:  # a multi-band camera: the stars in every band
        stars = stars[:, :, None]
    sky = frame.face < 0 if frame.reflectance.ndim == 2 else (frame.face < 0)[:, :, None]
    refl = np.where(sky, frame.reflectance + stars, frame.reflectance)
    exposure = exposure_for(refl, sensor)
    image = expose(refl, dataclasses.replace(sensor, exposure_s=exposure), seed=seed)
    return dataclasses.replace(frame, image=image, reflectance=refl, exposure_s=exposure)
