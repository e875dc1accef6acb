#!/usr/bin/env python3
"""texanim_render_test.py — an X3D TextureTransform animated by a PositionInterpolator2D, rendered
(issue 35): a quad with a 4 x 4 checker texture whose translation goes from (0, 0) to (0.5, 0) over
2 s (loop false). Predicted from the texture alone: at 1 s the checker has moved by a quarter of
the texture, one square, so every square shows the other colour (the picture inverts on the quad);
at 2 s it has moved two squares and looks as at 0 s; at 0.5 s half a square, half the quad's
pixels flipped. For each back-end given (the path tracer at 16 spp), `sy render --at T`:
  - MAD(0 s, 1 s) is large (the squares swapped) and at least 8x MAD(0 s, 2 s) (the same look);
  - the quad's pixels that flip between 0 s and 1 s are at least 80% of the quad's; between 0 s and
    0.5 s between 30% and 70%;
and with Whitted, the image at 1 s through one loopback `sy serve` (sort-first, and frames mode) is
pixel for pixel the local one (the targets and weights travel in the change list).

    texanim_render_test.py SY WORKDIR BACKEND...

Only the Python standard library (PNGs written and read by tests/support/png_write.py and png_read.py)."""
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from png_read import read_png as png_read  # noqa: E402  (one PNG decoder for the scripts)
from png_write import write_png  # noqa: E402  (and one encoder)


def read_png(path):
    """(w, h, channels, bytearray of 8-bit samples)"""
    w, h, ch, bps, px = png_read(path)
    assert bps == 1, path
    return w, h, ch, px


def gray(img):
    w, h, ch, px = img
    return [sum(px[k * ch:k * ch + 3]) / 3.0 if ch >= 3 else px[k] for k in range(w * h)]


X3D = """<X3D><Scene>
<NavigationInfo headlight='true'/>
<Viewpoint position='0 0 2.6' fieldOfView='0.9'/>
<Shape><Appearance><Material diffuseColor='1 1 1'/><ImageTexture url='"checker.png"'/><TextureTransform DEF='TT'/></Appearance>
<IndexedFaceSet solid='false' coordIndex='0 1 2 3 -1' texCoordIndex='0 1 2 3 -1'>
<Coordinate point='-1 -1 0 1 -1 0 1 1 0 -1 1 0'/><TextureCoordinate point='0 0 1 0 1 1 0 1'/></IndexedFaceSet></Shape>
<TimeSensor DEF='Clock' cycleInterval='2' loop='false'/>
<PositionInterpolator2D DEF='Slide' key='0 1' keyValue='0 0 0.5 0'/>
<ROUTE fromNode='Clock' fromField='fraction_changed' toNode='Slide' toField='set_fraction'/>
<ROUTE fromNode='Slide' fromField='value_changed' toNode='TT' toField='set_translation'/>
</Scene></X3D>
"""


def main():
    sy, work, backends = sys.argv[1], sys.argv[2], sys.argv[3:]
    os.makedirs(work, exist_ok=True)
    n, sq = 64, 16  # 4 x 4 squares of 16 texels
    rgb = bytearray()
    for y in range(n):
        for x in range(n):
            v = 230 if ((x // sq) + (y // sq)) % 2 == 0 else 20
            rgb += bytes((v, v, v))
    write_png(os.path.join(work, "checker.png"), n, n, rgb)
    scene = os.path.join(work, "slide.x3d")
    open(scene, "w").write(X3D)
    fails = []
    for b in backends:
        imgs = {}
        for t in ("0", "0.5", "1", "2"):
            out = os.path.join(work, "%s_%s.png" % (b, t))
            cmd = [sy, "render", scene, "-b", b, "-w", "96", "-h", "96", "--at", t, "-o", out]
            if b == "pathtracer":
                cmd += ["--spp", "16"]  # noisy, but a square's two colours stay far apart
            p = subprocess.run(cmd, capture_output=True, text=True)
            if p.returncode != 0:
                fails.append("%s --at %s: %s" % (b, t, p.stderr.strip()[-300:]))
                break
            imgs[t] = gray(read_png(out))
        if len(imgs) < 4:
            continue
        a = imgs["0"]
        mad = {t: sum(abs(x - y) for x, y in zip(a, imgs[t])) / len(a) for t in ("0.5", "1", "2")}
        # the quad's pixels: those a light square covers at 0 s or at 1 s (the background is black
        # at both); a pixel flips when it moved from one side of the middle grey to the other
        lo, hi = min(a), max(a)
        mid = (lo + hi) / 2
        quad = [k for k in range(len(a)) if max(a[k], imgs["1"][k]) > mid]
        flipped = {t: sum(1 for k in quad if (a[k] > mid) != (imgs[t][k] > mid)) / max(1, len(quad)) for t in ("0.5", "1", "2")}
        print("%s: mean abs diff to 0 s: 0.5 s %.1f, 1 s %.1f, 2 s %.1f; quad pixels flipped: 0.5 s %.0f%%, 1 s %.0f%%, "
              "2 s %.0f%% (%d quad pixels)" % (b, mad["0.5"], mad["1"], mad["2"], 100 * flipped["0.5"], 100 * flipped["1"],
                                               100 * flipped["2"], len(quad)))
        if not (mad["1"] > 20 and mad["1"] >= 8 * mad["2"]):
            fails.append("%s: 1 s does not differ from 0 s as a swapped checker does (mean abs diff %.1f, 2 s %.1f)" %
                         (b, mad["1"], mad["2"]))
        if not (len(quad) > 1000 and flipped["1"] >= 0.8 and flipped["2"] <= 0.1):
            fails.append("%s: %.0f%% of the quad flipped at 1 s, %.0f%% at 2 s (want >= 80%%, <= 10%%)" %
                         (b, 100 * flipped["1"], 100 * flipped["2"]))
        if not (0.3 <= flipped["0.5"] <= 0.7):
            fails.append("%s: %.0f%% of the quad flipped at 0.5 s (want 30-70%%: half a square)" % (b, 100 * flipped["0.5"]))
    # a cluster replica shows the same coordinates (the targets and weights travel in the change
    # list, the server's mirror morphs them): Whitted at 1 s through one loopback `sy serve`, sort-first
    # and frames mode, pixel for pixel the local image
    if "whitted" in backends and not fails:
        port_file = os.path.join(work, "serve.port")
        if os.path.exists(port_file):
            os.remove(port_file)
        srv = subprocess.Popen([sy, "serve", "--listen", "tcp://127.0.0.1:0", "--port-file", port_file, "--max-lifetime",
                                "600"], stderr=subprocess.DEVNULL)
        try:
            for _ in range(600):  # a hang guard: the port file appears once the server listens
                if os.path.exists(port_file) and os.path.getsize(port_file) > 0 or srv.poll() is not None:
                    break
                time.sleep(0.05)
            url = "tcp://127.0.0.1:" + open(port_file).read().strip()
            local = read_png(os.path.join(work, "whitted_1.png"))[3]
            runs = {"sort-first": ["--at", "1", "-o", os.path.join(work, "cluster_1.png")],
                    "frames": ["--frames", "1:1", "--fps", "1", "--cluster-mode", "frames", "-o", os.path.join(work, "cframe_#.png")]}
            for mode, extra in runs.items():
                p = subprocess.run([sy, "render", scene, "-b", "whitted", "-w", "96", "-h", "96", "--cluster", url] + extra,
                                   capture_output=True, text=True)
                out = extra[-1].replace("#", "1")
                if p.returncode != 0:
                    fails.append("cluster %s: %s" % (mode, p.stderr.strip()[-300:]))
                elif read_png(out)[3] != local:
                    fails.append("cluster %s: the image at 1 s differs from the local one" % mode)
                else:
                    print("cluster %s: the image at 1 s equals the local one" % mode)
        except OSError as e:
            fails.append("cluster: %s" % e)
        finally:
            srv.kill()
            srv.wait()
    for f in fails:
        print("FAIL: " + f)
    if not fails:
        print("texanim_render_test: all checks passed")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
