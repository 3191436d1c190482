"""Errors that reach the user as one clear message (exit code 2 at the command line)."""

from __future__ import annotations


class UserInputError(Exception):
    """Bad input from the user: a YAML field, a file or a command-line option. Message names the culprit."""
