# materials_cycles.py — Blender (Cycles) script: an independent render of a glTF model through
# Blender's own glTF importer and its materials, seen exactly as `sy render` saw it. Run by
# tests/cycles/materials.sh; rerun by hand with
#
#   blender -b -noaudio --factory-startup -P tests/cycles/materials_cycles.py -- \
#       --gltf MODEL.gltf --like SY_RENDER.exr --spp 1024 --bounces 8 --env 1,1,1 --out ref.exr
#
# --lighting is the importer's conversion of punctual lights (SPEC, Blender's default: candela /
# 683 x 4 pi as watts; COMPAT: candela x 4 pi as watts; RAW: candela as watts). COMPAT matches
# sy's lights: 12 point lights over a grey floor (`sy bench lights DIR --nodes 1 --tris 12`) came out
# with sy's mean 0.90 of Cycles' with COMPAT, 11.3 with RAW (the rest: the importer's materials).
# LightsPunctualLamp cannot tell: its lights sit in glass, which sy's shadow rays to punctual lights
# pass and Cycles' do not.
# Punctual lights get no size and single-sided materials emit from their front only, as in glTF.
#
# --like names an image `sy render` wrote: its header gives the size (sy:size), the camera-to-world
# matrix (sy:camera_to_world, column-major, glTF's Y-up world) and the projection (sy:projection:
# "perspective yfov RADIANS" or "orthographic ymag HALF_HEIGHT"); the script reads them with
# `sy info` (--sy names the executable). The world is a uniform environment of --env radiance that
# the camera does not see (transparent film: alpha 0 where nothing is hit, as sy's
# `--background 0,0,0,0`); everything else follows ../shared/notes/cycles-references.md: box filter
# of one pixel, no clamping, no denoising, no adaptive sampling, no glossy blur, caustics on, one
# bounce limit for every kind, Standard view transform, 32-bit EXR (scene-linear RGB).
#
# Prints "importer-extensions: NAME ..." (what this Blender's importer maps) and
# "ignored-extensions: NAME ..." (what the file uses that it does not), then Blender's own lines.
import json
import math
import subprocess
import sys

import bpy
from mathutils import Matrix


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    a = {"gltf": None, "like": None, "spp": 1024, "bounces": 8, "env": "1,1,1", "out": None, "sy": "sy", "seed": 0,
         "lighting": "SPEC"}
    i = 0
    while i < len(argv):
        k = argv[i]
        if k[2:] not in a or i + 1 >= len(argv):
            raise SystemExit("materials_cycles.py: unknown or incomplete option %r" % k)
        a[k[2:]] = int(argv[i + 1]) if k in ("--spp", "--bounces", "--seed") else argv[i + 1]
        i += 2
    for k in ("gltf", "like", "out"):
        if not a[k]:
            raise SystemExit("materials_cycles.py: --%s is required" % k)
    return a


def sy_view(sy, image):
    """(width, height, camera-to-world Matrix in glTF's world, projection kind, value) of an sy image."""
    info = json.loads(subprocess.run([sy, "info", image], check=True, capture_output=True, text=True).stdout)
    at = info["attributes"]
    w, h = (int(v) for v in at["sy:size"].split()[0].split("x"))
    m = [float(v) for v in at["sy:camera_to_world"].split()]
    if len(m) != 16:
        raise SystemExit("materials_cycles.py: %s: sy:camera_to_world has %d numbers" % (image, len(m)))
    cam = Matrix([[m[c * 4 + r] for c in range(4)] for r in range(4)])  # column-major -> rows
    kind, _, value = at["sy:projection"].split()
    return w, h, cam, kind, float(value)


def punctual_and_one_sided():
    """What the importer leaves to Blender's defaults, made glTF's (and sy's): punctual lights have
    no size (a new Blender light is a sphere of radius 0.25), and a single-sided material emits
    from its front only (Cycles' emission shaders emit from both sides): the emission strength
    times 1 - Backfacing."""
    for light in bpy.data.lights:
        light.shadow_soft_size = 0.0
    for mat in bpy.data.materials:
        if not mat.use_nodes or not mat.use_backface_culling:
            continue
        nt = mat.node_tree
        for node in list(nt.nodes):
            sock = node.inputs.get("Emission Strength") if node.type == "BSDF_PRINCIPLED" else (
                node.inputs.get("Strength") if node.type == "EMISSION" else None)
            if sock is None or sock.is_linked or sock.default_value == 0.0:
                continue
            geo = nt.nodes.new("ShaderNodeNewGeometry")
            front = nt.nodes.new("ShaderNodeMath")
            front.operation = "SUBTRACT"
            front.inputs[0].default_value = 1.0
            nt.links.new(geo.outputs["Backfacing"], front.inputs[1])
            scaled = nt.nodes.new("ShaderNodeMath")
            scaled.operation = "MULTIPLY"
            scaled.inputs[0].default_value = sock.default_value
            nt.links.new(front.outputs[0], scaled.inputs[1])
            nt.links.new(scaled.outputs[0], sock)


def main():
    a = parse_args()
    import numpy  # the 3.4 importer still says numpy.bool (cycles-references.md)
    if not hasattr(numpy, "bool"):
        numpy.bool = bool
    from io_scene_gltf2.io.imp.gltf2_io_gltf import glTFImporter
    w, h, cam_gltf, kind, value = sy_view(a["sy"], a["like"])

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=a["gltf"], convert_lighting_mode=a["lighting"].upper())
    punctual_and_one_sided()
    with open(a["gltf"], "rb") as f:
        head = f.read(4)
    used = []
    if head != b"glTF":
        with open(a["gltf"]) as f:
            used = json.load(f).get("extensionsUsed", [])
    managed = glTFImporter(a["gltf"], {"import_user_extensions": []}).extensions_managed
    print("importer-extensions:", " ".join(managed))
    print("ignored-extensions:", " ".join(e for e in used if e not in managed) or "-")

    scene = bpy.context.scene
    # glTF's Y-up world to Blender's Z-up one: (x, y, z) -> (x, -z, y); a camera looks along its
    # local -Z with +Y up in both, so only the world turns
    to_blender = Matrix(((1, 0, 0, 0), (0, 0, -1, 0), (0, 1, 0, 0), (0, 0, 0, 1)))
    cam_data = bpy.data.cameras.new("sy view")
    cam_data.sensor_fit = "VERTICAL"
    if kind == "perspective":
        cam_data.type = "PERSP"
        cam_data.angle_y = value
    else:
        cam_data.type = "ORTHO"
        cam_data.ortho_scale = 2.0 * value * max(1.0, w / h)
    cam_data.clip_start = 1e-4
    cam_data.clip_end = 1e6
    cam = bpy.data.objects.new("sy view", cam_data)
    scene.collection.objects.link(cam)
    cam.matrix_world = to_blender @ cam_gltf
    scene.camera = cam

    world = bpy.data.worlds.new("sy environment")
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = tuple(float(v) for v in a["env"].split(",")) + (1.0,)
    bg.inputs["Strength"].default_value = 1.0
    scene.world = world

    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = w, h, 100
    r.film_transparent = True
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.color_mode = "RGBA"
    r.filepath = a["out"]
    c = scene.cycles
    c.device = "CPU"
    c.samples = a["spp"]
    c.seed = a["seed"]
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    b = a["bounces"]
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = b
    c.transparent_max_bounces = b
    c.volume_bounces = 0
    scene.view_settings.view_transform = "Standard"
    bpy.ops.render.render(write_still=True)


main()
