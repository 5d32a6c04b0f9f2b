"""The one-call API a planner codes against (``decide``, ``plan``, ``load_model`` and
``support_probabilities`` are re-exported by :mod:`unstack`; ``payoff`` and ``model_names``
are called from here: ``unstack.api.payoff``).

``load_model`` names a shipped model or reads a model file; ``support_probabilities`` turns
a scene into support probabilities with a model (the default one when none is given);
``decide`` and ``plan`` take a scene or support probabilities and return a
:class:`~unstack.reasoner.decision.Decision` or a :class:`~unstack.reasoner.plan.Plan`;
``payoff`` lists the consistent worlds of a small scene with the cost of each action (Table II).

Light by design: deciding on support probabilities imports neither scikit-learn nor the
learning package; they load only when a scene needs probabilities. The shipped models are
loaded once per process (thread-safe) and shared: treat them as read-only.

Examples
--------
>>> import unstack
>>> supports = unstack.Supports(["top", "bottom"], [[0, 0.1], [0.9, 0]])
>>> unstack.decide(supports).choice
'top'
>>> unstack.plan(supports).order
['top', 'bottom']
"""

from __future__ import annotations

import os
import threading
import weakref
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, Union

from unstack.errors import InvalidArgument, ModelRequired
from unstack.reasoner.decision import DEFAULT_COST, Decision
from unstack.reasoner.plan import Plan
from unstack.scene import Box, Scene
from unstack.supports import Supports

if TYPE_CHECKING:
    from unstack.learning.model_file import SupportModel

__all__ = ["decide", "load_model", "model_label", "model_names", "payoff", "plan", "support_probabilities"]

ModelArgument = Union[None, str, os.PathLike[str], "SupportModel"]

_LOCK = threading.Lock()
#: Shipped models loaded so far: file path -> ((size, mtime), model).
_SHIPPED: dict[str, tuple[tuple[int, int], SupportModel]] = {}
#: What each loaded model is called in provenance metadata (by ``id``; dropped with the model).
_LABELS: dict[int, str] = {}
#: A lock per shipped model file, held while it is read: concurrent first loads read it once.
_LOADING: dict[str, threading.Lock] = {}


def model_names() -> tuple[str, ...]:
    """The names of the models shipped with the package (what :func:`load_model` accepts besides files).

    Returns
    -------
    tuple of str
        Read at call time from :data:`unstack.learning.model_file.BUNDLED_MODELS`.

    Examples
    --------
    >>> "paper" in model_names()
    True
    """
    from unstack.learning.model_file import BUNDLED_MODELS

    return tuple(BUNDLED_MODELS)


def _remember(model: SupportModel, label: str) -> SupportModel:
    key = id(model)
    with _LOCK:
        if key not in _LABELS:
            weakref.finalize(model, _LABELS.pop, key, None)
        _LABELS[key] = label
    return model


def _shipped(path: Path) -> SupportModel:
    """A shipped model, loaded once per process however many threads ask for it first (reloaded
    if the file changes); named ``default:`` when it is the default model, however it was asked
    for (by ``None`` or by its name), so a decision's provenance does not depend on which
    came first."""
    from unstack.learning.model_file import default_model_path
    from unstack.learning.model_file import load_model as read_model

    try:
        status = path.stat()
    except OSError:
        raise ModelRequired(
            f"the shipped model {path.name} is not installed; load a model file instead (unstack train makes one)"
        ) from None
    stamp = (status.st_size, status.st_mtime_ns)
    with _LOCK:
        loading = _LOADING.setdefault(str(path), threading.Lock())
    with loading:  # one thread reads the file; the others wait for its model, named before it is shared
        with _LOCK:
            cached = _SHIPPED.get(str(path))
        if cached is not None and cached[0] == stamp:
            return cached[1]
        kind = "default" if path == default_model_path() else "shipped"
        model = _remember(read_model(path), f"{kind}:{path.name}")
        with _LOCK:
            _SHIPPED[str(path)] = (stamp, model)
    return model


def load_model(name_or_path: str | os.PathLike[str] | None = None) -> SupportModel:
    """A support model: a shipped one by name, or a model file (``unstack.model/1``).

    Parameters
    ----------
    name_or_path : str or path-like, optional
        A name of :func:`model_names` (``"paper"``, ``"extended"``, ...) or the path of a
        model file; ``None`` is the default model
        (:func:`unstack.learning.model_file.default_model_path`). A file named like a
        shipped model is reached with a path such as ``"./paper"``.

    Returns
    -------
    SupportModel
        Shipped models are loaded once per process and shared (read-only).

    Raises
    ------
    InvalidArgument
        ``name_or_path`` is neither a string nor a path.
    ModelRequired
        The shipped model is not installed.
    InvalidModel
        The file is missing, unreadable or not an unstack model (loading never runs code
        from it).

    Examples
    --------
    >>> model = load_model("paper")
    >>> model.features.feature_set
    'paper'
    >>> load_model("paper") is model
    True
    """
    from unstack.learning import model_file

    if name_or_path is None:
        return _shipped(model_file.default_model_path())
    if not isinstance(name_or_path, str | os.PathLike):
        raise InvalidArgument(f"expected a model name or a model file path, got {type(name_or_path).__name__}")
    name = os.fspath(name_or_path)
    if isinstance(name_or_path, str) and name in model_file.BUNDLED_MODELS:
        return _shipped(model_file.bundled_model_path(name))
    if isinstance(name_or_path, str) and not os.path.exists(name) and os.sep not in name and "." not in name:
        shipped = ", ".join(model_names())
        raise model_file.InvalidModel(name, "$", f"no shipped model and no file of that name (shipped: {shipped})")
    return _remember(model_file.load_model(name), name)


def model_label(model: SupportModel) -> str:
    """How a model loaded by :func:`load_model` is named in provenance metadata.

    Parameters
    ----------
    model : SupportModel

    Returns
    -------
    str
        ``"default:FILE"``, ``"shipped:FILE"``, the path it was loaded from, or ``""``
        for a model built in memory.

    Examples
    --------
    >>> model_label(load_model("extended"))
    'shipped:extended-paper2.skops'
    """
    return _LABELS.get(id(model), "")


def _model(model: Any) -> SupportModel:
    """A loaded model from what a caller passed as ``model``."""
    if model is None or isinstance(model, str | os.PathLike):
        return load_model(model)
    if not (hasattr(model, "support_probability") and hasattr(model, "features")):
        raise InvalidArgument(
            f"model must be a model name, a model file path or a SupportModel, got {type(model).__name__}"
        )
    loaded: SupportModel = model
    return loaded


def support_probabilities(scene: Scene, model: ModelArgument = None, *, statics: bool = True) -> Supports:
    """``P(SUPP(X, Y))`` for every ordered pair of a scene's detected boxes, from a model.

    Parameters
    ----------
    scene : Scene
        Its detected boxes become the objects, in that order.
    model : str, path-like or SupportModel, optional
        A shipped model's name, a model file, or a loaded model; ``None``: the default
        model (loaded once per process).
    statics : bool
        Raise the probability that a box holds up another where statics says the other
        cannot stand without it -- a box leaning on it, a box across a gap on it
        (:mod:`unstack.understanding.statics`; each raise is a warning); ``False``: the model's
        probabilities alone.

    Returns
    -------
    Supports
        With the scene, the model and its warnings (``metadata["warnings"]``) recorded in
        the metadata.

    Raises
    ------
    InvalidArgument
        ``scene`` is not a :class:`~unstack.scene.Scene`, or ``model`` is of the wrong type.

    Examples
    --------
    >>> import unstack
    >>> supports = support_probabilities(unstack.load_scene("examples/pile5.scene.json"))
    >>> supports.n_objects, supports.metadata["model"].startswith("default:")
    (5, True)
    """
    if not isinstance(scene, Scene):
        raise InvalidArgument(f"expected a Scene, got {type(scene).__name__}")
    from unstack.pipeline import scene_support_probabilities
    from unstack.reasoner.arguments import check_flag

    statics = check_flag(statics, "statics")
    _refuse_changed_poses(scene)
    loaded = _model(model)
    return scene_support_probabilities(scene, loaded, model_name=model_label(loaded), statics=statics)


def _refuse_changed_poses(scene: Scene) -> None:
    """A box whose arrays were changed in place after the scene was made (they stay writeable:
    scipy's ``Rotation.apply`` refuses read-only arrays, and a planner hands a box's position to
    it) to a pose the scene's checks refuse -- not finite, a quaternion far from unit length, a
    size no carton has, a coordinate beyond :data:`~unstack.checks.MAX_COORDINATE`: one line
    naming it, not numbers that no check saw."""
    from unstack.errors import InvalidScene

    for index, box in enumerate(scene.boxes):
        try:
            Box(box.id, box.size, box.position, box.orientation_xyzw, box.mass, source=scene.source,
                path=f"$.boxes[{index}]")  # fmt: skip
        except InvalidScene as error:
            raise InvalidArgument(f"{error} (changed in place after the scene was made)") from None


def _supports(scene_or_supports: Any, model: Any, statics: bool = True) -> Supports:
    from unstack.reasoner.arguments import check_flag

    statics = check_flag(statics, "statics")
    if isinstance(scene_or_supports, Supports):
        if model is not None:
            raise InvalidArgument(
                f"{scene_or_supports.source}: a model turns a scene into support probabilities; these are "
                "support probabilities already, so the model would be ignored (pass no model)"
            )
        if statics is not True:
            raise InvalidArgument(
                f"{scene_or_supports.source}: statics adjusts the probabilities a model gives a scene; these are "
                "support probabilities already, so statics=False would be ignored"
            )
        return scene_or_supports
    if isinstance(scene_or_supports, Scene):
        return support_probabilities(scene_or_supports, model, statics=statics)
    raise InvalidArgument(f"expected a Scene or Supports, got {type(scene_or_supports).__name__}")


def payoff(scene_or_supports: Scene | Supports, model: ModelArgument = None, *, cost: str = "count") -> Any:
    """The payoff matrix (Table II): every consistent world, its probability and each action's cost.

    Parameters
    ----------
    scene_or_supports : Scene or Supports
        A scene (its probabilities come from ``model``) or support probabilities.
    model : str, path-like or SupportModel, optional
        For a scene only (default: the default model).
    cost : {"count", "mass", "load"}
        Eq. 11's count of supported boxes, their mass, or :func:`decide`'s ``load`` (each box with
        the hidden load on it, the box taken out with its own: the same expected costs).

    Returns
    -------
    PayoffMatrix
        Lists the worlds with a SAT solver: for small scenes (up to
        :data:`~unstack.reasoner.worlds.SAT_MAX_BOXES` boxes).

    Examples
    --------
    >>> import unstack
    >>> table = payoff(unstack.Supports(["top", "bottom"], [[0, 0.1], [0.9, 0]]))
    >>> len(table.worlds), table.expected_costs().round(2).tolist()
    (4, [0.1, 0.9])
    """
    from unstack.reasoner.payoff import payoff_matrix

    return payoff_matrix(_supports(scene_or_supports, model), cost=cost)


def decide(
    scene_or_supports: Scene | Supports,
    *,
    model: ModelArgument = None,
    method: str = "auto",
    cost: str = DEFAULT_COST,
    seed: int | None = None,
    samples: int | None = None,
    time_limit: float | None = None,
    near_tie_margin: float | None = None,
    free_cost: float | None = None,
    statics: bool = True,
    disturbance: Any = None,
    physics_veto: bool = False,
) -> Decision:
    """Which box to unload first: from a scene (through a model) or from support probabilities.

    Parameters
    ----------
    scene_or_supports : Scene or Supports
        A scene gets its probabilities from ``model`` (:func:`support_probabilities`).
    model : str, path-like or SupportModel, optional
        For a scene only (an error with support probabilities); ``None``: the default model.
    method : {"auto", "exact", "sat", "approx"}
        See :func:`unstack.reasoner.decision.decide`.
    cost : {"load", "count", "mass", "moves"}
        ``load`` (the default): Eq. 11 with every box counted together with the undetected
        load the cloud shows on it; ``count``: Eq. 11 exactly; ``mass``: their total mass;
        ``moves`` (a scene only): the boxes the pick is expected to move, from the learned
        disturbance model (:mod:`unstack.moves`).
    seed : int, optional
        Seed of the sampler: with it (and no ``time_limit``) the numbers are identical on
        every run, whatever the machine's load.
    samples : int, optional
        Recorded sweeps per sampled group (default
        :func:`~unstack.reasoner.sampling.default_samples` of its size).
    time_limit : float, optional
        Seconds for the whole decision instead of a fixed number of sweeps (not reproducible).
    near_tie_margin : float, optional
        Boxes whose expected cost is within this many boxes of the lowest count as tied, and
        the one resting highest is taken (boxes resting on one layer: the lowest cost). Default: 0.05
        (:data:`~unstack.reasoner.decision.NEAR_TIE_MARGIN`) for a scene (and for supports
        that carry heights), the minimum EC (Eq. 12) for supports without heights; 0 keeps Eq. 12
        exactly.
    free_cost : float, optional
        For a scene: the highest detected box (its centre) whose expected cost is below this
        is taken -- it holds nothing up (:func:`unstack.height_veto.free_highest`); when none
        is, the reasoner's choice. Default: 0.5 (:data:`~unstack.height_veto.FREE_COST`),
        0 with ``near_tie_margin=0`` (Eq. 12); 0 leaves the choice to the reasoner. Support
        probabilities (no box centres) and the ``moves`` cost take none.
    statics : bool
        For a scene: raise the probability that a box holds up another that cannot stand
        without it (:func:`support_probabilities`); ``False`` keeps the model's probabilities.
    disturbance : path-like or DisturbanceModel, optional
        With ``cost="moves"``: the disturbance model (default: the shipped one).
    physics_veto : bool
        For a scene, with the physics engine installed (``unstack[sim]``): try the pick in
        belief worlds built from the scene and, where it is expected to move a box, take the
        box holding nothing up expected to move the fewest (:func:`unstack.physics_veto.physics_veto`,
        seeded by ``seed``; 0.3-2 s on simulated piles of 5-40 boxes; not applied, with a warning,
        where the scene's poses cannot stand as reported). Not with support probabilities or
        the ``moves`` cost.

    Returns
    -------
    Decision
        ``choice``, ``expected_costs``, :meth:`~unstack.reasoner.decision.Decision.ranking`,
        :meth:`~unstack.reasoner.decision.Decision.to_dict`, ``warnings``.

    Raises
    ------
    InvalidArgument
        A wrong type or an argument out of its domain (also a :class:`ValueError`).
    NoConsistentWorld
        Hard evidence contradicts transitivity.
    TooLarge
        ``method`` cannot do the scene, or with ``time_limit`` a linked group's least sampling
        cannot come near the time left for it (hundreds of linked boxes with a limit of a
        second: the first sweeps tell, and the message says what the group needs).

    Examples
    --------
    >>> import unstack
    >>> decision = decide(unstack.load("examples/pile5.scene.json"))
    >>> decision.choice == decision.ranking()[0][0]
    True
    >>> decide(unstack.Supports(["a", "b"], [[0, 0.2], [0.7, 0]]), seed=0).choice
    'a'
    """
    from unstack.reasoner.arguments import check_flag, check_margin
    from unstack.reasoner.decision import decide as decide_supports

    if free_cost is not None:
        free_cost = check_margin(free_cost, "free_cost")
    physics_veto = check_flag(physics_veto, "physics_veto")
    veto_scene = _physics_veto_scene(scene_or_supports, cost) if physics_veto else None
    supports = _supports(scene_or_supports, model, statics)
    if cost == "moves":
        if not isinstance(scene_or_supports, Scene):
            raise InvalidArgument(
                f"{supports.source}: the moves cost reads the scene's poses and cloud; support probabilities "
                "alone are decided on load, count or mass"
            )
        if free_cost:
            raise InvalidArgument(
                "free_cost takes the highest box that holds nothing up by its expected load; the moves cost ties by "
                "near_tie_margin alone"
            )
        from unstack.moves import decide_on_moves

        decision: Decision = decide_on_moves(
            scene_or_supports,
            supports,
            disturbance=disturbance,
            near_tie_margin=near_tie_margin,
            method=method,
            seed=seed,
            samples=samples,
            time_limit=time_limit,
        )
    else:
        if disturbance is not None:
            raise InvalidArgument("a disturbance model is used by the moves cost only; pass cost='moves'")
        decision = decide_supports(
            supports,
            method=method,
            cost=cost,
            seed=seed,
            samples=samples,
            time_limit=time_limit,
            near_tie_margin=near_tie_margin,
        )
        decision = _free_highest(decision, scene_or_supports, supports, free_cost, near_tie_margin)
        decision = _doubting_free_cost(decision, supports, free_cost)
        if isinstance(scene_or_supports, Scene):  # statics ran here; a file's metadata is free-form
            decision = _statics_outweighed(decision, supports)
    if veto_scene is not None:
        from unstack.height_veto import FREE_COST
        from unstack.physics_veto import physics_veto as vetoed

        seeded = 0 if seed is None else seed
        decision = vetoed(decision, veto_scene, seed=seeded, free_cost=decision.free_cost or FREE_COST)
    return _described(decision, scene_or_supports, supports)


def _physics_veto_scene(given: Scene | Supports, cost: str) -> Scene:
    """The scene a physics veto runs on, refused before any work where it cannot run: no poses,
    or the moves cost."""
    if not isinstance(given, Scene):
        raise InvalidArgument(
            f"{given.source}: the physics veto builds the boxes' poses and the cloud in the engine, which support "
            "probabilities do not give; use the scene file"
        )
    if cost == "moves":
        raise InvalidArgument("the physics veto tries the pick of a cost that counts boxes held up; not the moves cost")
    return given


def _free_highest(
    decision: Decision,
    given: Scene | Supports,
    supports: Supports,
    free_cost: float | None,
    near_tie_margin: float | None,
) -> Decision:
    """The default pick on a scene: the highest free box (:func:`unstack.height_veto.free_highest`),
    a box statics found holding another up not counted free."""
    from unstack.height_veto import FREE_COST, free_highest

    if not isinstance(given, Scene):
        if free_cost:
            raise InvalidArgument(
                f"{given.source}: free_cost takes the highest box by its centre, which support probabilities do not "
                "give; use the scene file"
            )
        return decision
    if free_cost is None:
        free_cost = 0.0 if near_tie_margin == 0 else FREE_COST
    found = {  # of the boxes still in place (a plan's later steps)
        (str(finding["supporter"]), str(finding["held"]))
        for finding in supports.metadata.get("tip_supports", [])
        if {finding["supporter"], finding["held"]} <= set(decision.objects)
    }
    # two boxes found holding each other up contradict each other (poses off): neither is taken as held
    holding = {supporter for supporter, held in found if (held, supporter) not in found}
    return free_highest(decision, given, free_cost=free_cost, holding=holding)


def _doubting_free_cost(decision: Decision, supports: Supports, free_cost: float | None) -> Decision:
    """The decision warning when a free cost given is above every expected cost the boxes can have."""
    import dataclasses

    from unstack.reasoner.costs import margin_beyond_every_cost

    doubt = margin_beyond_every_cost(supports, decision.cost, "free_cost", free_cost)
    if doubt is None:
        return decision
    return dataclasses.replace(decision, warnings=(*decision.warnings, supports.named(doubt)))


def _statics_outweighed(decision: Decision, supports: Supports) -> Decision:
    """The decision warning where statics found a box holding another up that the consistent
    worlds then make unlikely: the raise said 0.65, the decision rests on the lower figure.

    ``supports`` comes from :func:`support_probabilities` on a scene in this call (its
    ``metadata["tip_supports"]`` is statics' own finding), never from a file: a supports file's
    metadata is free-form."""
    import dataclasses

    position = {box_id: k for k, box_id in enumerate(decision.objects)}
    said = []
    for found in supports.metadata.get("tip_supports", []):
        supporter, held = str(found["supporter"]), str(found["held"])
        if supporter not in position or held not in position:
            continue
        final = float(decision.marginals[position[supporter], position[held]])
        if final < 0.5:
            reverse = float(decision.marginals[position[held], position[supporter]])
            said.append(
                supports.named(
                    f"statics found that {held!r} cannot stand without {supporter!r}, but over the consistent worlds "
                    f"P({supporter} supports {held}) is {final:.2f} (raised to 0.65 before; P({held} supports "
                    f"{supporter}) {reverse:.2f}): the decision takes the lower figure; {supporter!r} may hold "
                    f"{held!r} up"
                )
            )
    return dataclasses.replace(decision, warnings=(*decision.warnings, *said)) if said else decision


def _described(decision: Decision, given: Scene | Supports, supports: Supports) -> Decision:
    """The decision with the support model it rests on and where its pick is."""
    import dataclasses

    from unstack.describe import pick_place

    model = str(supports.metadata.get("model", "")) if isinstance(given, Scene) else ""
    return dataclasses.replace(decision, model=model, pick=pick_place(given, decision.choice))


def plan(
    scene_or_supports: Scene | Supports,
    *,
    model: ModelArgument = None,
    method: str = "auto",
    cost: str = DEFAULT_COST,
    seed: int | None = None,
    samples: int | None = None,
    time_limit: float | None = None,
    progress: Callable[[int, int], None] | None = None,
    near_tie_margin: float | None = None,
    free_cost: float | None = None,
    statics: bool = True,
) -> Plan:
    """An unloading order: decide, take the chosen box out, decide again on the rest.

    Parameters
    ----------
    scene_or_supports : Scene or Supports
        A scene gets its probabilities from ``model`` once, before the first step.
    model, method, cost, seed, samples, time_limit, near_tie_margin, free_cost, statics
        As in :func:`decide` (the budget applies to each step, and on a scene each step takes
        the highest box holding nothing up as :func:`decide` does; without a budget each step
        samples :data:`~unstack.reasoner.plan.PLAN_SAMPLES` sweeps per group, from where
        the previous step's chains ended).
    progress : callable, optional
        ``progress(done, total)`` after every step.

    Returns
    -------
    Plan
        ``order``, ``steps`` and :meth:`~unstack.reasoner.plan.Plan.to_dict`.

    Raises
    ------
    InvalidArgument
        A wrong type or an argument out of its domain.
    TooLarge
        As in :func:`decide`, at a step.

    Examples
    --------
    >>> import unstack
    >>> supports = unstack.Supports(["top", "middle", "bottom"], [[0, 0.05, 0.02], [0.9, 0, 0.1], [0.8, 0.95, 0]])
    >>> plan(supports).order
    ['top', 'middle', 'bottom']
    """
    from unstack.reasoner.plan import unloading_plan

    if cost == "moves":
        raise InvalidArgument(
            "the moves cost decides the next pick on a scene as sensed now (a robot senses again after each "
            "pick); a plan is made on load, count or mass"
        )
    from unstack.reasoner.arguments import check_margin

    if free_cost is not None:
        free_cost = check_margin(free_cost, "free_cost")
    supports = _supports(scene_or_supports, model, statics)
    return unloading_plan(
        supports,
        method=method,
        cost=cost,
        seed=seed,
        samples=samples,
        time_limit=time_limit,
        progress=progress,
        near_tie_margin=near_tie_margin,
        choose_step=lambda decision: _doubting_free_cost(
            _free_highest(decision, scene_or_supports, supports, free_cost, near_tie_margin), supports, free_cost
        ),
    )
