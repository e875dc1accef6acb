"""png_write.py — one PNG encoder for the test scripts that need no third-party package
(tests/x3d/texanim_render_test.py, tests/x3d/texmap_render_test.py): 8-bit RGB, unfiltered rows."""
import struct
import zlib


def write_png(path, w, h, rgb):
    """Writes the w x h image rgb (bytes or a list of 8-bit samples, R G B per pixel, rows top down)."""
    raw = b"".join(b"\0" + bytes(rgb[y * w * 3:(y + 1) * w * 3]) for y in range(h))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
