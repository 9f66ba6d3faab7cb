"""Reads an 8-bit RGB or RGBA PNG (what Chromium's screenshots are) with zlib alone:
no PIL on the machines this runs on."""
import struct
import zlib


class PngError(ValueError):
    pass


class Image:
    def __init__(self, width, height, rows, bpp):
        self.width, self.height, self.rows, self.bpp = width, height, rows, bpp

    def pixel(self, x, y):
        i = x * self.bpp
        return self.rows[y][i:i + 3]


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    return a if pa <= pb and pa <= pc else b if pb <= pc else c


def png_size(data):
    """(width, height) from the IHDR chunk, without decoding the pixels."""
    if data[:8] != b"\x89PNG\r\n\x1a\n" or data[12:16] != b"IHDR":
        raise PngError("not a PNG")
    return struct.unpack(">II", data[16:24])


def read_png(data):
    """Image of PNG bytes (8-bit, colour type 2 or 6, not interlaced); PngError otherwise."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise PngError("not a PNG")
    pos, idat, hdr = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            hdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
    if hdr is None:
        raise PngError("no IHDR chunk")
    w, h, depth, ctype, _, _, interlace = hdr
    if depth != 8 or ctype not in (2, 6) or interlace:
        raise PngError(f"unsupported PNG (bit depth {depth}, colour type {ctype}, interlace {interlace})")
    bpp = 3 if ctype == 2 else 4
    raw, stride = zlib.decompress(idat), w * bpp
    rows, prev, i = [], bytearray(stride), 0
    for _ in range(h):
        ftype, line = raw[i], bytearray(raw[i + 1:i + 1 + stride])
        i += 1 + stride
        if ftype == 1:
            for x in range(bpp, stride):
                line[x] = (line[x] + line[x - bpp]) & 255
        elif ftype == 2:
            for x in range(stride):
                line[x] = (line[x] + prev[x]) & 255
        elif ftype == 3:
            for x in range(stride):
                line[x] = (line[x] + ((line[x - bpp] if x >= bpp else 0) + prev[x]) // 2) & 255
        elif ftype == 4:
            for x in range(stride):
                line[x] = (line[x] + _paeth(line[x - bpp] if x >= bpp else 0, prev[x],
                                            prev[x - bpp] if x >= bpp else 0)) & 255
        rows.append(bytes(line))
        prev = line
    return Image(w, h, rows, bpp)
