"""Judging a run: result columns, summary rows, safety / efficiency / comfort scores."""
