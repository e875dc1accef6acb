#!/usr/bin/env python3
"""grid_glb.py - a measuring helper, not a test (issue 39: memory per triangle on the user's path).

Writes the height field of apps/scenes/sy_height_field.c (a (g+1)^2-vertex grid of 2 g^2
triangles, g = ceil(sqrt(TRIS / 2)), 1 x 1 m in XZ, heights from a few sines) as a .glb with
positions and uint32 indices, and with --normals-uvs its normals and one UV set too, with a
camera at (0, 0.9, 0.9) looking 45 degrees down (the grid fills the view), for

    /usr/bin/time -v sy render grid.glb -b raster        (peak RSS / triangles)

    grid_glb.py OUT.glb [--tris N] [--normals-uvs]

Needs NumPy (Debian: python3-numpy; /usr/bin/python3 has it where the suite's Python tests run).
"""
import argparse
import json
import math
import os
import struct

import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--tris", type=int, default=10_000_000)
    ap.add_argument("--normals-uvs", action="store_true")
    a = ap.parse_args()
    g = max(1, math.ceil(math.sqrt(a.tris / 2)))
    if (g + 1) ** 2 * 3 > 2**32 - 1 or g * g * 6 > 2**32 - 1:
        raise SystemExit(f"grid_glb: {a.tris} triangles exceed the uint32 index range")
    t = np.arange(g + 1, dtype=np.float64) / g
    fx, fz = np.meshgrid(t, t)  # row z, column x: vertex z * (g + 1) + x
    amp, kx, kz = 0.04, 23.0, 17.0
    ph = 3.1 * kx * fx + 2.3 * kz * fz
    h = amp * np.sin(kx * fx) * np.cos(kz * fz) + 0.5 * amp * np.sin(ph)
    dx = amp * kx * np.cos(kx * fx) * np.cos(kz * fz) + 0.5 * amp * 3.1 * kx * np.cos(ph)
    dz = -amp * kz * np.sin(kx * fx) * np.sin(kz * fz) + 0.5 * amp * 2.3 * kz * np.cos(ph)
    il = 1.0 / np.sqrt(dx * dx + 1.0 + dz * dz)
    pos = np.stack([fx - 0.5, h, fz - 0.5], -1).reshape(-1, 3).astype(np.float32)
    zz, xx = np.meshgrid(np.arange(g, dtype=np.uint32), np.arange(g, dtype=np.uint32), indexing="ij")
    v0 = zz * (g + 1) + xx
    v1, v2 = v0 + 1, v0 + (g + 1)
    idx = np.stack([v0, v2, v1, v1, v2, v2 + 1], -1).reshape(-1).astype(np.uint32)
    arrays = [pos, idx]
    if a.normals_uvs:
        arrays.append(np.stack([-dx * il, il, -dz * il], -1).reshape(-1, 3).astype(np.float32))
        arrays.append(np.stack([fx, fz], -1).reshape(-1, 2).astype(np.float32))
    blob, views = bytearray(), []
    for arr in arrays:
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": arr.nbytes})
        blob += arr.tobytes()
        blob += b"\0" * (-len(blob) % 4)
    acc = [{"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3",
            "min": pos.min(0).tolist(), "max": pos.max(0).tolist()},
           {"bufferView": 1, "componentType": 5125, "count": len(idx), "type": "SCALAR"}]
    attrs = {"POSITION": 0}
    if a.normals_uvs:
        acc += [{"bufferView": 2, "componentType": 5126, "count": len(pos), "type": "VEC3"},
                {"bufferView": 3, "componentType": 5126, "count": len(pos), "type": "VEC2"}]
        attrs.update({"NORMAL": 2, "TEXCOORD_0": 3})
    doc = {"asset": {"version": "2.0", "generator": "switchyard tests/raster/grid_glb.py"}, "scene": 0,
           "scenes": [{"nodes": [0, 1]}],
           "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0.9, 0.9],
                                    "rotation": [-0.3826834, 0, 0, 0.9238795]}],
           "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01, "zfar": 10}}],
           "meshes": [{"primitives": [{"attributes": attrs, "indices": 1}]}],
           "accessors": acc, "bufferViews": views, "buffers": [{"byteLength": len(blob)}]}
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    tmp = a.out + ".tmp"
    with open(tmp, "wb") as f:  # a temporary name, renamed: no half file on failure
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(js) + 8 + len(blob)))
        f.write(struct.pack("<II", len(js), 0x4E4F534A) + js)
        f.write(struct.pack("<II", len(blob), 0x004E4942) + bytes(blob))
    os.replace(tmp, a.out)
    print(f"{a.out}: {len(idx) // 3} triangles, {len(pos)} vertices")


if __name__ == "__main__":
    main()
