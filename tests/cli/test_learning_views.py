"""The learning commands' tables: what a metric that a data set leaves undefined shows."""

from __future__ import annotations

from rich.console import Console

from unstack.cli.learning import metrics_view
from unstack.learning.metrics import classification_report


def test_a_metric_that_is_undefined_shows_as_n_a() -> None:
    report = {**classification_report([0, 0, 0], [0.2, 0.5, 0.9]), "balanced_error_rate": None}
    console = Console(width=100, record=True)
    console.print(metrics_view(report, "one class"))
    assert "balanced error rate (Eq. 16)  n/a" in console.export_text()
