"""Progress bars of the cube writer: tqdm if installed, else a one-line stderr counter."""

from __future__ import annotations

import sys
import time
from typing import Any

__all__ = ["NoProgress", "TextProgress", "progress_bar"]


class TextProgress:
    """A one-line stderr counter, used when tqdm is not installed."""

    def __init__(self, total: int, initial: int, desc: str) -> None:
        self.n, self.total, self.desc = initial, total, desc
        self.last = 0.0
        self._show(force=True)

    def _show(self, force: bool = False) -> None:
        now = time.monotonic()
        if force or now - self.last >= 0.5:
            self.last = now
            sys.stderr.write(f"\r{self.desc}: {self.n}/{self.total} blocks")
            sys.stderr.flush()

    def update(self, n: int = 1) -> None:
        self.n += n
        self._show(force=self.n == self.total)

    def close(self) -> None:
        self._show(force=True)
        sys.stderr.write("\n")
        sys.stderr.flush()


class NoProgress:
    def update(self, n: int = 1) -> None:
        pass

    def close(self) -> None:
        pass


def progress_bar(enabled: bool, total: int, initial: int, desc: str) -> Any:
    if not enabled:
        return NoProgress()
    try:
        from tqdm import tqdm
    except ImportError:
        return TextProgress(total, initial, desc)
    return tqdm(total=total, initial=initial, desc=desc, unit="block", file=sys.stderr)
