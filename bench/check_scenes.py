#!/usr/bin/env python3
"""Re-checks the camera poses of bench/scenes.json on the real scans: converts each scan with
`endocast convert` (to NIfTI, into a temporary folder), then samples it trilinearly in OUR world
frame (LPS mm, world = origin + direction·(spacing∘index), from `endocast info --json`) and prints,
per scene, the value at the eye, how far the lumen (by the scene's iso threshold) extends from the
eye along the view direction, the smallest distance from the eye to the threshold over 200
directions, and |up·view|. Needs numpy and nibabel (e.g. /opt/peers-venv from
../shared/peers/install_vtk.sh).  Usage, from the repository root:
    /opt/peers-venv/bin/python bench/check_scenes.py [ENDOCAST]  (default: bench/cargo_bin.py's)
"""
import json
import os
import subprocess
import sys
import tempfile

import cargo_bin
import nibabel as nib
import numpy as np


class Scan:
    """A converted scan with our geometry: trilinear samples at world (LPS mm) points."""

    def __init__(self, exe, scene, tmp):
        args = [f"--{k}={v}" for k, v in scene.get("open_options", {}).items()]
        out = os.path.join(tmp, scene["name"] + ".nii.gz")
        subprocess.run([exe, "convert", scene["volume"], *args, "-o", out], check=True, capture_output=True)
        info = json.loads(subprocess.run([exe, "info", "--json", scene["volume"], *args], check=True,
                                         capture_output=True, text=True).stdout)
        self.a = np.asarray(nib.load(out).dataobj).astype(np.float32)
        self.origin = np.array(info["origin_mm"])
        # direction_columns lists the index axes' unit world vectors: transpose to columns.
        self.m = np.array(info["direction_columns"]).T * np.array(info["spacing_mm"])
        self.m_inv = np.linalg.inv(self.m)

    def index(self, w):
        return self.m_inv @ (np.asarray(w, float) - self.origin)

    def sample(self, w):
        p = self.index(w)
        i0 = np.floor(p).astype(int)
        f = p - i0
        if np.any(i0 < 0) or np.any(i0 + 1 >= self.a.shape):
            return float("nan")
        c = self.a[i0[0]:i0[0] + 2, i0[1]:i0[1] + 2, i0[2]:i0[2] + 2]
        c = c[0] * (1 - f[0]) + c[1] * f[0]
        c = c[0] * (1 - f[1]) + c[1] * f[1]
        return float(c[0] * (1 - f[2]) + c[1] * f[2])

    def run(self, eye, d, inside, limit=200.0, step=0.25):
        """Distance (mm) from eye along unit d to the first sample outside the lumen."""
        for t in np.arange(0.0, limit, step):
            x = self.sample(eye + t * d)
            if not (x == x and inside(x)):
                return float(t)
        return limit


def main():
    exe = sys.argv[1] if len(sys.argv) > 1 else cargo_bin.endocast()
    doc = json.load(open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenes.json")))
    golden = np.pi * (3 - np.sqrt(5))
    sphere = [np.array([np.sqrt(1 - z * z) * np.cos(golden * i), np.sqrt(1 - z * z) * np.sin(golden * i), z])
              for i, z in enumerate(1 - 2 * (np.arange(200) + 0.5) / 200)]
    with tempfile.TemporaryDirectory() as tmp:
        for s in doc["scenes"]:
            scan = Scan(exe, s, tmp)
            iso = s["iso"]
            inside = (lambda x: x < iso) if s["lumen"] == "darker" else (lambda x: x > iso)
            eye, look, up = (np.array(s[k], float) for k in ("eye", "look_at", "up"))
            view = (look - eye) / np.linalg.norm(look - eye)
            clearance = min(scan.run(eye, d, inside, limit=60.0) for d in sphere)
            print(f"{s['name']}: value at eye {scan.sample(eye):.1f}, lumen ahead {scan.run(eye, view, inside):.1f} mm, "
                  f"clearance {clearance:.2f} mm, |up·view| {abs(up @ view) / np.linalg.norm(up):.3f} "
                  f"(stored: {s['check']})")


if __name__ == "__main__":
    main()
