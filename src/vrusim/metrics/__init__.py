"""Judging a run: result columns, summary rows, collision severity, injury risk, surrogate safety measures, scores."""
