"""A small OpenEXR reader in the Python standard library alone, for the benchmark scripts.

It reads what lookdev writes: single-part scan-line images, uncompressed or ZIP-compressed
(one or sixteen lines a block), with HALF, FLOAT or UINT channels. Anything else is refused by
name. Images are returned as a dict of channel name -> flat list of floats, row 0 at the top.
"""

import array
import struct
import zlib

_COMPRESSIONS = {0: ("none", 1), 2: ("ZIPS", 1), 3: ("ZIP", 16)}
_SAMPLE_BYTES = {0: 4, 1: 2, 2: 4}  # UINT, HALF, FLOAT


class ExrError(Exception):
    """A file this reader cannot read, with the reason."""


def _header(data, path):
    if len(data) < 8 or struct.unpack_from("<I", data, 0)[0] != 20000630:
        raise ExrError(f"{path}: not an OpenEXR file")
    version = struct.unpack_from("<I", data, 4)[0]
    if version & 0x200 or version & 0x1000:
        raise ExrError(f"{path}: tiled or multi-part EXR files are not supported here")
    at = 8
    attributes = {}
    while True:
        end = data.index(b"\0", at)
        name = data[at:end].decode("latin-1")
        at = end + 1
        if not name:
            break
        end = data.index(b"\0", at)
        kind = data[at:end].decode("latin-1")
        at = end + 1
        (size,) = struct.unpack_from("<i", data, at)
        at += 4
        attributes[name] = (kind, data[at : at + size])
        at += size
    return attributes, at


def _channels(value):
    channels = []
    at = 0
    while value[at] != 0:
        end = value.index(b"\0", at)
        name = value[at:end].decode("utf-8")
        pixel_type, _linear, x_sampling, y_sampling = struct.unpack_from("<iB3xii", value, end + 1)
        channels.append((name, pixel_type, x_sampling, y_sampling))
        at = end + 1 + 16
    return channels


def _unzip(raw, expected):
    """ZIP blocks: zlib, then a byte predictor, then the two interleaved halves."""
    packed = zlib.decompress(raw)
    if len(packed) != expected:
        raise ExrError(f"a ZIP block holds {len(packed)} bytes, expected {expected}")
    deltas = bytearray(packed)
    previous = deltas[0] if deltas else 0
    for i in range(1, len(deltas)):
        previous = (previous + deltas[i] - 128) & 0xFF
        deltas[i] = previous
    half = (len(deltas) + 1) // 2
    out = bytearray(len(deltas))
    out[0::2] = deltas[:half]
    out[1::2] = deltas[half:]
    return bytes(out)


def read(path):
    """Reads an EXR file: (width, height, {channel name: [float, ...]})."""
    with open(path, "rb") as f:
        data = f.read()
    attributes, at = _header(data, path)
    try:
        channels = _channels(attributes["channels"][1])
        compression = attributes["compression"][1][0]
        x0, y0, x1, y1 = struct.unpack("<4i", attributes["dataWindow"][1])
    except KeyError as missing:
        raise ExrError(f"{path}: the header has no {missing} attribute") from None
    if compression not in _COMPRESSIONS:
        raise ExrError(f"{path}: compression {compression} is not supported here (only none and ZIP)")
    if any(c[2] != 1 or c[3] != 1 for c in channels) or any(c[1] not in _SAMPLE_BYTES for c in channels):
        raise ExrError(f"{path}: subsampled or unknown channel types are not supported here")
    width, height = x1 - x0 + 1, y1 - y0 + 1
    lines_per_block = _COMPRESSIONS[compression][1]
    blocks = (height + lines_per_block - 1) // lines_per_block
    offsets = struct.unpack_from(f"<{blocks}Q", data, at)
    line_bytes = sum(_SAMPLE_BYTES[c[1]] for c in channels) * width
    planes = {c[0]: [] for c in channels}
    for offset in offsets:
        y, size = struct.unpack_from("<ii", data, offset)
        lines = min(lines_per_block, y1 + 1 - y)
        raw = data[offset + 8 : offset + 8 + size]
        expected = lines * line_bytes
        block = raw if size == expected else _unzip(raw, expected)
        at = 0
        for _ in range(lines):
            for name, pixel_type, _, _ in channels:
                count = width * _SAMPLE_BYTES[pixel_type]
                chunk = block[at : at + count]
                at += count
                if pixel_type == 1:
                    planes[name].extend(struct.unpack(f"<{width}e", chunk))
                else:
                    values = array.array("f" if pixel_type == 2 else "I", chunk)
                    planes[name].extend(values)
    return width, height, planes
