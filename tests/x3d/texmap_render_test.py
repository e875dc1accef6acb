#!/usr/bin/env python3
"""texmap_render_test.py — where an ImageTexture lands on X3D geometry, rendered (issue 35): the
texture transform (TextureTransform's center, scale, rotation and translation, the spec's
Tc' = -C x S x R x C x T x Tc) and the texture coordinates of the primitives Box, Sphere, Cylinder
and Cone (X3D 4.0, 13.3: each Box face upright seen from outside, +Y up, the top with -Z up and the
bottom with +Z up; Sphere, Cylinder and Cone sides wrapping counter-clockwise seen from above from
a seam at the back (-Z); the caps as circles cut from the texture, upright with the top tilted
towards +Z, the bottoms with the top tilted towards -Z).

The texture has four quadrants of four colours (top-left red, top-right green, bottom-left blue,
bottom-right white). Every scene is predicted here from the spec alone: a ray per pixel from the
Viewpoint hits the analytic shape; its texture coordinates (and the transform) give the quadrant.
`sy render` (each back-end given) renders it; pixels whose prediction is the same quadrant at the
pixel's centre and its four half-pixel neighbours (no edge, no seam, no silhouette) are compared
by hue with the prediction. A scene passes when at least 97 % of them agree. The transform
scenes: a quarter turn about the centre (the texture's appearance turns clockwise: red from the
top left to the top right), and 30 degrees with a non-uniform scale, a centre and a translation
(the order of the composition); and routed, a ScalarInterpolator turning the rotation from 0 to pi
over 2 s, rendered with --at at 0.5, 1 and 1.6 s (a quarter, a half and 0.8 of the turn), on the
quad, a Box and a Sphere.

With --reference view3dscene (by hand; needs view3dscene and xvfb-run) the same comparison is
made of view3dscene's screenshots against the predictions: the independent X3D browser's reading
of the spec.

    texmap_render_test.py SY WORKDIR BACKEND... [--reference view3dscene] [--only NAME_PART]

Only the Python standard library."""
import math
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from png_read import read_png  # noqa: E402  (one PNG decoder for the scripts)
from png_write import write_png  # noqa: E402  (and one encoder)

COLOURS = {"red": (230, 20, 20), "green": (20, 230, 20), "blue": (20, 20, 230), "white": (230, 230, 230)}
SIZE = 128
DIST = 2.6
FOV = 0.9


def quadrant(s, t):
    """The texture's colour at (s, t) (t up, repeating), or None within 0.02 of a quadrant's edge."""
    s, t = s - math.floor(s), t - math.floor(t)
    for v in (s, t):
        if min(abs(v - 0.5), v, 1 - v) < 0.02:
            return None
    top, left = t >= 0.5, s < 0.5
    return ("red" if left else "green") if top else ("blue" if left else "white")


def texture_transform(center=(0, 0), scale=(1, 1), rotation=0.0, translation=(0, 0)):
    """X3D: Tc' = -C x S x R x C x T x Tc (applied right to left)."""
    c, sn = math.cos(rotation), math.sin(rotation)

    def f(s, t):
        s, t = s + translation[0] + center[0], t + translation[1] + center[1]
        s, t = c * s - sn * t, sn * s + c * t
        return s * scale[0] - center[0], t * scale[1] - center[1]
    return f


# ---- the shapes: a ray (origin o, direction d) -> (distance, (s, t)) or None ----
def hit_quad(o, d):  # the IndexedFaceSet square -1..1 in z = 0, TextureCoordinate 0..1
    if abs(d[2]) < 1e-9:
        return None
    k = -o[2] / d[2]
    x, y = o[0] + k * d[0], o[1] + k * d[1]
    return (k, ((x + 1) / 2, (y + 1) / 2)) if k > 0 and abs(x) <= 1 and abs(y) <= 1 else None


def hit_box(o, d):  # size 2 2 2
    best = None
    for axis in range(3):
        for sign in (1, -1):
            if abs(d[axis]) < 1e-9:
                continue
            k = (sign - o[axis]) / d[axis]
            p = [o[i] + k * d[i] for i in range(3)]
            if k <= 0 or any(abs(p[i]) > 1 for i in range(3) if i != axis):
                continue
            x, y, z = p
            st = {(2, 1): ((x + 1) / 2, (y + 1) / 2), (2, -1): ((1 - x) / 2, (y + 1) / 2),
                  (0, 1): ((1 - z) / 2, (y + 1) / 2), (0, -1): ((z + 1) / 2, (y + 1) / 2),
                  (1, 1): ((x + 1) / 2, (1 - z) / 2), (1, -1): ((x + 1) / 2, (z + 1) / 2)}[(axis, sign)]
            if best is None or k < best[0]:
                best = (k, st)
    return best


def around(x, z):
    """s of a side: 0 at the back (-Z), counter-clockwise seen from +Y (-X at 0.25, +Z at 0.5)."""
    return (math.atan2(-x, -z) / (2 * math.pi)) % 1.0


def hit_sphere(o, d):  # radius 1; t linear in latitude
    b = sum(o[i] * d[i] for i in range(3))
    c = sum(v * v for v in o) - 1
    dd = sum(v * v for v in d)
    disc = b * b - dd * c
    if disc < 0:
        return None
    k = (-b - math.sqrt(disc)) / dd
    if k <= 0:
        return None
    x, y, z = (o[i] + k * d[i] for i in range(3))
    return (k, (around(x, z), 1 - math.acos(max(-1, min(1, y))) / math.pi))


def hit_round(o, d, cone):  # Cylinder radius 1 height 2, or Cone bottomRadius 1 height 2: side and caps
    cands = []
    # side: cylinder x^2 + z^2 = 1; cone x^2 + z^2 = ((1 - y) / 2)^2, -1 <= y <= 1
    if cone:
        # (ox + k dx)^2 + (oz + k dz)^2 = ((1 - oy - k dy) / 2)^2
        a = d[0] ** 2 + d[2] ** 2 - d[1] ** 2 / 4
        b = 2 * (o[0] * d[0] + o[2] * d[2]) + (1 - o[1]) * d[1] / 2
        c = o[0] ** 2 + o[2] ** 2 - (1 - o[1]) ** 2 / 4
    else:
        a = d[0] ** 2 + d[2] ** 2
        b = 2 * (o[0] * d[0] + o[2] * d[2])
        c = o[0] ** 2 + o[2] ** 2 - 1
    if abs(a) > 1e-12:
        disc = b * b - 4 * a * c
        if disc >= 0:
            for k in ((-b - math.sqrt(disc)) / (2 * a), (-b + math.sqrt(disc)) / (2 * a)):
                y = o[1] + k * d[1]
                if k > 0 and -1 <= y <= 1:
                    x, z = o[0] + k * d[0], o[2] + k * d[2]
                    cands.append((k, (around(x, z), (y + 1) / 2)))
    for y0 in ((-1,) if cone else (1, -1)):
        if abs(d[1]) < 1e-9:
            continue
        k = (y0 - o[1]) / d[1]
        x, z = o[0] + k * d[0], o[2] + k * d[2]
        if k > 0 and x * x + z * z <= 1:
            cands.append((k, ((x + 1) / 2, (1 - z) / 2) if y0 > 0 else ((x + 1) / 2, (z + 1) / 2)))
    return min(cands) if cands else None


# ---- viewpoints: (position, orientation axis-angle, camera right, camera up, camera forward) ----
def view(name):
    """A Viewpoint DIST + 1 from the origin on an axis, looking at the origin, with the up the spec
    names for what it sees there (the faces' and caps' upright directions)."""
    r = DIST + 1
    table = {  # position, orientation, right, up, forward
        "front": ((0, 0, r), (0, 1, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, -1)),
        "back": ((0, 0, -r), (0, 1, 0, math.pi), (-1, 0, 0), (0, 1, 0), (0, 0, 1)),
        "right": ((r, 0, 0), (0, 1, 0, math.pi / 2), (0, 0, -1), (0, 1, 0), (-1, 0, 0)),
        "left": ((-r, 0, 0), (0, 1, 0, -math.pi / 2), (0, 0, 1), (0, 1, 0), (1, 0, 0)),
        "top": ((0, r, 0), (1, 0, 0, -math.pi / 2), (1, 0, 0), (0, 0, -1), (0, -1, 0)),
        "bottom": ((0, -r, 0), (1, 0, 0, math.pi / 2), (1, 0, 0), (0, 0, 1), (0, 1, 0)),
    }
    return table[name]


def predict(hit, vname, tt):
    pos, _, right, up, fwd = view(vname)
    h = math.tan(FOV / 2)
    out = []
    for py in range(SIZE):
        for px in range(SIZE):
            classes = set()
            for ox, oy in ((0, 0), (-0.5, 0), (0.5, 0), (0, -0.5), (0, 0.5)):
                nx = ((px + 0.5 + ox) / SIZE) * 2 - 1
                ny = 1 - ((py + 0.5 + oy) / SIZE) * 2
                d = [fwd[i] + nx * h * right[i] + ny * h * up[i] for i in range(3)]
                r = hit(pos, d)
                classes.add(quadrant(*tt(*r[1])) if r else "none")
            out.append(classes.pop() if len(classes) == 1 else None)
    return out


def classify(rgb):
    m = max(rgb)
    if m < 25:
        return "dark"
    if min(rgb) / m > 0.6:
        return "white"
    return ("red", "green", "blue")[rgb.index(m)]


def compare(png, pred):
    w, h, ch, bps, px = read_png(png)
    if (w, h) != (SIZE, SIZE) or bps != 1:
        return 0.0, 0, "%s: %dx%d (want %dx%d, 8 bit)" % (png, w, h, SIZE, SIZE)
    n = agree = dark = 0
    for k, p in enumerate(pred):
        if p is None:
            continue
        got = classify(tuple(px[k * ch:k * ch + 3]))
        if p == "none":
            continue  # the background: what covers it is the silhouette's business (view3dscene_compare)
        n += 1
        dark += got == "dark"
        agree += got == p
    return agree / max(1, n), n, "%d of %d pixels agree, %d too dark to tell" % (agree, n, dark)


SHAPES = {"quad": hit_quad, "box": hit_box, "sphere": hit_sphere,
          "cylinder": lambda o, d: hit_round(o, d, False), "cone": lambda o, d: hit_round(o, d, True)}
GEOMETRY = {"quad": ("<IndexedFaceSet solid='false' coordIndex='0 1 2 3 -1' texCoordIndex='0 1 2 3 -1'>"
                     "<Coordinate point='-1 -1 0 1 -1 0 1 1 0 -1 1 0'/><TextureCoordinate point='0 0 1 0 1 1 0 1'/>"
                     "</IndexedFaceSet>"),
            "box": "<Box size='2 2 2'/>", "sphere": "<Sphere radius='1'/>", "cylinder": "<Cylinder radius='1' height='2'/>",
            "cone": "<Cone bottomRadius='1' height='2'/>"}
# (name, shape, viewpoint, TextureTransform attributes, the transform)
CASES = [("quad", "quad", "front", "", {})]
CASES += [("quad_rot90", "quad", "front", "rotation='1.5707963' center='0.5 0.5'",
           dict(rotation=math.pi / 2, center=(0.5, 0.5))),
          ("quad_rot30_scaled", "quad", "front", "rotation='0.5235988' center='0.3 0.6' scale='2 1' translation='0.1 0.2'",
           dict(rotation=math.pi / 6, center=(0.3, 0.6), scale=(2, 1), translation=(0.1, 0.2)))]
CASES += [("box_" + v, "box", v, "", {}) for v in ("front", "back", "right", "left", "top", "bottom")]
CASES += [("sphere_" + v, "sphere", v, "", {}) for v in ("front", "right", "left", "top")]
CASES += [("cylinder_" + v, "cylinder", v, "", {}) for v in ("front", "right", "top", "bottom")]
CASES += [("cone_" + v, "cone", v, "", {}) for v in ("front", "left", "bottom")]
CASES += [("box_rot90_top", "box", "top", "rotation='1.5707963' center='0.5 0.5'", dict(rotation=math.pi / 2, center=(0.5, 0.5)))]
# routed: a ScalarInterpolator turns the rotation from 0 to pi over a 2 s TimeSensor (sy render --at)
SPIN = ("<TimeSensor DEF='Clock' cycleInterval='2' loop='false'/>"
        "<ScalarInterpolator DEF='Spin' key='0 1' keyValue='0 3.1415927'/>"
        "<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Spin' toField='set_fraction'/>"
        "<ROUTE fromNode='Spin' fromField='value_changed' toNode='TT' toField='set_rotation'/>")
CASES += [("quad_spin_%s" % at, "quad", "front", "DEF='TT' center='0.5 0.5'", dict(rotation=math.pi * float(at) / 2,
                                                                                 center=(0.5, 0.5)), at)
          for at in ("0.5", "1", "1.6")]
CASES += [("box_spin_1", "box", "front", "DEF='TT' center='0.5 0.5'", dict(rotation=math.pi / 2, center=(0.5, 0.5)), "1"),
          ("sphere_spin_0.5", "sphere", "front", "DEF='TT' center='0.5 0.5'", dict(rotation=math.pi / 4, center=(0.5, 0.5)), "0.5")]


def scene_text(shape, vname, tt_attrs, routed):
    pos, ori = view(vname)[:2]
    return ("<X3D><Scene><NavigationInfo headlight='true'/>"
            "<Viewpoint position='%g %g %g' orientation='%g %g %g %.9g' fieldOfView='%g'/>"
            "<Shape><Appearance><Material diffuseColor='1 1 1'/><ImageTexture url='\"quadrants.png\"'/>%s</Appearance>%s</Shape>"
            "%s</Scene></X3D>\n" % (pos + ori + (FOV, "<TextureTransform %s/>" % tt_attrs if tt_attrs else "",
                                                 GEOMETRY[shape], SPIN if routed else "")))


def main():
    args = sys.argv[1:]
    reference, only = None, ""
    for opt in ("--reference", "--only"):
        if opt in args:
            i = args.index(opt)
            if opt == "--reference":
                reference = args[i + 1]
            else:
                only = args[i + 1]
            del args[i:i + 2]
    sy, work, backends = args[0], args[1], args[2:]
    os.makedirs(work, exist_ok=True)
    n = 64
    rgb = bytearray()
    for y in range(n):
        for x in range(n):
            rgb += bytes(COLOURS[quadrant((x + 0.5) / n, 1 - (y + 0.5) / n) or "red"])
    write_png(os.path.join(work, "quadrants.png"), n, n, rgb)
    renderers = list(backends)
    if reference == "view3dscene":
        for tool in ("view3dscene", "xvfb-run"):
            if not shutil.which(tool):
                print("SKIP: %s is not installed" % tool)
                return 77
        renderers.append("view3dscene")
    fails, worst = [], 1.0
    for case in CASES:
        name, shape, vname, tt_attrs, tt = case[:5]
        at = case[5] if len(case) > 5 else None
        if only not in name:
            continue
        scene = os.path.join(work, name + ".x3d")
        with open(scene, "w") as f:
            f.write(scene_text(shape, vname, tt_attrs, at is not None))
        pred = predict(SHAPES[shape], vname, texture_transform(**tt))
        for b in renderers:
            out = os.path.join(work, "%s_%s.png" % (name, b))
            if b == "view3dscene":
                cmd = ["xvfb-run", "-a", "-s", "-screen 0 1024x768x24", "view3dscene", scene, "--geometry",
                       "%dx%d" % (SIZE, SIZE), "--screenshot", at or "0", out]
            else:
                cmd = [sy, "render", scene, "-b", b, "-w", str(SIZE), "-h", str(SIZE), "-o", out] + (["--at", at] if at else [])
            p = subprocess.run(cmd, capture_output=True, text=True)
            if p.returncode != 0 or not os.path.exists(out):
                fails.append("%s %s: failed (exit %d): %s" % (name, b, p.returncode, (p.stderr or p.stdout).strip()[-300:]))
                continue
            frac, count, what = compare(out, pred)
            worst = min(worst, frac)
            print("%-22s %-11s %5.1f%%  (%s)" % (name, b, 100 * frac, what), flush=True)
            if count < 300 or frac < 0.97:
                fails.append("%s %s: %.1f%% of the texture agrees with the spec's mapping (want >= 97%% of >= 300 pixels; %s)"
                             % (name, b, 100 * frac, what))
    print("worst agreement: %.1f%%" % (100 * worst))
    for f in fails:
        print("FAIL: " + f)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
