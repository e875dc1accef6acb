#!/usr/bin/env python3
"""Silhouettes of animated X3D scenes against view3dscene (Castle Game Engine), an independent X3D browser.

For each scene, view3dscene (Debian `view3dscene`, under `xvfb-run`) takes screenshots with a
transparent background at several times of the scene's clock (`--screenshot TIME FILE`, from the
file's own first Viewpoint); `sy render SCENE --at TIME --background 0,0,0,0` renders the same
times with each back-end, and the coverage (alpha) IoU of each pair is printed. This measures the
X3D event model of issue 35 (TimeSensor, the interpolators, ROUTEs, DEF/USE) against a browser
that plays it, as tests/anim/blender_compare.py does for glTF animation with Blender.

A measurement, not a ctest: run it by hand (docs/TESTING.md, "Measurements"):
    tests/anim/view3dscene_compare.py --sy build/apps/sy/sy [--out DIR] [--check]
Exit 77 when view3dscene, xvfb-run or the test data is absent; 1 with --check when an IoU is below
--min-iou.
"""
import argparse
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from blender_compare import finish, png_alpha, render_compare, silhouette_args  # noqa: E402  (one PNG reader, IoU and summary for both)

# (scene under ../shared/testdata/x3d, times in seconds of its clock): the IndexedFaceSet example's
# piston and rocker arms run on one looping 5500 s TimeSensor through Position- and
# OrientationInterpolators (keys at fractions 0.3, 0.32, 0.5 and 0.75: times on and between keys)
SCENES = [
    ("web3d/X3dForWebAuthors/Chapter06GeometryPointsLinesPolygons/IndexedFaceSetExample.x3d",
     [1.0, 700.0, 1650.0, 1705.0, 2200.0, 3300.0, 4125.0, 5000.0, 6200.0]),
]
# Not compared: time 0 exactly (view3dscene shows the file's static pose until its clock first
# ticks, we the interpolators at fraction 0: IndexedFaceSetExample's piston, IoU 0.909 there);
# HelloX3dTrademark.x3d (its globe's texture is absent from the test data: view3dscene then draws
# no globe, we a grey one; its spinning labels agree by eye at every time).


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    silhouette_args(ap, "x3d", "raster,whitted")
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=240)
    a = ap.parse_args()
    for tool in ("view3dscene", "xvfb-run"):
        if not shutil.which(tool):
            print("SKIP: %s is not installed (the reference X3D browser runs under it)" % tool)
            return 77
    if not os.path.isdir(a.data):
        print("SKIP: %s absent (../shared/testdata)" % a.data)
        return 77
    if not os.access(a.sy, os.X_OK):
        print("view3dscene_compare: %s: not an executable sy" % a.sy, file=sys.stderr)
        return 2
    out = a.out or tempfile.mkdtemp(prefix="sy_view3dscene_compare_")
    backends = [b for b in a.backends.split(",") if b]
    rows, worst, failed = [], 1.0, False
    for rel, times in SCENES:
        path = os.path.join(a.data, rel)
        if not os.path.exists(path):
            print("%s: absent, skipped" % rel)
            continue
        name = os.path.splitext(os.path.basename(rel))[0]
        sdir = os.path.join(out, name)
        os.makedirs(sdir, exist_ok=True)
        for i, t in enumerate(times):
            # one view3dscene run per time: several --screenshot options in one run do not all show
            # the clock at their time (IndexedFaceSetExample's 1650 s shot showed the pose of 2200 s)
            ref_png = os.path.join(sdir, "view3dscene_%d.png" % i)
            cmd = ["xvfb-run", "-a", "-s", "-screen 0 1024x768x24", "view3dscene", path, "--screenshot-transparent",
                   "--geometry", "%dx%d" % (a.width, a.height), "--screenshot", repr(t), ref_png]
            v3 = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=300)
            if v3.returncode != 0 or not os.path.exists(ref_png):
                print("%s t=%g: view3dscene failed (exit %d):\n%s" % (name, t, v3.returncode, v3.stdout[-2000:]))
                failed = True
                continue
            rw, rh, ref = png_alpha(ref_png)
            for b in backends:
                png = os.path.join(sdir, "sy_%s_%d.png" % (b, i))
                sy = [a.sy, "render", path, "-b", b, "-w", str(rw), "-h", str(rh), "--at", repr(t),
                      "--background", "0,0,0,0", "-o", png]
                m = render_compare(a, sy, png, ref, name, t, b, "view3dscene", 24)
                if m is None:
                    failed = True
                    continue
                worst = min(worst, m[0])
                rows.append({"scene": rel, "time": t, "backend": b, "iou": m[0], "pixels_sy": m[1],
                             "pixels_view3dscene": m[2], "png": png})
    return finish(rows, worst, failed, out, a)


if __name__ == "__main__":
    sys.exit(main())
