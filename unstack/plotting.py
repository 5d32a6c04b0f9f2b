"""Matplotlib figures without pyplot: no backend switch, no global figure registry.

A host process (a robot's planner with its own GUI, say) keeps its matplotlib backend:
figures here are :class:`matplotlib.figure.Figure` objects drawn by their own Agg canvas,
and PNG files are written atomically.

Examples
--------
>>> import pathlib, tempfile
>>> plt = pyplot()
>>> figure, axes = plt.subplots()
>>> target = pathlib.Path(tempfile.mkdtemp()) / "empty.png"
>>> save_figure(figure, target)
>>> target.read_bytes()[:4]
b'\\x89PNG'
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

__all__ = ["CURVE_STYLES", "Plotting", "curve_labels", "figure", "pyplot", "save_figure", "subplots"]

#: (marker, line style) per curve: curves stay told apart where they cross or coincide.
CURVE_STYLES = (("o", "-"), ("s", "--"), ("^", "-."), ("D", ":"), ("v", "-"), ("P", "--"), ("X", "-."))


def figure(**options: Any) -> Any:
    """A :class:`matplotlib.figure.Figure` with its own Agg canvas (``options`` as for ``Figure``).

    Parameters
    ----------
    **options
        ``figsize``, ``dpi``, ... of :class:`matplotlib.figure.Figure`.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> figure(figsize=(2, 1)).get_size_inches().tolist()
    [2.0, 1.0]
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    drawn = Figure(**options)
    FigureCanvasAgg(drawn)
    return drawn


def subplots(*grid: Any, figsize: Any = None, **options: Any) -> tuple[Any, Any]:
    """A figure and its axes, as ``pyplot.subplots`` gives them, without pyplot.

    Parameters
    ----------
    *grid
        Rows and columns.
    figsize : tuple, optional
        Inches.
    **options
        Passed to :meth:`matplotlib.figure.Figure.subplots` (``sharex``, ``height_ratios``...).

    Returns
    -------
    figure : matplotlib.figure.Figure
    axes : Axes or array of Axes

    Examples
    --------
    >>> drawn, axes = subplots(1, 2)
    >>> len(axes)
    2
    """
    drawn = figure(figsize=figsize)
    return drawn, drawn.subplots(*grid, **options)


class Plotting:
    """The few ``pyplot`` entry points unstack's plots use, on pyplot-free figures."""

    figure = staticmethod(figure)
    subplots = staticmethod(subplots)

    @property
    def cm(self) -> Any:
        """:mod:`matplotlib.cm` (colour maps, ``ScalarMappable``)."""
        import matplotlib.cm

        return matplotlib.cm

    @staticmethod
    def close(_figure: Any) -> None:
        """Nothing to close: no figure is registered anywhere."""


def pyplot() -> Plotting:
    """Plotting helpers in the shape of ``matplotlib.pyplot`` that leave the backend alone.

    Returns
    -------
    Plotting
        ``figure``, ``subplots``, ``cm`` and ``close``.

    Examples
    --------
    >>> import matplotlib
    >>> before = matplotlib.get_backend()
    >>> _ = pyplot().subplots()
    >>> matplotlib.get_backend() == before
    True
    """
    return Plotting()


def curve_labels(labels: Sequence[str], curves: Sequence[Any], *, tolerance: float = 1e-9) -> list[str]:
    """Legend labels that say when a curve coincides with an earlier one (it would be hidden under it).

    Parameters
    ----------
    labels : sequence of str
    curves : sequence of array-like
        The y values of each curve, on the same x values.
    tolerance : float
        Largest difference (relative to the largest value) that counts as the same curve.

    Returns
    -------
    list of str

    Examples
    --------
    >>> curve_labels(["free", "highest", "random"], [[0, 1, 2], [0, 1, 2], [0, 3, 5]])
    ['free', 'highest (same curve as free)', 'random']
    """
    import numpy as np

    arrays = [np.asarray(curve, dtype=np.float64) for curve in curves]
    scale = max((float(np.nanmax(np.abs(a))) for a in arrays if a.size and np.isfinite(a).any()), default=1.0)
    result = []
    for index, (label, values) in enumerate(zip(labels, arrays, strict=True)):
        twin = next(
            (
                labels[earlier]
                for earlier in range(index)
                if arrays[earlier].shape == values.shape
                and np.allclose(arrays[earlier], values, rtol=0.0, atol=tolerance * max(scale, 1e-300), equal_nan=True)
            ),
            None,
        )
        result.append(f"{label} (same curve as {twin})" if twin is not None else label)
    return result


def save_figure(drawn: Any, output: str | os.PathLike[str], *, dpi: int = 110) -> None:
    """Write ``drawn`` (a figure) atomically; the format follows the suffix (PNG, SVG, PDF).

    Parameters
    ----------
    drawn : matplotlib.figure.Figure
    output : str or path-like
    dpi : int

    Returns
    -------
    None
    """
    from unstack.atomic import atomic_save_figure

    atomic_save_figure(drawn, output, dpi=dpi)
