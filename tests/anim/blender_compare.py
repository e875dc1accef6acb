#!/usr/bin/env python3
"""blender_compare.py — silhouettes of animated glTF models against Blender (issue 35).

For each model, Blender (its own glTF importer: animations, skins, morph targets) renders the
silhouette (alpha) at 4 times from a camera it derives from the posed bounds
(tests/anim/blender_silhouettes.py); `sy render MODEL --at T --look-at EYE:TARGET:UP --fov DEG
--background 0,0,0,0` renders the same view with each back-end; the coverage IoU of the two alphas
(a pixel is covered where alpha >= 0.5) is printed as a table, per model, time and back-end.

    tests/anim/blender_compare.py --sy build/apps/sy/sy [--data ../shared/testdata/gltf]
        [--out DIR] [--size 320] [--backends whitted,raster] [--min-iou 0.98] [--check] [--nlerp] [--reuse]
        [MODEL ...]

A measurement tool, not a test of the suite: Blender is not a project dependency (docs/TESTING.md).
Exit status: 0 done (with --check: every IoU >= --min-iou), 1 an IoU below it with --check, or a
render failed, 77 (the suite's skip code) when blender or the models are absent, 2 usage.
Only the Python standard library: the PNGs are decoded here (8/16-bit gray-alpha, RGB, RGBA).
"""
import argparse
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from png_read import read_png  # noqa: E402  (one PNG decoder for the scripts)

MODELS = ["AnimatedCube", "BoxAnimated", "InterpolationTest", "RiggedFigure", "CesiumMan", "Fox", "SimpleMorph",
          "AnimatedMorphCube"]
HERE = os.path.dirname(os.path.abspath(__file__))


def png_alpha(path):
    """(width, height, bytearray of coverage 0/1 per pixel: alpha >= half; 1 everywhere without alpha)."""
    w, h, ch, bps, px = read_png(path)
    if ch not in (2, 4):
        return w, h, bytearray([1]) * (w * h)
    step, off = ch * bps, (ch - 1) * bps  # the alpha sample's first (most significant) byte
    return w, h, bytearray(1 if px[k * step + off] >= 128 else 0 for k in range(w * h))


def iou(a, b):
    inter = sum(1 for x, y in zip(a, b) if x and y)
    union = sum(1 for x, y in zip(a, b) if x or y)
    return 1.0 if union == 0 else inter / union, sum(a), sum(b)


def silhouette_args(ap, data_sub, backends):
    """The options of a silhouette comparison (this one and view3dscene_compare.py): --sy, --data
    (../shared/testdata/DATA_SUB), --out, --backends, --min-iou, --check, --json."""
    ap.add_argument("--sy", default="build/apps/sy/sy")
    ap.add_argument("--data", default=os.path.join(HERE, "..", "..", "..", "shared", "testdata", data_sub))
    ap.add_argument("--out", default=None, help="keep the images here (default: a temporary directory)")
    ap.add_argument("--backends", default=backends)
    ap.add_argument("--min-iou", type=float, default=0.98)
    ap.add_argument("--check", action="store_true", help="exit 1 when an IoU is below --min-iou")
    ap.add_argument("--json", default=None, help="write the results here")


def render_compare(a, cmd, png, ref, name, t, b, ref_name, width):
    """Runs the `sy render` command line cmd (it writes png) and compares its silhouette with ref (a
    png_alpha coverage), printing the line of model or scene name at time t in back-end b (name
    padded to width; ref_name: what made ref); (IoU, pixels covered by sy, by ref), or None when sy
    render failed (printed). Shared with view3dscene_compare.py."""
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if r.returncode != 0:
        print("%s t=%g %s: sy render failed (exit %d): %s\n  %s" % (name, t, b, r.returncode, r.stdout.strip()[-600:],
                                                                    " ".join(cmd)))
        return None
    _, _, ours = png_alpha(png)
    v, n_ours, n_ref = iou(ours, ref)
    print("%-*s t=%-8g %-8s IoU %.4f  (covered: sy %6d, %s %6d)%s" %
          (width, name, t, b, v, n_ours, ref_name, n_ref, "" if v >= a.min_iou else "   < %.2f" % a.min_iou), flush=True)
    return v, n_ours, n_ref


def finish(rows, worst, failed, out, a):
    """The summary line and the exit status of a silhouette comparison (this one and
    view3dscene_compare.py): rows of dicts with "iou"; --json, --min-iou, --check from a."""
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)
    below = [r for r in rows if r["iou"] < a.min_iou]
    print("\n%d comparisons, worst IoU %.4f, %d below %.2f; images in %s" % (len(rows), worst, len(below), a.min_iou,
                                                                             out))
    if failed:
        return 1
    return 1 if a.check and below else 0


def blender_env():
    """The environment without a Python of pyenv's or a virtual environment first on PATH: Blender's
    embedded Python finds its prefix (and the system's numpy, which its glTF importer needs) from the
    python3 on PATH, so a driver run by another Python would break its import."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYENV", "PYTHON", "VIRTUAL_ENV"))}
    env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep)
                                  if ".pyenv" not in p and not (os.environ.get("VIRTUAL_ENV") and
                                                                p.startswith(os.environ["VIRTUAL_ENV"])))
    return env


def model_path(data, name):
    for sub, ext in (("glTF", ".gltf"), ("glTF-Binary", ".glb")):
        p = os.path.join(data, name, sub, name + ext)
        if os.path.exists(p):
            return p
    return None


def gltf_json(path):
    with open(path, "rb") as f:
        d = f.read()
    if d[:4] == b"glTF":
        n = struct.unpack("<I", d[12:16])[0]
        return json.loads(d[20:20 + n])
    return json.loads(d)


def times_of(path):
    """4 times inside the animations' range (every clip together): 10, 35, 60 and 85 % of it."""
    g = gltf_json(path)
    lo, hi = None, None
    for a in g.get("animations", []):
        for s in a.get("samplers", []):
            acc = g["accessors"][s["input"]]
            if "min" in acc and "max" in acc:
                lo = acc["min"][0] if lo is None else min(lo, acc["min"][0])
                hi = acc["max"][0] if hi is None else max(hi, acc["max"][0])
    if lo is None:
        lo, hi = 0.0, 1.0
    return [round(lo + f * (hi - lo), 4) for f in (0.1, 0.35, 0.6, 0.85)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    silhouette_args(ap, "gltf", "whitted,raster")
    ap.add_argument("--size", type=int, default=320)
    ap.add_argument("--fov", type=float, default=40.0)
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--blender-only", action="store_true", help="only Blender's half (the references)")
    ap.add_argument("--nlerp", action="store_true",
                    help="Blender's own quaternion interpolation (per-component lerp) instead of glTF's slerp")
    ap.add_argument("--times", default=None, help="comma-separated times for every model (default: 4 in range)")
    ap.add_argument("--reuse", action="store_true",
                    help="keep Blender's images already in --out for the same times (iterating on ours)")
    ap.add_argument("models", nargs="*")
    a = ap.parse_args()
    if not shutil.which(a.blender):
        print("SKIP: blender is not installed (the reference renderer of this measurement)")
        return 77
    if not os.path.isdir(a.data):
        print("SKIP: %s absent (../shared/testdata)" % a.data)
        return 77
    if not a.blender_only and not os.access(a.sy, os.X_OK):
        print("blender_compare: %s: not an executable sy" % a.sy, file=sys.stderr)
        return 2
    out = a.out or tempfile.mkdtemp(prefix="sy_blender_compare_")
    backends = [b for b in a.backends.split(",") if b]
    rows, worst, failed = [], 1.0, False
    for name in a.models or MODELS:
        path = model_path(a.data, name)
        if not path:
            print("%s: absent, skipped" % name)
            continue
        times = [float(t) for t in a.times.split(",")] if a.times else times_of(path)
        mdir = os.path.join(out, name)
        os.makedirs(mdir, exist_ok=True)
        cmd = [a.blender, "-b", "-noaudio", "--factory-startup", "-P", os.path.join(HERE, "blender_silhouettes.py"),
               "--"] + (["--nlerp"] if a.nlerp else []) + [path, mdir, str(a.size), str(a.size), str(a.fov)] + [repr(t) for t in times]
        cam_json = os.path.join(mdir, "camera.json")
        if a.reuse and os.path.exists(cam_json):
            with open(cam_json) as f:
                c = json.load(f)
                if c.get("times") == times and c.get("size") == a.size and c.get("nlerp", False) == a.nlerp:
                    cmd = None
        bl = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            env=blender_env()) if cmd else None
        if bl and (bl.returncode != 0 or not os.path.exists(cam_json)):
            print("%s: blender failed (exit %d):\n%s" % (name, bl.returncode, bl.stdout[-2000:]))
            failed = True
            continue
        with open(cam_json) as f:
            cam = json.load(f)
        if a.blender_only:
            continue
        look = "%s:%s:%s" % tuple(",".join("%.9g" % v for v in cam[k]) for k in ("eye", "target", "up"))
        for i, t in enumerate(times):
            _, _, ref = png_alpha(os.path.join(mdir, "blender_%d.png" % i))
            for b in backends:
                png = os.path.join(mdir, "sy_%s_%d.png" % (b, i))
                sy = [a.sy, "render", path, "-b", b, "-w", str(a.size), "-h", str(a.size), "--at", repr(t),
                      "--look-at", look, "--fov", "%.9g" % cam["fov"], "--background", "0,0,0,0", "-o", png]
                m = render_compare(a, sy, png, ref, name, t, b, "blender", 18)
                if m is None:
                    failed = True
                    continue
                worst = min(worst, m[0])
                rows.append({"model": name, "time": t, "frame": cam["frames"][i], "backend": b, "iou": m[0],
                             "pixels_sy": m[1], "pixels_blender": m[2], "png": png})
    return finish(rows, worst, failed, out, a)


if __name__ == "__main__":
    sys.exit(main())
