"""Support features of a pair of boxes (§III-A, Eqs. 2-7).

* DBAF (Eq. 2): at an interest point ``cp``,
  ``f(cp) = 1/N * sum_k (2 pi sigma)^(-3/2) exp(-||cp - p_k||^2 / (2 sigma^2))``
  over the N points of the scene's cloud; the paper's constant is kept as printed.
* Interest points (Eq. 3): the centroid moved ``±d`` along each world axis, in the order
  ``+x, -x, +y, -y, +z, -z``; ``F_DBAF(X)`` is the DBAF at the six of them.
* ``F_BB(X, Y) = BB_X - BB_Y`` (Eqs. 4-5) with ``BB = [min xyz, max xyz]`` of the
  axis-aligned bounding box of the *rotated* cuboid.
* ``F_XY = [dcc, F_BB(X, Y), F_DBAF(X), F_DBAF(Y)]`` (Eq. 6): 19 numbers; ``F_YX`` swaps
  the roles (Eq. 7).

``FeatureSettings(feature_set="extended")`` appends the 17 contact features of
:mod:`unstack.learning.contact_features` (vertical gap, footprint overlap, heights, what the
cloud shows between and on the boxes): 36 numbers. ``"paper"`` (the default) is Eq. 6 alone.

The DBAF sums are computed by one of two methods, chosen by ``dbaf_method``:

``"direct"``
    The exact sum over every point, compiled with numba and run on all cores.
``"kdtree"``
    A ``scipy.spatial.cKDTree`` of the cloud, summing only the points within the radius
    ``r = sigma * sqrt(2 ln(1 / tolerance))`` of each interest point. Every left-out term
    is below ``tolerance`` times the largest possible term, so the absolute error of a
    DBAF value is below ``tolerance * (2 pi sigma)^(-3/2)``.
``"auto"`` (default)
    ``kdtree`` when the truncation ball covers a small part of the cloud's bounding box,
    otherwise ``direct``. With the paper's sigma = 0.5 m and a container-sized cloud the
    ball covers most of the cloud and ``direct`` is faster (measured in the benchmarks).

Examples
--------
>>> from unstack.scene import Box
>>> boxes = [Box("a", [0.6, 0.4, 0.4], [1.0, 0.0, 0.2]), Box("b", [0.4, 0.3, 0.3], [1.0, 0.0, 0.55])]
>>> points = np.array([[0.7, 0.0, 0.2], [0.8, 0.0, 0.55]])
>>> features = pair_features(boxes, points, [(0, 1), (1, 0)])
>>> features.shape
(2, 19)
>>> round(float(features[0, 0]), 6)  # dcc
0.35
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass

import numpy as np

from unstack.geometry import bounding_boxes
from unstack.scene import Box

__all__ = [
    "FEATURE_NAMES",
    "FEATURE_SETS",
    "FeatureSettings",
    "choose_dbaf_method",
    "dbaf",
    "dbaf_features",
    "feature_names",
    "interest_points",
    "pair_features",
]

#: Names of the 19 features of ``F_XY``, in order.
FEATURE_NAMES: tuple[str, ...] = (
    "dcc",
    *(f"bb_{edge}_{axis}" for edge in ("min", "max") for axis in "xyz"),
    *(f"dbaf_x_{k}" for k in ("+x", "-x", "+y", "-y", "+z", "-z")),
    *(f"dbaf_y_{k}" for k in ("+x", "-x", "+y", "-y", "+z", "-z")),
)
#: Feature sets of ``FeatureSettings.feature_set``: Eq. 6 alone, or Eq. 6 and the contact features.
FEATURE_SETS = ("paper", "extended", "general")
#: The longest interest-point offset and DBAF width the features take (metres): ten times the
#: paper's 1 m and 0.5 m, beyond any container's width.
MAX_FEATURE_LENGTH = 10.0
#: Interest points whose truncation ball covers more than this share of the cloud's
#: bounding box make ``"auto"`` use the direct sum.
KDTREE_MAX_COVER = 0.05


@dataclass(frozen=True)
class FeatureSettings:
    """Parameters of the support features (the paper's values by default).

    Read by :func:`pair_features` and :func:`feature_names`; a trained model carries the
    settings it was trained with (:class:`~unstack.learning.model_file.SupportModel`), so new
    scenes are described as its training scenes were.

    Attributes
    ----------
    offset : float
        ``d``: how far the interest points are from the centroid (metres).
    sigma : float
        Width of the DBAF's Gaussian (metres).
    dbaf_method : {"auto", "direct", "kdtree"}
        How the DBAF sums are computed (see the module docstring).
    tolerance : float
        Largest neglected term of the ``kdtree`` method, relative to the largest term.
    feature_set : {"paper", "extended", "general"}
        ``"paper"``: the 19 numbers of Eq. 6; ``"extended"``: those and the 17 contact
        features (:mod:`unstack.learning.contact_features`); ``"general"``: 15 features
        that do not depend on how the cloud was sampled
        (:mod:`unstack.learning.general_features`), without Eq. 6.
    """

    offset: float = 1.0
    sigma: float = 0.5
    dbaf_method: str = "auto"
    tolerance: float = 1e-9
    feature_set: str = "paper"

    def __post_init__(self) -> None:
        from unstack.errors import UnstackError

        for name, length in (("offset", self.offset), ("sigma", self.sigma)):
            if not (math.isfinite(length) and 0 < length <= MAX_FEATURE_LENGTH):
                raise UnstackError(f"feature settings need 0 < {name} <= {MAX_FEATURE_LENGTH:g} m, got {length}")
        if not 0 < self.tolerance < 1:
            raise UnstackError(f"feature settings need 0 < tolerance < 1, got {self.tolerance}")
        if self.dbaf_method not in ("auto", "direct", "kdtree"):
            raise UnstackError(f"unknown DBAF method {self.dbaf_method!r}; expected auto, direct or kdtree")
        if self.feature_set not in FEATURE_SETS:
            raise UnstackError(f"unknown feature set {self.feature_set!r}; expected one of {', '.join(FEATURE_SETS)}")

    def to_dict(self) -> dict[str, float | str]:
        """JSON-ready dict."""
        return asdict(self)


def feature_names(settings: FeatureSettings | None = None) -> tuple[str, ...]:
    """Names of the columns :func:`pair_features` returns with these settings.

    Examples
    --------
    >>> len(feature_names()), len(feature_names(FeatureSettings(feature_set="extended")))
    (19, 36)
    """
    from unstack.learning.contact_features import CONTACT_FEATURE_NAMES
    from unstack.learning.general_features import GENERAL_FEATURE_NAMES

    settings = settings or FeatureSettings()
    if settings.feature_set == "general":
        return GENERAL_FEATURE_NAMES
    return FEATURE_NAMES + (CONTACT_FEATURE_NAMES if settings.feature_set == "extended" else ())


def interest_points(boxes: Sequence[Box], offset: float = 1.0) -> np.ndarray:
    """The six interest points of every box (Eq. 3), shape (n, 6, 3).

    Examples
    --------
    >>> interest_points([Box("a", [1, 1, 1], [0, 0, 0])], offset=1.0)[0, 4].tolist()
    [0.0, 0.0, 1.0]
    """
    steps = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=np.float64)
    centroids = np.array([box.position for box in boxes], dtype=np.float64).reshape(-1, 1, 3)
    return centroids + offset * steps[None, :, :]


def _normaliser(sigma: float, n_points: int) -> float:
    return 1.0 / (n_points * math.sqrt((2.0 * math.pi * sigma) ** 3))


def _truncation_radius(sigma: float, tolerance: float) -> float:
    return sigma * math.sqrt(2.0 * math.log(1.0 / tolerance))


def _dbaf_kdtree(points: np.ndarray, queries: np.ndarray, sigma: float, tolerance: float) -> np.ndarray:
    from scipy.spatial import cKDTree

    tree = cKDTree(points)
    query_tree = cKDTree(queries)
    radius = _truncation_radius(sigma, tolerance)
    distances = query_tree.sparse_distance_matrix(tree, radius, output_type="coo_matrix")
    terms = np.exp(-(distances.data**2) / (2.0 * sigma**2))
    sums: np.ndarray = np.bincount(distances.row, weights=terms, minlength=len(queries)).astype(np.float64)
    # sparse_distance_matrix drops pairs at distance exactly 0: add them back (each term is 1)
    coincident = query_tree.query_ball_tree(tree, 0.0)
    exact_hits = np.array([len(found) for found in coincident], dtype=np.float64)
    sums = sums + exact_hits - np.bincount(distances.row[distances.data == 0.0], minlength=len(queries))
    return sums


def choose_dbaf_method(points: np.ndarray, sigma: float, tolerance: float) -> str:
    """``"kdtree"`` when the kernel's truncation ball covers a small part of the cloud, else ``"direct"``.

    Examples
    --------
    >>> cloud = np.random.default_rng(0).uniform(0, 2, size=(100, 3))
    >>> choose_dbaf_method(cloud, 0.5, 1e-9), choose_dbaf_method(cloud, 0.02, 1e-9)
    ('direct', 'kdtree')
    """
    extent = np.ptp(points, axis=0)
    volume = float(np.prod(np.maximum(extent, 2.0 * sigma)))
    ball = 4.0 / 3.0 * math.pi * _truncation_radius(sigma, tolerance) ** 3
    return "kdtree" if ball / volume < KDTREE_MAX_COVER else "direct"


def dbaf(
    points: np.ndarray,
    queries: np.ndarray,
    *,
    sigma: float = 0.5,
    method: str = "auto",
    tolerance: float = 1e-9,
) -> np.ndarray:
    """DBAF (Eq. 2) of a point cloud at each query point.

    Parameters
    ----------
    points : numpy.ndarray, shape (N, 3)
        The scene's cloud. An empty cloud gives zeros (the caller warns).
    queries : numpy.ndarray, shape (Q, 3)
    sigma : float
    method : {"auto", "direct", "kdtree"}
    tolerance : float
        See :class:`FeatureSettings`.

    Returns
    -------
    numpy.ndarray, shape (Q,)

    Examples
    --------
    >>> value = dbaf(np.zeros((1, 3)), np.zeros((1, 3)), sigma=0.5)
    >>> bool(np.isclose(value[0], 1 / np.sqrt((2 * np.pi * 0.5) ** 3)))
    True
    """
    points = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
    queries = np.ascontiguousarray(queries, dtype=np.float64).reshape(-1, 3)
    if len(points) == 0:
        return np.zeros(len(queries))
    chosen = choose_dbaf_method(points, sigma, tolerance) if method == "auto" else method
    if chosen == "kdtree":
        sums = _dbaf_kdtree(points, queries, sigma, tolerance)
    else:
        from unstack.learning._dbaf_kernel import gaussian_sums

        sums = gaussian_sums(points, queries, 1.0 / (2.0 * sigma**2))
    values: np.ndarray = sums * _normaliser(sigma, len(points))
    return values


def dbaf_features(boxes: Sequence[Box], points: np.ndarray, settings: FeatureSettings | None = None) -> np.ndarray:
    """``F_DBAF`` of every box, shape (n, 6)."""
    settings = settings or FeatureSettings()
    queries = interest_points(boxes, settings.offset).reshape(-1, 3)
    values = dbaf(points, queries, sigma=settings.sigma, method=settings.dbaf_method, tolerance=settings.tolerance)
    return values.reshape(len(boxes), 6)


def pair_features(
    boxes: Sequence[Box],
    points: np.ndarray,
    pairs: Sequence[tuple[int, int]],
    settings: FeatureSettings | None = None,
) -> np.ndarray:
    """``F_XY`` (Eq. 6) for each ordered pair ``(X, Y)`` of box indices, shape (len(pairs), 19).

    With ``settings.feature_set == "extended"`` the 17 contact features follow: shape
    (len(pairs), 36); with ``"general"`` only the 15 general features; columns named by
    :func:`feature_names`.
    """
    settings = settings or FeatureSettings()
    index = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    if settings.feature_set == "general":
        from unstack.learning.general_features import general_features

        return general_features(boxes, [(int(a), int(b)) for a, b in index])
    used = np.unique(index)
    local = {int(box): row for row, box in enumerate(used)}
    subset = [boxes[int(box)] for box in used]
    dbafs = dbaf_features(subset, points, settings)
    boxes_bb = bounding_boxes(subset)
    centroids = np.array([box.position for box in subset]).reshape(-1, 3)
    x = np.array([local[int(value)] for value in index[:, 0]], dtype=np.int64)
    y = np.array([local[int(value)] for value in index[:, 1]], dtype=np.int64)
    dcc = np.linalg.norm(centroids[x] - centroids[y], axis=1)
    paper = np.column_stack([dcc, boxes_bb[x] - boxes_bb[y], dbafs[x], dbafs[y]])
    if settings.feature_set == "paper":
        return paper
    from unstack.learning.contact_features import contact_features

    return np.column_stack([paper, contact_features(boxes, points, [(int(a), int(b)) for a, b in index])])
