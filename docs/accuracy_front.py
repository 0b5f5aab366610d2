"""Figure: what accuracy costs in time, from a saved run of ``sbrdf-xr bench``.

``sbrdf-xr bench --csv docs/data/accuracy_front.csv --plot docs/img/accuracy_front.png``
runs the benchmark and draws the figure; ``python docs/accuracy_front.py [TABLE.csv]``
redraws it from the saved table (default ``docs/data/accuracy_front.csv``) without running
the benchmark again.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import pandas as pd
import xarray as xr

from sbrdf_xr import plot

HERE = Path(__file__).parent
OUT = HERE / "img"
TABLE = HERE / "data" / "accuracy_front.csv"
DPI = 80


def read_table(path: Path = TABLE) -> xr.Dataset:
    """A ``sbrdf-xr bench --csv`` table as the Dataset of ``bench.rows_to_dataset``."""
    frame = pd.read_csv(path)  # a case may repeat, once per sweep
    data = {c: ("case", frame[c].to_numpy()) for c in frame.columns if c != "case"}
    return xr.Dataset(data, coords={"case": ("case", frame["case"].to_numpy())})


def figures(path: Path = TABLE) -> dict[str, Any]:
    """The figure by file name."""
    return {"accuracy_front.png": plot.accuracy_front(read_table(path))}


def main(argv: list[str] | None = None) -> None:
    args = sys.argv[1:] if argv is None else argv
    OUT.mkdir(parents=True, exist_ok=True)
    for name, fig in figures(Path(args[0]) if args else TABLE).items():
        fig.savefig(OUT / name, dpi=DPI)
        plt.close(fig)
        print(f"wrote {OUT / name}")


if __name__ == "__main__":
    main()
