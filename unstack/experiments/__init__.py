"""Experiments that reproduce the paper's results (§V) and go beyond them.

Each experiment reads existing data sets (made by ``unstack simulate``), is seeded, and
writes JSON results and PNG plots; ``unstack experiment NAME`` runs it.

Examples
--------
>>> from unstack.experiments import EXPERIMENTS
>>> sorted(EXPERIMENTS)
['decisions', 'fig5a', 'real7', 'table1']
"""

EXPERIMENTS = {
    "table1": "unstack.experiments.table1",
    "decisions": "unstack.experiments.decisions",
    "fig5a": "unstack.experiments.fig5a",
    "real7": "unstack.experiments.real7",
}

__all__ = ["EXPERIMENTS"]
