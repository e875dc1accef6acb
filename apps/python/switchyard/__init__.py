"""switchyard: scene-graph rendering middleware, from Python (docs/PYTHON.md).

The three-line path::

    import switchyard
    img = switchyard.render("scene.gltf", backend="whitted", width=640, height=480)
    switchyard.write_exr("out.exr", img)

``img`` is a ``numpy.ndarray`` of shape (height, width, 4), float32, linear premultiplied RGBA,
row 0 at the top: the same pixels ``sy render`` writes for the same file, back-end and settings.

Objects, not handles: ``load()`` returns a :class:`Scene`; its :class:`Node`, :class:`Mesh`,
:class:`Material`, :class:`Light` and :class:`Camera` objects read and write the library's fields
as attributes. A :class:`Window` with :class:`Viewport` objects layers back-ends, renders stereo
and switches a live viewport's back-end; ``serve()`` shows a scene in a web browser as ``sy web``
does. Errors raise :class:`Error` subclasses carrying the
library's message; the library's log goes to the ``logging`` logger ``"switchyard"``. Loads and
renders release the GIL.
"""
import atexit
import logging

import numpy

from . import _switchyard as _c

__all__ = [
    "Error", "InvalidArgumentError", "InvalidHandleError", "OutOfMemoryError", "FileError", "ParseError",
    "UnsupportedError", "LimitError", "NotFoundError", "BackendError", "ProtocolError",
    "InvalidOperationError", "CancelledError", "SystemError_",
    "Scene", "Node", "Mesh", "Primitive", "Material", "Light", "Camera", "Window", "Viewport", "Backend",
    "Server", "load", "render", "serve", "backends", "read_exr", "write_exr", "version",
]

# ---------------------------------------------------------------- errors (one per sy_result)


class Error(Exception):
    """A library call failed: ``str(e)`` is the library's message, ``e.code`` its sy_result."""

    def __init__(self, message, code=0):
        super().__init__(message)
        self.code = code

    def __str__(self):
        return str(self.args[0]) if self.args else ""


class InvalidArgumentError(Error, ValueError):
    """SY_ERR_INVALID_ARGUMENT: a value the library does not accept (dtype, shape, NaN, range)."""


class InvalidHandleError(Error):
    """SY_ERR_INVALID_HANDLE: the object was destroyed (a stale handle) or belongs to another scene."""


class OutOfMemoryError(Error, MemoryError):
    """SY_ERR_OUT_OF_MEMORY."""


class FileError(Error, OSError):
    """SY_ERR_IO: a file could not be read or written."""


class ParseError(Error):
    """SY_ERR_PARSE: malformed input (a damaged file)."""


class UnsupportedError(Error):
    """SY_ERR_UNSUPPORTED: well-formed but not implemented."""


class LimitError(Error):
    """SY_ERR_LIMIT: a size or count beyond a limit."""


class NotFoundError(Error, LookupError):
    """SY_ERR_NOT_FOUND: a named file, camera or back-end does not exist."""


class BackendError(Error):
    """SY_ERR_BACKEND: a back-end library failed."""


class ProtocolError(Error):
    """SY_ERR_PROTOCOL: a network peer violated the protocol."""


class InvalidOperationError(Error):
    """SY_ERR_INVALID_OPERATION: a call out of order (a closed scene or window)."""


class CancelledError(Error):
    """SY_ERR_CANCELLED."""


class SystemError_(Error):
    """SY_ERR_SYSTEM: an operating-system call failed."""


_c._set_errors(Error, {1: InvalidArgumentError, 2: InvalidHandleError, 3: OutOfMemoryError, 4: FileError,
                       5: ParseError, 6: UnsupportedError, 7: LimitError, 8: NotFoundError, 9: BackendError,
                       10: ProtocolError, 11: InvalidOperationError, 12: CancelledError, 13: SystemError_})

# ---------------------------------------------------------------- log -> logging

logger = logging.getLogger("switchyard")
_LEVELS = {0: logging.ERROR, 1: logging.WARNING, 2: logging.INFO, 3: logging.DEBUG}


def _log(level, module, item, message):
    logger.log(_LEVELS.get(level, logging.DEBUG), "%s%s", item + ": " if item else "", message,
               extra={"sy_module": module, "sy_item": item})


def set_log_level(level):
    """The library's own level (``logging.DEBUG`` lets its debug messages through; default: INFO)."""
    lv = 3 if level <= logging.DEBUG else 2 if level <= logging.INFO else 1 if level <= logging.WARNING else 0
    _c._set_log(_log, lv)


_c._set_log(_log, 2)
atexit.register(_c._set_log, None)  # no Python callback once the interpreter is finalising


def version():
    """The library's version, "MAJOR.MINOR.PATCH"."""
    return _c.version()

# ---------------------------------------------------------------- arrays


def _array(buf):
    """A _Buffer (library memory) as a numpy array viewing it: no copy; the array keeps it alive."""
    return numpy.asarray(buf)


class Backend(tuple):
    """A registered back-end: ``name``, ``caps`` (CAP_* bits), ``default``, ``progressive``."""
    __slots__ = ()

    def __new__(cls, name, caps, default):
        return super().__new__(cls, (name, caps, default))

    name = property(lambda self: self[0])
    caps = property(lambda self: self[1])
    default = property(lambda self: self[2])
    progressive = property(lambda self: bool(self[1] & _c.CAP_PROGRESSIVE))
    aovs = property(lambda self: bool(self[1] & _c.CAP_AOVS))

    def __repr__(self):
        return "Backend(%r%s%s)" % (self.name, ", progressive" if self.progressive else "",
                                     ", default" if self.default else "")


def backends():
    """The back-ends registered in the library (the registry's answer, in registration order)."""
    return [Backend(*b) for b in _c.backends()]


CAP_DEPTH, CAP_PROGRESSIVE, CAP_AOVS = _c.CAP_DEPTH, _c.CAP_PROGRESSIVE, _c.CAP_AOVS
# Node.flags bits: shown (a hidden node's subtree is not drawn, hit or picked), hints, selected
# (highlighted alike by every back-end: a tint and an outline, mediators/sy_highlight.h)
NODE_VISIBLE, NODE_STATIC, NODE_ANIMATED, NODE_SELECTED = _c.NODE_VISIBLE, _c.NODE_STATIC, _c.NODE_ANIMATED, _c.NODE_SELECTED

# ---------------------------------------------------------------- scene objects


class _Methods:
    """What every scene object offers, given ``scene`` (a Scene), ``id`` and ``_type``."""
    __slots__ = ()
    _type = None

    def __eq__(self, other):
        return type(self) is type(other) and self.scene is other.scene and self.id == other.id

    def __hash__(self):
        return hash((type(self), id(self.scene), self.id))

    @property
    def valid(self):
        """False once the object (or its scene) is gone: any other use raises InvalidHandleError."""
        return self.scene._c._valid(self._type, self.id)

    def destroy(self):
        """Destroys the object in the scene (this Python object becomes stale)."""
        self.scene._c._destroy(self._type, self.id)

    def _fields(self):
        return self.scene._c._get(self._type, self.id)

    @property
    def name(self):
        return self._fields()["name"]

    def __repr__(self):
        try:
            n = self._fields()["name"]
        except Error:
            return "<%s %d (stale)>" % (type(self).__name__, self.id)
        return "<%s %d%s>" % (type(self).__name__, self.id, " %r" % n if n else "")


class _Object(_Methods):
    """An object of a scene: the scene (kept alive by it) and the library's handle id."""
    __slots__ = ("scene", "id")

    def __init__(self, scene, id):
        self.scene = scene
        self.id = id


class Node(_c._Node, _Methods):
    """A node: transform (TRS or matrix), children, optional mesh, light and camera.

    ``scene``, ``id``, ``translation``, ``rotation`` and ``scale`` are the C base's (_c._Node):
    setting a TRS field is one C call (the call-overhead target; apps/python/bench_overhead.py)."""
    __slots__ = ()
    _type = _c.TYPE_NODE

    @property
    def matrix(self):
        """The local matrix as a 4x4 numpy array (row-major view of the column-major sy_mat4: m[row, col])."""
        return numpy.array(self._fields()["matrix"], dtype=numpy.float32).reshape(4, 4).T

    @matrix.setter
    def matrix(self, m):
        self.scene._c._node_set(self.id, matrix=numpy.asarray(m, dtype=numpy.float32).reshape(4, 4).T.ravel().tolist())

    flags = property(lambda self: self._fields()["flags"], lambda self, v: self.scene._c._node_set(self.id, flags=v))

    @property
    def children(self):
        return [Node(self.scene, i) for i in self._fields()["children"]]

    def add_child(self, node):
        self.scene._c._node_set(self.id, add_child=node.id)

    def _ref(self, key, cls):
        i = self._fields()[key]
        return cls(self.scene, i) if i else None

    mesh = property(lambda self: self._ref("mesh", Mesh),
                    lambda self, m: self.scene._c._node_set(self.id, mesh=m.id if m else 0))
    light = property(lambda self: self._ref("light", Light),
                     lambda self, v: self.scene._c._node_set(self.id, light=v.id if v else 0))
    camera = property(lambda self: self._ref("camera", Camera),
                      lambda self, v: self.scene._c._node_set(self.id, camera=v.id if v else 0))


class Primitive(dict):
    """One primitive of a Mesh: ``positions`` (N, 3) float32, ``normals`` (N, 3) / ``tangents``
    (N, 4) / ``texcoords0``, ``texcoords1`` (N, 2) / ``colors`` (N, 4) float32 or None, ``indices``
    uint32 ((M, 3) triangles, (M, 2) lines, flat points; None: non-indexed), ``material`` (a
    Material or None), ``topology`` (TRIANGLES, LINES, POINTS). The arrays are read-only views of
    the library's immutable blobs (no copy); each keeps its data alive on its own, so it stays valid
    after the mesh changes or its scene is closed (it shows the data it was read from)."""
    TRIANGLES, LINES, POINTS = 0, 1, 2
    __slots__ = ()

    def __getattr__(self, key):
        try:
            return self[key]
        except KeyError:
            raise AttributeError(key) from None


class Mesh(_Object):
    """A mesh: primitives whose vertex data lives in the library's blobs. ``primitives`` lists them
    (:class:`Primitive`); ``positions``, ``normals`` and ``indices`` are those of a mesh with one
    primitive (read-only NumPy views, no copy)."""
    __slots__ = ()
    _type = _c.TYPE_MESH

    @property
    def primitives(self):
        out = []
        for p in self._fields()["primitives"]:
            q = Primitive((k, None if v is None else _array(v)) for k, v in p.items() if k not in ("material", "topology"))
            q["material"] = Material(self.scene, p["material"]) if p["material"] else None
            q["topology"] = p["topology"]
            out.append(q)
        return out

    def _one(self, key):
        prims = self._fields()["primitives"]
        if len(prims) != 1:
            raise InvalidOperationError("mesh %d has %d primitives: read them with Mesh.primitives" %
                                        (self.id, len(prims)), 11)
        v = prims[0][key]
        return None if v is None else _array(v)

    positions = property(lambda self: self._one("positions"), doc="(N, 3) float32, read-only (one primitive)")
    normals = property(lambda self: self._one("normals"), doc="(N, 3) float32 or None, read-only (one primitive)")
    indices = property(lambda self: self._one("indices"), doc="uint32 (M, 3) for triangles, or None (one primitive)")


class _Fielded(_Object):
    """An object whose fields the library lists by name (_switchyard's field tables)."""
    __slots__ = ()
    _keys = ()

    def __getattr__(self, key):
        if key in type(self)._keys:
            return self._fields()[key]
        raise AttributeError(key)

    def __setattr__(self, key, value):
        if key in type(self)._keys:
            self.scene._c._set(self._type, self.id, **{key: value})
        else:
            super().__setattr__(key, value)

    def set(self, **fields):
        """Sets several fields at once (one change of the object)."""
        self.scene._c._set(self._type, self.id, **fields)
        return self


class Material(_Fielded):
    """A glTF 2.0 metallic-roughness material: base_color (RGBA linear), metallic, roughness,
    emissive (RGB), emissive_strength, double_sided, alpha_mode (OPAQUE, MASK, BLEND), alpha_cutoff,
    transmission, ior, unlit."""
    OPAQUE, MASK, BLEND = 0, 1, 2
    __slots__ = ()
    _type = _c.TYPE_MATERIAL
    _keys = ("base_color", "metallic", "roughness", "emissive", "emissive_strength", "double_sided", "alpha_mode",
             "alpha_cutoff", "transmission", "ior", "unlit")


class Light(_Fielded):
    """A punctual light (KHR_lights_punctual): type (POINT, SPOT, DIRECTIONAL), color, intensity
    (candela; lux for directional), range, inner_cone, outer_cone. Placed by the node carrying it."""
    __slots__ = ()
    POINT, SPOT, DIRECTIONAL = 0, 1, 2
    _type = _c.TYPE_LIGHT
    _keys = ("type", "color", "intensity", "range", "inner_cone", "outer_cone")


class Camera(_Fielded):
    """A camera (glTF): projection (PERSPECTIVE, ORTHOGRAPHIC), yfov (radians), aspect, znear, zfar,
    xmag, ymag. Placed by the node carrying it."""
    __slots__ = ()
    PERSPECTIVE, ORTHOGRAPHIC = 0, 1
    _type = _c.TYPE_CAMERA
    _keys = ("projection", "yfov", "aspect", "znear", "zfar", "xmag", "ymag")


class _Closing:
    """close() frees the library object now; ``with`` closes at the end of the block."""
    __slots__ = ()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def close(self):
        self._c.close()


class Scene(_Closing):
    """A scene graph (sy_scene): ``Scene()`` is empty, ``switchyard.load(path)`` reads a file.

    Usable as a context manager (``with switchyard.load(p) as s:``) to free it deterministically;
    otherwise it is freed when the last reference goes. Objects of a closed scene raise; close()
    refuses while a Window shows the scene."""

    def __init__(self, _impl=None):
        self._c = _impl if _impl is not None else _c._Scene()

    def commit(self):
        """Seals the changes since the last commit into a change list (render() commits too)."""
        self._c.commit()

    def _objects(self, cls):
        return [cls(self, i) for i in self._c._ids(cls._type)]

    nodes = property(lambda self: self._objects(Node))
    meshes = property(lambda self: self._objects(Mesh))
    materials = property(lambda self: self._objects(Material))
    lights = property(lambda self: self._objects(Light))
    cameras = property(lambda self: self._objects(Camera))

    @property
    def root(self):
        """The loaded file's root node (None for a scene built in Python: every root is drawn)."""
        i = self._c._info()["root"]
        return Node(self, i) if i else None

    @property
    def camera(self):
        """The node whose camera renders (the file's first, or the default one framing the scene)."""
        i = self._c._info()["camera"]
        return Node(self, i) if i else None

    @camera.setter
    def camera(self, node):
        self._c._set_camera(node.id if node is not None else 0)

    def set_time(self, seconds, clip=None):
        """Sets the animation clock (every clip, or the one named or numbered by clip) and commits, as
        ``load(at=, clip=)`` and ``sy render --at/--clip`` do."""
        self._c._set_time(seconds, None if clip is None else str(clip))

    def info(self):
        """Counts of the objects and the root / camera / background ids."""
        return self._c._info()

    def add_node(self, name=None, parent=None, mesh=None, light=None, camera=None, matrix=None, translation=None,
                 rotation=None, scale=None):
        """Creates a node (under parent, else a root)."""
        n = Node(self, self._c._create(_c.TYPE_NODE, name))
        if parent is not None:
            parent.add_child(n)
        for k, v in (("mesh", mesh), ("light", light), ("camera", camera)):
            if v is not None:
                setattr(n, k, v)
        if matrix is not None:
            n.matrix = matrix
        if translation is not None or rotation is not None or scale is not None:
            self._c._node_set(n.id, translation=translation, rotation=rotation, scale=scale)
        return n

    def add_mesh(self, positions, indices=None, normals=None, material=None, name=None, parent=None):
        """A triangle mesh from buffer-protocol arrays and a node instancing it; returns the Node.

        positions: float32 (N, 3), C-contiguous (copied once, into the library's blob);
        indices: uint32 (M, 3) or flat (3M,), each < N (None: every three vertices a triangle);
        normals: float32 (N, 3) or None (flat shading). Wrong dtype, shape or layout, NaN or
        infinite coordinates and indices out of range raise InvalidArgumentError."""
        _, node = self._c._add_mesh(positions, indices, normals, material.id if material else 0, name,
                                    parent.id if parent else 0)
        return Node(self, node)

    def add_material(self, name=None, **fields):
        """Creates a material (glTF defaults) and sets the given fields."""
        m = Material(self, self._c._create(_c.TYPE_MATERIAL, name))
        return m.set(**fields) if fields else m

    def add_light(self, type=Light.DIRECTIONAL, name=None, node=None, **fields):
        """Creates a light of type and a node carrying it (or attaches it to node); returns the Light."""
        li = Light(self, self._c._create(_c.TYPE_LIGHT, name))
        li.set(type=type, **fields)
        (node or self.add_node(name)).light = li
        return li

    def add_camera(self, name=None, node=None, **fields):
        """Creates a camera and a node carrying it (or attaches it to node); returns the camera's Node."""
        c = Camera(self, self._c._create(_c.TYPE_CAMERA, name))
        if fields:
            c.set(**fields)
        node = node or self.add_node(name)
        node.camera = c
        return node

    def render(self, backend=None, width=0, height=0, spp=0, seed=0, params=None, aovs=False, progress=None,
               servers=None, cluster_mode=None, secret_file=None):
        """Renders the scene; returns an (height, width, 4) float32 array (linear, premultiplied).

        backend: a registered name (switchyard.backends(); None: the library's default); width /
        height: 0 takes the default (512 high, the width from the camera's aspect, as sy render);
        spp: samples per pixel of a progressive back-end (default 64), refused by others; params:
        "k=v,k=v" back-end parameters; progress: called as progress(done, total) after each pass
        (tqdm: ``lambda d, t: bar.update(d - bar.n)``); Ctrl-C stops after the pass in progress
        with KeyboardInterrupt. aovs=True returns (image, dict): "depth" always (linear distance
        along the view axis, inf where nothing was hit) and the back-end's feature buffers
        (variance, albedo, normal, ...) where it keeps them.

        servers: render on a cluster of ``sy serve`` servers (docs/CLUSTER.md) exactly as ``sy render
        --cluster`` does: "tcp://host:port,..." or a cluster configuration file; cluster_mode:
        "sort-first" (default), "balanced", "cooperative", ...; secret_file: the shared secret (else
        $SY_CLUSTER_SECRET). backend is what the servers run."""
        servers = _servers(servers)
        rgba, planes, _ = self._c._render(backend, width, height, spp, seed, params, aovs, progress, servers,
                                          cluster_mode, None if secret_file is None else str(secret_file))
        img = Image._of(rgba)
        if not aovs:
            return img
        return img, {k: _array(v) for k, v in planes.items()}


def _servers(servers):
    """servers= as the C half takes it: "url,url,..." or a configuration file's path (or None)."""
    import os
    if servers is None or isinstance(servers, str):
        return servers
    if isinstance(servers, os.PathLike):
        return os.fspath(servers)
    return ",".join(servers)


class Image(numpy.ndarray):
    """An (H, W, 4) float32 linear image: a numpy array that Jupyter shows (``_repr_png_``)."""

    @staticmethod
    def _of(buf):
        return _array(buf).view(Image)

    def _repr_png_(self):
        if self.ndim != 3 or self.shape[2] not in (3, 4):
            return None
        return _png(numpy.asarray(self))


def _png(rgba):
    """8-bit sRGB PNG bytes of a linear float image (for notebooks; sy render's PNG output tone-maps
    with more options)."""
    import struct
    import zlib
    a = numpy.clip(numpy.nan_to_num(rgba, nan=0.0, posinf=1.0), 0.0, 1.0)
    c = a[..., :3]
    srgb = numpy.where(c <= 0.0031308, 12.92 * c, 1.055 * numpy.power(c, 1 / 2.4) - 0.055)
    px = numpy.concatenate([srgb, a[..., 3:4] if a.shape[2] == 4 else numpy.ones_like(c[..., :1])], axis=2)
    px = (px * 255.0 + 0.5).astype(numpy.uint8)
    h, w = px.shape[:2]
    raw = b"".join(b"\x00" + px[y].tobytes() for y in range(h))

    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def load(path, camera=None, strict=False, allow_paths=(), max_scene_mb=0, variant=None, env=None, env_color=None,
         env_intensity=None, env_hidden=False, background=None, no_default_light=False, at=None, clip=None):
    """Reads a scene file into a new Scene: glTF 2.0 (.gltf, .glb), X3D, and what Assimp reads (OBJ,
    FBX, COLLADA, PLY, STL, ...), recognised by content, exactly as ``sy render`` loads it (a file
    without a camera gets one framing it). camera: a camera's name or number; strict: whatever the
    loader would skip or repair is an error; allow_paths: more folders external files may lie in;
    max_scene_mb: the file's memory budget (0: the default); variant: a glTF material variant.

    The world, as sy's flags: env: a lat-long environment map (EXR or .hdr; --env); env_color: a
    uniform environment (R, G, B) (--env-color); env_intensity (--env-intensity); env_hidden: camera
    rays see the background, not the environment (--env-hidden); background: (R, G, B[, A]) linear,
    what camera rays see where nothing is hit (--background); no_default_light (--no-default-light).
    The time, as sy render's --at / --clip: at: seconds on the animation clock (every clip, or the
    one named or numbered by clip); a scene without animations is left as loaded (a note on the log).
    The GIL is released while the file loads."""
    import os
    return Scene(_c.load(os.fspath(path), camera, strict, tuple(os.fspath(p) for p in allow_paths), max_scene_mb,
                         variant, None if env is None else os.fspath(env), env_color, env_intensity, env_hidden,
                         background, no_default_light, at, None if clip is None else str(clip)))


def render(scene, backend=None, width=0, height=0, spp=0, seed=0, params=None, aovs=False, progress=None,
           servers=None, cluster_mode=None, secret_file=None, **load_options):
    """Renders a file (loaded with load_options) or a Scene: ``Scene.render`` in one call."""
    opts = dict(backend=backend, width=width, height=height, spp=spp, seed=seed, params=params, aovs=aovs,
                progress=progress, servers=servers, cluster_mode=cluster_mode, secret_file=secret_file)
    if isinstance(scene, Scene):
        return scene.render(**opts)
    with load(scene, **load_options) as s:
        out = s.render(**opts)
    return out

# ---------------------------------------------------------------- the web view


class Server(_Closing):
    """The web view of a scene, served by a thread of its own (``serve()`` returns it): ``url`` (the
    address to open, with ``?token=`` when one is required), ``port``; ``stop()`` (or ``with``) stops
    serving. While it serves, the server owns the scene: calls on the Scene raise RuntimeError."""

    _live = None  # the servers not stopped yet (a WeakSet): stopped at interpreter exit

    def __init__(self, scene, impl, owns_scene):
        import weakref
        self.scene, self._c, self._owns = scene, impl, owns_scene
        info = impl._info()
        self.url, self.port = info["url"], info["port"]
        if Server._live is None:
            Server._live = weakref.WeakSet()
            atexit.register(lambda: [srv.stop() for srv in list(Server._live)])
        Server._live.add(self)

    @property
    def running(self):
        return self._c is not None and self._c._info()["running"]

    def stop(self):
        """Stops serving (waits for the server's thread); the scene is usable again (a scene the
        server loaded from a path is closed). Raises the error that ended serving, if any."""
        if self._c is None:
            return
        impl, self._c = self._c, None
        try:
            impl.stop()
        finally:
            if self._owns:
                self.scene.close()

    close = stop  # _Closing's with-block ends in stop()

    def __repr__(self):
        return "<Server %s%s>" % (self.url, "" if self._c is not None else " (stopped)")


def serve(scene, port=8080, host="127.0.0.1", backend=None, token=None, width=1920, height=1200, quality=80,
          filter=None, threshold=0.0, budget_ms=0.0, clip=None, bookmarks=None, **load_options):
    """Serves the web view of a Scene or a file (loaded with load_options) as ``sy web`` does
    (docs/WEB.md): an HTTP + WebSocket server whose page shows ``backend``'s view of the scene,
    streamed as JPEG and steered by the page; stills at ``/api/frame.jpg?w=W&h=H``. Returns a
    :class:`Server` at once (``url``, ``port``, ``stop()``, a context manager); it serves on a
    thread of its own, without the GIL.

    host: the address to listen on (default loopback, served to this machine only; any other needs
    the access token, generated unless ``token`` is given, and is in ``url``); port: 0 takes a free
    one; width / height: the largest frame (sy web's -w/-h); quality: the streamed frames' quality
    (sy web's --quality: JPEG's and the video stream's quantizer); filter / threshold: a display
    filter of a back-end with filters; budget_ms: the frame-time budget while the view moves (0:
    33 ms); clip: the clip the page's timeline plays, a name or an index (sy web's --clip; an unknown
    one raises NotFoundError naming the clips; None: every clip together; the page may choose
    another); bookmarks: the file of the saved views every page shares (sy web's --bookmarks, the
    format sy view keeps; read at start, rewritten on each save; None: the server keeps them while
    it runs; docs/WEB.md, "Saved views")."""
    owns = not isinstance(scene, Scene)
    if owns:
        scene = load(scene, **load_options)
    elif load_options:
        raise TypeError("serve: load options given with a Scene: %s" % ", ".join(sorted(load_options)))
    if not hasattr(_c, "_Web"):
        if owns:
            scene.close()
        raise UnsupportedError("serve: this switchyard was built without the web view (SY_WITH_WEB: libwebsockets, "
                               "libturbojpeg, libsodium, cJSON)", 6)
    listen = "[%s]:%d" % (host, port) if ":" in host else "%s:%d" % (host, port)
    try:
        impl = _c._Web(scene._c, backend, listen, token, width, height, quality, filter, threshold, budget_ms,
                       None if clip is None else str(clip), None if bookmarks is None else str(bookmarks))
    except BaseException:
        if owns:
            scene.close()
        raise
    return Server(scene, impl, owns)


# ---------------------------------------------------------------- windows and viewports


class Viewport:
    """A viewport of a Window (sy_viewport): its back-end can be switched while it lives."""
    __slots__ = ("window", "index")

    def __init__(self, window, index):
        self.window, self.index = window, index

    @property
    def backend(self):
        return self.window._c._viewport(self.index)["backend"]

    @backend.setter
    def backend(self, name):
        self.set_backend(name)

    def set_backend(self, name, params=None, servers=None, cluster_mode=None, secret_file=None):
        """Switches the back-end (the previous one's context stays cached in the window's pool);
        servers= etc.: ``name`` rendered on a cluster, as ``Window.add_viewport``."""
        self.window._c._set_backend(self.index, name, params, _servers(servers), cluster_mode,
                                    None if secret_file is None else str(secret_file))

    @property
    def active(self):
        return self.window._c._viewport(self.index)["active"]

    @active.setter
    def active(self, on):
        self.window._c._set_active(self.index, bool(on))

    @property
    def clip_planes(self):
        """The section planes (sy_viewport_set_clip_planes): a list of up to 6 (a, b, c, d) in world
        coordinates; what a*x + b*y + c*z + d >= 0 for every plane keeps is drawn, picked and seen by
        every ray. Setting [] removes them; NaN, infinite values, a zero normal (a, b, c) or a
        seventh plane raise InvalidArgumentError (a ValueError) naming the plane, keeping the planes before."""
        return self.window._c._clip_planes(self.index)

    @clip_planes.setter
    def clip_planes(self, planes):
        self.window._c._set_clip_planes(self.index, [] if planes is None else list(planes))

    @property
    def clip_cap(self):
        """The section caps' colour (linear RGB, each in [0, 1]) filling the cut faces of closed
        meshes, or None (the default: a cut closed mesh shows its inside). A colour outside [0, 1]
        or NaN raises InvalidArgumentError (a ValueError)."""
        return self.window._c._clip_cap(self.index)

    @clip_cap.setter
    def clip_cap(self, rgb):
        self.window._c._set_clip_cap(self.index, None if rgb is None else tuple(rgb))

    def __repr__(self):
        return "<Viewport %d of %r>" % (self.index, self.window)


class Window(_Closing):
    """A window (sy_window) showing one Scene through ordered viewports (back to front), each with
    its own back-end, rectangle, root, camera, eye and composite mode. The window keeps the back-ends'
    contexts between renders: a progressive viewport keeps accumulating while nothing changes, and
    switching a viewport's back-end and back finds the cached context again. close() (or ``with``)
    frees the window, its viewports and contexts now."""
    REPLACE, DEPTH, ALPHA_OVER = 0, 1, 2
    MONO, LEFT, RIGHT = 0, 1, 2

    def __init__(self, scene, width, height):
        self.scene = scene
        self._c = _c._Window(scene._c, width, height)
        self.viewports = []

    def add_viewport(self, backend=None, params=None, x=0, y=0, width=0, height=0, root=None, camera=None,
                     eye=0, eye_separation=0.0, zero_parallax=0.0, composite=0, active=True, servers=None,
                     cluster_mode=None, secret_file=None):
        """Adds a viewport (0 size: the whole window; root / camera None: the scene's own).

        servers / cluster_mode / secret_file: the viewport renders ``backend`` on a cluster of ``sy
        serve`` servers, set up as ``Scene.render(servers=)`` (the viewport's back-end is then the
        cluster class, named cluster-python-N)."""
        i = self._c._add_viewport(backend, params, x, y, width, height, -1 if root is None else root.id,
                                  -1 if camera is None else camera.id, -1, eye, eye_separation, zero_parallax,
                                  composite, active, _servers(servers), cluster_mode,
                                  None if secret_file is None else str(secret_file))
        v = Viewport(self, i)
        self.viewports.append(v)
        return v

    def render(self, spp=0, seed=0, aovs=False, progress=None):
        """Renders every active viewport and composites them; returns (H, W, 4) float32 as Scene.render
        (aovs=True: the depth of the composite, and the feature buffers of a single viewport)."""
        rgba, planes, _ = self._c._render(spp, seed, aovs, progress)
        img = Image._of(rgba)
        return (img, {k: _array(v) for k, v in planes.items()}) if aovs else img


# ---------------------------------------------------------------- files


def read_exr(path):
    """Reads an OpenEXR file: {channel name: (H, W) float32 array} ("R", "G", "B", "A", "Z", ...)."""
    import os
    _, _, planes = _c.read_exr(os.fspath(path))
    return {k: _array(v) for k, v in planes.items()}


def write_exr(path, rgba, depth=None, half=False):
    """Writes an (H, W, 4) float32 image (and an (H, W) depth as Z) as OpenEXR (float, or half)."""
    import os
    _c.write_exr(os.fspath(path), numpy.ascontiguousarray(rgba, dtype=numpy.float32),
                 None if depth is None else numpy.ascontiguousarray(depth, dtype=numpy.float32), half)
