"""from_arrays.py OUT.exr: a scene built from NumPy arrays (a height field of 64 x 64 vertices),
a material, a sun and a camera, rendered by every picture back-end of the registry side by side."""
import sys

import numpy

import switchyard

n = 64
x, z = numpy.meshgrid(numpy.linspace(-1, 1, n), numpy.linspace(-1, 1, n))
y = 0.2 * numpy.sin(4 * x) * numpy.cos(3 * z)
positions = numpy.ascontiguousarray(numpy.stack([x, y, z], axis=-1).reshape(-1, 3), dtype=numpy.float32)
quad = numpy.arange(n * n, dtype=numpy.uint32).reshape(n, n)[:-1, :-1].ravel()
indices = numpy.stack([quad, quad + n, quad + 1, quad + 1, quad + n, quad + n + 1], axis=1).reshape(-1, 3)

scene = switchyard.Scene()
scene.add_mesh(positions, indices, material=scene.add_material(base_color=(0.8, 0.5, 0.2, 1), roughness=0.4))
sun = scene.add_node("sun", rotation=(-0.38, 0.0, 0.0, 0.92))  # tilted down (x, y, z, w)
scene.add_light(switchyard.Light.DIRECTIONAL, node=sun, intensity=8.0)
view = scene.add_camera("view", yfov=0.8, znear=0.05)  # the node carrying the camera
view.translation, view.rotation = (0.0, 1.2, 2.6), (-0.2, 0.0, 0.0, 0.98)
scene.camera = view

names = [b.name for b in switchyard.backends() if b.name in ("whitted", "pathtracer", "raster")]
images = [scene.render(backend=b, width=256, height=192, spp=16 if b == "pathtracer" else 0) for b in names]
switchyard.write_exr(sys.argv[1] if len(sys.argv) > 1 else "from_arrays.exr", numpy.concatenate(images, axis=1))
print("back-ends side by side:", ", ".join(names))
