"""Independent readers for the tests: the NRRD and MetaImage files of ../shared/data, and PNG.

Deliberately small and separate from endocast's readers, so a test compares two readings of
the same bytes; they read only what the shared files use.
"""

import gzip
import struct
import zlib
from pathlib import Path

import numpy as np

NRRD_TYPES = {"short": "i2", "int16": "i2", "unsigned char": "u1", "uchar": "u1", "uint8": "u1"}
META_TYPES = {"MET_UCHAR": "u1", "MET_SHORT": "i2", "MET_USHORT": "u2"}


def _vectors(text):
    """NRRD's "(a,b,c) (d,e,f) ..." as a list of 3-vectors."""
    return [[float(x) for x in part.strip("()").split(",")] for part in text.split()]


def read_nrrd(path):
    """(array indexed [i, j, k], 4x4 LPS affine) of an attached or detached NRRD file."""
    path = Path(path)
    raw = path.read_bytes()
    header, _, data = raw.partition(b"\n\n")
    fields = {}
    for line in header.decode("latin-1").splitlines()[1:]:
        if line.startswith("#") or ": " not in line:
            continue
        key, value = line.split(": ", 1)
        fields[key.strip()] = value.strip()
    sizes = [int(s) for s in fields["sizes"].split()]
    if "data file" in fields:
        pattern, first, last, step = fields["data file"].split()
        numbers = range(int(first), int(last) + 1, int(step))
        data = b"".join((path.parent / (pattern % n)).read_bytes() for n in numbers)
    if fields.get("encoding") == "gzip":
        data = gzip.decompress(data)
    endian = ">" if fields.get("endian") == "big" else "<"
    dtype = np.dtype(endian + NRRD_TYPES[fields["type"]])
    count = int(np.prod(sizes))
    array = np.frombuffer(data, dtype=dtype, count=count).reshape(sizes, order="F")
    affine = np.eye(4)
    if "space directions" in fields:
        affine[:3, :3] = np.array(_vectors(fields["space directions"])).T
    else:
        affine[:3, :3] = np.diag([float(s) for s in fields["spacings"].split()])
    if "space origin" in fields:
        affine[:3, 3] = _vectors(fields["space origin"])[0]
    return array, affine


def read_metaimage(path):
    """(array indexed [i, j, k], spacing) of a MetaImage .mha with its data LOCAL."""
    raw = Path(path).read_bytes()
    end = raw.index(b"ElementDataFile = LOCAL") + len(b"ElementDataFile = LOCAL")
    end = raw.index(b"\n", end) + 1
    fields = {}
    for line in raw[:end].decode("latin-1").splitlines():
        key, value = line.split("=", 1)
        fields[key.strip()] = value.strip()
    data = raw[end:]
    if fields.get("CompressedData") == "True":
        data = zlib.decompress(data)
    sizes = [int(s) for s in fields["DimSize"].split()]
    endian = ">" if fields.get("BinaryDataByteOrderMSB") == "True" else "<"
    dtype = np.dtype(endian + META_TYPES[fields["ElementType"]])
    count = int(np.prod(sizes))
    array = np.frombuffer(data, dtype=dtype, count=count).reshape(sizes, order="F")
    spacing = [float(s) for s in fields["ElementSpacing"].split()]
    return array, spacing


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    return b if pb <= pc else c


def read_png_rgb(path):
    """The colour of an 8-bit RGB or RGBA PNG (not interlaced; as `endocast render` and
    `save_png` write) as (height, width, 3)."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    pos, idat = 8, b""
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos : pos + 8])
        chunk = data[pos + 8 : pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            width, height, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", chunk)
            assert depth == 8 and color in (2, 6) and interlace == 0, "only 8-bit RGB(A)"
        elif kind == b"IDAT":
            idat += chunk
    raw = zlib.decompress(idat)
    bpp = 3 if color == 2 else 4
    stride = bpp * width
    rows, prev = [], bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        kind, line = raw[start], bytearray(raw[start + 1 : start + 1 + stride])
        for x in range(stride):
            left = line[x - bpp] if x >= bpp else 0
            up, corner = prev[x], (prev[x - bpp] if x >= bpp else 0)
            add = (0, left, up, (left + up) // 2, _paeth(left, up, corner))[kind]
            line[x] = (line[x] + add) & 0xFF
        rows.append(bytes(line))
        prev = line
    return np.frombuffer(b"".join(rows), np.uint8).reshape(height, width, bpp)[..., :3]
