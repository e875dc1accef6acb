# cornell_cycles.py — Blender (Cycles) script: an independent reference of a glTF scene made of
# Lambertian and emissive materials (the Cornell box), and per-object region statistics of EXR
# images against it. Run by tests/cycles/cornell_direct.sh; rerun by hand with
#
#   blender -b -noaudio --factory-startup -P tests/cycles/cornell_cycles.py -- \
#       --gltf ../shared/testdata/cornell/cornell_box.gltf --size 256 --spp 1024 --bounces 0 \
#       --out ref.exr [--compare raster.exr whitted.exr ...]
#
# The scene is rebuilt from the glTF JSON, not through Blender's importer (whose materials are not
# an exact match, see ../shared/notes/cycles-references.md): every material is a Diffuse BSDF of its
# baseColorFactor (roughness 0), emission emissiveFactor x KHR_materials_emissive_strength from the
# front face only, the camera is the glTF camera (vertical fit), black world, box filter of one
# pixel, no clamping, no denoising, no adaptive sampling, Standard view transform, 32-bit EXR.
# --bounces 0 is direct light only: the camera ray, its hit, light sampling there.
#
# --compare: for every object with at least 200 interior pixels (pixels whose 3x3 neighbourhood
# hits that object alone, found by casting each pixel centre's camera ray into the rebuilt scene)
# prints the reference's mean RGB and each image's luminance ratio to it.
import base64
import json
import math
import os
import struct
import sys

import bpy
from mathutils import Matrix, Quaternion, Vector


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    a = {"gltf": None, "size": 256, "spp": 1024, "bounces": 0, "out": None, "compare": [], "seed": 0}
    i = 0
    while i < len(argv):
        k = argv[i]
        if k == "--compare":
            a["compare"] = argv[i + 1:]
            break
        if k not in ("--gltf", "--size", "--spp", "--bounces", "--out", "--seed") or i + 1 >= len(argv):
            raise SystemExit("cornell_cycles.py: unknown or incomplete option %r" % k)
        v = argv[i + 1]
        a[k[2:]] = v if k in ("--gltf", "--out") else int(v)
        i += 2
    if not a["gltf"]:
        raise SystemExit("cornell_cycles.py: --gltf FILE is required")
    return a


COMPONENTS = {5120: ("b", 1), 5121: ("B", 1), 5122: ("h", 2), 5123: ("H", 2), 5125: ("I", 4), 5126: ("f", 4)}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}


def load_buffers(doc, base):
    out = []
    for b in doc["buffers"]:
        uri = b["uri"]
        if uri.startswith("data:"):
            out.append(base64.b64decode(uri.split(",", 1)[1]))
        else:
            with open(os.path.join(base, uri), "rb") as f:
                out.append(f.read())
    return out


def accessor(doc, bufs, i):
    acc = doc["accessors"][i]
    bv = doc["bufferViews"][acc["bufferView"]]
    fmt, size = COMPONENTS[acc["componentType"]]
    n = WIDTH[acc["type"]]
    stride = bv.get("byteStride", size * n)
    start = bv.get("byteOffset", 0) + acc.get("byteOffset", 0)
    data = bufs[bv["buffer"]]
    return [struct.unpack_from("<%d%s" % (n, fmt), data, start + k * stride) for k in range(acc["count"])]


def node_matrix(node):
    if "matrix" in node:
        m = node["matrix"]
        return Matrix([[m[c * 4 + r] for c in range(4)] for r in range(4)])
    t = Vector(node.get("translation", [0, 0, 0]))
    q = node.get("rotation", [0, 0, 0, 1])
    s = node.get("scale", [1, 1, 1])
    return Matrix.Translation(t) @ Quaternion((q[3], q[0], q[1], q[2])).to_matrix().to_4x4() @ \
        Matrix.Diagonal((s[0], s[1], s[2], 1.0))


# glTF is Y up, Blender Z up: (x, y, z) -> (x, -z, y)
Y_UP_TO_Z_UP = Matrix(((1, 0, 0, 0), (0, 0, -1, 0), (0, 1, 0, 0), (0, 0, 0, 1)))


def make_material(m):
    mat = bpy.data.materials.new(m.get("name", "material"))
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    base = m.get("pbrMetallicRoughness", {}).get("baseColorFactor", [1, 1, 1, 1])
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (base[0], base[1], base[2], 1.0)
    diffuse.inputs["Roughness"].default_value = 0.0
    e = m.get("emissiveFactor", [0, 0, 0])
    strength = m.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
    if max(e) > 0.0:
        emit = nt.nodes.new("ShaderNodeEmission")
        emit.inputs["Color"].default_value = (e[0] * strength, e[1] * strength, e[2] * strength, 1.0)
        emit.inputs["Strength"].default_value = 1.0
        front = nt.nodes.new("ShaderNodeMixShader")  # emission from the front face only
        geo = nt.nodes.new("ShaderNodeNewGeometry")
        black = nt.nodes.new("ShaderNodeEmission")
        black.inputs["Strength"].default_value = 0.0
        nt.links.new(geo.outputs["Backfacing"], front.inputs["Fac"])
        nt.links.new(emit.outputs["Emission"], front.inputs[1])
        nt.links.new(black.outputs["Emission"], front.inputs[2])
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(diffuse.outputs["BSDF"], add.inputs[0])
        nt.links.new(front.outputs["Shader"], add.inputs[1])
        nt.links.new(add.outputs["Shader"], out.inputs["Surface"])
    else:
        nt.links.new(diffuse.outputs["BSDF"], out.inputs["Surface"])
    return mat


def build_scene(path, size):
    with open(path) as f:
        doc = json.load(f)
    bufs = load_buffers(doc, os.path.dirname(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    mats = [make_material(m) for m in doc.get("materials", [])]
    cam_obj = None
    roots = doc["scenes"][doc.get("scene", 0)]["nodes"]
    stack = [(i, Matrix.Identity(4)) for i in roots]
    while stack:
        i, parent = stack.pop()
        node = doc["nodes"][i]
        world = parent @ node_matrix(node)
        for c in node.get("children", []):
            stack.append((c, world))
        if "mesh" in node:
            for pi, prim in enumerate(doc["meshes"][node["mesh"]]["primitives"]):
                if prim.get("mode", 4) != 4:
                    raise SystemExit("cornell_cycles.py: only triangle primitives are supported")
                pos = accessor(doc, bufs, prim["attributes"]["POSITION"])
                idx = [t[0] for t in accessor(doc, bufs, prim["indices"])] if "indices" in prim else \
                    list(range(len(pos)))
                me = bpy.data.meshes.new("%s.%d" % (node.get("name", "mesh"), pi))
                me.from_pydata([tuple(p) for p in pos], [], [tuple(idx[k:k + 3]) for k in range(0, len(idx), 3)])
                me.update()
                if "material" in prim:
                    me.materials.append(mats[prim["material"]])
                ob = bpy.data.objects.new(node.get("name", "node%d" % i), me)
                ob.matrix_world = Y_UP_TO_Z_UP @ world
                scene.collection.objects.link(ob)
        if "camera" in node and cam_obj is None:
            c = doc["cameras"][node["camera"]]["perspective"]
            cd = bpy.data.cameras.new("camera")
            cd.sensor_fit = "VERTICAL"
            cd.angle_y = c["yfov"]
            cd.clip_start = c.get("znear", 0.01)
            cd.clip_end = c.get("zfar", 1000.0)
            cam_obj = bpy.data.objects.new("camera", cd)
            cam_obj.matrix_world = Y_UP_TO_Z_UP @ world  # both look down local -Z, Y up
            scene.collection.objects.link(cam_obj)
    if cam_obj is None:
        raise SystemExit("cornell_cycles.py: the scene has no camera")
    scene.camera = cam_obj
    r = scene.render
    r.resolution_x = r.resolution_y = size
    r.resolution_percentage = 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world
    return scene


def render(scene, a):
    r = scene.render
    r.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = a["spp"]
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.seed = a["seed"]
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    cy.sample_clamp_direct = cy.sample_clamp_indirect = 0.0
    cy.blur_glossy = 0.0
    cy.caustics_reflective = cy.caustics_refractive = True
    b = a["bounces"]
    cy.max_bounces = cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = b
    cy.transparent_max_bounces = max(b, 8)
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    r.film_transparent = False
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.color_mode = "RGBA"
    r.filepath = os.path.abspath(a["out"])
    bpy.ops.render.render(write_still=True)


def object_map(scene, size):
    """Object name hit by each pixel centre's camera ray, rows top first."""
    cam = scene.camera
    dg = bpy.context.evaluated_depsgraph_get()
    origin = cam.matrix_world.translation
    rot = cam.matrix_world.to_3x3()
    t = math.tan(cam.data.angle_y * 0.5)
    names = []
    for y in range(size):
        row = []
        for x in range(size):
            px = ((x + 0.5) / size * 2.0 - 1.0) * t
            py = (1.0 - (y + 0.5) / size * 2.0) * t
            d = (rot @ Vector((px, py, -1.0))).normalized()
            hit, _, _, _, ob, _ = scene.ray_cast(dg, origin, d)
            row.append(ob.name if hit else None)
        names.append(row)
    return names


def read_exr(path, size):
    img = bpy.data.images.load(os.path.abspath(path), check_existing=False)
    img.colorspace_settings.name = "Non-Color"
    if tuple(img.size) != (size, size):
        raise SystemExit("cornell_cycles.py: %s is %dx%d, expected %dx%d" % (path, img.size[0], img.size[1], size, size))
    px = img.pixels[:]
    bpy.data.images.remove(img)
    # Blender's rows are bottom first
    return lambda x, y: px[4 * ((size - 1 - y) * size + x):4 * ((size - 1 - y) * size + x) + 3]


def compare(scene, a):
    size = a["size"]
    names = object_map(scene, size)
    regions = {}
    for y in range(1, size - 1):
        for x in range(1, size - 1):
            n = names[y][x]
            if n and all(names[y + j][x + i] == n for j in (-1, 0, 1) for i in (-1, 0, 1)):
                regions.setdefault(n, []).append((x, y))
    images = [(os.path.basename(a["out"]), read_exr(a["out"], size))] + \
        [(os.path.basename(p), read_exr(p, size)) for p in a["compare"]]
    lum = lambda c: 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
    print("region statistics (interior pixels of each object; luminance ratio = image / reference):")
    print("%-12s %6s  %-26s  %s" % ("object", "pixels", "reference mean RGB", "  ".join("%18s" % n for n, _ in images[1:])))
    worst = 0.0
    for name in sorted(regions):
        pix = regions[name]
        if len(pix) < 200:
            continue
        means = []
        for _, get in images:
            s = [0.0, 0.0, 0.0]
            for x, y in pix:
                c = get(x, y)
                for k in range(3):
                    s[k] += c[k]
            means.append([v / len(pix) for v in s])
        ref = means[0]
        if not lum(ref) > 0.0:
            continue
        cols = []
        for m in means[1:]:
            r = lum(m) / lum(ref)
            if name != "light" and "block" not in name:
                worst = max(worst, abs(r - 1.0))
            cols.append("%18.3f" % r)
        print("%-12s %6d  %8.4f %8.4f %8.4f  %s" % (name, len(pix), *ref, "  ".join(cols)))
    print("largest luminance deviation on the walls and the floor: %.1f %%" % (100.0 * worst))


def main():
    a = parse_args()
    if not a["out"]:
        raise SystemExit("cornell_cycles.py: --out FILE.exr is required")
    scene = build_scene(a["gltf"], a["size"])
    if not os.path.exists(a["out"]) or not a["compare"]:
        render(scene, a)
    if a["compare"]:
        compare(scene, a)


main()
