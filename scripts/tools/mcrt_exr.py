"""Minimal OpenEXR input and output for the scripts: single-part scanline files of 32-bit float
channels, uncompressed or ZIP(S) compressed, as mcrt writes them. Only zlib and numpy: Debian 12
has no Python OpenEXR binding.

    read_exr(path)                → {channel name: (height, width) float32 array}
    read_exr_header(path)         → {attribute name: raw bytes}
    read_exr_float_attribute(path, name) → float, or None when absent (e.g. "spp")
    write_exr(path, channels, compression="zip", float_attributes=None)

Layout: OpenEXR "File Layout" document; the ZIP predictor and byte split: ImfZip.cpp.
"""

import struct
import zlib
from pathlib import Path

import numpy as np

NO_COMPRESSION, ZIPS_COMPRESSION, ZIP_COMPRESSION = 0, 2, 3
FLOAT_PIXELS = 2
MAGIC = b"\x76\x2f\x31\x01"


def _parse_header(data, path):
    if data[:4] != MAGIC:
        raise ValueError("%s: not an OpenEXR file" % path)
    if data[5] & 0x1e:  # version flags: tiled, long names, deep, multipart
        raise ValueError("%s: only single-part scanline EXRs are supported" % path)
    pos, attributes = 8, {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        end2 = data.index(b"\0", end + 1)
        size, = struct.unpack_from("<i", data, end2 + 1)
        attributes[name] = data[end2 + 5:end2 + 5 + size]
        pos = end2 + 5 + size
    return attributes, pos + 1


def read_exr_header(path):
    """The header attributes of an EXR as a dict name → raw value bytes."""
    data = Path(path).read_bytes()
    return _parse_header(data, path)[0]


def read_exr_float_attribute(path, name):
    """A float header attribute (e.g. mcrt's `spp`), or None when the file has none."""
    raw = read_exr_header(path).get(name)
    if raw is None or len(raw) != 4:
        return None
    return struct.unpack("<f", raw)[0]


def read_exr(path):
    """Channels of a single-part scanline EXR of FLOAT channels, uncompressed or ZIP(S), as a
    dict name → (height, width) float32 array (OpenEXR "File Layout" and ImfZip.cpp)."""
    data = Path(path).read_bytes()
    attributes, pos = _parse_header(data, path)
    channels, raw, p = [], attributes["channels"], 0
    while raw[p] != 0:
        end = raw.index(b"\0", p)
        name = raw[p:end].decode()
        pixel_type, = struct.unpack_from("<i", raw, end + 1)
        if pixel_type != FLOAT_PIXELS:
            raise ValueError("%s: channel %s is not 32-bit float" % (path, name))
        channels.append(name)  # stored in this (alphabetical) order
        p = end + 17
    compression = attributes["compression"][0]
    lines_per_chunk = {NO_COMPRESSION: 1, ZIPS_COMPRESSION: 1, ZIP_COMPRESSION: 16}.get(compression)
    if lines_per_chunk is None:
        raise ValueError("%s: compression %d is not supported" % (path, compression))
    xmin, ymin, xmax, ymax = struct.unpack("<4i", attributes["dataWindow"])
    width, height = xmax - xmin + 1, ymax - ymin + 1
    chunks = (height + lines_per_chunk - 1) // lines_per_chunk
    offsets = struct.unpack_from("<%dQ" % chunks, data, pos)
    image = np.zeros((height, len(channels), width), np.float32)
    for offset in offsets:
        y, size = struct.unpack_from("<ii", data, offset)
        block = data[offset + 8:offset + 8 + size]
        lines = min(lines_per_chunk, ymax - y + 1)
        raw_size = lines * len(channels) * width * 4
        if size < raw_size:
            # ZIP: zlib, then undo the predictor (running sum of byte deltas − 128) and the
            # split of even and odd bytes into two halves.
            t = np.frombuffer(zlib.decompress(block), np.uint8)
            t = (np.cumsum(t.astype(np.int64) - 128) + 128).astype(np.uint8)
            half = (len(t) + 1) // 2
            block = np.empty_like(t)
            block[0::2], block[1::2] = t[:half], t[half:]
            block = block.tobytes()
        values = np.frombuffer(block, "<f4").reshape(lines, len(channels), width)
        image[y - ymin:y - ymin + lines] = values
    return {name: image[:, i, :] for i, name in enumerate(channels)}


def _attribute(name, type_name, value):
    return name.encode() + b"\0" + type_name.encode() + b"\0" + struct.pack("<i", len(value)) + value


def _zip_block(raw):
    """ImfZip.cpp: split even and odd bytes into two halves, byte deltas + 128, then zlib."""
    b = np.frombuffer(raw, np.uint8)
    t = np.concatenate([b[0::2], b[1::2]]).astype(np.int16)
    d = t.copy()
    d[1:] = (t[1:] - t[:-1] + 128 + 256) & 0xff
    return zlib.compress(d.astype(np.uint8).tobytes(), 6)


def write_exr(path, channels, compression="zip", float_attributes=None):
    """Writes `channels` (name → (height, width) array, converted to float32) as a single-part
    scanline EXR, `compression` "zip" (16 lines per chunk) or "none". `float_attributes` adds
    float header attributes (name → value), e.g. {"spp": 64}. Written under a temporary name,
    then renamed."""
    names = sorted(channels)  # the channel list must be in alphabetical order
    if not names:
        raise ValueError("write_exr: no channels")
    arrays = [np.ascontiguousarray(channels[n], dtype="<f4") for n in names]
    height, width = arrays[0].shape
    if any(a.shape != (height, width) for a in arrays):
        raise ValueError("write_exr: channels differ in size")
    code, lines_per_chunk = {"zip": (ZIP_COMPRESSION, 16), "none": (NO_COMPRESSION, 1)}[compression]

    chlist = b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", FLOAT_PIXELS, 0, 1, 1)
                      for n in names) + b"\0"
    box = struct.pack("<4i", 0, 0, width - 1, height - 1)
    header = [_attribute("channels", "chlist", chlist),
              _attribute("compression", "compression", bytes([code])),
              _attribute("dataWindow", "box2i", box),
              _attribute("displayWindow", "box2i", box),
              _attribute("lineOrder", "lineOrder", b"\0"),
              _attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
              _attribute("screenWindowCenter", "v2f", struct.pack("<2f", 0.0, 0.0)),
              _attribute("screenWindowWidth", "float", struct.pack("<f", 1.0))]
    for name, value in sorted((float_attributes or {}).items()):
        header.append(_attribute(name, "float", struct.pack("<f", float(value))))
    head = MAGIC + struct.pack("<I", 2) + b"".join(header) + b"\0"

    stacked = np.stack(arrays, axis=1)  # (height, channels, width): scanline layout
    chunks = []
    for y in range(0, height, lines_per_chunk):
        raw = stacked[y:y + lines_per_chunk].tobytes()
        block = raw
        if code == ZIP_COMPRESSION:
            packed = _zip_block(raw)
            if len(packed) < len(raw):  # otherwise stored raw, as OpenEXR does
                block = packed
        chunks.append(struct.pack("<ii", y, len(block)) + block)
    offset = len(head) + 8 * len(chunks)
    table = []
    for chunk in chunks:
        table.append(offset)
        offset += len(chunk)
    out = Path(path)
    temporary = out.with_name(out.name + ".tmp")
    temporary.write_bytes(head + struct.pack("<%dQ" % len(table), *table) + b"".join(chunks))
    temporary.replace(out)
