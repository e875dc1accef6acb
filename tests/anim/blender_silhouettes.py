# blender_silhouettes.py — the reference half of tests/anim/blender_compare.py (issue 35): Blender's
# own glTF importer (io_scene_gltf2, which plays animations, skins and morph targets) poses a glTF
# file at given times and renders its silhouette (alpha) from one camera, which it also writes out
# so that `sy render --look-at EYE:TARGET:UP --fov DEG` can use exactly the same view.
#
#   blender -b -noaudio --factory-startup -P tests/anim/blender_silhouettes.py -- \
#       MODEL.gltf OUT_DIR WIDTH HEIGHT FOV_DEG T1 [T2 ...]
#
# Writes OUT_DIR/blender_<i>.png (RGBA, alpha = coverage, no anti-aliasing) for each time Ti and
# OUT_DIR/camera.json: {"eye": [x,y,z], "target": [...], "up": [...], "fov": deg, "times": [...],
# "fps": f, "frames": [...]} in glTF coordinates (+Y up; Blender's importer maps glTF (x, y, z) to
# Blender (x, -z, y), and this script maps back).
#
# Which animation plays: Blender's importer makes every glTF animation an NLA track and makes only
# animations[0] active. Switchyard's `sy render --at T` without --clip plays every clip when no two
# drive the same object, else only the first (sy_cli_default_clip); so here, when some object has
# tracks of two animations, every object takes animations[0]'s action (none: it stays as loaded),
# and otherwise each object takes the action of its one track, the same rule.
#
# Time: the importer keys glTF time t at frame t * fps (scene fps, 24 by default; no offset), so
# time t is frame t * fps, set with frame_set(whole, subframe=fraction).
#
# The camera: the union of the evaluated (posed) world bounds of every mesh over all the times,
# looked at from the direction (0.5, 0.4, 1) (glTF coordinates) at the distance where those
# bounds' corners fill 90 % of the view. --nlerp (before MODEL): see slerp_keys. Not a project dependency: a measurement tool (TESTING.md).
import bpy
import json
import math
import os
import sys
from mathutils import Quaternion, Vector

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
nlerp = "--nlerp" in argv  # keep Blender's own quaternion interpolation (see slerp_keys below)
argv = [a for a in argv if a != "--nlerp"]
if len(argv) < 6:
    print("usage: blender -b -P blender_silhouettes.py -- MODEL OUT_DIR W H FOV_DEG T1 [T2 ...]", file=sys.stderr)
    sys.exit(2)
model, out_dir, width, height, fov = argv[0], argv[1], int(argv[2]), int(argv[3]), float(argv[4])
times = [float(t) for t in argv[5:]]
os.makedirs(out_dir, exist_ok=True)

# Debian's Blender 3.4 runs on a NumPy (>= 1.24) that dropped the np.bool alias its glTF importer
# still uses (AttributeError: module 'numpy' has no attribute 'bool'): put the alias back.
import numpy
for _alias, _type in (("bool", bool), ("int", int), ("float", float), ("object", object)):
    if _alias not in numpy.__dict__:
        setattr(numpy, _alias, _type)

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
bpy.ops.import_scene.gltf(filepath=model)

# Every object: the action of the last animation (file order) with a track on it.
with open(model, "rb") as f:
    data = f.read()
if data[:4] == b"glTF":
    jlen = int.from_bytes(data[12:16], "little")
    gltf_json = json.loads(data[20:20 + jlen])
else:
    gltf_json = json.loads(data)
anim_names = []
for i, a in enumerate(gltf_json.get("animations", [])):
    anim_names.append(a.get("name") or "Anim_%d" % i)


def tracks_of(idblock):
    ad = getattr(idblock, "animation_data", None)
    return ad.nla_tracks if ad else []


def track_action(t, name):
    """The track's action when it is the animation named (the importer may suffix duplicate names)."""
    return t.strips[0].action if t.strips and (t.name == name or t.name.startswith(name + ".")) else None


animated = [o for o in list(bpy.data.objects) + [k for k in bpy.data.shape_keys] if list(tracks_of(o))]
alternatives = any(len(list(tracks_of(o))) > 1 for o in animated)
for obj in animated:
    tracks = list(tracks_of(obj))
    chosen = None
    if alternatives:  # only animations[0] plays
        for t in tracks:
            chosen = chosen or (track_action(t, anim_names[0]) if anim_names else None)
    else:
        chosen = tracks[0].strips[0].action if tracks[0].strips else None
    obj.animation_data.action = chosen

# glTF's LINEAR rotation is a spherical linear interpolation (slerp) between keys; the importer
# writes the four quaternion components as LINEAR F-curves, which Blender interpolates one by one
# (then normalises): a normalised lerp, whose angle runs ahead of slerp's in the first half of a key
# interval and behind in the second (28 degrees against 36 a fifth of the way through a 180-degree
# step). Unless --nlerp, every LINEAR rotation interval gets SLERP_STEPS - 1 keys of its own slerp
# between its ends, so Blender's per-component lerp between them follows slerp to well under a degree.
# STEP (CONSTANT) and CUBICSPLINE (Bezier: glTF's spline is per component, then normalised) are left.
SLERP_STEPS = 16


def slerp_keys(action):
    groups = {}
    for fc in action.fcurves:
        if fc.data_path.endswith("rotation_quaternion"):
            groups.setdefault(fc.data_path, {})[fc.array_index] = fc
    for fcs in groups.values():
        if len(fcs) != 4:
            continue
        pts = [list(fcs[i].keyframe_points) for i in range(4)]
        if len({len(p) for p in pts}) != 1:
            continue
        keys = [(pts[0][j].co[0], Quaternion([pts[i][j].co[1] for i in range(4)]), pts[0][j].interpolation)
                for j in range(len(pts[0]))]
        extra = []
        for (f0, q0, how), (f1, q1, _) in zip(keys, keys[1:]):
            if how != "LINEAR":
                continue
            if q0.dot(q1) < 0:  # the importer already flips antipodes; glTF's shorter arc either way
                q1 = -q1
            for k in range(1, SLERP_STEPS):
                u = k / SLERP_STEPS
                extra.append((f0 + (f1 - f0) * u, q0.slerp(q1, u)))
        for f, q in extra:
            for i in range(4):
                kp = fcs[i].keyframe_points.insert(f, q[i], options={"FAST"})
                kp.interpolation = "LINEAR"
        for i in range(4):
            fcs[i].update()


if not nlerp:
    for act in bpy.data.actions:
        slerp_keys(act)


# CUBICSPLINE: Blender 3.4's importer keeps the key values and drops glTF's tangents ("TODO manage
# tangent?" in gltf2_blender_animation_node.py), giving the keys AUTO Bezier handles: a different
# curve between keys. Unless --nlerp, the channels of plain object nodes (not joints) get FREE
# handles a third of each key interval away, displaced by the glTF tangent times a third of the
# interval: exactly glTF's cubic Hermite spline (the Bezier's time is then linear in its parameter),
# in Blender's axes (the importer's Y-up to Z-up maps, linear for tangents).
def gltf_binary(path, doc):
    import base64
    with open(path, "rb") as f:
        raw = f.read()
    bufs = []
    for i, b in enumerate(doc.get("buffers", [])):
        uri = b.get("uri")
        if uri is None:  # the GLB's BIN chunk
            jlen = int.from_bytes(raw[12:16], "little")
            off = 20 + jlen
            blen = int.from_bytes(raw[off:off + 4], "little")
            bufs.append(raw[off + 8:off + 8 + blen])
        elif uri.startswith("data:"):
            bufs.append(base64.b64decode(uri.split(",", 1)[1]))
        else:
            from urllib.parse import unquote
            with open(os.path.join(os.path.dirname(path), unquote(uri)), "rb") as f:
                bufs.append(f.read())
    return bufs


def accessor_floats(doc, bufs, index):
    import struct
    acc = doc["accessors"][index]
    if acc.get("componentType") != 5126 or "bufferView" not in acc or "sparse" in acc:
        return None
    n = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}.get(acc["type"])
    if n is None:
        return None
    bv = doc["bufferViews"][acc["bufferView"]]
    stride = bv.get("byteStride") or 4 * n
    base = bv.get("byteOffset", 0) + acc.get("byteOffset", 0)
    data = bufs[bv["buffer"]]
    return [struct.unpack_from("<%df" % n, data, base + stride * k) for k in range(acc["count"])]


GLTF_TO_BLENDER = {  # component i of the Blender F-curve = sign * glTF component j
    "rotation": ("rotation_quaternion", [(3, 1), (0, 1), (2, -1), (1, 1)]),  # glTF xyzw -> Blender wxyz (x, -z, y)
    "translation": ("location", [(0, 1), (2, -1), (1, 1)]),
    "scale": ("scale", [(0, 1), (2, 1), (1, 1)]),
}


def cubic_tangents(doc, bufs):
    joints = {j for sk in doc.get("skins", []) for j in sk.get("joints", [])}
    fixed = 0
    for ai, anim in enumerate(doc.get("animations", [])):
        for ch in anim.get("channels", []):
            smp = anim["samplers"][ch["sampler"]]
            node, path = ch["target"].get("node"), ch["target"].get("path")
            if smp.get("interpolation") != "CUBICSPLINE" or node is None or node in joints or path not in GLTF_TO_BLENDER:
                continue
            times = [t[0] for t in accessor_floats(doc, bufs, smp["input"]) or []]
            vals = accessor_floats(doc, bufs, smp["output"])
            obj = bpy.data.objects.get(doc["nodes"][node].get("name", ""))
            if not times or not vals or len(vals) != 3 * len(times) or obj is None or obj.type == "ARMATURE":
                continue
            action = None
            for t in tracks_of(obj):
                if t.strips and (t.name == anim_names[ai] or t.name.startswith(anim_names[ai] + ".")):
                    action = t.strips[0].action
            if action is None:
                continue
            data_path, comps = GLTF_TO_BLENDER[path]
            for bi, (gj, sign) in enumerate(comps):
                fc = action.fcurves.find(data_path, index=bi)
                if fc is None or len(fc.keyframe_points) != len(times):
                    continue
                for k, kp in enumerate(fc.keyframe_points):
                    a_in, b_out = sign * vals[3 * k][gj], sign * vals[3 * k + 2][gj]
                    kp.handle_left_type = kp.handle_right_type = "FREE"
                    if k > 0:
                        dt = times[k] - times[k - 1]
                        kp.handle_left = (kp.co[0] - dt * fps / 3, kp.co[1] - a_in * dt / 3)
                    if k + 1 < len(times):
                        dt = times[k + 1] - times[k]
                        kp.handle_right = (kp.co[0] + dt * fps / 3, kp.co[1] + b_out * dt / 3)
                fc.update()
                fixed += 1
    return fixed

fps = scene.render.fps / scene.render.fps_base
frames = [t * fps for t in times]
if not nlerp:
    n_fixed = cubic_tangents(gltf_json, gltf_binary(model, gltf_json))
    if n_fixed:
        print("blender_silhouettes: %d CUBICSPLINE F-curves given glTF's tangents" % n_fixed)


def set_time(frame):
    whole = math.floor(frame)
    scene.frame_set(int(whole), subframe=frame - whole)


def world_points():
    dg = bpy.context.evaluated_depsgraph_get()
    pts = []
    for obj in scene.objects:
        if obj.type != "MESH":
            continue
        ev = obj.evaluated_get(dg)
        me = ev.to_mesh()
        mw = ev.matrix_world
        pts.extend(mw @ v.co for v in me.vertices)
        ev.to_mesh_clear()
    return pts


lo = Vector((math.inf,) * 3)
hi = Vector((-math.inf,) * 3)
for fr in frames:
    set_time(fr)
    for p in world_points():
        lo = Vector(map(min, lo, p))
        hi = Vector(map(max, hi, p))
if not math.isfinite(lo.x):
    print("blender_silhouettes: %s: no mesh vertices" % model, file=sys.stderr)
    sys.exit(1)


def to_gltf(v):  # Blender (x, y, z) -> glTF (x, z, -y)
    return [v.x, v.z, -v.y]


def from_gltf(v):  # glTF (x, y, z) -> Blender (x, -z, y)
    return Vector((v[0], -v[2], v[1]))


center_b = (lo + hi) / 2
radius = (hi - lo).length / 2
d = Vector((0.5, 0.4, 1.0)).normalized()  # from the target towards the eye, glTF coordinates
half = math.radians(fov) / 2
# the distance at which the 8 corners of the posed bounds fill 90 % of the (square) view
fwd = -d
right = fwd.cross(Vector((0.0, 1.0, 0.0))).normalized()
up = right.cross(fwd)
center_g = to_gltf(center_b)
dist = 0.0
for cx in (lo.x, hi.x):
    for cy in (lo.y, hi.y):
        for cz in (lo.z, hi.z):
            p = Vector(to_gltf(Vector((cx, cy, cz)))) - Vector(center_g)
            reach = max(abs(p.dot(right)), abs(p.dot(up))) / (math.tan(half) * 0.9)
            dist = max(dist, p.dot(d) + reach)
eye_g = [center_g[i] + d[i] * dist for i in range(3)]

cam_data = bpy.data.cameras.new("silhouette_camera")
cam_data.sensor_fit = "VERTICAL"
cam_data.angle_y = math.radians(fov)
cam_data.clip_start = max(dist - radius * 1.5, dist * 1e-3)
cam_data.clip_end = dist + radius * 2
cam = bpy.data.objects.new("silhouette_camera", cam_data)
scene.collection.objects.link(cam)
eye_b = from_gltf(eye_g)
cam.location = eye_b
cam.rotation_euler = (center_b - eye_b).to_track_quat("-Z", "Y").to_euler()
scene.camera = cam

scene.render.engine = "BLENDER_WORKBENCH"
scene.display.render_aa = "OFF"
scene.render.film_transparent = True
scene.render.resolution_x, scene.render.resolution_y = width, height
scene.render.resolution_percentage = 100
scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1
scene.render.image_settings.file_format = "PNG"
scene.render.image_settings.color_mode = "RGBA"
scene.render.image_settings.color_depth = "8"

for i, fr in enumerate(frames):
    set_time(fr)
    scene.render.filepath = os.path.join(out_dir, "blender_%d.png" % i)
    bpy.ops.render.render(write_still=True)

with open(os.path.join(out_dir, "camera.json"), "w") as f:
    json.dump({"eye": eye_g, "target": center_g, "up": [0, 1, 0], "fov": fov, "times": times, "fps": fps,
               "frames": frames, "radius": radius, "bounds_blender": [list(lo), list(hi)],
               "animations": anim_names, "size": width, "nlerp": nlerp}, f, indent=1)
print("blender_silhouettes: %s: %d frames written to %s" % (model, len(frames), out_dir))
