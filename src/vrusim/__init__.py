"""vrusim: closed-loop simulation of vulnerable-road-user safety tests."""

__version__ = "0.1.0"
