"""Checks that a figure can be read: no text on another text, every axis label with its unit.

:func:`figure_problems` draws a figure once and reads the bounding box of every text the
renderer actually drew (titles, axis labels, tick labels, annotations, offset texts, colour
bar labels; each legend counted as one box) to find:

* **overlaps**: two boxes that share more than ``tolerance`` pixels in both directions;
* **cut-off text**: a box that reaches outside the figure;
* **axis labels without units**, by :data:`UNIT_RULE`.

The package's figures, its documentation figures and the notebooks' figures are held to it
by the test suite.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

__all__ = ["UNIT_RULE", "figure_problems", "label_has_unit"]

#: When an axis label is complete (checked by :func:`label_has_unit`).
UNIT_RULE = (
    "every axis that shows tick labels (x, y, z and colour bars) has a label, and the label "
    "carries its unit in square brackets ('wavelength [nm]', 'magnitude [AB mag]', "
    "'time [UTC]', '[1]' for a dimensionless quantity), or is unitless by design: a ratio of "
    "like quantities written 'a / b', or a count 'number of ...'; an axis whose ticks are "
    "names (categories, not numbers) needs no label"
)

_UNIT = re.compile(r"\[[^\[\]]+\]")
_RATIO = re.compile(r"\S\s+/\s+\S")


def label_has_unit(text: str) -> bool:
    """True if an axis label satisfies :data:`UNIT_RULE`.

    Examples
    --------
    >>> [label_has_unit(t) for t in ("wavelength [nm]", "time [UTC]", "wavelength",
    ...                              "wall time / reference wall time", "number of attitudes")]
    [True, True, False, True, True]
    """
    t = text.strip()
    return bool(_UNIT.search(t) or _RATIO.search(t) or t.lower().startswith("number of "))


@contextmanager
def _drawn_texts() -> Iterator[dict[int, tuple[Any, Any, Any]]]:
    """Collect ``id -> (text, window extent, renderer)`` of every text drawn meanwhile."""
    from matplotlib.text import Text

    drawn: dict[int, tuple[Any, Any, Any]] = {}
    original = Text.draw

    def draw(self: Any, renderer: Any) -> None:
        original(self, renderer)
        if self.get_visible() and self.get_text().strip():
            drawn[id(self)] = (self, self.get_window_extent(renderer), renderer)

    Text.draw = draw  # type: ignore[method-assign]
    try:
        yield drawn
    finally:
        Text.draw = original  # type: ignore[method-assign]


def _name_of(text: Any, fig: Any) -> str:
    """What a text is, for messages: ``'x label of axes 0'`` and its content."""
    where = ""
    for k, ax in enumerate(fig.axes):
        axes = {"x": ax.xaxis, "y": ax.yaxis, **({"z": ax.zaxis} if hasattr(ax, "zaxis") else {})}
        for name, axis in axes.items():
            if text is axis.label:
                where = f"{name} label of axes {k}"
            elif text is axis.get_offset_text():
                where = f"{name} offset text of axes {k}"
            elif any(text is t.label1 or text is t.label2 for t in _ticks(axis)):
                where = f"{name} tick label of axes {k}"
        for attr in ("title", "_left_title", "_right_title"):
            if text is getattr(ax, attr, None):
                where = f"title of axes {k}"
        if where:
            break
    if not where and text is getattr(fig, "_suptitle", None):
        where = "figure title"
    return f"{where or type(text).__name__.lower()} {text.get_text()!r}"


def _named(axis: Any) -> bool:
    """True for an axis whose ticks are names (categories) rather than numbers or dates."""
    from matplotlib import dates

    formatter = axis.get_major_formatter()
    if isinstance(formatter, (dates.DateFormatter, dates.AutoDateFormatter)):
        return False
    texts = [re.sub(r"\\[A-Za-z]+", "", t.get_text()) for t in axis.get_majorticklabels()]
    texts = [t for t in texts if t.strip()]
    return bool(texts) and all(any(c.isalpha() for c in t) for t in texts)


def _ticks(axis: Any) -> list[Any]:
    return [*axis.get_major_ticks(), *axis.get_minor_ticks()]


def _legends(fig: Any) -> list[Any]:
    found = [ax.get_legend() for ax in fig.axes]
    return [lg for lg in [*found, *fig.legends] if lg is not None and lg.get_visible()]


def _overlap(a: Any, b: Any, tolerance: float) -> bool:
    w = min(a.x1, b.x1) - max(a.x0, b.x0)
    h = min(a.y1, b.y1) - max(a.y0, b.y0)
    return w > tolerance and h > tolerance


def figure_problems(fig: Any, *, tolerance: float = 1.0, inside: bool = True) -> list[str]:
    """What makes a figure hard to read: overlapping or cut-off text, labels without units.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        Drawn once here (with its layout engine), as it would be saved.
    tolerance : float
        Pixels two boxes may share (in both directions) without counting as an overlap
        (at the figure's dpi; 1 px: touching is not overlapping).
    inside : bool
        Also report text reaching outside the figure (cut off when saved without
        ``bbox_inches="tight"``).

    Returns
    -------
    list of str
        One sentence per problem (empty for a readable figure): the two texts that
        overlap, the text that is cut off, the axis whose label breaks :data:`UNIT_RULE`.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> fig, ax = plt.subplots(figsize=(4, 3), layout="constrained")
    >>> _ = ax.plot([400, 700], [0.2, 0.3])
    >>> _ = ax.set(xlabel="wavelength [nm]", ylabel="albedo [1]")
    >>> figure_problems(fig)
    []
    >>> _ = ax.set_ylabel("albedo")
    >>> _ = ax.annotate("a note", (550, 0.25))
    >>> _ = ax.annotate("over it", (550, 0.25))
    >>> for problem in figure_problems(fig):
    ...     print(problem)
    annotation 'a note' overlaps annotation 'over it'
    y axis of axes 0: label 'albedo' has no unit in brackets
    >>> plt.close(fig)
    """
    with _drawn_texts() as drawn:
        fig.draw_without_rendering()
    renderer = next((r for _, _, r in drawn.values()), None)
    boxes: list[tuple[str, Any]] = []
    in_legend: set[int] = set()
    for lg in _legends(fig):
        members = [*lg.get_texts(), lg.get_title()]
        in_legend.update(id(t) for t in members)
        if renderer is not None and any(id(t) in drawn for t in members):
            title = lg.get_title().get_text() or ", ".join(t.get_text() for t in lg.get_texts()[:2])
            boxes.append((f"legend {title!r}", lg.get_window_extent(renderer)))
    for key, (text, box, _) in drawn.items():
        if key not in in_legend:
            boxes.append((_name_of(text, fig), box))
    problems = []
    for i, (name_a, a) in enumerate(boxes):
        for name_b, b in boxes[i + 1 :]:
            if _overlap(a, b, tolerance):
                problems.append(f"{name_a} overlaps {name_b}")
    if inside:
        frame = fig.bbox
        for name, box in boxes:
            if (
                box.x0 < frame.x0 - tolerance
                or box.y0 < frame.y0 - tolerance
                or box.x1 > frame.x1 + tolerance
                or box.y1 > frame.y1 + tolerance
            ):
                problems.append(f"{name} reaches outside the figure")
    for k, ax in enumerate(fig.axes):
        axes = {"x": ax.xaxis, "y": ax.yaxis, **({"z": ax.zaxis} if hasattr(ax, "zaxis") else {})}
        for name, axis in axes.items():
            shown = any(id(t.label1) in drawn or id(t.label2) in drawn for t in _ticks(axis))
            text = axis.label.get_text() if id(axis.label) in drawn else ""
            if shown and not _named(axis) and not label_has_unit(text):
                what = f"label {text!r} has no unit in brackets" if text else "no label"
                problems.append(f"{name} axis of axes {k}: {what}")
    return problems
