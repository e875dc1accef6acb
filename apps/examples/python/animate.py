"""animate.py [SCENE] [FRAMES]: moves one object of a scene (default: the built-in demo) over a
number of frames in a window that keeps its back-end between renders, and prints what each frame
cost. The first render translates the whole scene into the back-end (a snapshot); every later one
applies only the change list of the node that moved, so a moving frame costs the render, not the
scene's translation again."""
import math
import sys
import time

import switchyard

path = sys.argv[1] if len(sys.argv) > 1 else "demo"
frames = int(sys.argv[2]) if len(sys.argv) > 2 else 24
backend = "raster" if "raster" in [b.name for b in switchyard.backends()] else None

with switchyard.load(path) as scene:
    mover = next(n for n in scene.nodes if n.mesh is not None)  # the first node that draws a mesh
    x0, y0, z0 = mover.translation
    with switchyard.Window(scene, 320, 240) as win:
        win.add_viewport(backend)
        t = time.perf_counter()
        win.render()
        first = time.perf_counter() - t
        print("first frame (the whole scene translated): %.1f ms" % (first * 1e3))
        costs = []
        for f in range(frames):
            a = 2.0 * math.pi * f / frames
            mover.translation = (x0 + 0.3 * math.cos(a), y0, z0 + 0.3 * math.sin(a))  # one node changes
            t = time.perf_counter()
            win.render()  # commits: the change list holds that node alone
            costs.append(time.perf_counter() - t)
        costs.sort()
        print("moving frames: median %.1f ms over %d (%.2f of the first)"
              % (costs[len(costs) // 2] * 1e3, frames, costs[len(costs) // 2] / first))
