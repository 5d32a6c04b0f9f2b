"""Experiments that reproduce the paper's results (§V) and go beyond them.

Each experiment reads existing data sets (made by ``unstack simulate``), is seeded, and
writes JSON results and plots; ``unstack experiment NAME`` runs it. One module per
experiment: ``table1``, ``fig5a``, ``decisions`` (Fig. 4), ``real7``, ``unloading``,
``generalisation`` (with ``canonical_scenes``).
"""
