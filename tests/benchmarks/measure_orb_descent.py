"""Measure: ORB feature matching + the essential matrix on a 10-frame descent over the
README's ``fbm-cratered`` asteroid with the camera's default (auto) exposure (issue 32's
acceptance: rotation within 0.2 deg and translation direction within 2 deg of the
manifest's relative poses on every pair).

The body and frames come from the README's commands (magnitude 400, seed 1; the camera
example's approach with 10 frames at 768 x 768, lunar-lambert), run as a user would. Per
consecutive pair: ORB (4000 features) on the 8-bit image (the linear 16-bit frame's top
byte, and the sRGB display PNG), brute-force Hamming matching with cross-check,
findEssentialMat (RANSAC, 0.999, 1 px) with OpenCV's camera matrix (cx - 0.5, cy - 0.5)
and recoverPose, against R_rel = R_b^T R_a and t_rel ~ R_b^T (p_a - p_b).

Usage: ``python tests/benchmarks/measure_orb_descent.py [WORK_FOLDER]``.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np


def run(*args: str, cwd: Path) -> None:
    subprocess.run(list(args), cwd=cwd, check=True)


def pair_errors(img_a, img_b, k, rel_r, rel_t) -> tuple[float, float, int]:
    import cv2

    orb = cv2.ORB_create(4000)
    ka, da = orb.detectAndCompute(img_a, None)
    kb, db = orb.detectAndCompute(img_b, None)
    if da is None or db is None:
        return math.nan, math.nan, 0
    matches = cv2.BFMatcher(cv2.NORM_HAMMING, crossCheck=True).match(da, db)
    pa = np.float64([ka[m.queryIdx].pt for m in matches])
    pb = np.float64([kb[m.trainIdx].pt for m in matches])
    if len(pa) < 8:
        return math.nan, math.nan, len(pa)
    e, inl = cv2.findEssentialMat(pa, pb, k, method=cv2.RANSAC, prob=0.999, threshold=1.0)
    if e is None:
        return math.nan, math.nan, len(pa)
    _, r, t, _ = cv2.recoverPose(e[:3], pa, pb, k, mask=inl)
    rot = math.degrees(math.acos(np.clip((np.trace(r.T @ rel_r) - 1) / 2, -1, 1)))
    tt = t.ravel() / np.linalg.norm(t)
    tr = math.degrees(math.acos(np.clip(tt @ rel_t, -1, 1)))
    return rot, tr, int(inl.sum())


def main() -> int:
    import cv2
    from PIL import Image

    from latlong.sensors import quaternion_to_matrix

    work = Path(sys.argv[1] if len(sys.argv) > 1 else "orb_descent_run").resolve()
    (work / "out").mkdir(parents=True, exist_ok=True)
    if not (work / "out/a.npz").exists():
        run("latlong", "build", "--preset", "fbm-cratered", "--magnitude", "400", "--seed", "1",
            "-o", "out/a.npz", "-q", cwd=work)
    if not (work / "out/orb/frames.json").exists():
        run("latlong", "camera", "out/a.npz", "-o", "out/orb", "--target-lat-lon", "10,30",
            "--range-m", "150,25", "--frames", "10", "--path-angle-deg", "30", "--fov-deg",
            "40", "--size", "768x768", "--sun-direction=-0.26,0.96,0.05", "--reflectance",
            "lunar-lambert", "-q", cwd=work)
    doc = json.loads((work / "out/orb/frames.json").read_text())
    i = doc["intrinsics"]
    k = np.array([[i["fx"], 0, i["cx"] - 0.5], [0, i["fy"], i["cy"] - 0.5], [0, 0, 1.0]])
    frames = doc["frames"]
    for label, key in (("linear 16-bit >> 8", "image"), ("sRGB display", "display")):
        worst_r = worst_t = 0.0
        ok = 0
        for a, b in zip(frames[:-1], frames[1:], strict=True):
            imgs = []
            for f in (a, b):
                arr = np.asarray(Image.open(work / "out/orb" / f["files"][key]))
                imgs.append((arr >> 8).astype(np.uint8) if arr.dtype == np.uint16 else arr)
            ra, rb = (quaternion_to_matrix(f["quaternion_wxyz"]) for f in (a, b))
            pa, pb = (np.asarray(f["position_m"]) for f in (a, b))
            rel_t = rb.T @ (pa - pb)
            rot, tr, n = pair_errors(*imgs, k, rb.T @ ra, rel_t / np.linalg.norm(rel_t))
            worst_r, worst_t = max(worst_r, rot), max(worst_t, tr)
            ok += int(rot <= 0.2 and tr <= 2.0)
            print(f"  {label}: rotation {rot:.3f} deg, translation direction {tr:.2f} deg, "
                  f"{n} inliers")
        print(f"{label}: {ok} of {len(frames) - 1} pairs within 0.2 deg / 2 deg; worst "
              f"rotation {worst_r:.3f} deg, worst translation direction {worst_t:.2f} deg "
              f"(exposures {[round(f['exposure_s'], 4) for f in frames]})")
    cv2.setNumThreads(0)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
