"""render_file.py SCENE OUT.exr [BACKEND]: the three-line path of docs/PYTHON.md as a program: load a
scene file, render it with one back-end (default: whitted), write an OpenEXR image."""
import sys

import switchyard

if len(sys.argv) < 3:
    sys.exit("usage: render_file.py SCENE OUT.exr [BACKEND]")
img = switchyard.render(sys.argv[1], backend=sys.argv[3] if len(sys.argv) > 3 else "whitted", width=640, height=480)
switchyard.write_exr(sys.argv[2], img)
print("%s: %dx%d, mean alpha %.3f" % (sys.argv[2], img.shape[1], img.shape[0], img[..., 3].mean()))
