"""Shared helpers of the command-line tests: invoke the app and check a user error."""

from __future__ import annotations

from typer.testing import CliRunner

from vrusim.cli.app import app

runner = CliRunner()


def invoke(*args):
    """Run `vrusim ARGS...` in-process; exceptions other than exit codes propagate."""
    return runner.invoke(app, [str(a) for a in args], catch_exceptions=False)


def assert_user_error(result, *names: str) -> None:
    """Exit 2, every name in the output, no traceback, nothing on stdout."""
    assert result.exit_code == 2, result.output
    for name in names:
        assert name in result.output, (name, result.output)
    assert "Traceback" not in result.output
    assert result.stdout == ""
