"""tests/python: the Python package switchyard (apps/python, docs/PYTHON.md), run by ctest as
python_package with PYTHONPATH=BUILD/python, SY_BIN (the sy program) and SY_TESTDATA_DIR."""
import gc
import os
import subprocess
import threading

import numpy
import pytest

import switchyard

TESTDATA = os.environ.get("SY_TESTDATA_DIR", os.path.join(os.path.dirname(__file__), "../../../shared/testdata"))
BOX = os.path.join(TESTDATA, "gltf/Box/glTF/Box.gltf")
CORNELL = os.path.join(TESTDATA, "cornell/cornell_box.gltf")
SY = os.environ.get("SY_BIN")
NAMES = [b.name for b in switchyard.backends()]
needs_whitted = pytest.mark.skipif("whitted" not in NAMES, reason="built without the Embree back-ends (no whitted)")
needs_pt = pytest.mark.skipif("pathtracer" not in NAMES, reason="built without the Embree back-ends (no pathtracer)")


def need(path):
    if not os.path.exists(path):
        pytest.skip("test data absent: %s (../shared/testdata)" % path)


def sy_render(scene, out, *args):
    if not SY or not os.path.exists(SY):
        pytest.skip("the sy program is not given (SY_BIN)")
    subprocess.run([SY, "render", scene, "-o", out, *args], check=True, capture_output=True)
    return switchyard.read_exr(out)


def assert_same_pixels(img, ref):
    """img (H x W x 4) equals the EXR channels ref (read_exr) bit for bit."""
    for i, c in enumerate("RGBA"):
        assert numpy.array_equal(img[..., i], ref[c]), "channel %s differs from sy render" % c


def triangle_scene():
    """A triangle over the lower-left half of an orthographic camera's square view."""
    s = switchyard.Scene()
    pos = numpy.array([[-1, -1, 0], [1, -1, 0], [-1, 1, 0]], dtype=numpy.float32)
    s.add_mesh(pos, numpy.array([0, 1, 2], dtype=numpy.uint32))
    s.camera = s.add_camera("ortho", projection=switchyard.Camera.ORTHOGRAPHIC, xmag=1.0, ymag=1.0, znear=0.1,
                            zfar=10.0)
    s.camera.translation = (0.0, 0.0, 2.0)
    return s


def test_backends_from_the_registry():
    bs = switchyard.backends()
    assert bs, "no back-end registered"
    assert sum(b.default for b in bs) <= 1
    assert all(isinstance(b.name, str) and b.name for b in bs)
    if "pathtracer" in NAMES:
        assert next(b for b in bs if b.name == "pathtracer").progressive


@needs_whitted
def test_three_line_render_equals_sy_render(tmp_path):
    """The three-line path gives the pixels `sy render` writes (float EXR), bit for bit (Whitted)."""
    need(BOX)
    img = switchyard.render(BOX, backend="whitted", width=96, height=64)
    assert isinstance(img, numpy.ndarray) and img.shape == (64, 96, 4) and img.dtype == numpy.float32
    covered = img[..., 3] > 0.5
    assert 0.1 < covered.mean() < 0.9, "the box covers part of the image"
    assert img[..., :3][covered].mean() > 0.05, "the box is lit"
    ref = sy_render(BOX, str(tmp_path / "box.exr"), "-b", "whitted", "-w", "96", "-h", "64")
    assert_same_pixels(img, ref)


@needs_whitted
def test_cornell_whitted_equals_sy_render(tmp_path):
    """Issue 38's target: the Cornell box rendered from Python equals sy render's EXR (Whitted), bit for bit."""
    need(CORNELL)
    img = switchyard.render(CORNELL, backend="whitted", width=64, height=48)
    assert (img[..., 3] > 0.5).mean() > 0.5 and img[..., :3].mean() > 0.01, "the box covers most of the view, lit"
    ref = sy_render(CORNELL, str(tmp_path / "cbw.exr"), "-b", "whitted", "-w", "64", "-h", "48")
    assert_same_pixels(img, ref)


@needs_pt
def test_pathtracer_same_seed_and_spp_equals_sy_render(tmp_path):
    """The Cornell box through the path tracer: same spp and seed as sy render, bit for bit."""
    need(CORNELL)
    img, aovs = switchyard.render(CORNELL, backend="pathtracer", width=48, height=48, spp=4, aovs=True)
    ref = sy_render(CORNELL, str(tmp_path / "cb.exr"), "-b", "pathtracer", "-w", "48", "-h", "48", "--spp", "4")
    assert_same_pixels(img, ref)
    assert "depth" in aovs and aovs["depth"].shape == (48, 48)
    assert numpy.isfinite(aovs["depth"]).mean() > 0.9, "the closed box is hit nearly everywhere"
    assert set(aovs) - {"depth"}, "the path tracer's feature buffers come along"


@needs_whitted
def test_triangle_from_arrays_covers_half_the_image():
    s = triangle_scene()
    img = s.render(backend="whitted", width=64, height=64)
    n = int((img[..., 3] > 0.5).sum())
    # the lower-left half of the square: 64*63/2 pixels strictly inside, the diagonal split
    assert abs(n - 64 * 64 / 2) <= 64, "covered %d pixels" % n
    assert img[48, 8, 3] > 0.5 and img[8, 48, 3] == 0.0, "lower-left covered, upper-right empty (row 0 = top)"


def test_bad_input_raises():
    s = switchyard.Scene()
    good = numpy.zeros((3, 3), dtype=numpy.float32)
    good[1, 0] = good[2, 1] = 1
    idx = numpy.array([0, 1, 2], dtype=numpy.uint32)
    E = switchyard.InvalidArgumentError
    with pytest.raises(E, match="dtype must be float32"):
        s.add_mesh(good.astype(numpy.float64), idx)
    with pytest.raises(E, match="dtype must be uint32"):
        s.add_mesh(good, idx.astype(numpy.int64))
    with pytest.raises(E, match=r"shape \(3, 2\)"):
        s.add_mesh(good[:, :2].copy(), idx)
    with pytest.raises(E, match="not C-contiguous"):
        s.add_mesh(numpy.zeros((6, 3), dtype=numpy.float32)[::2], idx)
    bad = good.copy()
    bad[1, 2] = numpy.nan
    with pytest.raises(E, match="vertex 1 has a NaN"):
        s.add_mesh(bad, idx)
    with pytest.raises(E, match="index 2 is 7"):
        s.add_mesh(good, numpy.array([0, 1, 7], dtype=numpy.uint32))
    with pytest.raises(E, match="multiple of 3"):
        s.add_mesh(good, idx[:2].copy())
    with pytest.raises(E, match="buffer"):
        s.add_mesh("not an array", idx)
    assert isinstance(E("x"), ValueError), "InvalidArgumentError is a ValueError too"
    with pytest.raises(switchyard.Error) as e:
        switchyard.load("/nonexistent/scene.gltf")
    assert "/nonexistent/scene.gltf" in str(e.value), "the library's message names the file"
    with pytest.raises(switchyard.NotFoundError, match="not registered"):
        s.render(backend="no-such-backend", width=8, height=8)
    if "whitted" in NAMES:
        with pytest.raises(E, match="not progressive"):
            s.render(backend="whitted", width=8, height=8, spp=4)
    n = s.add_mesh(good, idx)
    n.destroy()
    assert not n.valid
    with pytest.raises(switchyard.InvalidHandleError):
        n.translation = (1, 2, 3)
    s.close()
    with pytest.raises(switchyard.InvalidOperationError, match="closed"):
        s.add_mesh(good, idx)


def test_objects_read_and_write_fields():
    s = switchyard.Scene()
    m = s.add_material("red", base_color=(1, 0, 0, 1), roughness=0.25)
    node = s.add_mesh(numpy.eye(3, dtype=numpy.float32), material=m, name="tri")
    assert node.name == "tri" and node.mesh is not None
    assert m.base_color == (1.0, 0.0, 0.0, 1.0) and m.roughness == 0.25
    node.translation = (1, 2, 3)
    assert node.translation == (1.0, 2.0, 3.0)
    assert numpy.allclose(node.matrix[:3, 3], [1, 2, 3]), "matrix[row, col]: translation in the last column"
    li = s.add_light(switchyard.Light.POINT, intensity=5.0)
    assert li.intensity == 5.0 and li.type == switchyard.Light.POINT
    assert len(s.nodes) == 2 and len(s.materials) == 1
    with pytest.raises(switchyard.InvalidArgumentError):
        m.roughness = float("nan")
    with pytest.raises(TypeError, match="no field 'shininess'"):
        m.set(shininess=3)
    cam = s.add_camera(znear=0.5).camera
    with pytest.raises(switchyard.InvalidArgumentError):
        cam.zfar = 0.25  # before znear: the library's setter refuses it


def test_node_trs_fields_are_the_c_base():
    """Node's TRS fields are getset descriptors of the C base (the call-overhead path): any
    3-/4-sequence, a clear error for anything else, no deletion, cycles through the scene collected."""
    import weakref
    s = switchyard.Scene()
    node = s.add_mesh(numpy.eye(3, dtype=numpy.float32))
    assert isinstance(node, switchyard._c._Node) and node.scene is s
    node.translation = [4, 5, 6]
    node.scale = numpy.array([2, 2, 2], numpy.float32)
    node.rotation = (0.0, 0.0, 0.0, 1.0)
    assert node.translation == (4.0, 5.0, 6.0) and node.scale == (2.0, 2.0, 2.0)
    assert numpy.allclose(node.matrix[:3, 3], [4, 5, 6]) and numpy.allclose(node.matrix[0, 0], 2)
    assert node == s.nodes[0] and hash(node) == hash(s.nodes[0])
    E = switchyard.InvalidArgumentError
    with pytest.raises(E, match="translation: expected 3 numbers, got 2"):
        node.translation = (1, 2)
    with pytest.raises(E, match="rotation: expected a sequence of 4 numbers"):
        node.rotation = 5
    with pytest.raises(TypeError):
        node.translation = ("a", 0, 0)
    with pytest.raises(E):
        node.translation = (float("nan"), 0, 0)
    with pytest.raises(AttributeError, match="cannot be deleted"):
        del node.scale
    assert node.translation == (4.0, 5.0, 6.0), "a refused value leaves the node as it was"
    with pytest.raises(TypeError):
        switchyard.Node(object(), 1)
    s.keep = node  # a cycle scene -> node -> scene: the collector frees it
    ref = weakref.ref(s)
    del s, node
    gc.collect()
    assert ref() is None


def test_serve_the_web_view_over_http():
    """serve() as sy web: a loopback server on an ephemeral port answers the page and a still (JPEG)
    over HTTP, owns the scene while it serves, and stop() hands it back."""
    import urllib.request
    if not hasattr(switchyard._c, "_Web"):
        pytest.skip("built without the web view (SY_WITH_WEB)")
    s = switchyard.load("demo")
    with switchyard.serve(s, port=0, backend=NAMES[0]) as srv:
        assert srv.port > 0 and srv.url.startswith("http://127.0.0.1:%d/" % srv.port) and srv.running
        page = urllib.request.urlopen(srv.url, timeout=30).read()
        assert b"<canvas" in page
        origin = "http://127.0.0.1:%d" % srv.port
        req = urllib.request.Request(origin + "/api/frame.jpg?w=64&h=48", headers={"Origin": origin})
        jpg = urllib.request.urlopen(req, timeout=60).read()
        assert jpg[:3] == b"\xff\xd8\xff", "a JPEG still"
        with pytest.raises(RuntimeError, match="in use"):
            s.nodes
    assert not srv.running and "stopped" in repr(srv)
    assert len(s.nodes) > 0, "the scene is usable again after stop()"
    with pytest.raises(switchyard.NotFoundError):
        switchyard.serve(s, port=0, backend="no-such-backend")
    s.close()
    t = switchyard.Scene()
    t.add_mesh(numpy.eye(3, dtype=numpy.float32))
    with pytest.raises(switchyard.InvalidArgumentError, match="no camera"):
        switchyard.serve(t, port=0)
    srv = switchyard.serve("demo", port=0)  # from a path: the server's own scene, closed by stop()
    srv.stop()
    srv.stop()
    with pytest.raises(switchyard.InvalidOperationError, match="closed"):
        srv.scene.nodes


def _two_clips_gltf(path):
    """A glTF of one triangle, a camera and two clips, "slide" (x) and "lift" (y), on the same node."""
    import base64
    import json
    import struct
    data = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<2f", 0, 1) + \
        struct.pack("<6f", 0, 0, 0, 1, 0, 0) + struct.pack("<6f", 0, 0, 0, 0, 1, 0)
    views = [(0, 36), (36, 8), (44, 24), (68, 24)]
    channel = [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
           "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0.5, 0.5, 4]}],
           "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
           "buffers": [{"byteLength": len(data),
                        "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
           "bufferViews": [{"buffer": 0, "byteOffset": o, "byteLength": n} for o, n in views],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0],
                          "max": [1, 1, 0]},
                         {"bufferView": 1, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
                         {"bufferView": 2, "componentType": 5126, "count": 2, "type": "VEC3"},
                         {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}],
           "animations": [{"name": "slide", "channels": channel, "samplers": [{"input": 1, "output": 2}]},
                          {"name": "lift", "channels": channel, "samplers": [{"input": 1, "output": 3}]}]}
    path.write_text(json.dumps(doc))
    return str(path)


def _ws_message(port, kind, timeout=30):
    """The first text message of type ``kind`` that a page connected to the server on ``port``
    (GET /ws, subprotocol sy-view, a same-origin Origin) receives: a minimal WebSocket client."""
    import base64
    import json
    import socket
    sock = socket.create_connection(("127.0.0.1", port), timeout=timeout)
    key = base64.b64encode(os.urandom(16)).decode()
    sock.sendall(("GET /ws HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nOrigin: http://127.0.0.1:%d\r\nUpgrade: websocket\r\n"
                  "Connection: Upgrade\r\nSec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\n"
                  "Sec-WebSocket-Protocol: sy-view\r\n\r\n" % (port, port, key)).encode())
    buf = b""

    def need(n):
        nonlocal buf
        while len(buf) < n:
            chunk = sock.recv(65536)
            if not chunk:
                raise EOFError("the server closed the WebSocket")
            buf += chunk
    try:
        while b"\r\n\r\n" not in buf:
            need(len(buf) + 1)
        head, buf = buf.split(b"\r\n\r\n", 1)
        assert b" 101 " in head.split(b"\r\n")[0], head
        while True:  # server frames: unmasked, whole messages
            need(2)
            op, n, off = buf[0] & 0x0F, buf[1] & 0x7F, 2
            if n == 126:
                need(4)
                n, off = int.from_bytes(buf[2:4], "big"), 4
            elif n == 127:
                need(10)
                n, off = int.from_bytes(buf[2:10], "big"), 10
            need(off + n)
            payload, buf = buf[off:off + n], buf[off + n:]
            if op == 8:
                raise EOFError("the server closed the WebSocket")
            if op == 1:
                msg = json.loads(payload)
                if msg.get("t") == kind:
                    return msg
    finally:
        sock.close()


def test_serve_plays_the_clip_given(tmp_path):
    """serve(..., clip=NAME|INDEX) is sy web --clip (sy_web_desc.clip): the page's clock plays that
    clip (its index in hello's clips); without it the clip sy web plays without --clip (two clips on
    the same node: the first); an unknown clip, or a clip of a scene without animations, raises
    NotFoundError before anything serves."""
    if not hasattr(switchyard._c, "_Web"):
        pytest.skip("built without the web view (SY_WITH_WEB)")
    path = _two_clips_gltf(tmp_path / "clips.gltf")
    for clip, index in (("lift", 1), (0, 0), ("1", 1), (None, 0)):
        with switchyard.serve(path, port=0, backend=NAMES[0], clip=clip) as srv:
            assert _ws_message(srv.port, "hello")["clips"] == ["slide", "lift"]
            clock = _ws_message(srv.port, "clock")
            assert clock["clip"] == index and clock["end"] == 1, (clip, clock)
    with pytest.raises(switchyard.NotFoundError, match="clip walk"):
        switchyard.serve(path, port=0, clip="walk")
    with pytest.raises(switchyard.NotFoundError, match="no animations"):
        switchyard.serve("demo", port=0, clip=0)


def test_serve_keeps_the_saved_views_file(tmp_path):
    """serve(..., bookmarks=FILE) is sy web --bookmarks: the views sy view saved in FILE are listed
    to every page ("views"); without it the server keeps the pages' views itself; a file that is no
    views' file is left as it is (the list says why)."""
    if not hasattr(switchyard._c, "_Web"):
        pytest.skip("built without the web view (SY_WITH_WEB)")
    marks = tmp_path / "demo.bookmarks"
    marks.write_text("# sy bookmarks\n4 3 2 4 0 0.5 0 0 1 0 35\n")
    with switchyard.serve("demo", port=0, backend=NAMES[0], bookmarks=marks) as srv:
        views = _ws_message(srv.port, "views")
        assert views["kept"] and [v["n"] for v in views["views"]] == [4], views
        assert views["views"][0]["eye"] == [3, 2, 4] and abs(views["views"][0]["fov"] - 35) < 1e-4, views
    with switchyard.serve("demo", port=0, backend=NAMES[0]) as srv:
        views = _ws_message(srv.port, "views")
        assert not views["kept"] and views["views"] == [], views
    marks.write_text("4 not a view\n")
    with switchyard.serve("demo", port=0, backend=NAMES[0], bookmarks=str(marks)) as srv:
        views = _ws_message(srv.port, "views")
        assert not views["kept"] and "could not be read" in views["note"], views
    assert marks.read_text() == "4 not a view\n"


@needs_whitted
def test_default_clip_is_sy_renders(tmp_path):
    """Without clip=, load(at=) and Scene.set_time play the clip sy render plays without --clip (two
    clips on one node: the first, "slide"), not every clip together ("lift" would win)."""
    path = _two_clips_gltf(tmp_path / "clips.gltf")
    ref = sy_render(path, str(tmp_path / "ref.exr"), "-b", "whitted", "-w", "48", "-h", "40", "--at", "0.5")
    assert_same_pixels(switchyard.render(path, backend="whitted", width=48, height=40, at=0.5), ref)
    with switchyard.load(path) as s:
        s.set_time(0.5)
        slide = s.render(backend="whitted", width=48, height=40)
        assert_same_pixels(slide, ref)
        s.set_time(0.5, clip="lift")
        assert not numpy.array_equal(s.render(backend="whitted", width=48, height=40), slide)


@needs_whitted
def test_load_world_and_time_options_equal_sy_render(tmp_path):
    """load()'s world and time options are sy render's --background / --at: the same pixels."""
    path = os.path.join(TESTDATA, "gltf/AnimatedCube/glTF/AnimatedCube.gltf")
    need(path)
    ref = sy_render(path, str(tmp_path / "ref.exr"), "-b", "whitted", "-w", "48", "-h", "40", "--at", "0.5",
                    "--background", "0.2,0.3,0.4")
    img = switchyard.render(path, backend="whitted", width=48, height=40, at=0.5, background=(0.2, 0.3, 0.4))
    assert_same_pixels(img, ref)
    assert numpy.allclose(img[0, 0], (0.2, 0.3, 0.4, 1.0)), "the background where nothing is hit"
    still = switchyard.render(path, backend="whitted", width=48, height=40)
    assert not numpy.array_equal(img[..., :3] * (img[..., 3:] > 0.99), still[..., :3] * (img[..., 3:] > 0.99))
    with switchyard.load(path) as s:
        s.set_time(0.5, clip=0)
        assert numpy.array_equal(s.render(backend="whitted", width=48, height=40),
                                 switchyard.render(path, backend="whitted", width=48, height=40, at=0.5))
    E = switchyard.InvalidArgumentError
    for kw, err, msg in ((dict(env_color=(1, 2)), E, "env_color"), (dict(background=(1, 2, 3, 4, 5)), E, "background"),
                         (dict(at=float("nan")), E, "finite"), (dict(env_intensity=-1), E, "env_intensity"),
                         (dict(clip="nope"), switchyard.NotFoundError, "nope"),
                         (dict(env=str(tmp_path / "missing.exr")), switchyard.NotFoundError, "missing.exr")):
        with pytest.raises(err, match=msg):
            switchyard.load(path, **kw)


def test_mesh_data_as_read_only_views():
    """Mesh.positions / indices / normals / primitives: read-only NumPy views of the library's blobs
    (no copy) that keep their data alive after the scene is closed."""
    s = switchyard.Scene()
    pos = numpy.random.default_rng(1).random((6, 3), dtype=numpy.float32)
    nrm = numpy.tile(numpy.array([0, 0, 1], numpy.float32), (6, 1))
    mesh = s.add_mesh(pos, numpy.arange(6, dtype=numpy.uint32), normals=nrm, name="m").mesh
    p, idx = mesh.positions, mesh.indices
    assert p.dtype == numpy.float32 and p.shape == (6, 3) and numpy.array_equal(p, pos)
    assert idx.dtype == numpy.uint32 and idx.shape == (2, 3) and numpy.array_equal(idx.ravel(), numpy.arange(6))
    assert numpy.array_equal(mesh.normals, nrm) and mesh.name == "m"
    assert not p.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        p[0, 0] = 1.0
    base = p.base
    while isinstance(base, (numpy.ndarray, memoryview)):
        base = base.obj if isinstance(base, memoryview) else base.base
    assert isinstance(base, switchyard._c._BlobView), "a view of the blob, not a copy"
    prim, = mesh.primitives
    assert prim.topology == switchyard.Primitive.TRIANGLES and prim.material is None and prim.colors is None
    assert numpy.array_equal(prim["positions"], pos)
    live = switchyard._c.blob_live_count()
    s.close()
    assert numpy.array_equal(p, pos), "the view keeps its blob after the scene is closed"
    assert switchyard._c.blob_live_count() > 0
    del p, idx, prim, base
    gc.collect()
    assert switchyard._c.blob_live_count() < live
    with pytest.raises(switchyard.InvalidOperationError):
        mesh.positions


@needs_whitted
def test_window_switches_backends_on_a_live_viewport():
    s = triangle_scene()
    with switchyard.Window(s, 32, 32) as w:
        vp = w.add_viewport("whitted")
        a = numpy.array(w.render())
        other = next((n for n in ("pathtracer", "raster") if n in NAMES), None)
        if other:
            vp.backend = other
            assert vp.backend == other
            w.render()
            vp.backend = "whitted"
        b = numpy.array(w.render())
        assert numpy.array_equal(a, b), "back to whitted: the same image"
        with pytest.raises(switchyard.InvalidOperationError, match="Window"):
            s.close()  # a window still shows it
    with pytest.raises(switchyard.InvalidOperationError, match="window is closed"):
        w.render()
    with pytest.raises(switchyard.InvalidOperationError):
        vp.backend = "whitted"
    s.close()


@needs_whitted
def test_two_renders_in_two_threads():
    need(BOX)
    ref = switchyard.render(BOX, backend="whitted", width=48, height=32)
    out = [None, None]
    errors = []

    def work(i):
        try:
            out[i] = switchyard.render(BOX, backend="whitted", width=48, height=32)
        except Exception as e:  # noqa: BLE001 (reported below)
            errors.append(e)
    ts = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert not errors
    assert all(numpy.array_equal(o, ref) for o in out)


def rss_kb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") // 1024


@needs_whitted
def test_no_growth_over_repeated_renders_and_scenes():
    """Render in a loop and build / drop object graphs: blobs and RSS come back (no leak)."""
    gc.collect()
    blobs0 = switchyard._c.blob_live_count()
    pos = numpy.random.default_rng(1).random((300, 3), dtype=numpy.float32)
    idx = numpy.arange(300, dtype=numpy.uint32)

    def once():
        with switchyard.Scene() as s:
            m = s.add_material(base_color=(0.5, 0.5, 0.5, 1))
            s.add_mesh(pos, idx, material=m)
            img = s.render(backend="whitted", width=16, height=16)
            assert img.shape == (16, 16, 4)
    for _ in range(20):
        once()
    gc.collect()
    before = rss_kb()
    for _ in range(200):
        once()
    for _ in range(2000):
        s = switchyard.Scene()
        s.add_mesh(pos, idx)
        del s
    gc.collect()
    grown = rss_kb() - before
    assert switchyard._c.blob_live_count() <= blobs0, "every blob is released"
    if "libasan" in os.environ.get("LD_PRELOAD", ""):
        return  # AddressSanitizer keeps freed memory in quarantine; LeakSanitizer checks instead
    assert grown < 4096, "RSS grew by %d KiB over 200 renders and 2000 scenes" % grown


def test_png_repr_and_exr_round_trip(tmp_path):
    img = switchyard.Image._of(_flat_image())
    png = img._repr_png_()
    assert png.startswith(b"\x89PNG")
    p = str(tmp_path / "x.exr")
    switchyard.write_exr(p, img)
    back = switchyard.read_exr(p)
    assert numpy.array_equal(back["G"], numpy.asarray(img)[..., 1])


def _flat_image():
    s = switchyard.Scene()
    s.add_mesh(numpy.eye(3, dtype=numpy.float32))
    if "whitted" in NAMES:
        rgba, _, _ = s._c._render("whitted", 8, 6)
        return rgba
    pytest.skip("no whitted back-end")


def test_log_goes_to_logging(caplog):
    """The library's log callback reaches the logging logger "switchyard" (a load's debug line)."""
    import logging
    need(BOX)
    switchyard.set_log_level(logging.DEBUG)
    try:
        with caplog.at_level(logging.DEBUG, logger="switchyard"):
            switchyard.load(BOX).close()
        assert any(r.name == "switchyard" and "loaded in" in r.getMessage() for r in caplog.records), caplog.records
    finally:
        switchyard.set_log_level(logging.INFO)


@needs_pt
def test_progress_and_ctrl_c_after_a_pass():
    """progress(done, total) after each pass up to (spp, spp); SIGINT raises KeyboardInterrupt
    after the pass in progress instead of running on."""
    import signal
    s = triangle_scene()
    calls = []
    s.render(backend="pathtracer", width=16, height=16, spp=8, progress=lambda d, t: calls.append((d, t)))
    assert calls and calls[-1] == (8, 8) and all(t == 8 for _, t in calls)
    assert [d for d, _ in calls] == sorted(d for d, _ in calls)
    calls.clear()

    def interrupt(d, t):
        calls.append(d)
        signal.raise_signal(signal.SIGINT)
    with pytest.raises(KeyboardInterrupt):
        s.render(backend="pathtracer", width=16, height=16, spp=1 << 20, progress=interrupt)
    assert len(calls) == 1, "stopped after the first pass"


@needs_pt
def test_sigint_during_a_render_without_the_gil():
    """A SIGINT arriving while the render runs without the GIL (from a timer thread) raises
    KeyboardInterrupt after the pass in progress, long before the samples asked for are done."""
    import signal
    s = triangle_scene()
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            s.render(backend="pathtracer", width=32, height=32, spp=1 << 24)
    finally:
        timer.cancel()
    img = s.render(backend="whitted", width=8, height=8) if "whitted" in NAMES else None
    assert img is None or img.shape == (8, 8, 4), "the scene is usable after the interrupt"


@needs_whitted
def test_examples_run_as_written(tmp_path):
    """apps/examples/python: the programs run and write their images (animate.py: what its frames cost)."""
    import sys
    ex = os.path.join(os.path.dirname(__file__), "../../apps/examples/python")
    out = str(tmp_path / "arrays.exr")
    subprocess.run([sys.executable, os.path.join(ex, "from_arrays.py"), out], check=True, capture_output=True)
    a = switchyard.read_exr(out)["A"]
    assert a.shape[0] == 192 and a.shape[1] % 256 == 0 and (a > 0.5).mean() > 0.1
    if os.path.exists(BOX):
        out = str(tmp_path / "box.exr")
        subprocess.run([sys.executable, os.path.join(ex, "render_file.py"), BOX, out], check=True, capture_output=True)
        assert switchyard.read_exr(out)["A"].shape == (480, 640)
    r = subprocess.run([sys.executable, os.path.join(ex, "animate.py"), "demo", "3"], check=True, capture_output=True,
                       text=True)
    assert "first frame" in r.stdout and "moving frames: median" in r.stdout, r.stdout


@needs_whitted
def test_reference_counts_and_ownership():
    """Renders and object access leave the scene's reference count as it was; an image outlives its
    scene (it owns the library's pixels); objects keep their scene alive, not the other way round."""
    import sys
    s = triangle_scene()
    node = s.nodes[0]
    before = sys.getrefcount(s), sys.getrefcount(s._c)
    for _ in range(10):
        img = s.render(backend="whitted", width=8, height=8)
        _ = node.translation, s.materials, s.camera
    del _
    assert (sys.getrefcount(s), sys.getrefcount(s._c)) == before
    buf = numpy.asarray(img).base
    while isinstance(buf, (numpy.ndarray, memoryview)):
        buf = buf.obj if isinstance(buf, memoryview) else buf.base
    assert isinstance(buf, switchyard._c._Buffer), "the array views the library's allocation"
    s.close()
    assert float(numpy.asarray(img)[..., 3].sum()) > 0, "the image outlives its scene"
    assert not node.valid


def test_render_on_a_cluster_equals_the_local_render(tmp_path):
    """servers=: two `sy serve` processes on loopback render sort-first; the image equals the local
    one bit for bit (float pixels), as sy render --cluster's does (tests/cluster/cluster_cli_test.sh)."""
    import time
    if "whitted" not in NAMES:
        pytest.skip("built without the Embree back-ends (no whitted)")
    if not SY or not os.path.exists(SY):
        pytest.skip("the sy program is not given (SY_BIN)")
    secret = tmp_path / "secret"
    secret.write_text("python-test-secret\n")
    secret.chmod(0o600)
    procs, urls = [], []
    try:
        for k in range(2):
            port = tmp_path / ("%d.port" % k)
            procs.append(subprocess.Popen([SY, "serve", "--listen", "tcp://127.0.0.1:0", "--port-file", str(port),
                                           "--secret-file", str(secret), "--max-lifetime", "300"],
                                          stderr=subprocess.DEVNULL))
            while not (port.exists() and port.read_text().strip()):  # the server writes it once listening
                if procs[-1].poll() is not None:
                    pytest.fail("sy serve exited with %s" % procs[-1].returncode)
                time.sleep(0.01)
            urls.append("tcp://127.0.0.1:%s" % port.read_text().strip())
        s = switchyard.load("demo")
        local = s.render(backend="whitted", width=120, height=80)
        remote = s.render(backend="whitted", width=120, height=80, servers=urls, secret_file=secret)
        assert numpy.array_equal(local, remote)
        with pytest.raises(switchyard.Error):
            s.render(backend="whitted", width=8, height=8, servers="tcp://127.0.0.1:1", secret_file=secret)
        with switchyard.Window(s, 120, 80) as win:  # a Window viewport on the same servers
            vp = win.add_viewport("whitted", servers=urls, secret_file=secret)
            assert vp.backend.startswith("cluster-python-")
            assert numpy.array_equal(win.render(), local)
            vp.backend = "whitted"  # back to local on the live viewport
            assert numpy.array_equal(win.render(), local)
            vp.set_backend("whitted", servers=urls, secret_file=secret)
            assert numpy.array_equal(win.render(), local)
    finally:
        for p in procs:
            p.terminate()
            p.wait()


@needs_pt
@needs_whitted
def test_notebook_block_of_the_docs_runs_as_written():
    """docs/PYTHON.md, "In a notebook": the block runs as written and shows two images side by side."""
    import re
    doc = open(os.path.join(os.path.dirname(__file__), "../../docs/PYTHON.md")).read()
    block = re.search(r"## In a notebook.*?```python\n(.*?)```", doc, re.S).group(1)
    env = {}
    exec(compile(block, "docs/PYTHON.md", "exec"), env)
    img = env["side_by_side"]
    assert isinstance(img, switchyard.Image) and img.shape == (240, 640, 4)
    assert img._repr_png_().startswith(b"\x89PNG")


@needs_whitted
@needs_pt
def test_hidden_and_selected_nodes_and_the_id_aovs():
    """Node.flags: clearing NODE_VISIBLE hides a node (its pixels change), NODE_SELECTED highlights one
    (orange tint); the path tracer's AOVs hold object_id / instance_id planes naming scene nodes."""
    s = switchyard.load("demo")
    ns = [n for n in s.nodes if n.mesh is not None]
    plain = s.render(backend="whitted", width=96, height=64)
    ns[0].flags = ns[0].flags | switchyard.NODE_SELECTED
    ns[1].flags = ns[1].flags & ~switchyard.NODE_VISIBLE
    s.commit()
    changed = s.render(backend="whitted", width=96, height=64)
    assert float(numpy.abs(plain - changed).mean()) > 0.01
    _, aovs = s.render(backend="pathtracer", width=96, height=64, spp=1, aovs=True)
    ids = {int(v) for v in numpy.unique(aovs["object_id"])} - {0}
    assert aovs["instance_id"].shape[:2] == (64, 96)
    assert ids and ids <= {n.id for n in s.nodes}
    assert ns[1].id not in ids  # hidden: never under a pixel


def test_type_stubs_name_every_public_name():
    """switchyard/__init__.pyi declares every name of __all__, and every public method of the classes."""
    import ast
    stub = os.path.join(os.path.dirname(switchyard.__file__), "__init__.pyi")
    tree = ast.parse(open(stub).read())
    declared, members = set(), {}
    for n in tree.body:
        if isinstance(n, (ast.ClassDef, ast.FunctionDef)):
            declared.add(n.name)
            if isinstance(n, ast.ClassDef):
                members[n.name] = {b.name for b in n.body if isinstance(b, ast.FunctionDef)} | \
                    {b.target.id for b in n.body if isinstance(b, ast.AnnAssign)}
        elif isinstance(n, ast.Assign):
            declared.update(t.id for t in n.targets if isinstance(t, ast.Name))
    missing = [n for n in switchyard.__all__ if n not in declared]
    assert not missing, "names of __all__ without a stub: %s" % missing
    for cls in ("Scene", "Window", "Viewport", "Server", "Mesh", "Node", "Material", "Light", "Camera", "Backend"):
        have = members[cls] | members.get("_Object", set())
        public = {m for m in vars(getattr(switchyard, cls)) if not m.startswith("_")}
        assert public <= have, "%s: %s without a stub" % (cls, sorted(public - have))


def _cube_scene():
    """The cube [-0.5, 0.5]^3 (closed, wound outward) under an orthographic camera looking down -Z."""
    s = switchyard.Scene()
    p = numpy.array([[-.5, -.5, -.5], [.5, -.5, -.5], [.5, .5, -.5], [-.5, .5, -.5],
                     [-.5, -.5, .5], [.5, -.5, .5], [.5, .5, .5], [-.5, .5, .5]], dtype=numpy.float32)
    i = numpy.array([0, 3, 2, 0, 2, 1, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4, 3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3,
                     1, 2, 6, 1, 6, 5], dtype=numpy.uint32)
    s.add_mesh(p, i)
    s.camera = s.add_camera("ortho", projection=switchyard.Camera.ORTHOGRAPHIC, xmag=1.0, ymag=1.0, znear=0.1,
                            zfar=10.0)
    s.camera.translation = (0.0, 0.0, 3.0)
    return s


@needs_whitted
def test_viewport_clip_planes_and_caps():
    """Viewport.clip_planes and .clip_cap: round trip, bad values refused (the planes before stay),
    the cut seen in the image, a cut closed cube capped in the cap colour."""
    s = triangle_scene()
    with switchyard.Window(s, 32, 32) as w:
        vp = w.add_viewport("whitted")
        assert vp.clip_planes == [] and vp.clip_cap is None
        full = numpy.array(w.render())
        vp.clip_planes = [(-1.0, 0.0, 0.0, -0.5)]  # keeps x <= -0.5: the left quarter
        assert vp.clip_planes == [(-1.0, 0.0, 0.0, -0.5)]
        cut = numpy.array(w.render())
        covered_full, covered_cut = (full[..., 3] > 0.5).sum(), (cut[..., 3] > 0.5).sum()
        assert 0 < covered_cut < 0.5 * covered_full, (covered_cut, covered_full)
        assert (cut[:, 12:, 3] <= 0.5).all(), "the removed half still shows"
        for bad, what in (([(float("nan"), 0, 0, 0)], "not finite"), ([(0, 0, 0, 1)], "normal"),
                          ([(1, 0, 0, 0)] * 7, "at most 6")):
            with pytest.raises(switchyard.InvalidArgumentError, match=what):
                vp.clip_planes = bad
            assert vp.clip_planes == [(-1.0, 0.0, 0.0, -0.5)], "a refused plane changed the planes"
        with pytest.raises(ValueError):
            vp.clip_planes = [(1, 0, 0)]
        with pytest.raises(TypeError):
            vp.clip_planes = [("a", 0, 0, 0)]
        for bad in ((float("nan"), 0, 0), (2, 0, 0), (-0.5, 0, 0)):
            with pytest.raises(switchyard.InvalidArgumentError, match="colour"):
                vp.clip_cap = bad
        vp.clip_cap = (0.25, 0.5, 1.0)
        assert vp.clip_cap == (0.25, 0.5, 1.0)
        vp.clip_cap = None
        assert vp.clip_cap is None
        vp.clip_planes = []
        assert numpy.array_equal(numpy.array(w.render()), full), "removing the planes brings the uncut image back"
    s.close()
    s = _cube_scene()
    with switchyard.Window(s, 32, 32) as w:
        vp = w.add_viewport("whitted")
        vp.clip_planes = [(0.0, 0.0, -1.0, 0.0)]  # keeps z <= 0: the camera looks into the cut cube
        inside = numpy.array(w.render())
        vp.clip_cap = (0.25, 0.5, 1.0)
        capped = numpy.array(w.render())
    s.close()
    square = capped[10:22, 10:22]  # well inside the cube's square (half the view)
    assert numpy.allclose(square[..., :3], (0.25, 0.5, 1.0), atol=1e-4), square[0, 0]
    assert not numpy.allclose(inside[10:22, 10:22, :3], (0.25, 0.5, 1.0), atol=0.05), "capped without clip_cap"
    assert (inside[10:22, 10:22, 3] > 0.99).all(), "without caps the cube's inside shows"
