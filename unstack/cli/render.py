"""Rich renderings of decisions, plans and payoff matrices for the terminal.

Box ids are shown as plain text with control characters escaped: an id never becomes
rich markup or a terminal escape sequence.
"""

from __future__ import annotations

from typing import Any

from rich.console import Group
from rich.table import Table
from rich.text import Text

from unstack.cli.text import printable
from unstack.reasoner.decision import HIGH_RHAT, Decision
from unstack.reasoner.payoff import PayoffMatrix
from unstack.reasoner.plan import Plan

__all__ = ["decision_view", "payoff_view", "plan_view"]


def _id(box: str) -> Text:
    """A box id as a table cell: never markup, never a control sequence."""
    return Text(printable(box))


def _number(value: float) -> str:
    """An expected cost or its error: four decimals, or three significant digits for a value
    too small to show in four (masses of grams, or a unit error, stay readable)."""
    return f"{value:.4f}" if value == 0 or abs(value) >= 1e-3 else f"{value:.3g}"


#: Above this many boxes the support matrix is left to the JSON output.
MATRIX_MAX_BOXES = 12


def decision_view(decision: Decision, cloud: bool = True) -> Group:
    """The choice and where it is, what the cost counts, every box's expected cost, the
    conditional support matrix, and the model, method and evidence it rests on (``cloud``:
    whether the undetected load came from a point cloud, a scene's, or from a supports file)."""
    from unstack.describe import COST_UNITS, cost_in_words, model_in_words, place_in_words

    index = {box: i for i, box in enumerate(decision.objects)}
    order = [index[box] for box, _, _ in decision.ranking()]  # the pick first, then by EC
    costs = Table()
    costs.add_column("rank", justify="right")
    costs.add_column("box")
    costs.add_column(f"EC ({COST_UNITS.get(decision.cost, 'cost')})", justify="right")
    sampled = decision.sampling is not None and decision.expected_cost_errors is not None
    if sampled:
        costs.add_column("± s.e.", justify="right")
    costs.add_column("")
    for rank, i in enumerate(order, start=1):
        box = decision.objects[i]
        mark = "<- unload first" if box == decision.choice else ("tie" if box in decision.ties else "")
        error = [] if not sampled else [_number(float(decision.expected_cost_errors[i]))]  # type: ignore[index]
        costs.add_row(str(rank), _id(box), _number(float(decision.expected_costs[i])), *error, mark)
    matrix: Table | Text
    if len(decision.objects) <= MATRIX_MAX_BOXES:
        matrix = Table(title="P(row supports column | consistent world)", title_justify="left")
        matrix.add_column("supports ->")
        for box in decision.objects:
            matrix.add_column(_id(box), justify="right")
        for i, box in enumerate(decision.objects):
            cells = ["-" if i == j else f"{decision.marginals[i, j]:.3f}" for j in range(len(decision.objects))]
            matrix.add_row(_id(box), *cells)
    else:
        matrix = Text(f"({len(decision.objects)} boxes: P(row supports column | consistent world) is in --json)")
    headline = Text.assemble(("Unload first: ", "bold"), (printable(decision.choice), "bold green"))
    near = decision.near_tie_margin
    if decision.choice_probability < 1.0 or decision.sampling is not None:
        what = f"within {near:g} of the minimum EC" if near else "the minimum EC"
        what = f"below {decision.free_cost:g}" if decision.free_cost else what
        headline.append(f"  (P(truly {what}) = {decision.choice_probability:.3f})")
    if len(decision.ties) > 1:
        others = ", ".join(printable(t) for t in decision.ties if t != decision.choice)
        vetoed = decision.physics_veto is not None and decision.physics_veto["vetoed"]
        rule = "expected to move as few in the belief; the box resting highest wins" if vetoed else None
        rule = rule or _tie_rule(near, decision.free_cost)
        headline.append(f"  (tied with {others}: {rule})")
    if decision.pick is not None:
        headline.append(f"\nwhere: {place_in_words(decision.pick)}")
    headline.append(f"\nEC, the expected {cost_in_words(decision.cost, cloud=cloud)}", style="dim")
    parts: list[Any] = [headline]
    if decision.physics_veto is not None:
        parts.append(_physics(decision.physics_veto, decision.choice))
    if decision.reasons:
        parts.append(_why(decision, COST_UNITS.get(decision.cost, "boxes"), cloud))
    return Group(*parts, costs, matrix, _footer(decision, model_in_words(decision.model)))


def _footer(decision: Decision, model: str) -> Text:
    """What the decision rests on: the model, the method, hard evidence, the sampler's run."""
    worlds = "" if decision.consistent_worlds is None else f", {decision.consistent_worlds:,} consistent worlds"
    evidence = decision.evidence
    hard = (
        f"hard evidence (probabilities 0 or 1): {len(evidence.forced)} forced, {len(evidence.forbidden)} forbidden"
        if evidence.forced or evidence.forbidden
        else "no hard evidence"
    )
    groups = (
        f", {len(decision.components)} independent groups (largest {max(len(g) for g in decision.components)})"
        if len(decision.components) > 1 and any(len(group) > 1 for group in decision.components)
        else ""
    )
    footer = Text(
        f"support model: {model}\nmethod {decision.method}{worlds}{groups}; {hard}; {decision.seconds:.3f} s",
        style="dim",
    )
    if decision.sampling is not None:
        seed = decision.sampling["seed"]
        seeded = f"seed {seed}" if seed is not None else "no seed (a run differs slightly; --seed 0 repeats one)"
        footer.append(
            f"\nsampled: {sum(decision.sampling['samples']):,} sweeps in {decision.sampling['chains']} chains per "
            f"group, {seeded}, largest R-hat {decision.sampling['rhat_max']} (near 1 when the chains agree; "
            f"above {HIGH_RHAT} they have not mixed); ± s.e. are standard errors (about "
            f"95 % of true values lie within 2 of them; --samples {4 * max(decision.sampling['samples'])} halves them)"
        )
    return footer


def _physics(record: dict[str, Any], choice: str) -> Text:
    """What physics on the belief expected the pick, and the boxes tried instead, to move."""
    if "skipped" in record:
        count = len(record["skipped"])
        poses = "1 pose cannot" if count == 1 else f"{count} poses cannot"
        return Text(f"physics on what the robot sees: not applied, {poses} stand as reported (see the warning); "
                    f"the reasoner's pick {printable(choice)} is kept\n")  # fmt: skip
    tried = record["tried"]
    pick = tried[0]
    text = Text(
        f"physics on what the robot sees: in {record['worlds']} belief worlds taking {printable(pick['box'])} moved "
        f"{pick['expected_moved']:.2f} boxes on average"
    )
    if not record["vetoed"]:
        text.append(f" (a veto at {record['veto_at']:g}): kept\n")
        return text
    others = ", ".join(f"{printable(item['box'])} {item['expected_moved']:.2f}" for item in tried[1:])
    text.append(f" (a veto at {record['veto_at']:g}): vetoed")
    text.append(
        f"; tried instead {others}; {printable(choice)} moves the fewest\n"
        if others
        else "; no box holding nothing up to take instead\n"
    )
    return text


def _why(decision: Decision, unit: str, cloud: bool) -> Text:
    """Why the pick and the runner-up cost what they cost: their EC (in ``unit``) and the
    relations and load that drive it (the load from the point cloud, or from the file)."""
    from unstack.reasoner.reasons import MAY_HOLD_PROBABILITY

    by_box = {reason["box"]: reason for reason in decision.reasons}
    ranked = sorted(decision.objects, key=lambda box: (box != decision.choice, by_box[box]["expected_moves"], box))
    text = Text()
    for label, box in zip(("pick", "runner-up"), ranked[:2], strict=False):
        reason = by_box[box]
        drivers = [f"{printable(box)} holds up {printable(other)}: P {p:.2f}" for other, p in reason["holds_up"]]
        if "may_hold_up" in reason:  # none named: the likeliest, and how many make the cost together
            other, p, count = reason["may_hold_up"]
            among = f", one of {count} at P {MAY_HOLD_PROBABILITY:.2f} or more" if count > 1 else ""
            drivers.append(f"{printable(box)} may hold up {printable(other)}: P {p:.2f}{among}")
        if reason["hidden_load"] >= 0.05:
            shown = "the cloud shows" if cloud else "the file's hidden_load puts"
            drivers.append(f"{shown} {reason['hidden_load']:.2f} undetected boxes on it")
        if reason["held_by"] is not None and reason["held_by"][1] >= 0.5:
            drivers.append(f"held up by {printable(reason['held_by'][0])}: P {reason['held_by'][1]:.2f}")
        nothing = "it holds up no detected box and " + ("the cloud shows no load on it" if cloud else "carries no load")
        because = "; ".join(drivers) if drivers else nothing
        text.append(f"{label} {printable(box)}: EC {reason['expected_moves']:.2f} {unit} ({because})\n")
    return text


def payoff_view(table: PayoffMatrix, limit: int) -> Group:
    """Table II: the most probable consistent worlds with the cost of each action."""
    objects = table.objects
    worlds = table.worlds
    order = sorted(range(len(worlds)), key=lambda i: -worlds.probabilities[i])[:limit]
    view = Table(
        title="Payoff matrix (Table II): consistent worlds, P(w), cost of unloading each box", title_justify="left"
    )
    view.add_column("world", justify="right")
    view.add_column("P(w)", justify="right")
    view.add_column("support relations")
    for box in objects:
        view.add_column(_id(f"A:{box}"), justify="right")
    for i in order:
        relations = [f"{objects[x]}>{objects[y]}" for x, y in zip(*worlds.worlds[i].nonzero(), strict=True)]
        view.add_row(
            str(i + 1),
            f"{worlds.probabilities[i]:.4g}",
            _id(" ".join(relations) or "(none)"),
            *(f"{c:g}" for c in table.costs[i]),
        )
    expected = table.expected_costs()
    view.add_section()
    view.add_row("EC", "", "", *(_number(float(c)) for c in expected))
    shown = (
        f"showing the {len(order)} most probable of {len(worlds):,} consistent worlds"
        if len(order) < len(worlds)
        else f"{len(worlds):,} consistent worlds"
    )
    note = Text(f"{shown}; 'x>y' means x supports y", style="dim")
    return Group(view, note)


def plan_view(result: Plan, cloud: bool = True) -> Group:
    """The unloading order, one row per pick, with errors when steps were sampled, and what
    the columns mean (``cloud``: whether the undetected load came from a point cloud)."""
    from unstack.describe import cost_in_words

    table = Table(title="Unloading plan (each step decided on the boxes still in place)", title_justify="left")
    sampled = any(step.decision.sampling is not None for step in result.steps)
    columns = ("step", "unload", "EC", *(("± s.e.", "P(minimum)") if sampled else ()), "boxes in place")
    for column in columns:
        table.add_column(column, justify="right" if column != "unload" else "left")
    for number, step in enumerate(result.steps, start=1):
        errors = (_number(step.expected_cost_error), f"{step.decision.choice_probability:.3f}") if sampled else ()
        table.add_row(str(number), _id(step.choice), _number(step.expected_cost), *errors, str(len(step.remaining)))
    if not result.steps:
        return Group(table)
    cost = cost_in_words(result.steps[0].decision.cost, cloud=cloud)
    note = f"EC: the expected cost of the pick among the boxes in place, {cost}"
    if sampled:
        note += (
            "; ± s.e.: its standard error (the step was sampled); P(minimum): the probability that the pick "
            "truly has the lowest EC at its step (the sampler's certainty of the ranking, not that the pick moves "
            "nothing: that is what the EC says)"
        )
        free = {step.decision.free_cost for step in result.steps if step.decision.free_cost}
        if free:
            note += f" (at a step that took the highest box below {min(free):g}: that its EC is truly below it)"
    return Group(table, Text(note, style="dim"))


def _tie_rule(margin: float, free_cost: float) -> str:
    """How the choice was made among the tied boxes, in words."""
    if free_cost:
        return (
            f"EC below {free_cost:g}, so more likely than not holding nothing up; the box whose centre is highest wins "
            "(on equal heights, the larger id)"
        )
    if margin:
        return f"EC within {margin:g} of the lowest; the box resting highest wins, on one layer the lowest EC"
    return "smallest id wins"
