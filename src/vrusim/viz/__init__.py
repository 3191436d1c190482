"""Figures and terminal views of results."""
