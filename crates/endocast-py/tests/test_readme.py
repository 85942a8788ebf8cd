"""README.md's Python block (issue 31): it runs as written, from a folder where ../shared/data
is the shared scans, and the picture it writes matches the committed docs/examples one within
the tolerance of crates/endocast-cli/tests/readme.rs (which runs README's sh blocks)."""

import re
import struct
import zlib

import numpy as np

from conftest import REPO

# The same limits as readme.rs's `Tolerance`: a pixel differs when a channel differs by more
# than 24 (of 255); at most 1 % of the pixels may differ and the mean difference is at most 2.
CHANNEL, SHARE_DIFFERING, MEAN = 24, 0.01, 2.0


def readme_python():
    """The one ```python block of README.md."""
    blocks = re.findall(r"^```python\n(.*?)^```$", (REPO / "README.md").read_text(), re.S | re.M)
    assert len(blocks) == 1, f"README.md has {len(blocks)} python blocks"
    return blocks[0]


def unfilter(kind, line, prev, bpp):
    """One PNG scanline (int32 arrays) undone from its filter `kind`."""
    if kind == 0:
        return line
    if kind == 2:
        return (line + prev) & 255
    out = line.copy()
    for i in range(len(out)):
        a = int(out[i - bpp]) if i >= bpp else 0
        b = int(prev[i])
        c = int(prev[i - bpp]) if i >= bpp else 0
        if kind == 1:
            out[i] = (out[i] + a) & 255
        elif kind == 3:
            out[i] = (out[i] + (a + b) // 2) & 255
        else:
            p = a + b - c
            pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            out[i] = (out[i] + pred) & 255
    return out


def read_rgb(path):
    """An 8-bit RGB or RGBA PNG (not interlaced) as an (H, W, 3) uint8 array."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    pos, idat = 8, b""
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert depth == 8 and colour in (2, 6) and interlace == 0, f"{path}: not 8-bit RGB(A)"
        elif kind == b"IDAT":
            idat += body
    bpp = 3 if colour == 2 else 4
    stride = width * bpp
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(height, stride + 1)
    rows, prev = [], np.zeros(stride, np.int32)
    for row in raw:
        prev = unfilter(row[0], row[1:].astype(np.int32), prev, bpp)
        rows.append(prev)
    return np.array(rows, np.uint8).reshape(height, width, bpp)[..., :3]


def test_readme_python_block_runs_and_makes_its_picture(shared_data, tmp_path, monkeypatch):
    (tmp_path / "shared").symlink_to(shared_data.resolve().parent)
    work = tmp_path / "work"
    (work / "docs" / "examples").mkdir(parents=True)
    monkeypatch.chdir(work)
    exec(compile(readme_python(), "README.md (python block)", "exec"), {})
    name = "docs/examples/python-trachea.png"
    made, committed = read_rgb(work / name), read_rgb(REPO / name)
    assert made.shape == committed.shape, f"{name}: {made.shape}, committed {committed.shape}"
    diff = np.abs(made.astype(np.int16) - committed.astype(np.int16))
    share = float((diff.max(axis=2) > CHANNEL).mean())
    mean = float(diff.mean())
    assert share <= SHARE_DIFFERING and mean <= MEAN, (
        f"{name} no longer matches README's python block: {share:.3%} of the pixels differ by "
        f"more than {CHANNEL} (at most {SHARE_DIFFERING:.0%}), mean difference {mean:.3f} "
        f"(at most {MEAN}); bench/readme_pictures.sh makes it again"
    )
