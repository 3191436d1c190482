"""ncap."""
