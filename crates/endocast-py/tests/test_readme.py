"""README.md's Python block (issue 31): it runs as written, from a folder where ../shared/data
is the shared scans, and the picture it writes matches the committed docs/examples one within
the tolerance of crates/endocast-cli/tests/readme.rs (which runs README's sh blocks)."""

import re

import numpy as np

from conftest import REPO
from reference import read_png_rgb

# The same limits as readme.rs's `Tolerance`: a pixel differs when a channel differs by more
# than 24 (of 255); at most 1 % of the pixels may differ and the mean difference is at most 2.
CHANNEL, SHARE_DIFFERING, MEAN = 24, 0.01, 2.0


def readme_python():
    """The one ```python block of README.md."""
    blocks = re.findall(r"^```python\n(.*?)^```$", (REPO / "README.md").read_text(), re.S | re.M)
    assert len(blocks) == 1, f"README.md has {len(blocks)} python blocks"
    return blocks[0]


def test_readme_python_block_runs_and_makes_its_picture(shared_data, tmp_path, monkeypatch):
    (tmp_path / "shared").symlink_to(shared_data.resolve().parent)
    work = tmp_path / "work"
    (work / "docs" / "examples").mkdir(parents=True)
    monkeypatch.chdir(work)
    exec(compile(readme_python(), "README.md (python block)", "exec"), {})
    name = "docs/examples/python-trachea.png"
    made, committed = read_png_rgb(work / name), read_png_rgb(REPO / name)
    assert made.shape == committed.shape, f"{name}: {made.shape}, committed {committed.shape}"
    diff = np.abs(made.astype(np.int16) - committed.astype(np.int16))
    share = float((diff.max(axis=2) > CHANNEL).mean())
    mean = float(diff.mean())
    assert share <= SHARE_DIFFERING and mean <= MEAN, (
        f"{name} no longer matches README's python block: {share:.3%} of the pixels differ by "
        f"more than {CHANNEL} (at most {SHARE_DIFFERING:.0%}), mean difference {mean:.3f} "
        f"(at most {MEAN}); bench/readme_pictures.sh makes it again"
    )
