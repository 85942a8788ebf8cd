#!/usr/bin/env python3
"""Evict the files under the given paths from the page cache (posix_fadvise DONTNEED), so that
the next read is a cold read from disk. Needs no privileges."""
import os
import sys

for root in sys.argv[1:]:
    paths = [root] if os.path.isfile(root) else [
        os.path.join(d, f) for d, _, files in os.walk(root) for f in files]
    for path in paths:
        fd = os.open(path, os.O_RDONLY)
        try:
            os.posix_fadvise(fd, 0, 0, os.POSIX_FADV_DONTNEED)
        finally:
            os.close(fd)
